//! A rosbag2 bag: a folder with numbered `.mcap` files and the `metadata.yaml` that ROS 2's
//! `ros2 bag` and the `rosbags` library read. The bag cuts files by size and age, keeps the
//! audit chain running across them, rewrites `metadata.yaml` at every flush, and deletes the
//! oldest bags of the records folder when it grows past its cap. Time comes in from the
//! caller (nanoseconds since the epoch), so the bag itself reads no clock.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};

use crate::chain::Chain;
use crate::mcap::Compression;
use crate::writer::{FileStats, McapWriter};

/// Open chunks are written once they hold this much, whatever the flush interval.
const CHUNK_BYTES: usize = 1 << 20;

/// One topic of the bag.
#[derive(Debug, Clone, PartialEq)]
pub struct BagTopic {
    /// Full ROS name, `/lathe1/spindle`.
    pub name: String,
    /// `cnc_msgs/msg/SpindleState`.
    pub type_name: String,
    /// rosbag2's `offered_qos_profiles` (YAML text).
    pub qos: String,
}

#[derive(Debug, Clone)]
pub struct BagOptions {
    pub compression: Compression,
    pub flush_ns: u64,
    pub split_bytes: u64,
    pub split_ns: u64,
}

/// One file of the bag as `metadata.yaml` lists it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FileInfo {
    pub path: String,
    pub stats: FileStats,
    /// Channel id → topic index, in this file.
    pub channels: BTreeMap<u16, usize>,
}

/// Everything `metadata.yaml` says.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BagInfo {
    pub topics: Vec<BagTopic>,
    pub files: Vec<FileInfo>,
}

impl BagInfo {
    pub fn to_yaml(&self) -> String {
        let mut per_topic = vec![0u64; self.topics.len()];
        let (mut start, mut end, mut total) = (u64::MAX, 0u64, 0u64);
        for f in &self.files {
            for (ch, n) in &f.stats.per_channel {
                if let Some(&t) = f.channels.get(ch) {
                    per_topic[t] += n;
                }
            }
            if let Some(s) = f.stats.start_time {
                start = start.min(s);
                end = end.max(f.stats.end_time);
            }
            total += f.stats.messages;
        }
        if start == u64::MAX {
            start = 0;
        }
        let q = |s: &str| {
            let escaped = s
                .replace('\\', "\\\\")
                .replace('"', "\\\"")
                .replace('\n', "\\n");
            format!("\"{escaped}\"")
        };
        let mut y = String::from("rosbag2_bagfile_information:\n  version: 8\n");
        y += "  storage_identifier: mcap\n  relative_file_paths:\n";
        for f in &self.files {
            y += &format!("    - {}\n", q(&f.path));
        }
        y += &format!(
            "  duration:\n    nanoseconds: {}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {total}\n",
            end.saturating_sub(start)
        );
        y += "  topics_with_message_count:\n";
        for (t, n) in self.topics.iter().zip(&per_topic) {
            y += &format!(
                "    - topic_metadata:\n        name: {}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: {}\n        type_description_hash: \"\"\n      message_count: {n}\n",
                q(&t.name),
                q(&t.type_name),
                q(&t.qos)
            );
        }
        y += "  compression_format: \"\"\n  compression_mode: \"\"\n  files:\n";
        for f in &self.files {
            let s = f.stats.start_time.unwrap_or(0);
            y += &format!(
                "    - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {s}\n      duration:\n        nanoseconds: {}\n      message_count: {}\n",
                q(&f.path),
                f.stats.end_time.saturating_sub(s),
                f.stats.messages
            );
        }
        y += "  custom_data: ~\n  ros_distro: \"\"\n";
        y
    }

    pub fn write(&self, dir: &Path) -> Result<(), String> {
        cnc_runtime::persist::write_atomic(&dir.join("metadata.yaml"), &self.to_yaml())
    }
}

/// rosbag2's QoS text for a topic of this delivery.
pub fn offered_qos(delivery: cnc_runtime::topics::Delivery) -> String {
    use cnc_runtime::topics::Delivery;
    // rmw enums: history 1 keep last; reliability 1 reliable; durability 1 transient local,
    // 2 volatile.
    let (depth, durability) = match delivery {
        Delivery::State => (1, 1),
        Delivery::Events(n) => (n, 2),
        Delivery::Commands => (1024, 2),
    };
    format!(
        "- history: 1\n  depth: {depth}\n  reliability: 1\n  durability: {durability}\n  deadline:\n    sec: 0\n    nsec: 0\n  lifespan:\n    sec: 0\n    nsec: 0\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 0\n    nsec: 0\n  avoid_ros_namespace_conventions: false"
    )
}

struct OpenFile {
    writer: McapWriter<File>,
    started_ns: u64,
    /// Topic index → channel id in this file.
    channels: BTreeMap<usize, u16>,
}

/// A bag being recorded.
pub struct Bag {
    dir: PathBuf,
    name: String,
    options: BagOptions,
    info: BagInfo,
    open: Option<OpenFile>,
    /// Where the chain goes on in the next file.
    chain: Chain,
    last_flush_ns: u64,
}

