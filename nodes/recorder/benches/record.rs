//! Recorder throughput: 200,000 axis-state-sized messages (about the size of `AxisState` with
//! two axes) through `McapWriter` with each compression, chunks closed every 1 MiB as the bag
//! does, then `audit::verify_file` over the result. The reference is copying the same message
//! bytes into one buffer, timed in the same run; the ratio says how much the MCAP layout,
//! compression and hashing cost over moving the bytes.

use std::collections::BTreeMap;
use std::time::Instant;

use cnc_recorder::audit::verify_file;
use cnc_recorder::chain::Chain;
use cnc_recorder::mcap::Compression;
use cnc_recorder::schema::ros2msg;
use cnc_recorder::writer::McapWriter;

const MESSAGES: u64 = 200_000;
const SIZE: usize = 120;

fn message(i: u64) -> Vec<u8> {
    let mut m = vec![0u8, 1, 0, 0];
    // Slowly changing positions, as a real axis topic has.
    for k in 0..(SIZE - 4) / 8 {
        m.extend((((i / 4) as f64 * 0.001 + k as f64).to_bits()).to_le_bytes());
    }
    m
}

fn main() {
    let payloads: Vec<Vec<u8>> = (0..1024).map(message).collect();
    // Reference: the bytes copied once.
    let t = Instant::now();
    let mut copy: Vec<u8> = Vec::with_capacity(MESSAGES as usize * SIZE);
    for i in 0..MESSAGES {
        copy.extend_from_slice(&payloads[(i % 1024) as usize]);
    }
    let reference = t.elapsed().as_secs_f64();
    std::hint::black_box(&copy);
    println!(
        "reference copy: {:.0} messages/s ({} MB)",
        MESSAGES as f64 / reference,
        copy.len() / 1_000_000
    );
    let schema = ros2msg("cnc_msgs/msg/AxisState").unwrap_or_default();
    for c in [Compression::None, Compression::Lz4, Compression::Zstd] {
        let t = Instant::now();
        let mut w = match McapWriter::new(Vec::new(), c, Chain::new()) {
            Ok(w) => w,
            Err(e) => panic!("{e}"),
        };
        let ch = w
            .add_channel(
                "/m/axes",
                "cnc_msgs/msg/AxisState",
                &schema,
                BTreeMap::new(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
        for i in 0..MESSAGES {
            let p = &payloads[(i % 1024) as usize];
            w.write(ch, i * 4_000_000, i * 4_000_000, p)
                .unwrap_or_else(|e| panic!("{e}"));
            if w.open_chunk_bytes() >= 1 << 20 {
                w.close_chunk().unwrap_or_else(|e| panic!("{e}"));
            }
        }
        let (bytes, stats, _) = w.finish().unwrap_or_else(|e| panic!("{e}"));
        let write = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let verified = verify_file("bench", &bytes, [0; 32]);
        let verify = t.elapsed().as_secs_f64();
        assert_eq!(verified.map(|v| v.1), Ok(stats.chunks as u64));
        println!(
            "{:>4}: write {:.0} messages/s ({:.2}x the copy's time), file {:.1} MB ({:.0} % of raw), {} chunks; audit verify {:.0} MB/s",
            if c.name().is_empty() { "none" } else { c.name() },
            MESSAGES as f64 / write,
            write / reference,
            bytes.len() as f64 / 1e6,
            100.0 * bytes.len() as f64 / copy.len() as f64,
            stats.chunks,
            bytes.len() as f64 / 1e6 / verify
        );
    }
}
