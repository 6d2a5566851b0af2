//! The PLC's memory: the byte tables, timers, counters and edge detectors, and the part of it
//! that survives a restart (keep relays K, data registers D, timer and counter presets).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::address::{
    BitAddr, ByteAddr, Space, COUNTERS, EDGES, FIXED_COUNTERS, FIXED_TIMERS, TIMERS,
};

/// An on-delay timer: running since a scan time, ms.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timer {
    pub preset_ms: u32,
    pub since: Option<u64>,
}

impl Timer {
    /// The timer's contact after a scan at `now_ms` with input `act`.
    pub fn run(&mut self, act: bool, now_ms: u64) -> bool {
        if act {
            let since = *self.since.get_or_insert(now_ms);
            now_ms.saturating_sub(since) >= u64::from(self.preset_ms)
        } else {
            self.since = None;
            false
        }
    }

    /// Elapsed time while running, ms.
    pub fn elapsed(&self, now_ms: u64) -> u64 {
        self.since.map_or(0, |s| now_ms.saturating_sub(s))
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counter {
    pub preset: i64,
    pub current: i64,
}

#[derive(Debug, Clone)]
pub struct Memory {
    tables: Vec<Vec<u8>>,
    pub timers: Vec<Timer>,
    pub fixed_timers: Vec<Timer>,
    pub counters: Vec<Counter>,
    pub fixed_counters: Vec<Counter>,
    /// DIFU/DIFD: ACT of the previous scan.
    pub edges: Vec<bool>,
    /// Per step: ACT of the previous execution (counters and shift registers count edges).
    pub step_act: Vec<bool>,
}

impl Default for Memory {
    fn default() -> Self {
        Memory {
            tables: Space::ALL.iter().map(|s| vec![0; s.size()]).collect(),
            timers: vec![Timer::default(); TIMERS as usize],
            fixed_timers: vec![Timer::default(); FIXED_TIMERS as usize],
            counters: vec![Counter::default(); COUNTERS as usize],
            fixed_counters: vec![Counter::default(); FIXED_COUNTERS as usize],
            edges: vec![false; EDGES as usize],
            step_act: Vec::new(),
        }
    }
}

fn slot(s: Space) -> usize {
    Space::ALL.iter().position(|x| *x == s).unwrap_or(0)
}

impl Memory {
    pub fn table(&self, s: Space) -> &[u8] {
        &self.tables[slot(s)]
    }
    pub fn table_mut(&mut self, s: Space) -> &mut [u8] {
        &mut self.tables[slot(s)]
    }

    pub fn byte(&self, a: ByteAddr) -> u8 {
        self.table(a.space)
            .get(a.index as usize)
            .copied()
            .unwrap_or(0)
    }

    pub fn set_byte(&mut self, a: ByteAddr, v: u8) {
        if let Some(d) = self.table_mut(a.space).get_mut(a.index as usize) {
            *d = v;
        }
    }

    pub fn bit(&self, b: BitAddr) -> bool {
        self.byte(b.byte) >> b.bit & 1 == 1
    }

    pub fn set_bit(&mut self, b: BitAddr, on: bool) {
        let v = self.byte(b.byte);
        let m = 1u8 << b.bit;
        self.set_byte(b.byte, if on { v | m } else { v & !m });
    }

    /// A binary value of `format` bytes, least significant first. One byte reads unsigned
    /// (0–255: codes, tool numbers, masks); two and four bytes read signed.
    pub fn read(&self, a: ByteAddr, format: u8) -> i64 {
        let t = self.table(a.space);
        let i = a.index as usize;
        let b = |k: usize| t.get(i + k).copied().unwrap_or(0);
        match format {
            1 => i64::from(b(0)),
            2 => i64::from(i16::from_le_bytes([b(0), b(1)])),
            _ => i64::from(i32::from_le_bytes([b(0), b(1), b(2), b(3)])),
        }
    }

    /// Writes the low `format` bytes of `v`.
    pub fn write(&mut self, a: ByteAddr, format: u8, v: i64) {
        let bytes = v.to_le_bytes();
        let i = a.index as usize;
        let t = self.table_mut(a.space);
        for (k, byte) in bytes.iter().take(format as usize).enumerate() {
            if let Some(d) = t.get_mut(i + k) {
                *d = *byte;
            }
        }
    }

    /// What survives a restart.
    pub fn retained(&self) -> Retained {
        Retained {
            k: self.table(Space::K).to_vec(),
            d: self.table(Space::D).to_vec(),
            timer_presets: (0..TIMERS)
                .map(|n| (n, self.timers[n as usize].preset_ms))
                .collect(),
            counter_presets: (0..COUNTERS)
                .map(|n| (n, self.counters[n as usize].preset))
                .collect(),
        }
    }

    /// Whether `r` is what this memory retains now, compared in place: the scan asks every
    /// time, so it must not build a [`Retained`] to find out.
    pub fn retains(&self, r: &Retained) -> bool {
        self.table(Space::K) == r.k.as_slice()
            && self.table(Space::D) == r.d.as_slice()
            && r.timer_presets.len() == TIMERS as usize
            && r.counter_presets.len() == COUNTERS as usize
            && r.timer_presets.iter().all(|(n, v)| {
                self.timers
                    .get(*n as usize)
                    .is_some_and(|t| t.preset_ms == *v)
            })
            && r.counter_presets.iter().all(|(n, v)| {
                self.counters
                    .get(*n as usize)
                    .is_some_and(|c| c.preset == *v)
            })
    }

    /// Restores what a previous run kept; sizes that do not match are cut or padded.
    pub fn restore(&mut self, r: &Retained) {
        for (space, data) in [(Space::K, &r.k), (Space::D, &r.d)] {
            for (d, s) in self.table_mut(space).iter_mut().zip(data) {
                *d = *s;
            }
        }
        for (n, v) in &r.timer_presets {
            if let Some(t) = self.timers.get_mut(*n as usize) {
                t.preset_ms = *v;
            }
        }
        for (n, v) in &r.counter_presets {
            if let Some(c) = self.counters.get_mut(*n as usize) {
                c.preset = (*v).clamp(0, 32767);
            }
        }
    }
}

/// Keep relays, data registers and presets, as stored in the PLC memory file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Retained {
    #[serde(default)]
    pub k: Vec<u8>,
    #[serde(default)]
    pub d: Vec<u8>,
    #[serde(default)]
    pub timer_presets: BTreeMap<u16, u32>,
    #[serde(default)]
    pub counter_presets: BTreeMap<u16, i64>,
}

impl Retained {
    /// The kept memory of a machine's first power-up (no memory file yet): the keep relays
    /// the machine builder sets on (`K1.1`, a setting the ladder reads), all else zero.
    pub fn first_power_up(keep_relays: &[String]) -> Result<Retained, String> {
        let mut k = vec![0u8; Space::K.size()];
        for text in keep_relays {
            match crate::address::parse(text)? {
                crate::address::Address::Bit(b) if b.byte.space == Space::K => {
                    k[usize::from(b.byte.index)] |= 1 << b.bit;
                }
                _ => return Err(format!("{text}: not a keep relay bit (K0.0–K19.7)")),
            }
        }
        Ok(Retained {
            k,
            ..Retained::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_first_power_up_sets_the_builders_keep_relays_and_refuses_other_addresses() {
        let r = Retained::first_power_up(&["K1.1".into(), "k2.0".into()]).expect("keep relays");
        assert_eq!((r.k[1], r.k[2], r.k[0]), (0b10, 0b1, 0));
        assert!(r.d.is_empty() && r.timer_presets.is_empty());
        for bad in ["R1.1", "K1", "K20.0", "K1.8", "x"] {
            assert!(Retained::first_power_up(&[bad.into()]).is_err(), "{bad}");
        }
    }

    #[test]
    fn retains_tells_a_change_of_what_is_kept_and_only_that() {
        let mut m = Memory::default();
        let kept = m.retained();
        assert!(m.retains(&kept));
        // A relay that is not kept changes nothing kept.
        m.set_byte(
            ByteAddr {
                space: Space::R,
                index: 3,
            },
            7,
        );
        assert!(m.retains(&kept));
        m.set_byte(
            ByteAddr {
                space: Space::D,
                index: 100,
            },
            1,
        );
        assert!(!m.retains(&kept));
        let kept = m.retained();
        m.counters[2].preset = 5;
        assert!(!m.retains(&kept));
        assert!(m.retains(&m.retained()));
    }
}
