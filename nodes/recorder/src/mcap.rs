//! The MCAP container format (mcap.dev/spec, version 0): records are `opcode: u8`,
//! `length: u64` and `length` bytes of body, all little-endian, between two magic strings.
//! This module encodes the records the recorder writes and decodes what it reads back;
//! [`crate::writer`] and [`crate::reader`] put them together into files.

use std::collections::BTreeMap;

pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

pub mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const MESSAGE: u8 = 0x05;
    pub const CHUNK: u8 = 0x06;
    pub const MESSAGE_INDEX: u8 = 0x07;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const STATISTICS: u8 = 0x0B;
    pub const METADATA: u8 = 0x0C;
    pub const METADATA_INDEX: u8 = 0x0D;
    pub const SUMMARY_OFFSET: u8 = 0x0E;
    pub const DATA_END: u8 = 0x0F;
}

/// Chunk compression, as MCAP names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Compression {
    None,
    #[default]
    Zstd,
    Lz4,
}

impl Compression {
    pub fn name(self) -> &'static str {
        match self {
            Compression::None => "",
            Compression::Zstd => "zstd",
            Compression::Lz4 => "lz4",
        }
    }

    pub fn compress(self, data: &[u8]) -> Result<Vec<u8>, String> {
        match self {
            Compression::None => Ok(data.to_vec()),
            Compression::Zstd => zstd::bulk::compress(data, 3).map_err(|e| format!("zstd: {e}")),
            Compression::Lz4 => {
                use std::io::Write;
                let mut enc = lz4_flex::frame::FrameEncoder::new(Vec::new());
                enc.write_all(data).map_err(|e| format!("lz4: {e}"))?;
                enc.finish().map_err(|e| format!("lz4: {e}"))
            }
        }
    }
}

/// Decompresses a chunk's records; `size` is the uncompressed size the chunk declares.
pub fn decompress(name: &str, data: &[u8], size: u64) -> Result<Vec<u8>, String> {
    // A damaged size field must not make us allocate without bound.
    let size = usize::try_from(size).map_err(|_| "chunk size out of range".to_string())?;
    if size > 1 << 30 {
        return Err(format!("chunk of {size} bytes declared: larger than 1 GiB"));
    }
    let out = match name {
        "" => data.to_vec(),
        "zstd" => zstd::bulk::decompress(data, size).map_err(|e| format!("zstd: {e}"))?,
        "lz4" => {
            use std::io::Read;
            let mut out = Vec::with_capacity(size);
            lz4_flex::frame::FrameDecoder::new(data)
                .take(size as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("lz4: {e}"))?;
            out
        }
        other => return Err(format!("unknown chunk compression {other:?}")),
    };
    if out.len() != size {
        return Err(format!(
            "chunk decompresses to {} bytes, declared {size}",
            out.len()
        ));
    }
    Ok(out)
}

/// Builds one record body.
#[derive(Default)]
pub struct Body(pub Vec<u8>);

impl Body {
    pub fn u8(mut self, v: u8) -> Self {
        self.0.push(v);
        self
    }
    pub fn u16(mut self, v: u16) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    pub fn u32(mut self, v: u32) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    pub fn u64(mut self, v: u64) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    pub fn string(self, s: &str) -> Self {
        self.u32(s.len() as u32).raw(s.as_bytes())
    }
    /// A `u32`-length-prefixed byte array.
    pub fn bytes(self, b: &[u8]) -> Self {
        self.u32(b.len() as u32).raw(b)
    }
    pub fn raw(mut self, b: &[u8]) -> Self {
        self.0.extend_from_slice(b);
        self
    }
    /// A map or array: `u32` byte length, then the entries.
    pub fn sized(self, inner: Body) -> Self {
        self.bytes(&inner.0)
    }
    pub fn string_map(self, map: &BTreeMap<String, String>) -> Self {
        let mut inner = Body::default();
        for (k, v) in map {
            inner = inner.string(k).string(v);
        }
        self.sized(inner)
    }
    /// The whole record: opcode, length, body.
    pub fn record(self, opcode: u8) -> Vec<u8> {
        let mut r = Vec::with_capacity(9 + self.0.len());
        r.push(opcode);
        r.extend((self.0.len() as u64).to_le_bytes());
        r.extend(self.0);
        r
    }
}

