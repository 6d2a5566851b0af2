//! ROS 2 service mappings, decided per request.
//!
//! rmw_cyclonedds puts a 16-byte header (client GUID half + sequence number) in front of the
//! request payload and expects it echoed in the reply; rmw_fastrtps-style (DDS-RPC "enhanced")
//! requests carry no header, and the reply names the request in the `related_sample_identity`
//! inline QoS. Requests from both arrive on the same topic, so each is classified by its bytes:
//! a payload that decodes exactly as the request type is enhanced; one that decodes exactly after
//! a 16-byte header is Cyclone. A ros2-client Cyclone client also sets `related_sample_identity`
//! with the header's sequence number, which settles the rare payload that fits both.

use byteorder::{BigEndian, LittleEndian};
use serde::de::DeserializeOwned;

/// How a request came, and so how its reply goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mapping {
    Enhanced,
    /// The 16-byte header to echo.
    Cyclone([u8; 16]),
}

/// Decodes `bytes` as exactly one `T` (up to 3 bytes of final alignment padding).
pub fn decode_exact<T: DeserializeOwned>(bytes: &[u8], little_endian: bool) -> Option<T> {
    let result = if little_endian {
        cdr_encoding::from_bytes::<T, LittleEndian>(bytes)
    } else {
        cdr_encoding::from_bytes::<T, BigEndian>(bytes)
    };
    match result {
        Ok((value, used))
            if used <= bytes.len()
                && bytes.len() - used <= 3
                && bytes[used..].iter().all(|&b| b == 0) =>
        {
            Some(value)
        }
        _ => None,
    }
}

/// Sequence number in a Cyclone header: `seq_high: i32`, `seq_low: u32` after 8 GUID bytes.
fn header_seq(header: &[u8], little_endian: bool) -> i64 {
    let (hi, lo) = if little_endian {
        (
            i32::from_le_bytes([header[8], header[9], header[10], header[11]]),
            u32::from_le_bytes([header[12], header[13], header[14], header[15]]),
        )
    } else {
        (
            i32::from_be_bytes([header[8], header[9], header[10], header[11]]),
            u32::from_be_bytes([header[12], header[13], header[14], header[15]]),
        )
    };
    ((hi as i64) << 32) | lo as i64
}

/// Classifies a request payload. `related_seq` is the sequence number of the sample's
/// `related_sample_identity`, if it had one.
pub fn classify<T: DeserializeOwned>(
    bytes: &[u8],
    little_endian: bool,
    related_seq: Option<i64>,
) -> Option<(Mapping, T)> {
    let with_header = || -> Option<(Mapping, T)> {
        if bytes.len() < 16 {
            return None;
        }
        let value = decode_exact::<T>(&bytes[16..], little_endian)?;
        let mut header = [0u8; 16];
        header.copy_from_slice(&bytes[..16]);
        Some((Mapping::Cyclone(header), value))
    };
    if let Some(seq) = related_seq {
        if bytes.len() >= 16 && header_seq(&bytes[..16], little_endian) == seq {
            if let Some(found) = with_header() {
                return Some(found);
            }
        }
    }
    if let Some(value) = decode_exact::<T>(bytes, little_endian) {
        return Some((Mapping::Enhanced, value));
    }
    with_header()
}

/// The mapping of a request that does not decode, so that its refusal reaches the client: a
/// Cyclone header whose sequence number matches the sample's `related_sample_identity` says
/// Cyclone; anything else is answered as enhanced.
pub fn guess_mapping(bytes: &[u8], little_endian: bool, related_seq: Option<i64>) -> Mapping {
    match related_seq {
        Some(seq) if bytes.len() >= 16 && header_seq(&bytes[..16], little_endian) == seq => {
            let mut header = [0u8; 16];
            header.copy_from_slice(&bytes[..16]);
            Mapping::Cyclone(header)
        }
        _ => Mapping::Enhanced,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cnc_msgs::srv::{ResetRequest, StartProgramRequest, StopRequest};

    fn cdr<T: serde::Serialize>(v: &T) -> Vec<u8> {
        cdr_encoding::to_vec::<_, LittleEndian>(v).unwrap()
    }

    fn cyclone(seq: u32, payload: &[u8]) -> Vec<u8> {
        let mut b = vec![1, 2, 3, 4, 5, 6, 7, 8];
        b.extend(0i32.to_le_bytes());
        b.extend(seq.to_le_bytes());
        b.extend(payload);
        b
    }

    #[test]
    fn both_mappings_of_every_request_type_are_told_apart() {
        for name in [
            "p",
            "part7.nc",
            "O0001",
            "a_longer_program_name_with_digits_0123456789",
        ] {
            let req = StartProgramRequest { name: name.into() };
            let plain = cdr(&req);
            assert_eq!(
                classify::<StartProgramRequest>(&plain, true, None),
                Some((Mapping::Enhanced, req.clone()))
            );
            let cy = cyclone(42, &plain);
            let (m, v) = classify::<StartProgramRequest>(&cy, true, None).unwrap();
            assert_eq!(v, req);
            assert!(matches!(m, Mapping::Cyclone(h) if h[..8] == [1, 2, 3, 4, 5, 6, 7, 8]));
        }
        let reset = cdr(&ResetRequest::default());
        assert_eq!(
            classify::<ResetRequest>(&reset, true, None).map(|x| x.0),
            Some(Mapping::Enhanced)
        );
        assert!(matches!(
            classify::<ResetRequest>(&cyclone(1, &reset), true, None),
            Some((Mapping::Cyclone(_), _))
        ));
        let stop = cdr(&StopRequest { mode: 2 });
        assert!(matches!(
            classify::<StopRequest>(&cyclone(9, &stop), true, Some(9)),
            Some((Mapping::Cyclone(_), StopRequest { mode: 2 }))
        ));
    }

    #[test]
    fn an_undecodable_request_is_answered_in_the_mapping_its_identity_names() {
        let bad = cyclone(5, &[3, 0, 0, 0, 0xc3, 0x28, 0, 0]);
        assert!(matches!(
            guess_mapping(&bad, true, Some(5)),
            Mapping::Cyclone(h) if h[..8] == [1, 2, 3, 4, 5, 6, 7, 8]
        ));
        assert_eq!(guess_mapping(&bad, true, Some(6)), Mapping::Enhanced);
        assert_eq!(guess_mapping(&bad, true, None), Mapping::Enhanced);
        assert_eq!(guess_mapping(&[1, 2], true, Some(0)), Mapping::Enhanced);
    }

    #[test]
    fn garbage_is_rejected_not_guessed() {
        assert_eq!(
            classify::<StartProgramRequest>(&[0xff; 7], true, None),
            None
        );
        assert_eq!(classify::<StartProgramRequest>(&[], true, None), None);
        // Invalid UTF-8 in the string.
        let mut bad = vec![3, 0, 0, 0, 0xc3, 0x28, 0];
        bad.push(0);
        assert_eq!(classify::<StartProgramRequest>(&bad, true, None), None);
    }
}
