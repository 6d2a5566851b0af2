//! Samples as bytes: a DDS reader or writer that leaves the CDR payload undecoded, for the
//! service servers (which must look at the bytes to tell the two service mappings apart), the
//! recorder and replay.

use ros2_client::dds::rustdds::{bytes::Bytes, no_key, RepresentationIdentifier};

/// Payload bytes as they travel, without the encapsulation header.
#[derive(Debug)]
pub struct Raw {
    pub bytes: Vec<u8>,
    pub little_endian: bool,
}

pub struct RawAdapter;

impl no_key::DeserializerAdapter<Raw> for RawAdapter {
    type Error = std::io::Error;
    type Decoded = Raw;
    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &[
            RepresentationIdentifier::CDR_LE,
            RepresentationIdentifier::CDR_BE,
        ]
    }
    fn transform_decoded(decoded: Raw) -> Raw {
        decoded
    }
}

impl no_key::DefaultDecoder<Raw> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}

#[derive(Clone)]
pub struct RawDecoder;

impl<'de> no_key::Decode<'de, Raw> for RawDecoder {
    type Error = std::io::Error;
    fn decode_bytes(
        self,
        input: &'de [u8],
        encoding: RepresentationIdentifier,
    ) -> Result<Raw, Self::Error> {
        Ok(Raw {
            bytes: input.to_vec(),
            little_endian: encoding != RepresentationIdentifier::CDR_BE,
        })
    }
}

impl no_key::SerializerAdapter<Raw> for RawAdapter {
    type Error = std::io::Error;
    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }
    fn to_bytes(value: &Raw) -> Result<Bytes, Self::Error> {
        Ok(Bytes::from(value.bytes.clone()))
    }
}

impl Raw {
    /// The payload as rosbag2 stores it: the 4-byte encapsulation header, then the CDR bytes.
    pub fn serialized(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(4 + self.bytes.len());
        out.extend_from_slice(if self.little_endian {
            &[0, 1, 0, 0]
        } else {
            &[0, 0, 0, 0]
        });
        out.extend_from_slice(&self.bytes);
        out
    }

    /// A serialized message (header and CDR) as a little-endian sample; `None` for anything
    /// else (big-endian or not CDR), which the writer could not label correctly.
    pub fn from_serialized(data: &[u8]) -> Option<Raw> {
        match data {
            [0, 1, _, _, rest @ ..] => Some(Raw {
                bytes: rest.to_vec(),
                little_endian: true,
            }),
            _ => None,
        }
    }
}
