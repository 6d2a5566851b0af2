//! `cnc record recover`: after a crash (`kill -9`, power cut) the last file of a bag has no
//! summary or footer and may end inside a record. Recovery keeps the file up to its last audit
//! link byte for byte (so the chain still verifies), adds data end, summary and footer, keeps
//! the damaged original beside it as `*.mcap.damaged`, and rewrites `metadata.yaml` from the
//! files themselves.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::bag::{BagInfo, BagTopic, FileInfo};
use crate::mcap::{op, Body};
use crate::reader::{scan, scan_file, Scan};
use crate::writer::{FileStats, Summary};

/// What recovery did to one file.
#[derive(Debug, Clone, PartialEq)]
pub enum FileOutcome {
    Intact,
    Repaired {
        kept_bytes: u64,
        dropped_bytes: u64,
        messages: u64,
    },
}

/// The statistics of what a scan holds.
pub fn stats_of(s: &Scan) -> FileStats {
    let mut st = FileStats {
        chunks: s.chunks.len() as u32,
        ..FileStats::default()
    };
    for m in &s.messages {
        st.messages += 1;
        st.start_time = Some(st.start_time.map_or(m.log_time, |t| t.min(m.log_time)));
        st.end_time = st.end_time.max(m.log_time);
        *st.per_channel.entry(m.channel).or_insert(0) += 1;
    }
    st
}

/// A complete file from a damaged one: the bytes up to the last audit link, then data end,
/// summary and footer.
pub fn repair(data: &[u8]) -> Result<(Vec<u8>, u64), String> {
    let first = scan(data)?;
    let keep = first.consistent_end as usize;
    let mut out = data[..keep].to_vec();
    let s = scan(&out)?;
    let messages = s.messages.len() as u64;
    out.extend(Body::default().u32(0).record(op::DATA_END));
    let summary = Summary {
        schemas: s.schemas.clone(),
        channels: s.channels.clone(),
        chunk_indexes: s.chunks.clone(),
        metadata_indexes: s.metadata.clone(),
        stats: stats_of(&s),
    };
    let start = out.len() as u64;
    out.extend(summary.to_bytes(start));
    Ok((out, messages))
}

/// Recovers one file in place if it needs it.
pub fn recover_file(path: &Path) -> Result<FileOutcome, String> {
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let s = scan(&data).map_err(|e| format!("{}: {e}", path.display()))?;
    if s.has_footer && s.problem.is_none() && s.data_end.is_some() {
        return Ok(FileOutcome::Intact);
    }
    let (repaired, messages) = repair(&data).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut damaged = path.as_os_str().to_owned();
    damaged.push(".damaged");
    let damaged = PathBuf::from(damaged);
    std::fs::copy(path, &damaged).map_err(|e| format!("{}: {e}", damaged.display()))?;
    let tmp = path.with_extension("mcap.tmp");
    std::fs::write(&tmp, &repaired).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))?;
    let kept = s.consistent_end;
    Ok(FileOutcome::Repaired {
        kept_bytes: kept,
        dropped_bytes: data.len() as u64 - kept,
        messages,
    })
}

/// The `.mcap` files of a bag folder in recording order (`name_0.mcap`, `name_1.mcap`, …).
pub fn bag_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .map(|p| {
            let n = p
                .file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.rsplit('_').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or(u64::MAX);
            (n, p)
        })
        .collect();
    files.sort();
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// `metadata.yaml` as the files of the bag say it should be.
pub fn bag_info(dir: &Path) -> Result<BagInfo, String> {
    let mut info = BagInfo::default();
    for path in bag_files(dir)? {
        let (_, s) = scan_file(&path)?;
        let mut channels = BTreeMap::new();
        for ch in &s.channels {
            let type_name = s
                .schema(ch.schema_id)
                .map(|x| x.name.clone())
                .unwrap_or_default();
            let topic = BagTopic {
                name: ch.topic.clone(),
                type_name,
                qos: ch
                    .metadata
                    .get("offered_qos_profiles")
                    .cloned()
                    .unwrap_or_default(),
            };
            let i = match info.topics.iter().position(|t| t.name == topic.name) {
                Some(i) => i,
                None => {
                    info.topics.push(topic);
                    info.topics.len() - 1
                }
            };
            channels.insert(ch.id, i);
        }
        info.files.push(FileInfo {
            path: path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or_default()
                .to_string(),
            stats: stats_of(&s),
            channels,
        });
    }
    Ok(info)
}

/// Recovers a bag folder (or one file); returns one line per file.
pub fn recover(path: &Path) -> Result<Vec<String>, String> {
    let (dir, files) = if path.is_dir() {
        (path.to_path_buf(), bag_files(path)?)
    } else {
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        (dir, vec![path.to_path_buf()])
    };
    let mut report = Vec::new();
    for f in &files {
        let line = match recover_file(f)? {
            FileOutcome::Intact => format!("{}: intact", f.display()),
            FileOutcome::Repaired {
                kept_bytes,
                dropped_bytes,
                messages,
            } => format!(
                "{}: repaired, {messages} messages in {kept_bytes} bytes kept, {dropped_bytes} bytes after the last audit link dropped (original kept as .damaged)",
                f.display()
            ),
        };
        report.push(line);
    }
    if dir.join("metadata.yaml").exists() || path.is_dir() {
        bag_info(&dir)?.write(&dir)?;
        report.push(format!("{}: metadata.yaml rewritten", dir.display()));
    }
    Ok(report)
}
