//! Tool monitoring by workpiece count (`001` §9.13; inventory §5.4; `docs/decisions.md`
//! D111): the data `$TC_TP8[t]`, `$TC_TP9[t]`, `$TC_MOP1…MOP13[t,d]`, `SETPIECE(n)` counting
//! the pieces down on every cutting edge used since the last SETPIECE, and
//! `RESETMON(state,t,d,mon)` setting them back to their setpoints. A count at its prewarning
//! limit is message 6411, at zero message 6413 and the tool is disabled: T cannot select it
//! again until RESETMON.
//!
//! The data live in the core's kept store (keys [`BASE`]…), so they survive power-off as the
//! offset page's do; only edges on the offset page have them.
//!
//! Tool life (type 1, D122): the remaining life `$TC_MOP2` of the active edge goes down by the
//! cutting time the machine counted while it was active (motion's `$AC_CUTTING_TIME`, D121),
//! accounted at preprocessing stops: the run's first block, every block that changes the edge
//! (T, D, M6), the main program's end, and a block that reads `$TC_MOP2` or sets the life
//! clock's factor `$A_MONIFACT`.

use cnc_interpreter_core::{Fault, ProgramError};

use super::block::{Block, Item};
use super::expr::{EvalError, Expr, Val};
use super::Sinumerik;

/// Where the monitoring data start in the core's common store: datum `k` of edge T×10+D is
/// `BASE + k × SPAN + T×10+D` (the tool's own data with D 0).
pub const BASE: i64 = 20_000_000;
const SPAN: i64 = 1_000_000;
/// The data in key order: tool state and monitoring type per tool, then per edge.
const DATA: [&str; 8] = [
    "$TC_TP8",
    "$TC_TP9",
    "$TC_MOP1",
    "$TC_MOP2",
    "$TC_MOP3",
    "$TC_MOP4",
    "$TC_MOP11",
    "$TC_MOP13",
];
/// Keys of the kept store that hold monitoring data (the shell keeps them).
pub const KEYS: std::ops::RangeInclusive<i64> = BASE..=BASE + DATA.len() as i64 * SPAN - 1;

/// Positions in [`DATA`].
const TP8: usize = 0;
const TP9: usize = 1;
const MOP1: usize = 2;
const MOP2: usize = 3;
const MOP3: usize = 4;
const MOP4: usize = 5;
const MOP11: usize = 6;
const MOP13: usize = 7;

/// `$TC_TP8` bits (§9.13.1).
const ACTIVE: i64 = 1;
const DISABLED: i64 = 4;
const PREWARNING: i64 = 16;
/// `$TC_TP9` bits: life, count.
const LIFE: i64 = 1;
const COUNT: i64 = 2;
/// The life clock's factor (§9.13.2): 1.0 at each program's start.
const MONIFACT: &str = "$A_MONIFACT";
/// Message numbers of the SINUMERIK alarm list (the manual names none, D111).
pub const PREWARNING_REACHED: u32 = 6411;
pub const LIMIT_REACHED: u32 = 6413;

fn key(datum: usize, t: u32, d: u32) -> i64 {
    BASE + datum as i64 * SPAN + i64::from(t) * 10 + i64::from(d)
}

/// Where the kept store holds datum `name` (`$TC_MOP4`) of tool `t`, edge `d` (0 for the
/// tool's own `$TC_TP8`/`$TC_TP9`): what the offset page's monitoring screen reads and sets.
pub fn kept_key(name: &str, t: u32, d: u32) -> Option<i64> {
    index_of(name).map(|k| key(k, t, d))
}

fn index_of(name: &str) -> Option<usize> {
    DATA.iter().position(|n| *n == name)
}

impl Sinumerik {
    fn datum(&self, datum: usize, t: u32, d: u32) -> f64 {
        self.core
            .common
            .get(&key(datum, t, d))
            .copied()
            .unwrap_or(0.0)
    }

    fn set_datum(&mut self, datum: usize, t: u32, d: u32, v: f64) {
        self.core.common.insert(key(datum, t, d), v);
    }

    /// A monitoring datum as the program has left it (for checks): `$TC_MOP4`, tool, edge.
    pub fn tool_datum(&self, name: &str, t: u32, d: u32) -> f64 {
        index_of(name).map_or(0.0, |k| self.datum(k, t, d))
    }

    /// The edges of the offset page (T×10+D entries) of tool `t`.
    fn edges_of(&self, t: u32) -> Vec<u32> {
        (1..=9)
            .filter(|d| self.core.setup.offsets.tools.contains_key(&(t * 10 + d)))
            .collect()
    }