/// Reads a record body field by field; every read checks the bounds.
pub struct Fields<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Fields { data, pos: 0 }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.data.len())
            .ok_or_else(|| format!("record ends inside a field at byte {}", self.pos))?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    pub fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    pub fn u16(&mut self) -> Result<u16, String> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    pub fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    pub fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    pub fn long_bytes(&mut self) -> Result<&'a [u8], String> {
        let n = usize::try_from(self.u64()?).map_err(|_| "length out of range".to_string())?;
        self.take(n)
    }
    pub fn string(&mut self) -> Result<String, String> {
        let b = self.bytes()?;
        String::from_utf8(b.to_vec()).map_err(|_| "string is not UTF-8".to_string())
    }
    pub fn string_map(&mut self) -> Result<BTreeMap<String, String>, String> {
        let mut inner = Fields::new(self.bytes()?);
        let mut map = BTreeMap::new();
        while !inner.at_end() {
            let k = inner.string()?;
            let v = inner.string()?;
            map.insert(k, v);
        }
        Ok(map)
    }
    pub fn rest(&mut self) -> &'a [u8] {
        let s = &self.data[self.pos..];
        self.pos = self.data.len();
        s
    }
    pub fn at_end(&self) -> bool {
        self.pos >= self.data.len()
    }
}

/// One record as found in a byte buffer.
#[derive(Debug, Clone, Copy)]
pub struct RawRecord<'a> {
    pub offset: usize,
    pub opcode: u8,
    pub body: &'a [u8],
}

impl RawRecord<'_> {
    /// Offset just past the record.
    pub fn end(&self) -> usize {
        self.offset + 9 + self.body.len()
    }
}

/// The record at `offset`, or why there is none (truncated, or past the end).
pub fn record_at(data: &[u8], offset: usize) -> Result<RawRecord<'_>, String> {
    if offset + 9 > data.len() {
        return Err(format!("file ends inside a record header at byte {offset}"));
    }
    let opcode = data[offset];
    let mut len = [0u8; 8];
    len.copy_from_slice(&data[offset + 1..offset + 9]);
    let len = u64::from_le_bytes(len);
    let start = offset + 9;
    let end = usize::try_from(len)
        .ok()
        .and_then(|l| start.checked_add(l))
        .filter(|&e| e <= data.len())
        .ok_or_else(|| format!("record at byte {offset} runs past the end of the file"))?;
    Ok(RawRecord {
        offset,
        opcode,
        body: &data[start..end],
    })
}

/// A message record's fields.
pub struct Message<'a> {
    pub channel: u16,
    pub sequence: u32,
    pub log_time: u64,
    pub publish_time: u64,
    pub data: &'a [u8],
}

pub fn message_record(m: &Message) -> Vec<u8> {
    Body::default()
        .u16(m.channel)
        .u32(m.sequence)
        .u64(m.log_time)
        .u64(m.publish_time)
        .raw(m.data)
        .record(op::MESSAGE)
}

pub fn parse_message(body: &[u8]) -> Result<Message<'_>, String> {
    let mut f = Fields::new(body);
    Ok(Message {
        channel: f.u16()?,
        sequence: f.u32()?,
        log_time: f.u64()?,
        publish_time: f.u64()?,
        data: f.rest(),
    })
}

/// A schema: `ros2msg` text of one type.
#[derive(Debug, Clone, PartialEq)]
pub struct Schema {
    pub id: u16,
    pub name: String,
    pub encoding: String,
    pub data: Vec<u8>,
}

impl Schema {
    pub fn record(&self) -> Vec<u8> {
        Body::default()
            .u16(self.id)
            .string(&self.name)
            .string(&self.encoding)
            .bytes(&self.data)
            .record(op::SCHEMA)
    }
    pub fn parse(body: &[u8]) -> Result<Self, String> {
        let mut f = Fields::new(body);
        Ok(Schema {
            id: f.u16()?,
            name: f.string()?,
            encoding: f.string()?,
            data: f.bytes()?.to_vec(),
        })
    }
}

/// A channel: one topic.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    pub id: u16,
    pub schema_id: u16,
    pub topic: String,
    pub message_encoding: String,
    pub metadata: BTreeMap<String, String>,
}

impl Channel {
    pub fn record(&self) -> Vec<u8> {
        Body::default()
            .u16(self.id)
            .u16(self.schema_id)
            .string(&self.topic)
            .string(&self.message_encoding)
            .string_map(&self.metadata)
            .record(op::CHANNEL)
    }
    pub fn parse(body: &[u8]) -> Result<Self, String> {
        let mut f = Fields::new(body);
        Ok(Channel {
            id: f.u16()?,
            schema_id: f.u16()?,
            topic: f.string()?,
            message_encoding: f.string()?,
            metadata: f.string_map()?,
        })
    }
}

/// A chunk's fields, records still compressed.
pub struct Chunk<'a> {
    pub start_time: u64,
    pub end_time: u64,
    pub uncompressed_size: u64,
    pub uncompressed_crc: u32,
    pub compression: String,
    pub records: &'a [u8],
}