impl Bag {
    /// Creates the bag folder `root/name` and its first file.
    pub fn create(
        root: &Path,
        name: &str,
        topics: Vec<BagTopic>,
        options: BagOptions,
        now_ns: u64,
    ) -> Result<Bag, String> {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let mut bag = Bag {
            dir,
            name: name.into(),
            options,
            info: BagInfo {
                topics,
                files: Vec::new(),
            },
            open: None,
            chain: Chain::new(),
            last_flush_ns: now_ns,
        };
        bag.open_file(now_ns)?;
        Ok(bag)
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Files begun so far.
    pub fn file_count(&self) -> usize {
        self.info.files.len()
    }

    fn open_file(&mut self, now_ns: u64) -> Result<(), String> {
        let file_name = format!("{}_{}.mcap", self.name, self.info.files.len());
        let path = self.dir.join(&file_name);
        let file = File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let writer = McapWriter::new(file, self.options.compression, self.chain.clone())?;
        self.info.files.push(FileInfo {
            path: file_name,
            ..FileInfo::default()
        });
        self.open = Some(OpenFile {
            writer,
            started_ns: now_ns,
            channels: BTreeMap::new(),
        });
        self.info.write(&self.dir)
    }

    /// Adds one message of topic `topic` (index into the bag's topics).
    pub fn record(
        &mut self,
        topic: usize,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), String> {
        let t = self
            .info
            .topics
            .get(topic)
            .ok_or_else(|| format!("no topic {topic}"))?
            .clone();
        let open = self.open.as_mut().ok_or("bag is closed")?;
        let channel = match open.channels.get(&topic) {
            Some(&c) => c,
            None => {
                let schema = crate::schema::ros2msg(&t.type_name)?;
                let meta = BTreeMap::from([("offered_qos_profiles".to_string(), t.qos.clone())]);
                let c = open
                    .writer
                    .add_channel(&t.name, &t.type_name, &schema, meta)?;
                open.channels.insert(topic, c);
                if let Some(f) = self.info.files.last_mut() {
                    f.channels.insert(c, topic);
                }
                c
            }
        };
        open.writer.write(channel, log_time, publish_time, data)?;
        if open.writer.open_chunk_bytes() >= CHUNK_BYTES {
            self.flush(log_time)?;
        }
        Ok(())
    }

    /// Called often: flushes when the interval is up and cuts the file when it is full or old.
    pub fn tick(&mut self, now_ns: u64) -> Result<(), String> {
        if now_ns.saturating_sub(self.last_flush_ns) >= self.options.flush_ns {
            self.flush(now_ns)?;
        }
        let Some(open) = &self.open else {
            return Ok(());
        };
        if open.writer.position() >= self.options.split_bytes
            || now_ns.saturating_sub(open.started_ns) >= self.options.split_ns
        {
            self.close_file()?;
            self.open_file(now_ns)?;
        }
        Ok(())
    }

    /// Writes the open chunk and its audit link, syncs the file and rewrites `metadata.yaml`.
    pub fn flush(&mut self, now_ns: u64) -> Result<(), String> {
        self.last_flush_ns = now_ns;
        let Some(open) = self.open.as_mut() else {
            return Ok(());
        };
        let before = open.writer.stats().chunks;
        open.writer.close_chunk()?;
        if open.writer.stats().chunks == before {
            return Ok(());
        }
        open.writer
            .get_ref()
            .sync_data()
            .map_err(|e| format!("{}: {e}", self.dir.display()))?;
        if let Some(f) = self.info.files.last_mut() {
            f.stats = open.writer.stats().clone();
        }
        self.info.write(&self.dir)
    }

    fn close_file(&mut self) -> Result<(), String> {
        let Some(open) = self.open.take() else {
            return Ok(());
        };
        let (file, stats, chain) = open.writer.finish()?;
        file.sync_all()
            .map_err(|e| format!("{}: {e}", self.dir.display()))?;
        self.chain = Chain::starting_from(chain.last_hash());
        if let Some(f) = self.info.files.last_mut() {
            f.stats = stats;
        }
        self.info.write(&self.dir)
    }

    /// Finishes the last file and `metadata.yaml`.
    pub fn close(mut self) -> Result<BagInfo, String> {
        self.close_file()?;
        Ok(self.info)
    }
}

/// Deletes the oldest bags (by name: they are named by their start time) of `root` while the
/// folder holds more than `cap_bytes`; `keep` is never deleted. Returns the bags deleted.
pub fn rotate(root: &Path, cap_bytes: u64, keep: &Path) -> Result<Vec<PathBuf>, String> {
    let mut bags: Vec<(PathBuf, u64)> = Vec::new();
    let entries = std::fs::read_dir(root).map_err(|e| format!("{}: {e}", root.display()))?;
    for e in entries.flatten() {
        let path = e.path();
        if path.is_dir() && path.join("metadata.yaml").exists() {
            bags.push((path.clone(), dir_size(&path)));
        }
    }
    bags.sort();
    let mut total: u64 = bags.iter().map(|b| b.1).sum();
    let mut deleted = Vec::new();
    for (path, size) in bags {
        if total <= cap_bytes {
            break;
        }
        if path == keep {
            continue;
        }
        std::fs::remove_dir_all(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        total -= size;
        deleted.push(path);
    }
    Ok(deleted)
}

fn dir_size(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .filter_map(|e| e.metadata().ok())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}
