//! The 802D's variables (`001` §9.9, §9.12; inventory §2.3–§2.5, §3.12, §5.5): the
//! arithmetic parameters R0–R299 (kept across power-off in the core's common store, where the
//! offset page's R list reads them), the program's own `DEF` variables (visible only in the
//! program that defines them), the 512-byte NC/PLC area `$A_DBB/W/D/R`, and the system
//! variables the manual's examples read.

use std::collections::HashMap;

use cnc_interpreter_core::Fault;

use super::expr::{EvalError, Val};

/// Where R0 lives in the core's common store (R0–R299 are keys 10000–10299; the shell keeps
/// them across power-off, decision D78).
pub const R_BASE: i64 = 10_000;
pub const R_COUNT: i64 = 300;
/// The NC/PLC shared area, bytes (§9.9.3).
pub const PLC_BYTES: usize = 512;

/// A `DEF` variable: its type, its values (one, or an array's in row order) and its shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Var {
    pub ty: String,
    pub len: Option<usize>,
    pub dims: Vec<usize>,
    pub values: Vec<Val>,
}

impl Var {
    pub fn new(ty: &str, len: Option<usize>, dims: &[usize]) -> Var {
        let n = dims.iter().product::<usize>().max(1);
        let zero = if ty == "STRING" {
            Val::Str(String::new())
        } else {
            Val::Num(0.0)
        };
        Var {
            ty: ty.to_string(),
            len,
            dims: dims.to_vec(),
            values: vec![zero; n],
        }
    }

    /// The element an index list names, in row order.
    pub fn slot(&self, name: &str, idx: &[Val]) -> Result<usize, EvalError> {
        if idx.len() != self.dims.len() {
            return Err(EvalError::new(
                Fault::MacroVariable,
                format!(
                    "{name} has {} index(es), {} given",
                    self.dims.len(),
                    idx.len()
                ),
            ));
        }
        let mut at = 0;
        for (i, (v, &d)) in idx.iter().zip(&self.dims).enumerate() {
            let k = v.num()?;
            if k.fract() != 0.0 || k < 0.0 || k >= d as f64 {
                return Err(EvalError::new(
                    Fault::OutOfRange,
                    format!(
                        "{name}: index {} of dimension {} is outside 0…{}",
                        crate_show(k),
                        i + 1,
                        d - 1
                    ),
                ));
            }
            at = at * d + k as usize;
        }
        Ok(at)
    }

    /// `v` as this type stores it (INT truncates toward the nearest whole number, BOOL is 0
    /// or 1, CHAR a code 0…255, STRING at most its length).
    pub fn coerce(&self, name: &str, v: Val) -> Result<Val, EvalError> {
        let bad =
            |what: &str| EvalError::new(Fault::OutOfRange, format!("{name} ({}): {what}", self.ty));
        Ok(match (self.ty.as_str(), v) {
            ("STRING", Val::Str(s)) => {
                if s.chars().count() > self.len.unwrap_or(200) {
                    return Err(bad("string longer than declared"));
                }
                Val::Str(s)
            }
            ("STRING", Val::Num(x)) => Val::Str(crate_show(x)),
            (_, Val::Str(_)) => return Err(bad("a string cannot be stored here")),
            ("INT", Val::Num(x)) => {
                let r = x.round();
                if !(-2_147_483_648.0..=2_147_483_647.0).contains(&r) {
                    return Err(bad("beyond the 32-bit range"));
                }
                Val::Num(r)
            }
            ("BOOL", Val::Num(x)) => Val::Num(f64::from(u8::from(x != 0.0))),
            ("CHAR", Val::Num(x)) => {
                let r = x.round();
                if !(0.0..=255.0).contains(&r) {
                    return Err(bad("a character code is 0…255"));
                }
                Val::Num(r)
            }
            (_, Val::Num(x)) => Val::Num(x),
        })
    }
}

fn crate_show(v: f64) -> String {
    cnc_interpreter_core::show(v)
}

/// One program level's own variables.
pub type Scope = HashMap<String, Var>;

/// The NC/PLC area (§9.9.3), read and written by byte, word, double word or REAL.
#[derive(Debug, Clone)]
pub struct PlcArea {
    pub bytes: Vec<u8>,
}

impl Default for PlcArea {
    fn default() -> Self {
        PlcArea {
            bytes: vec![0; PLC_BYTES],
        }
    }
}