    /// The tool and edge a `$TC_…[t]` or `$TC_…[t,d]` names; per-tool data take `[t]` and, as
    /// the manual's own example writes it, `[t,d]` with `d` ignored (inventory conflict 10).
    fn monitored_edge(&self, name: &str, idx: &[Val]) -> Result<(u32, u32), EvalError> {
        let per_tool = name.starts_with("$TC_TP");
        let whole = |v: &Val, what: &str, max: f64| -> Result<u32, EvalError> {
            let x = v.num()?;
            if x.fract() != 0.0 || !(1.0..=max).contains(&x) {
                return Err(EvalError::new(
                    Fault::OutOfRange,
                    format!(
                        "{name}: {what} {} does not exist",
                        cnc_interpreter_core::show(x)
                    ),
                ));
            }
            Ok(x as u32)
        };
        let (t, d) = match (idx, per_tool) {
            ([t] | [t, _], true) => (whole(t, "tool", 32_000.0)?, 0),
            ([t, d], false) => (whole(t, "tool", 32_000.0)?, whole(d, "edge", 9.0)?),
            _ => {
                let form = if per_tool { "[t]" } else { "[t,d]" };
                return Err(EvalError::new(
                    Fault::MacroVariable,
                    format!("{name}{form}: tool and edge numbers"),
                ));
            }
        };
        let known = match d {
            0 => !self.edges_of(t).is_empty(),
            d => self.core.setup.offsets.tools.contains_key(&(t * 10 + d)),
        };
        if !known {
            return Err(EvalError::new(
                Fault::ToolNumber,
                format!("{name}: T{t} D{d} is not on the offset page"),
            ));
        }
        Ok((t, d))
    }

    /// Reads `$TC_TP8/9[t]`, `$TC_MOPk[t,d]` or `$A_MONIFACT`; None if `name` is none of them.
    pub(super) fn monitor_read(&self, name: &str, idx: &[Val]) -> Option<Result<f64, EvalError>> {
        if name == MONIFACT {
            return Some(Ok(self.monifact));
        }
        let k = index_of(name)?;
        Some(self.monitored_edge(name, idx).map(|(t, d)| {
            let v = self.datum(k, t, d);
            // Bit 0 of the state is the tool in the spindle now.
            match k == TP8 && t == self.tool {
                true => (v as i64 | ACTIVE) as f64,
                false => v,
            }
        }))
    }

    /// Writes a monitoring datum; None if `name` is none. The counts and types are integers
    /// (a value with a fraction is rounded, as the control converts REAL to INT).
    pub(super) fn monitor_write(
        &mut self,
        name: &str,
        idx: &[Val],
        v: &Val,
    ) -> Option<Result<(), EvalError>> {
        if name == MONIFACT {
            return Some(self.set_monifact(v));
        }
        let k = index_of(name)?;
        Some(self.write_datum(k, name, idx, v))
    }

    /// `$A_MONIFACT=f` (§9.13.2): from here on a minute of cutting takes `f` minutes of life;
    /// above 0. The block that writes it is a preprocessing stop (see [`Self::life_stop`]), so
    /// the time cut before it is accounted with the factor it had.
    fn set_monifact(&mut self, v: &Val) -> Result<(), EvalError> {
        let f = v.num()?;
        if !(f > 0.0 && f <= 1.0e6) {
            return Err(EvalError::new(
                Fault::OutOfRange,
                format!(
                    "{MONIFACT} is above 0, not {}",
                    cnc_interpreter_core::show(f)
                ),
            ));
        }
        self.monifact = f;
        Ok(())
    }

    fn write_datum(&mut self, k: usize, name: &str, idx: &[Val], v: &Val) -> Result<(), EvalError> {
        let (t, d) = self.monitored_edge(name, idx)?;
        let mut x = v.num()?;
        if !x.is_finite() || x.abs() > 1.0e9 {
            return Err(EvalError::new(Fault::OutOfRange, format!("{name}: {x}")));
        }
        if matches!(k, TP8 | TP9 | MOP3 | MOP4 | MOP13) {
            x = x.round();
        }
        if k == TP9 && !(0.0..=3.0).contains(&x) {
            return Err(EvalError::new(
                Fault::OutOfRange,
                "$TC_TP9: 0 none, 1 life, 2 count, 3 both",
            ));
        }
        self.set_datum(k, t, d, x);
        if k == TP9 {
            self.life_used = self.life_in_use();
        }
        Ok(())
    }

