//! recorder node shell: one undecoded subscriber per recorded topic on the machine bus, each
//! sample written as the node published it (encapsulation header and CDR, what DDS carries)
//! into the bag under `recorder.directory/<namespace>_<UTC start time>/`. The bag holds what
//! the machine's nodes published, never what a foreign participant wrote on a topic of the
//! same name (the bus is not on the network).

use std::path::PathBuf;
use std::time::Duration;

use cnc_runtime::bus::RawSubscription;
use cnc_runtime::clock::wall_ns;
use cnc_runtime::dds::RosNode;
use cnc_runtime::topics::{self, Topic};
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::bag::{offered_qos, rotate, Bag, BagOptions, BagTopic};
use crate::mcap::Compression;

/// The topics of `cfg` the recorder records: those its machine publishes that the config
/// does not leave out.
pub fn recorded_topics(cfg: &LaunchConfig) -> Vec<Topic> {
    topics::published_by(cfg)
        .into_iter()
        .filter(|t| cfg.recorder.records(t.path))
        .collect()
}

pub fn compression(name: &str) -> Result<Compression, String> {
    match name {
        "zstd" => Ok(Compression::Zstd),
        "lz4" => Ok(Compression::Lz4),
        "none" => Ok(Compression::None),
        other => Err(format!("unknown compression {other:?}: zstd, lz4 or none")),
    }
}

/// `2026-11-21 10:15:00 UTC` → `20261121T101500Z`, from nanoseconds since the epoch.
pub fn utc_stamp(ns: u64) -> String {
    let secs = ns / 1_000_000_000;
    let (days, rest) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}{m:02}{d:02}T{:02}{:02}{:02}Z",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    )
}

/// Runs the recorder until shutdown; returns the bag folder it wrote.
pub fn run(cfg: LaunchConfig, shutdown: Shutdown) -> Result<PathBuf, String> {
    run_then(cfg, shutdown, || {})
}

/// [`run`], calling `subscribed` once every topic has its subscriber on the machine bus: a
/// node started after that loses none of its samples to the recording (the bus keeps no
/// history for late subscribers beyond a state's last value).
pub fn run_then(
    cfg: LaunchConfig,
    shutdown: Shutdown,
    subscribed: impl FnOnce(),
) -> Result<PathBuf, String> {
    let rc = &cfg.recorder;
    let ns = cfg.machine.namespace.clone();
    let ros = RosNode::new(&cfg.network, &ns, "recorder")?;
    let recorded = recorded_topics(&cfg);
    let mut readers: Vec<RawSubscription> = Vec::new();
    let mut bag_topics = Vec::new();
    for t in &recorded {
        readers.push(ros.bus().raw_subscription(t)?);
        bag_topics.push(BagTopic {
            name: format!("/{ns}/{}", t.path),
            type_name: t.type_name.into(),
            qos: offered_qos(t.delivery),
        });
    }
    subscribed();
    let options = BagOptions {
        compression: compression(&rc.compression)?,
        flush_ns: rc.flush_ms * 1_000_000,
        split_bytes: rc.split_mib << 20,
        split_ns: rc.split_seconds * 1_000_000_000,
    };
    let start = wall_ns();
    let name = format!("{ns}_{}", utc_stamp(start));
    let mut bag = Bag::create(&rc.directory, &name, bag_topics, options, start)?;
    let bag_dir = bag.dir().to_path_buf();
    log::info!(
        "recorder: {} topics into {}",
        recorded.len(),
        bag_dir.display()
    );
    let cap = rc.max_total_mib << 20;
    let rotate_now = |dir: &PathBuf| match rotate(&rc.directory, cap, dir) {
        Ok(deleted) => {
            for d in deleted {
                log::info!("recorder: deleted old bag {}", d.display());
            }
        }
        Err(e) => log::warn!("recorder: rotation: {e}"),
    };
    rotate_now(&bag_dir);
    let mut files = 1;
    let mut last_error = String::new();
    loop {
        // Stop only after a last drain, so what arrived before shutdown is kept.
        let stopping = shutdown.requested();
        let mut took = 0;
        for (i, reader) in readers.iter().enumerate() {
            while let Ok(Some((data, published))) = reader.take() {
                took += 1;
                if let Err(e) = bag.record(i, wall_ns(), published, &data) {
                    if e != last_error {
                        log::error!("recorder: {e}");
                        last_error = e;
                    }
                }
            }
        }
        if let Err(e) = bag.tick(wall_ns()) {
            if e != last_error {
                log::error!("recorder: {e}");
                last_error = e;
            }
        }
        if bag.file_count() != files {
            files = bag.file_count();
            rotate_now(&bag_dir);
        }
        if stopping {
            break;
        }
        if took == 0 {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    bag.close()?;
    Ok(bag_dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_stamps() {
        assert_eq!(utc_stamp(0), "19700101T000000Z");
        // 2026-11-21 10:15:30 UTC.
        assert_eq!(utc_stamp(1_795_256_130 * 1_000_000_000), "20261121T101530Z");
        // 2000-02-29 23:59:59 UTC (leap day).
        assert_eq!(utc_stamp(951_868_799 * 1_000_000_000), "20000229T235959Z");
    }
}
