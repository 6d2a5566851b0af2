//! PLC addresses with the sizes of the Huaxing manual (`000` §18.1, inventory §9.1).
//!
//! Byte-addressed tables: X, Y, F, G, R (R0–R999 and the system relays R9000–R9099), D, K and
//! A. Timers (T0–T39) and counters (C0–C39) are numbered units, not byte tables: their presets
//! sit on the PLC parameter page. Labels L1–L9999 and subroutines P1–P9999 are numbers.

use std::fmt;

/// A byte-addressed table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Space {
    /// Machine → PLC.
    X,
    /// PLC → machine.
    Y,
    /// NC → PLC.
    F,
    /// PLC → NC.
    G,
    /// Internal relays.
    R,
    /// Data registers.
    D,
    /// Keep relays.
    K,
    /// Message requests (PLC alarms).
    A,
}

pub const TIMERS: u16 = 40;
pub const COUNTERS: u16 = 40;
/// Fixed timers and counters (TMRB, CTRB) and edge detectors (DIFU, DIFD): FANUC PMC numbers.
pub const FIXED_TIMERS: u16 = 100;
pub const FIXED_COUNTERS: u16 = 100;
pub const EDGES: u16 = 256;
pub const LABELS: u16 = 9999;
/// The system relays R9000–R9099 follow R0–R999 in the R table.
pub const SYSTEM_RELAYS: u16 = 9000;
const R_USER: usize = 1000;
const R_SYSTEM: usize = 100;

impl Space {
    pub const ALL: [Space; 8] = [
        Space::X,
        Space::Y,
        Space::F,
        Space::G,
        Space::R,
        Space::D,
        Space::K,
        Space::A,
    ];

    /// Bytes in the table.
    pub fn size(self) -> usize {
        match self {
            Space::X | Space::Y => 20,
            Space::F | Space::G => 256,
            Space::R => R_USER + R_SYSTEM,
            Space::D => 1000,
            Space::K => 20,
            Space::A => 10,
        }
    }

    pub fn letter(self) -> char {
        match self {
            Space::X => 'X',
            Space::Y => 'Y',
            Space::F => 'F',
            Space::G => 'G',
            Space::R => 'R',
            Space::D => 'D',
            Space::K => 'K',
            Space::A => 'A',
        }
    }

    fn from_letter(c: char) -> Option<Space> {
        Space::ALL.into_iter().find(|s| s.letter() == c)
    }

    /// Where the written address `number` sits in the table, if it exists.
    fn index(self, number: u32) -> Option<usize> {
        let n = number as usize;
        match self {
            Space::R if n < R_USER => Some(n),
            Space::R if (9000..9000 + R_SYSTEM).contains(&n) => Some(R_USER + n - 9000),
            Space::R => None,
            _ if n < self.size() => Some(n),
            _ => None,
        }
    }
}

/// `count` consecutive bytes of a table, e.g. the 4 bytes of `D100` in `ADDB 4, D100, …`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ByteAddr {
    pub space: Space,
    /// Index into the table (R9000 is 1000).
    pub index: u16,
}

/// One bit of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitAddr {
    pub byte: ByteAddr,
    pub bit: u8,
}

impl ByteAddr {
    /// The number as written (R9000 for index 1000).
    pub fn number(self) -> u32 {
        let i = u32::from(self.index);
        if self.space == Space::R && i as usize >= R_USER {
            i - R_USER as u32 + 9000
        } else {
            i
        }
    }

    /// Whether a program may write here: X and F belong to the machine and the NC, the
    /// system relays to the PLC itself.
    pub fn writable(self) -> bool {
        match self.space {
            Space::X | Space::F => false,
            Space::R => (self.index as usize) < R_USER,
            _ => true,
        }
    }

    /// Checks that `count` bytes from here stay in one table (and out of the system relays
    /// when starting below them).
    pub fn span(self, count: usize) -> Result<(), String> {
        let end = self.index as usize + count;
        let limit = if self.space == Space::R && (self.index as usize) < R_USER {
            R_USER
        } else {
            self.space.size()
        };
        if count == 0 || end > limit {
            Err(format!(
                "{count} bytes from {self} leave the {} table",
                self.space.letter()
            ))
        } else {
            Ok(())
        }
    }
}

impl fmt::Display for ByteAddr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", self.space.letter(), self.number())
    }
}

impl fmt::Display for BitAddr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.byte, self.bit)
    }
}

/// A written address: a byte (`D100`) or a bit (`X1.0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Address {
    Byte(ByteAddr),
    Bit(BitAddr),
}

