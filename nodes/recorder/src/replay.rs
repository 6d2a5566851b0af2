//! `cnc replay BAG`: publishes a recording on DDS again, each message at its original offset
//! from the first (scaled by a speed factor), with the bytes it was recorded with.
//!
//! A replay goes to a namespace of its own (default: the recorded one with `_replay` after
//! it), so it never drives the machine it was recorded on: the recording holds the internal
//! command topics too, and a replay into the live namespace would start programs.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::RosNode;
use cnc_runtime::raw::{Raw, RawAdapter};
use cnc_runtime::topics;
use ros2_client::dds::rustdds::{no_key::DataWriter, DataWriterStatus, QosPolicies, StatusEvented};
use ros2_client::qos::History;

use crate::reader::scan_file;
use crate::recover::bag_files;

/// One message to send: where in the table of topics, when, what.
struct Scheduled {
    log_time: u64,
    topic: usize,
    data: Vec<u8>,
}

/// What a replay did.
#[derive(Debug, Default)]
pub struct ReplayReport {
    pub namespace: String,
    pub sent: u64,
    /// Messages of topics that are not in the machine's table, or not little-endian CDR.
    pub skipped: u64,
    pub seconds: f64,
}

/// `/lathe1/spindle` → (`lathe1`, index of `spindle` in [`topics::ALL`]).
fn place(full: &str) -> Option<(String, usize)> {
    let rest = full.strip_prefix('/')?;
    let (ns, path) = rest.split_once('/')?;
    let i = topics::ALL.iter().position(|t| t.path == path)?;
    Some((ns.to_string(), i))
}

/// How to replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions {
    /// Namespace to publish under; default `<recorded>_replay`.
    pub namespace: Option<String>,
    /// 1 = recorded timing; 2 = twice as fast.
    pub speed: f64,
    /// Start only once this topic (path under the namespace, e.g. `axes`) has a reader, up to
    /// [`WAIT_LIMIT`]: without it, messages sent before discovery are lost to a late viewer.
    pub wait_for: Option<String>,
}

/// History of each replay writer.
const REPLAY_DEPTH: usize = 64;

/// Longest wait for `wait_for`'s reader.
pub const WAIT_LIMIT: Duration = Duration::from_secs(10);

/// Replays `bag` (a bag folder or one file) on `network`.
pub fn replay(
    bag: &Path,
    network: &NetworkConfig,
    options: &ReplayOptions,
    stop: &dyn Fn() -> bool,
) -> Result<ReplayReport, String> {
    let (namespace, speed) = (options.namespace.as_deref(), options.speed);
    if !(speed.is_finite() && speed > 0.0) {
        return Err(format!("speed {speed}: must be a positive number"));
    }
    let files = if bag.is_dir() {
        bag_files(bag)?
    } else {
        vec![bag.to_path_buf()]
    };
    let mut report = ReplayReport::default();
    let mut recorded_ns: Option<String> = None;
    let mut schedule = Vec::new();
    for f in &files {
        let (_, s) = scan_file(f)?;
        let mut where_of: BTreeMap<u16, usize> = BTreeMap::new();
        for ch in &s.channels {
            if let Some((ns, i)) = place(&ch.topic) {
                recorded_ns.get_or_insert(ns);
                where_of.insert(ch.id, i);
            }
        }
        for m in s.messages {
            match where_of.get(&m.channel) {
                Some(&topic) => schedule.push(Scheduled {
                    log_time: m.log_time,
                    topic,
                    data: m.data,
                }),
                None => report.skipped += 1,
            }
        }
    }
    schedule.sort_by_key(|m| m.log_time);
    let target = match namespace {
        Some(n) => n.to_string(),
        None => format!("{}_replay", recorded_ns.as_deref().unwrap_or("machine")),
    };
    report.namespace = target.clone();
    let mut ros = RosNode::new(network, &target, "replay")?;
    let participant = ros.participant();
    let mut writers: BTreeMap<usize, DataWriter<Raw, RawAdapter>> = BTreeMap::new();
    for m in &schedule {
        if writers.contains_key(&m.topic) {
            continue;
        }
        let t = &topics::ALL[m.topic];
        // Deeper than the machine's own writers: a replay burst must survive a lost packet
        // (a depth-1 writer would have replaced it before the resend) and a reader that
        // matches a moment after the writer.
        let qos: QosPolicies = (&t.qos().history(History::KeepLast {
            depth: REPLAY_DEPTH,
        }))
            .into();
        let dds_topic = ros.dds_topic(t)?;
        let publisher = participant
            .create_publisher(&qos)
            .map_err(|e| format!("replay {}: {e:?}", t.path))?;
        let w = publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&dds_topic, Some(qos))
            .map_err(|e| format!("replay {}: {e:?}", t.path))?;
        writers.insert(m.topic, w);
    }
    // Give discovery a moment, as `ros2 bag play` does, so the first messages find readers.
    std::thread::sleep(Duration::from_millis(500));
    if let Some(path) = &options.wait_for {
        let i = topics::ALL
            .iter()
            .position(|t| t.path == path)
            .ok_or_else(|| format!("--wait-for {path}: not a topic of the machine"))?;
        let w = writers
            .get(&i)
            .ok_or_else(|| format!("--wait-for {path}: the recording has no such messages"))?;
        let t0 = Instant::now();
        let mut readers = 0;
        while readers == 0 {
            while let Some(status) = w.try_recv_status() {
                if let DataWriterStatus::PublicationMatched { current, .. } = status {
                    readers = current.count();
                }
            }
            if readers == 0 && (t0.elapsed() > WAIT_LIMIT || stop()) {
                return Err(format!("no reader of {path} within {WAIT_LIMIT:?}"));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        // The writer has seen the reader; give the reader as long to see the writer, or it
        // drops the first samples as coming from nobody it knows.
        std::thread::sleep(Duration::from_millis(500));
    }
    let first = schedule.first().map_or(0, |m| m.log_time);
    let start = Instant::now();
    for m in schedule {
        let due = Duration::from_nanos(((m.log_time - first) as f64 / speed) as u64);
        while start.elapsed() < due {
            if stop() {
                report.seconds = start.elapsed().as_secs_f64();
                return Ok(report);
            }
            std::thread::sleep(
                due.saturating_sub(start.elapsed())
                    .min(Duration::from_millis(20)),
            );
        }
        let (Some(raw), Some(w)) = (Raw::from_serialized(&m.data), writers.get(&m.topic)) else {
            report.skipped += 1;
            continue;
        };
        match w.write(raw, None) {
            Ok(()) => report.sent += 1,
            Err(e) => {
                log::warn!("replay: {e:?}");
                report.skipped += 1;
            }
        }
    }
    // The last messages may still be on their way: leaving now would drop the participant
    // under them.
    for w in writers.values() {
        let _ = w.wait_for_acknowledgments(Duration::from_secs(2));
    }
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}
