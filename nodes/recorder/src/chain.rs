//! The audit chain: tamper evidence for recordings.
//!
//! A file's data section is cut into segments, each ending where the writer closed a chunk.
//! After each segment the writer puts a metadata record named [`RECORD_NAME`] holding
//! `hash = SHA-256(previous hash ‖ segment bytes)`, the segment's place and the previous hash.
//! A segment begins just after the previous link (or after the magic), so every byte of the
//! data section — schemas, channels, chunks, indexes and the links themselves — is covered.
//! The first file of a bag starts from 32 zero bytes; each further file starts from the last
//! hash of the file before it, so a missing or reordered file breaks the chain too.

use std::collections::BTreeMap;

use sha2::{Digest, Sha256};

pub const RECORD_NAME: &str = "cnc_audit_chain";

pub type Hash = [u8; 32];

pub fn hex(h: &Hash) -> String {
    h.iter().map(|b| format!("{b:02x}")).collect()
}

pub fn parse_hex(s: &str) -> Option<Hash> {
    if s.len() != 64 || !s.is_ascii() {
        return None;
    }
    let mut h = [0u8; 32];
    for (i, b) in h.iter_mut().enumerate() {
        *b = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(h)
}

/// The running chain of one file.
#[derive(Clone)]
pub struct Chain {
    prev: Hash,
    hasher: Sha256,
    /// Links written so far in this file.
    links: u64,
    /// Offset where the current segment began and its length so far.
    segment_start: u64,
    segment_len: u64,
}

impl Chain {
    /// A chain starting from `prev`, for a file whose first segment begins after the magic.
    pub fn starting_from(prev: Hash) -> Self {
        Chain {
            prev,
            hasher: Sha256::new_with_prefix(prev),
            links: 0,
            segment_start: crate::mcap::MAGIC.len() as u64,
            segment_len: 0,
        }
    }

    pub fn new() -> Self {
        Self::starting_from([0; 32])
    }

    /// The hash the next file of the bag starts from.
    pub fn last_hash(&self) -> Hash {
        self.prev
    }

    pub fn absorb(&mut self, bytes: &[u8]) {
        self.hasher.update(bytes);
        self.segment_len += bytes.len() as u64;
    }

    /// Ends the segment: the fields of the link record to write next. The link record's own
    /// bytes, absorbed as they are written, begin the next segment.
    pub fn close_segment(&mut self) -> BTreeMap<String, String> {
        let hasher = std::mem::replace(&mut self.hasher, Sha256::new());
        let hash: Hash = hasher.finalize().into();
        let link = BTreeMap::from([
            ("index".to_string(), self.links.to_string()),
            ("segment_offset".to_string(), self.segment_start.to_string()),
            ("segment_length".to_string(), self.segment_len.to_string()),
            ("prev".to_string(), hex(&self.prev)),
            ("hash".to_string(), hex(&hash)),
        ]);
        self.links += 1;
        self.prev = hash;
        self.hasher = Sha256::new_with_prefix(hash);
        self.segment_start += self.segment_len;
        self.segment_len = 0;
        link
    }
}

impl Default for Chain {
    fn default() -> Self {
        Self::new()
    }
}

/// One link as read back from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    pub index: u64,
    pub segment_offset: u64,
    pub segment_length: u64,
    pub prev: Hash,
    pub hash: Hash,
}

impl Link {
    pub fn parse(map: &BTreeMap<String, String>) -> Option<Link> {
        let num = |k: &str| map.get(k)?.parse::<u64>().ok();
        Some(Link {
            index: num("index")?,
            segment_offset: num("segment_offset")?,
            segment_length: num("segment_length")?,
            prev: parse_hex(map.get("prev")?)?,
            hash: parse_hex(map.get("hash")?)?,
        })
    }
}

/// SHA-256(prev ‖ bytes).
pub fn link_hash(prev: &Hash, bytes: &[u8]) -> Hash {
    let mut h = Sha256::new_with_prefix(prev);
    h.update(bytes);
    h.finalize().into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_is_the_hash_of_the_previous_hash_and_the_segment() {
        let mut c = Chain::new();
        c.absorb(b"abc");
        c.absorb(b"def");
        let l = Link::parse(&c.close_segment()).unwrap();
        assert_eq!(l.hash, link_hash(&[0; 32], b"abcdef"));
        assert_eq!((l.index, l.segment_offset, l.segment_length), (0, 8, 6));
        c.absorb(b"xyz");
        let l2 = Link::parse(&c.close_segment()).unwrap();
        assert_eq!(l2.prev, l.hash);
        assert_eq!(l2.hash, link_hash(&l.hash, b"xyz"));
        assert_eq!(l2.segment_offset, 14);
        assert_eq!(parse_hex(&hex(&l2.hash)), Some(l2.hash));
        assert_eq!(parse_hex("zz"), None);
    }
}