impl PlcArea {
    fn width(kind: &str) -> Option<usize> {
        match kind {
            "$A_DBB" => Some(1),
            "$A_DBW" => Some(2),
            "$A_DBD" | "$A_DBR" => Some(4),
            _ => None,
        }
    }

    fn span(kind: &str, idx: &[Val]) -> Result<(usize, usize), EvalError> {
        let w = PlcArea::width(kind).unwrap_or(1);
        let at = match idx {
            [v] => v.num()?,
            _ => {
                return Err(EvalError::new(
                    Fault::MacroVariable,
                    format!("{kind}[n] needs one index"),
                ))
            }
        };
        // Compared as numbers: a huge index must not wrap when made an offset.
        if at.fract() != 0.0 || at < 0.0 || at + w as f64 > PLC_BYTES as f64 {
            return Err(EvalError::new(
                Fault::OutOfRange,
                format!(
                    "{kind}[{}] is outside the {PLC_BYTES}-byte PLC area",
                    crate_show(at)
                ),
            ));
        }
        Ok((at as usize, w))
    }

    pub fn is_plc(name: &str) -> bool {
        PlcArea::width(name).is_some()
    }

    pub fn read(&self, kind: &str, idx: &[Val]) -> Result<f64, EvalError> {
        let (at, w) = PlcArea::span(kind, idx)?;
        let b = &self.bytes[at..at + w];
        Ok(match kind {
            "$A_DBB" => f64::from(b[0]),
            "$A_DBW" => f64::from(i16::from_le_bytes([b[0], b[1]])),
            "$A_DBD" => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        })
    }

    pub fn write(&mut self, kind: &str, idx: &[Val], v: f64) -> Result<(), EvalError> {
        let (at, w) = PlcArea::span(kind, idx)?;
        let range = |lo: f64, hi: f64| {
            if v.fract() == 0.0 && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(EvalError::new(
                    Fault::OutOfRange,
                    format!("{kind}: {} does not fit", crate_show(v)),
                ))
            }
        };
        let bytes: Vec<u8> = match kind {
            "$A_DBB" => {
                range(-128.0, 255.0)?;
                vec![(v as i64 & 0xff) as u8]
            }
            "$A_DBW" => {
                range(-32768.0, 65535.0)?;
                ((v as i64 & 0xffff) as u16).to_le_bytes().to_vec()
            }
            "$A_DBD" => {
                range(-2_147_483_648.0, 4_294_967_295.0)?;
                ((v as i64 & 0xffff_ffff) as u32).to_le_bytes().to_vec()
            }
            _ => (v as f32).to_le_bytes().to_vec(),
        };
        self.bytes[at..at + w].copy_from_slice(&bytes);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_index_in_row_order_and_refuse_outside() {
        let v = Var::new("INT", None, &[2, 3]);
        assert_eq!(v.values.len(), 6);
        assert_eq!(v.slot("B", &[Val::Num(1.0), Val::Num(2.0)]), Ok(5));
        assert!(v.slot("B", &[Val::Num(2.0), Val::Num(0.0)]).is_err());
        assert!(v.slot("B", &[Val::Num(1.0)]).is_err());
        assert_eq!(v.coerce("B", Val::Num(2.6)), Ok(Val::Num(3.0)));
        let s = Var::new("STRING", Some(3), &[]);
        assert!(s.coerce("S", Val::Str("Hallo".into())).is_err());
    }

    #[test]
    fn the_plc_area_holds_bytes_words_and_reals() {
        let mut a = PlcArea::default();
        a.write("$A_DBW", &[Val::Num(4.0)], -2.0).unwrap();
        assert_eq!(a.read("$A_DBW", &[Val::Num(4.0)]).unwrap(), -2.0);
        assert_eq!(a.read("$A_DBB", &[Val::Num(4.0)]).unwrap(), 254.0);
        a.write("$A_DBR", &[Val::Num(8.0)], 1.5).unwrap();
        assert_eq!(a.read("$A_DBR", &[Val::Num(8.0)]).unwrap(), 1.5);
        assert!(a.write("$A_DBD", &[Val::Num(510.0)], 1.0).is_err());
        assert!(a.write("$A_DBB", &[Val::Num(0.0)], 300.0).is_err());
        assert!(a.read("$A_DBB", &[Val::Num(1e30)]).is_err());
        assert!(a.read("$A_DBW", &[Val::Num(f64::MAX)]).is_err());
    }
}
