//! `cnc audit verify BAG`: walks the audit chain (see [`crate::chain`]) through every file of a
//! bag and reports the first segment whose bytes no longer give the recorded hash, a link that
//! is missing, or a file that does not continue the chain of the one before.

use std::path::Path;

use crate::chain::{link_hash, Hash, Link, RECORD_NAME};
use crate::mcap::{self, op, parse_metadata};
use crate::reader::walk;

/// The result of a verification.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Every segment matches; `chunks` segments in `files` files, ending in hash `last`.
    Intact {
        files: usize,
        chunks: u64,
        last: Hash,
    },
    /// The first problem found.
    Altered(String),
}

/// Verifies one file's data section, starting from `prev`; returns the last hash and the
/// number of links, or the first problem.
pub fn verify_file(name: &str, data: &[u8], prev: Hash) -> Result<(Hash, u64), String> {
    if data.len() < 8 || &data[..8] != mcap::MAGIC {
        return Err(format!("{name}: not an MCAP file"));
    }
    let (records, problem) = walk(data);
    let mut prev = prev;
    let mut segment_start = mcap::MAGIC.len();
    let mut links = 0u64;
    for r in &records {
        if r.opcode != op::METADATA {
            continue;
        }
        let Ok((record_name, map)) = parse_metadata(r.body) else {
            continue;
        };
        if record_name != RECORD_NAME {
            continue;
        }
        let where_ = format!(
            "{name}: chunk {links} (bytes {segment_start}..{})",
            r.offset
        );
        let link = Link::parse(&map).ok_or_else(|| format!("{where_}: audit link unreadable"))?;
        if link.index != links {
            return Err(format!(
                "{where_}: link {} found where link {links} belongs: a chunk is missing",
                link.index
            ));
        }
        if link.prev != prev {
            return Err(format!(
                "{where_}: link does not continue the chain (previous file or chunk missing or altered)"
            ));
        }
        if link.segment_offset != segment_start as u64
            || link.segment_length != (r.offset - segment_start) as u64
        {
            return Err(format!(
                "{where_}: segment recorded as {} bytes at {}: data inserted or removed",
                link.segment_length, link.segment_offset
            ));
        }
        if link_hash(&prev, &data[segment_start..r.offset]) != link.hash {
            return Err(format!("{where_}: altered (hash does not match)"));
        }
        prev = link.hash;
        segment_start = r.offset;
        links += 1;
    }
    if let Some(p) = problem {
        return Err(format!(
            "{name}: record structure broken after chunk {links} (byte {segment_start} on): {p}"
        ));
    }
    // After the last link only channel records (of topics that had no message yet) and the
    // data end record may follow.
    let unlinked: Vec<u8> = records
        .iter()
        .filter(|r| r.offset > segment_start)
        .map(|r| r.opcode)
        .filter(|&o| !matches!(o, op::SCHEMA | op::CHANNEL | op::DATA_END))
        .collect();
    if !unlinked.is_empty() {
        return Err(format!(
            "{name}: records after the last audit link (opcodes {unlinked:?}) are not covered"
        ));
    }
    if let Some(f) = mcap::footer(data) {
        let start = f.summary_start as usize;
        let footer_at = data.len() - 8 - 29;
        if start <= footer_at && f.summary_crc != 0 {
            let mut crc = crc32fast::Hasher::new();
            crc.update(&data[start..footer_at + 9 + 16]);
            if crc.finalize() != f.summary_crc {
                return Err(format!("{name}: summary altered (CRC does not match)"));
            }
        }
    }
    Ok((prev, links))
}

/// Verifies a bag folder (or one file).
pub fn verify(path: &Path) -> Result<Verdict, String> {
    let files = if path.is_dir() {
        crate::recover::bag_files(path)?
    } else {
        vec![path.to_path_buf()]
    };
    if files.is_empty() {
        return Err(format!("{}: no .mcap files", path.display()));
    }
    let mut prev = [0u8; 32];
    let mut chunks = 0;
    for f in &files {
        let data = std::fs::read(f).map_err(|e| format!("{}: {e}", f.display()))?;
        let name = f.display().to_string();
        match verify_file(&name, &data, prev) {
            Ok((last, n)) => {
                prev = last;
                chunks += n;
            }
            Err(e) => return Ok(Verdict::Altered(e)),
        }
    }
    Ok(Verdict::Intact {
        files: files.len(),
        chunks,
        last: prev,
    })
}
