//! Writes one MCAP file: messages gather in a chunk in memory; [`McapWriter::close_chunk`]
//! compresses it and writes it with its message indexes and the audit link (see
//! [`crate::chain`]), so that everything before the link is on disk and covered by the chain.
//! [`McapWriter::finish`] adds the summary section and the footer.

use std::collections::BTreeMap;
use std::io::Write;

use crate::chain::Chain;
use crate::mcap::{
    message_record, metadata_record, op, Body, Channel, ChunkIndex, Compression, Message, Schema,
    MAGIC,
};

/// Header `library` field.
pub const LIBRARY: &str = concat!("cnc_recorder ", env!("CARGO_PKG_VERSION"));

#[derive(Default)]
struct OpenChunk {
    records: Vec<u8>,
    start_time: u64,
    end_time: u64,
    /// Per channel: (log time, offset of the message inside the chunk's records).
    index: BTreeMap<u16, Vec<(u64, u64)>>,
    messages: u64,
}

/// What one file holds so far, for the summary and for the bag's `metadata.yaml`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FileStats {
    pub messages: u64,
    pub start_time: Option<u64>,
    pub end_time: u64,
    pub per_channel: BTreeMap<u16, u64>,
    pub chunks: u32,
}

pub struct McapWriter<W: Write> {
    out: W,
    pos: u64,
    compression: Compression,
    schemas: Vec<Schema>,
    channels: Vec<Channel>,
    chunk: OpenChunk,
    chunk_indexes: Vec<ChunkIndex>,
    metadata_indexes: Vec<(u64, u64, String)>,
    sequences: BTreeMap<u16, u32>,
    stats: FileStats,
    chain: Chain,
}

impl<W: Write> McapWriter<W> {
    /// Starts a file: magic and header. `chain` continues the audit chain of the bag's
    /// previous file, or starts a new one.
    pub fn new(mut out: W, compression: Compression, chain: Chain) -> Result<Self, String> {
        out.write_all(MAGIC).map_err(|e| e.to_string())?;
        let mut w = McapWriter {
            out,
            pos: MAGIC.len() as u64,
            compression,
            schemas: Vec::new(),
            channels: Vec::new(),
            chunk: OpenChunk::default(),
            chunk_indexes: Vec::new(),
            metadata_indexes: Vec::new(),
            sequences: BTreeMap::new(),
            stats: FileStats::default(),
            chain,
        };
        let header = Body::default()
            .string("ros2")
            .string(LIBRARY)
            .record(op::HEADER);
        w.emit(&header)?;
        Ok(w)
    }

    fn emit(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.out.write_all(bytes).map_err(|e| e.to_string())?;
        self.chain.absorb(bytes);
        self.pos += bytes.len() as u64;
        Ok(())
    }

    /// Adds a topic with its `ros2msg` schema; returns its channel id.
    pub fn add_channel(
        &mut self,
        topic: &str,
        type_name: &str,
        schema_text: &str,
        metadata: BTreeMap<String, String>,
    ) -> Result<u16, String> {
        let schema_id = match self.schemas.iter().find(|s| s.name == type_name) {
            Some(s) => s.id,
            None => {
                let s = Schema {
                    id: self.schemas.len() as u16 + 1,
                    name: type_name.into(),
                    encoding: "ros2msg".into(),
                    data: schema_text.as_bytes().to_vec(),
                };
                self.emit(&s.record())?;
                let id = s.id;
                self.schemas.push(s);
                id
            }
        };
        let ch = Channel {
            id: self.channels.len() as u16 + 1,
            schema_id,
            topic: topic.into(),
            message_encoding: "cdr".into(),
            metadata,
        };
        self.emit(&ch.record())?;
        let id = ch.id;
        self.channels.push(ch);
        Ok(id)
    }

    /// Adds one message (CDR bytes with their encapsulation header) to the open chunk.
    pub fn write(
        &mut self,
        channel: u16,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), String> {
        if !self.channels.iter().any(|c| c.id == channel) {
            return Err(format!("no channel {channel}"));
        }
        let seq = self.sequences.entry(channel).or_insert(0);
        *seq = seq.wrapping_add(1);
        let c = &mut self.chunk;
        if c.messages == 0 {
            c.start_time = log_time;
            c.end_time = log_time;
        }
        c.start_time = c.start_time.min(log_time);
        c.end_time = c.end_time.max(log_time);
        c.index
            .entry(channel)
            .or_default()
            .push((log_time, c.records.len() as u64));
        c.records.extend(message_record(&Message {
            channel,
            sequence: *seq,
            log_time,
            publish_time,
            data,
        }));
        c.messages += 1;
        let s = &mut self.stats;
        s.messages += 1;
        s.start_time = Some(s.start_time.map_or(log_time, |t| t.min(log_time)));
        s.end_time = s.end_time.max(log_time);
        *s.per_channel.entry(channel).or_insert(0) += 1;
        Ok(())
    }

    /// Bytes in the open chunk, uncompressed.
    pub fn open_chunk_bytes(&self) -> usize {
        self.chunk.records.len()
    }

    /// Bytes written to the file so far.
    pub fn position(&self) -> u64 {
        self.pos
    }

    pub fn stats(&self) -> &FileStats {
        &self.stats
    }