/// Parses `X1.0`, `R9091.1`, `D100`; the error says what is wrong.
pub fn parse(text: &str) -> Result<Address, String> {
    let mut chars = text.chars();
    let letter = chars
        .next()
        .map(|c| c.to_ascii_uppercase())
        .ok_or("empty address")?;
    let space = Space::from_letter(letter).ok_or_else(|| format!("{text:?} is not an address"))?;
    let rest = chars.as_str();
    let (num, bit) = match rest.split_once('.') {
        Some((n, b)) => (n, Some(b)),
        None => (rest, None),
    };
    if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit()) || num.len() > 5 {
        return Err(format!("{text:?} is not an address"));
    }
    let number: u32 = num
        .parse()
        .map_err(|_| format!("{text:?} is not an address"))?;
    let index = space.index(number).ok_or_else(|| {
        format!(
            "{text} is outside the {letter} table ({})",
            match space {
                Space::R => "R0–R999, R9000–R9099".to_string(),
                s => format!("{letter}0–{letter}{}", s.size() - 1),
            }
        )
    })?;
    let byte = ByteAddr {
        space,
        index: index as u16,
    };
    match bit {
        None => Ok(Address::Byte(byte)),
        Some(b) => match b.parse::<u8>() {
            Ok(bit) if bit < 8 && b.len() == 1 => Ok(Address::Bit(BitAddr { byte, bit })),
            _ => Err(format!("{text}: bit must be 0–7")),
        },
    }
}

/// A numbered timer or counter with a preset (`T1`, `C0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Timer(u16),
    Counter(u16),
}

impl Unit {
    /// Parses `T0`–`T39` or `C0`–`C39`; anything else is an error naming the text.
    pub fn parse(text: &str) -> Result<Unit, String> {
        let mut chars = text.trim().chars();
        let kind = chars.next().map(|c| c.to_ascii_uppercase());
        let n: Option<u16> = chars.as_str().parse().ok();
        match (kind, n) {
            (Some('T'), Some(n)) if n < TIMERS => Ok(Unit::Timer(n)),
            (Some('C'), Some(n)) if n < COUNTERS => Ok(Unit::Counter(n)),
            _ => Err(format!(
                "{text:?} is not a timer T0–T{} or counter C0–C{}",
                TIMERS - 1,
                COUNTERS - 1
            )),
        }
    }

    /// Whether `value` is a valid preset: ms for a timer, a count 0–32767 for a counter.
    pub fn preset_ok(self, value: i64) -> bool {
        match self {
            Unit::Timer(_) => (0..=i64::from(u32::MAX)).contains(&value),
            Unit::Counter(_) => (0..=32767).contains(&value),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_parse_with_the_manual_sizes() {
        let Address::Bit(b) = parse("X19.7").unwrap() else {
            panic!()
        };
        assert_eq!(b.to_string(), "X19.7");
        assert!(parse("X20.0").unwrap_err().contains("outside the X table"));
        assert!(parse("R999").is_ok());
        assert!(parse("R1000").is_err());
        let Address::Byte(r) = parse("R9091").unwrap() else {
            panic!()
        };
        assert_eq!((r.index, r.number(), r.writable()), (1091, 9091, false));
        assert!(parse("R9100").is_err());
        assert!(parse("D999").is_ok() && parse("D1000").is_err());
        assert!(parse("K19").is_ok() && parse("K20").is_err());
        assert!(parse("A9.7").is_ok() && parse("A10.0").is_err());
        assert!(parse("G255").is_ok() && parse("F256").is_err());
        assert!(parse("Y1.8").unwrap_err().contains("bit must be 0–7"));
        assert!(parse("Q1").is_err() && parse("X").is_err() && parse("X-1").is_err());
        let Address::Byte(d) = parse("D998").unwrap() else {
            panic!()
        };
        assert!(d.span(2).is_ok() && d.span(4).is_err());
        let Address::Byte(r) = parse("R998").unwrap() else {
            panic!()
        };
        assert!(
            r.span(4).is_err(),
            "a word may not run into the system relays"
        );
    }

    #[test]
    fn units_parse_without_panicking_on_any_text() {
        assert_eq!(Unit::parse("t39"), Ok(Unit::Timer(39)));
        assert_eq!(Unit::parse("C0"), Ok(Unit::Counter(0)));
        for bad in ["T40", "C", "", "中1", "X1", "T-1", "T1.0"] {
            assert!(Unit::parse(bad).is_err(), "{bad}");
        }
        assert!(Unit::Counter(0).preset_ok(32767) && !Unit::Counter(0).preset_ok(32768));
        assert!(!Unit::Timer(0).preset_ok(-1));
    }
}