impl<'a> Chunk<'a> {
    pub fn parse(body: &'a [u8]) -> Result<Self, String> {
        let mut f = Fields::new(body);
        Ok(Chunk {
            start_time: f.u64()?,
            end_time: f.u64()?,
            uncompressed_size: f.u64()?,
            uncompressed_crc: f.u32()?,
            compression: f.string()?,
            records: f.long_bytes()?,
        })
    }

    /// The records inside, decompressed and checked against the chunk's CRC.
    pub fn decompressed(&self) -> Result<Vec<u8>, String> {
        let out = decompress(&self.compression, self.records, self.uncompressed_size)?;
        if self.uncompressed_crc != 0 && crc32fast::hash(&out) != self.uncompressed_crc {
            return Err("chunk CRC does not match its records".into());
        }
        Ok(out)
    }
}

/// Where a chunk is and what it holds: the summary's chunk index record.
#[derive(Debug, Clone, PartialEq)]
pub struct ChunkIndex {
    pub start_time: u64,
    pub end_time: u64,
    pub offset: u64,
    pub length: u64,
    /// (channel, offset of its message index record).
    pub message_indexes: Vec<(u16, u64)>,
    pub index_length: u64,
    pub compression: String,
    pub compressed_size: u64,
    pub uncompressed_size: u64,
}

impl ChunkIndex {
    pub fn record(&self) -> Vec<u8> {
        let mut offsets = Body::default();
        for (c, o) in &self.message_indexes {
            offsets = offsets.u16(*c).u64(*o);
        }
        Body::default()
            .u64(self.start_time)
            .u64(self.end_time)
            .u64(self.offset)
            .u64(self.length)
            .sized(offsets)
            .u64(self.index_length)
            .string(&self.compression)
            .u64(self.compressed_size)
            .u64(self.uncompressed_size)
            .record(op::CHUNK_INDEX)
    }
}

/// A metadata record: a name and a string map.
pub fn metadata_record(name: &str, map: &BTreeMap<String, String>) -> Vec<u8> {
    Body::default()
        .string(name)
        .string_map(map)
        .record(op::METADATA)
}

pub fn parse_metadata(body: &[u8]) -> Result<(String, BTreeMap<String, String>), String> {
    let mut f = Fields::new(body);
    Ok((f.string()?, f.string_map()?))
}

/// The footer: where the summary starts and its CRC.
pub struct Footer {
    pub summary_start: u64,
    pub summary_offset_start: u64,
    pub summary_crc: u32,
}

/// Reads the footer of a complete file, if it has one.
pub fn footer(data: &[u8]) -> Option<Footer> {
    // Footer record (9 + 20 bytes) and the closing magic.
    let n = data.len();
    if n < 8 + 29 + 8 || &data[n - 8..] != MAGIC {
        return None;
    }
    let r = record_at(data, n - 8 - 29).ok()?;
    if r.opcode != op::FOOTER {
        return None;
    }
    let mut f = Fields::new(r.body);
    Some(Footer {
        summary_start: f.u64().ok()?,
        summary_offset_start: f.u64().ok()?,
        summary_crc: f.u32().ok()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_compression_round_trips() {
        let data: Vec<u8> = (0..10_000u32)
            .flat_map(|i| (i % 251).to_le_bytes())
            .collect();
        for c in [Compression::None, Compression::Zstd, Compression::Lz4] {
            let packed = c.compress(&data).unwrap();
            assert_eq!(
                decompress(c.name(), &packed, data.len() as u64).unwrap(),
                data
            );
            assert!(decompress(c.name(), &packed, data.len() as u64 - 1).is_err());
        }
        assert!(decompress("brotli", &data, 4).is_err());
    }

    #[test]
    fn records_round_trip_and_truncation_is_an_error() {
        let ch = Channel {
            id: 3,
            schema_id: 1,
            topic: "/lathe1/spindle".into(),
            message_encoding: "cdr".into(),
            metadata: [("offered_qos_profiles".to_string(), "x".to_string())].into(),
        };
        let rec = ch.record();
        let r = record_at(&rec, 0).unwrap();
        assert_eq!(r.opcode, op::CHANNEL);
        assert_eq!(Channel::parse(r.body).unwrap(), ch);
        for cut in 0..rec.len() {
            assert!(record_at(&rec[..cut], 0).is_err());
        }
        // A body whose inner lengths lie is an error, not a panic.
        let mut bad = rec.clone();
        bad[9 + 4] = 0xff;
        assert!(Channel::parse(record_at(&bad, 0).unwrap().body).is_err());
    }
}