    pub fn get_ref(&self) -> &W {
        &self.out
    }

    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// Writes the open chunk (if it holds messages), its message indexes and its audit link,
    /// and flushes the output.
    pub fn close_chunk(&mut self) -> Result<(), String> {
        if self.chunk.messages == 0 {
            return self.out.flush().map_err(|e| e.to_string());
        }
        let chunk = std::mem::take(&mut self.chunk);
        let compressed = self.compression.compress(&chunk.records)?;
        let record = Body::default()
            .u64(chunk.start_time)
            .u64(chunk.end_time)
            .u64(chunk.records.len() as u64)
            .u32(crc32fast::hash(&chunk.records))
            .string(self.compression.name())
            .u64(compressed.len() as u64)
            .raw(&compressed)
            .record(op::CHUNK);
        let chunk_start = self.pos;
        self.emit(&record)?;
        let chunk_length = self.pos - chunk_start;
        let mut message_indexes = Vec::new();
        let index_start = self.pos;
        for (channel, entries) in &chunk.index {
            let mut list = Body::default();
            for (t, o) in entries {
                list = list.u64(*t).u64(*o);
            }
            message_indexes.push((*channel, self.pos));
            let rec = Body::default()
                .u16(*channel)
                .sized(list)
                .record(op::MESSAGE_INDEX);
            self.emit(&rec)?;
        }
        self.chunk_indexes.push(ChunkIndex {
            start_time: chunk.start_time,
            end_time: chunk.end_time,
            offset: chunk_start,
            length: chunk_length,
            message_indexes,
            index_length: self.pos - index_start,
            compression: self.compression.name().into(),
            compressed_size: compressed.len() as u64,
            uncompressed_size: chunk.records.len() as u64,
        });
        self.stats.chunks += 1;
        let link = self.chain.close_segment();
        let rec = metadata_record(crate::chain::RECORD_NAME, &link);
        let at = self.pos;
        self.emit(&rec)?;
        self.metadata_indexes
            .push((at, rec.len() as u64, crate::chain::RECORD_NAME.into()));
        // The link's own bytes begin the next segment, so a change to it breaks the chain too.
        self.out.flush().map_err(|e| e.to_string())
    }

    /// Closes the last chunk and writes data end, the summary and the footer.
    pub fn finish(mut self) -> Result<(W, FileStats, Chain), String> {
        self.close_chunk()?;
        self.emit(&Body::default().u32(0).record(op::DATA_END))?;
        let summary = Summary {
            schemas: self.schemas.clone(),
            channels: self.channels.clone(),
            chunk_indexes: std::mem::take(&mut self.chunk_indexes),
            metadata_indexes: std::mem::take(&mut self.metadata_indexes),
            stats: self.stats.clone(),
        }
        .to_bytes(self.pos);
        self.out.write_all(&summary).map_err(|e| e.to_string())?;
        self.out.flush().map_err(|e| e.to_string())?;
        Ok((self.out, self.stats, self.chain))
    }
}

/// The summary section: what a reader needs to find everything without scanning the file.
pub struct Summary {
    pub schemas: Vec<Schema>,
    pub channels: Vec<Channel>,
    pub chunk_indexes: Vec<ChunkIndex>,
    /// (offset, length, name) of each metadata record.
    pub metadata_indexes: Vec<(u64, u64, String)>,
    pub stats: FileStats,
}

impl Summary {
    /// The summary, its offsets, the footer and the closing magic, to be written at
    /// `summary_start` (just after the data end record).
    pub fn to_bytes(&self, summary_start: u64) -> Vec<u8> {
        let mut summary = Vec::new();
        let mut groups: Vec<(u8, u64, u64)> = Vec::new();
        let mut group = |summary: &mut Vec<u8>, opcode: u8, records: Vec<Vec<u8>>| {
            if records.is_empty() {
                return;
            }
            let start = summary_start + summary.len() as u64;
            for r in records {
                summary.extend(r);
            }
            groups.push((opcode, start, summary_start + summary.len() as u64 - start));
        };
        group(
            &mut summary,
            op::SCHEMA,
            self.schemas.iter().map(Schema::record).collect(),
        );
        group(
            &mut summary,
            op::CHANNEL,
            self.channels.iter().map(Channel::record).collect(),
        );
        group(
            &mut summary,
            op::CHUNK_INDEX,
            self.chunk_indexes.iter().map(ChunkIndex::record).collect(),
        );
        group(
            &mut summary,
            op::METADATA_INDEX,
            self.metadata_indexes
                .iter()
                .map(|(o, l, n)| {
                    Body::default()
                        .u64(*o)
                        .u64(*l)
                        .string(n)
                        .record(op::METADATA_INDEX)
                })
                .collect(),
        );
        let s = &self.stats;
        let mut counts = Body::default();
        for (c, n) in &s.per_channel {
            counts = counts.u16(*c).u64(*n);
        }
        let statistics = Body::default()
            .u64(s.messages)
            .u16(self.schemas.len() as u16)
            .u32(self.channels.len() as u32)
            .u32(0)
            .u32(self.metadata_indexes.len() as u32)
            .u32(s.chunks)
            .u64(s.start_time.unwrap_or(0))
            .u64(s.end_time)
            .sized(counts)
            .record(op::STATISTICS);
        group(&mut summary, op::STATISTICS, vec![statistics]);
        let summary_offset_start = summary_start + summary.len() as u64;
        for (opcode, start, length) in groups {
            summary.extend(
                Body::default()
                    .u8(opcode)
                    .u64(start)
                    .u64(length)
                    .record(op::SUMMARY_OFFSET),
            );
        }
        // The summary CRC covers the summary and the footer up to the CRC field.
        let head = Body::default()
            .u64(summary_start)
            .u64(summary_offset_start)
            .u32(0)
            .record(op::FOOTER);
        let mut crc = crc32fast::Hasher::new();
        crc.update(&summary);
        crc.update(&head[..head.len() - 4]);
        summary.extend(
            Body::default()
                .u64(summary_start)
                .u64(summary_offset_start)
                .u32(crc.finalize())
                .record(op::FOOTER),
        );
        summary.extend(MAGIC);
        summary
    }
}
