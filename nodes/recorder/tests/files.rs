//! MCAP files as the recorder writes them, read back by its own reader; the audit chain against
//! every single flipped byte; recovery of a file cut off at every byte.

use std::collections::BTreeMap;

use cnc_recorder::audit::verify_file;
use cnc_recorder::chain::Chain;
use cnc_recorder::mcap::Compression;
use cnc_recorder::reader::scan;
use cnc_recorder::recover::repair;
use cnc_recorder::schema::ros2msg;
use cnc_recorder::writer::McapWriter;

/// A file with two topics and `chunks` chunks of 5 messages; returns the bytes and, per
/// chunk, the offset just past its audit link.
fn sample(compression: Compression, chunks: u64) -> (Vec<u8>, Vec<usize>) {
    let mut w = McapWriter::new(Vec::new(), compression, Chain::new()).unwrap();
    let a = w
        .add_channel(
            "/lathe1/spindle",
            "cnc_msgs/msg/SpindleState",
            &ros2msg("cnc_msgs/msg/SpindleState").unwrap(),
            BTreeMap::new(),
        )
        .unwrap();
    let b = w
        .add_channel(
            "/lathe1/alarms",
            "cnc_msgs/msg/ActiveAlarms",
            &ros2msg("cnc_msgs/msg/ActiveAlarms").unwrap(),
            BTreeMap::new(),
        )
        .unwrap();
    let mut ends = Vec::new();
    for c in 0..chunks {
        for i in 0..5u64 {
            let t = 1_000_000_000 * c + i * 1000;
            let payload: Vec<u8> = [0u8, 1, 0, 0]
                .into_iter()
                .chain((0..40).map(|k| (k + i + c) as u8))
                .collect();
            w.write(if i % 2 == 0 { a } else { b }, t, t, &payload)
                .unwrap();
        }
        w.close_chunk().unwrap();
        ends.push(w.position() as usize);
    }
    let (bytes, stats, _) = w.finish().unwrap();
    assert_eq!(stats.messages, 5 * chunks);
    assert_eq!(stats.chunks as u64, chunks);
    (bytes, ends)
}

#[test]
fn a_finished_file_reads_back_whole_with_every_compression() {
    for c in [Compression::None, Compression::Zstd, Compression::Lz4] {
        let (bytes, _) = sample(c, 3);
        let s = scan(&bytes).unwrap();
        assert!(s.has_footer, "{c:?}");
        assert_eq!(s.problem, None);
        assert_eq!(s.messages.len(), 15);
        assert_eq!(s.channels.len(), 2);
        assert_eq!(s.links.len(), 3);
        assert_eq!(
            s.messages.iter().filter(|m| m.channel == 1).count(),
            9,
            "{c:?}"
        );
        // Sequence numbers count per channel.
        let seqs: Vec<u32> = s
            .messages
            .iter()
            .filter(|m| m.channel == 2)
            .map(|m| m.sequence)
            .collect();
        assert_eq!(seqs, (1..=6).collect::<Vec<_>>());
        assert_eq!(verify_file("f", &bytes, [0; 32]).map(|x| x.1), Ok(3));
    }
}

#[test]
fn every_flipped_byte_of_the_data_section_is_reported() {
    let (bytes, _) = sample(Compression::Zstd, 3);
    let s = scan(&bytes).unwrap();
    let data_end = s.data_end.unwrap() as usize;
    for at in 8..data_end {
        let mut bad = bytes.clone();
        bad[at] ^= 0x01;
        assert!(
            verify_file("f", &bad, [0; 32]).is_err(),
            "flip at byte {at} of {data_end} not detected"
        );
    }
    // The summary is protected by its CRC.
    let summary_at = data_end + 13;
    let mut bad = bytes.clone();
    bad[summary_at + 20] ^= 0x40;
    assert!(verify_file("f", &bad, [0; 32])
        .unwrap_err()
        .contains("summary"));
    // A file that does not start from the previous file's last hash breaks the chain.
    assert!(verify_file("f", &bytes, [1; 32])
        .unwrap_err()
        .contains("does not continue"));
}

#[test]
fn a_file_cut_at_any_byte_is_repaired_up_to_its_last_link() {
    let (bytes, ends) = sample(Compression::Lz4, 4);
    let s = scan(&bytes).unwrap();
    let data_end = s.data_end.unwrap() as usize;
    let header_end = 8 + 9 + 8 + 4 + cnc_recorder::writer::LIBRARY.len();
    for cut in header_end..data_end {
        let (fixed, messages) = repair(&bytes[..cut]).unwrap();
        let closed = ends.iter().filter(|&&e| e <= cut).count();
        assert_eq!(messages, 5 * closed as u64, "cut at {cut}");
        let r = scan(&fixed).unwrap();
        assert!(r.has_footer && r.problem.is_none(), "cut at {cut}");
        assert_eq!(r.messages.len(), 5 * closed);
        assert_eq!(r.messages[..], s.messages[..5 * closed]);
        assert_eq!(
            verify_file("f", &fixed, [0; 32]).map(|x| x.1),
            Ok(closed as u64),
            "cut at {cut}"
        );
    }
    assert!(repair(b"not mcap").is_err());
}