    /// Whether a tool of the offset page is monitored by its life.
    pub(super) fn life_in_use(&self) -> bool {
        let tools = self.core.setup.offsets.tools.keys().map(|e| e / 10);
        tools
            .filter(|t| *t > 0)
            .any(|t| self.datum(TP9, t, 0) as i64 & LIFE != 0)
    }

    /// Whether `block` must wait for a preprocessing stop that accounts the active edge's
    /// life: with life monitoring in use, the run's first block, a block that changes the
    /// edge (T, D, M6), ends the main program (M2, M30), reads `$TC_MOP2` or sets
    /// `$A_MONIFACT`.
    pub(super) fn life_stop(&self, block: &Block, line: &str) -> bool {
        if !self.life_used {
            return false;
        }
        let main = self.core.depth() == 1;
        let changes = block.items.iter().any(|item| match item {
            Item::Word { letter, value, .. } => {
                matches!(letter, 'T' | 'D')
                    || (*letter == 'M'
                        && (*value == 6.0 || (main && matches!(*value as u32, 2 | 30))))
            }
            Item::Assign { name, .. } => matches!(name.as_ref(), "T" | "D" | MONIFACT),
            _ => false,
        });
        self.life_start.is_none()
            || changes
            || super::lex::strip_comment(line)
                .to_ascii_uppercase()
                .contains("$TC_MOP2")
    }

    /// After a preprocessing stop: the timers as the machine reported them (none without a
    /// machine), and the active edge's life down by the cutting time since its last stop.
    pub(super) fn machine_read(&mut self) {
        if let Some(t) = self.core.machine_timers() {
            self.timers = t;
        }
        let now = self.timers.cutting;
        let Some(start) = self.life_start.replace(now) else {
            return;
        };
        let (t, d) = (self.tool, self.edge);
        if t == 0 || d == 0 || self.core.searching || self.datum(TP9, t, 0) as i64 & LIFE == 0 {
            return;
        }
        if !self.core.setup.offsets.tools.contains_key(&(t * 10 + d)) {
            return;
        }
        let left = self.datum(MOP2, t, d) - (now - start).max(0.0) / 60.0 * self.monifact;
        self.set_datum(MOP2, t, d, left);
        let warn = self.datum(MOP1, t, d);
        self.reach_limits(t, d, left, warn);
    }

    /// A remaining count or life `left` at or below its prewarning limit `warn` (if one is
    /// set) is message 6411, at or below 0 message 6413 and the tool disabled; each once.
    fn reach_limits(&mut self, t: u32, d: u32, left: f64, warn: f64) {
        let state = self.datum(TP8, t, 0) as i64;
        let (flag, number, text) = if left <= 0.0 {
            (DISABLED, LIMIT_REACHED, "has reached its monitoring limit")
        } else if warn > 0.0 && left <= warn {
            (
                PREWARNING,
                PREWARNING_REACHED,
                "has reached its prewarning limit",
            )
        } else {
            return;
        };
        if state & flag == 0 {
            self.set_datum(TP8, t, 0, (state | flag) as f64);
            let shown = format!("{number} tool {t} {text} with D = {d}");
            self.messages.push((self.core.line, shown.clone()));
            self.core.operator_message(shown);
        }
    }

    /// A cutting edge became active: SETPIECE will count it (§9.13.3, "SETPIECE memory").
    pub(super) fn edge_loaded(&mut self) {
        let edge = (self.tool, self.edge);
        if edge.0 > 0 && edge.1 > 0 && !self.setpiece_memory.contains(&edge) {
            self.setpiece_memory.push(edge);
        }
    }

    /// A disabled tool cannot be selected (§9.13.2).
    pub(super) fn check_not_disabled(&self, t: u32) -> Result<(), ProgramError> {
        let state = self.datum(TP8, t, 0) as i64;
        if t > 0 && state & DISABLED != 0 {
            return Err(self.fault(
                Fault::ToolNumber,
                format!(
                    "T{t} is disabled: its monitoring limit is reached ({LIMIT_REACHED}); \
                     RESETMON or the offset page first"
                ),
            ));
        }
        Ok(())
    }

