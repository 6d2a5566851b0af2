//! Reads an MCAP file front to back, as far as it is intact: what the recorder's own tools
//! (recover, audit verify, replay) need. It never trusts a length it has not checked.

use crate::chain::{Link, RECORD_NAME};
use crate::mcap::{
    self, op, parse_message, parse_metadata, Channel, Chunk, ChunkIndex, Schema, MAGIC,
};

#[derive(Debug, Clone, PartialEq)]
pub struct ScannedMessage {
    pub channel: u16,
    pub sequence: u32,
    pub log_time: u64,
    pub publish_time: u64,
    pub data: Vec<u8>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ScannedLink {
    pub offset: u64,
    pub length: u64,
    pub link: Link,
}

#[derive(Debug, Default)]
pub struct Scan {
    pub schemas: Vec<Schema>,
    pub channels: Vec<Channel>,
    pub messages: Vec<ScannedMessage>,
    pub chunks: Vec<ChunkIndex>,
    pub links: Vec<ScannedLink>,
    /// (offset, length, name) of every metadata record.
    pub metadata: Vec<(u64, u64, String)>,
    /// Just past the last audit link (or the header): a cut here leaves a consistent file.
    pub consistent_end: u64,
    /// Offset of the data end record, when the file has one.
    pub data_end: Option<u64>,
    /// The file ends with a valid footer and magic.
    pub has_footer: bool,
    /// Why the scan stopped before the data end, if it did.
    pub problem: Option<String>,
}

impl Scan {
    pub fn channel(&self, id: u16) -> Option<&Channel> {
        self.channels.iter().find(|c| c.id == id)
    }
    pub fn schema(&self, id: u16) -> Option<&Schema> {
        self.schemas.iter().find(|s| s.id == id)
    }
}

/// The records of the data section, from after the magic up to the data end record or the
/// first record that is cut off; the error says where the walk stopped early.
pub fn walk(data: &[u8]) -> (Vec<mcap::RawRecord<'_>>, Option<String>) {
    let mut out = Vec::new();
    let mut at = MAGIC.len();
    while at < data.len() {
        match mcap::record_at(data, at) {
            Ok(r) => {
                at = r.end();
                let end = r.opcode == op::DATA_END;
                out.push(r);
                if end {
                    return (out, None);
                }
            }
            Err(e) => return (out, Some(e)),
        }
    }
    (out, Some("file ends without a data end record".into()))
}

/// Scans a whole file. Fails only when `data` is not an MCAP file at all.
pub fn scan(data: &[u8]) -> Result<Scan, String> {
    if data.len() < MAGIC.len() || &data[..MAGIC.len()] != MAGIC {
        return Err("not an MCAP file (no magic)".into());
    }
    let (records, walk_problem) = walk(data);
    let mut s = Scan {
        consistent_end: MAGIC.len() as u64,
        has_footer: mcap::footer(data).is_some(),
        ..Scan::default()
    };
    match records.first() {
        Some(r) if r.opcode == op::HEADER => s.consistent_end = r.end() as u64,
        _ => return Err("not an MCAP file (no header record)".into()),
    }
    let mut problem = None;
    for r in &records {
        if let Err(e) = take_record(&mut s, r) {
            problem = Some(format!("record at byte {}: {e}", r.offset));
            break;
        }
    }
    s.problem = problem.or(walk_problem);
    Ok(s)
}

fn take_record(s: &mut Scan, r: &mcap::RawRecord) -> Result<(), String> {
    match r.opcode {
        op::SCHEMA => {
            let schema = Schema::parse(r.body)?;
            if !s.schemas.iter().any(|x| x.id == schema.id) {
                s.schemas.push(schema);
            }
        }
        op::CHANNEL => {
            let ch = Channel::parse(r.body)?;
            if !s.channels.iter().any(|x| x.id == ch.id) {
                s.channels.push(ch);
            }
        }
        op::CHUNK => {
            let chunk = Chunk::parse(r.body)?;
            let records = chunk.decompressed()?;
            let mut at = 0;
            while at < records.len() {
                let inner = mcap::record_at(&records, at)?;
                at = inner.end();
                match inner.opcode {
                    op::MESSAGE => {
                        let m = parse_message(inner.body)?;
                        s.messages.push(ScannedMessage {
                            channel: m.channel,
                            sequence: m.sequence,
                            log_time: m.log_time,
                            publish_time: m.publish_time,
                            data: m.data.to_vec(),
                        });
                    }
                    op::SCHEMA | op::CHANNEL => take_record(s, &inner)?,
                    _ => {}
                }
            }
            s.chunks.push(ChunkIndex {
                offset: r.offset as u64,
                length: r.end() as u64 - r.offset as u64,
                start_time: chunk.start_time,
                end_time: chunk.end_time,
                compression: chunk.compression.clone(),
                compressed_size: chunk.records.len() as u64,
                uncompressed_size: chunk.uncompressed_size,
                message_indexes: Vec::new(),
                index_length: 0,
            });
        }
        op::MESSAGE_INDEX => {
            let channel = mcap::Fields::new(r.body).u16()?;
            if let Some(c) = s.chunks.last_mut() {
                c.message_indexes.push((channel, r.offset as u64));
                c.index_length += r.end() as u64 - r.offset as u64;
            }
        }
        op::METADATA => {
            let (name, map) = parse_metadata(r.body)?;
            let (offset, length) = (r.offset as u64, r.end() as u64 - r.offset as u64);
            if name == RECORD_NAME {
                let link = Link::parse(&map).ok_or("audit link with missing fields")?;
                s.links.push(ScannedLink {
                    offset,
                    length,
                    link,
                });
                s.consistent_end = offset + length;
            }
            s.metadata.push((offset, length, name));
        }
        op::DATA_END => s.data_end = Some(r.offset as u64),
        _ => {}
    }
    Ok(())
}

/// Reads a file and scans it.
pub fn scan_file(path: &std::path::Path) -> Result<(Vec<u8>, Scan), String> {
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let s = scan(&data).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((data, s))
}