    /// `SETPIECE(n[,s])`: `n` pieces made since the last SETPIECE come off the remaining count
    /// of every count-monitored edge used since then and of the active edge. Nothing counts
    /// during a block search (§9.13.3).
    pub(super) fn setpiece(&mut self, args: &[Option<Expr>]) -> Result<(), ProgramError> {
        let number = |s: &Self, e: &Option<Expr>, what: &str, max: f64| {
            let x = match e {
                Some(e) => s.value(e)?.num().map_err(|e| s.eval_error(e))?,
                None => return Err(s.fault(Fault::MacroArgument, format!("SETPIECE: no {what}"))),
            };
            if x.fract() != 0.0 || !(0.0..=max).contains(&x) {
                return Err(s.fault(
                    Fault::OutOfRange,
                    format!(
                        "SETPIECE: {what} is 0…{max}, not {}",
                        cnc_interpreter_core::show(x)
                    ),
                ));
            }
            Ok(x)
        };
        let n = match args {
            [n] => number(self, n, "piece count", 32_000.0)?,
            [n, s] => {
                if number(self, s, "spindle", 2.0)? > 1.0 {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        "SETPIECE: this machine has one spindle (s = 1)",
                    ));
                }
                number(self, n, "piece count", 32_000.0)?
            }
            _ => return Err(self.fault(Fault::MacroArgument, "SETPIECE(n) or SETPIECE(n,s)")),
        };
        self.edge_loaded();
        let edges = std::mem::take(&mut self.setpiece_memory);
        if self.core.searching {
            return Ok(());
        }
        for (t, d) in edges {
            if self.datum(TP9, t, 0) as i64 & COUNT == 0 {
                continue;
            }
            let left = self.datum(MOP4, t, d) - n;
            self.set_datum(MOP4, t, d, left);
            let warn = self.datum(MOP3, t, d);
            self.reach_limits(t, d, left, warn);
        }
        Ok(())
    }

    /// `RESETMON(state, t[, d[, mon]])`: the remaining count (and life) back to the setpoint,
    /// the tool enabled again; `state` gets 0 or the manual's −1…−4.
    pub(super) fn resetmon(&mut self, args: &[Option<Expr>]) -> Result<(), ProgramError> {
        let (state, rest) = match args {
            [Some(Expr::Var(name, idx)), rest @ ..] if idx.is_empty() && !rest.is_empty() => {
                (name.to_string(), rest)
            }
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    "RESETMON(state, t[, d[, mon]]): state is a DEF INT variable",
                ))
            }
        };
        let mut values = [0.0; 3];
        for (slot, e) in values.iter_mut().zip(rest) {
            if let Some(e) = e {
                *slot = self.value(e)?.num().map_err(|e| self.eval_error(e))?;
            }
        }
        if rest.len() > 3
            || values
                .iter()
                .zip([32_000.0, 9.0, 3.0])
                .any(|(v, max)| v.fract() != 0.0 || !(0.0..=max).contains(v))
        {
            return Err(self.fault(
                Fault::OutOfRange,
                "RESETMON: t 0…32000 (0 all), d 0…9 (0 all), mon 0…3 (1 life, 2 count)",
            ));
        }
        let [t, d, mon] = values.map(|v| v as u32);
        let code = self.reset_monitoring(t, d, i64::from(mon));
        self.write_value(&state, &[], Val::Num(code))
            .map_err(|e| self.eval_error(e))
    }

    fn reset_monitoring(&mut self, t: u32, d: u32, mon: i64) -> f64 {
        let tools: Vec<u32> = match t {
            0 => {
                let mut all: Vec<u32> = self
                    .core
                    .setup
                    .offsets
                    .tools
                    .keys()
                    .map(|e| e / 10)
                    .filter(|t| self.datum(TP9, *t, 0) != 0.0)
                    .collect();
                all.dedup();
                if all.is_empty() {
                    return -3.0;
                }
                all
            }
            t if self.edges_of(t).is_empty() => return -2.0,
            t if d > 0 && !self.edges_of(t).contains(&d) => return -1.0,
            t if self.datum(TP9, t, 0) == 0.0 => return -3.0,
            t => vec![t],
        };
        let mut done = false;
        for t in tools {
            let types = self.datum(TP9, t, 0) as i64;
            let mask = if mon == 0 { types } else { mon & types };
            if mask == 0 {
                continue;
            }
            let edges = match d {
                0 => self.edges_of(t),
                d => vec![d],
            };
            for d in edges {
                if mask & COUNT != 0 {
                    self.set_datum(MOP4, t, d, self.datum(MOP13, t, d));
                }
                if mask & LIFE != 0 {
                    self.set_datum(MOP2, t, d, self.datum(MOP11, t, d));
                }
            }
            let state = self.datum(TP8, t, 0) as i64;
            self.set_datum(TP8, t, 0, (state & !(DISABLED | PREWARNING)) as f64);
            done = true;
        }
        if done {
            0.0
        } else {
            -4.0
        }
    }
}
