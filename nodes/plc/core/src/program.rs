//! The ladder program in its mnemonic text form, parsed and checked before it may run.
//!
//! One instruction per line, operands separated by commas or spaces, `;` starts a comment:
//!
//! ```text
//! SYM  TURRET_CW  Y2.5            ; a name for an address
//! MSG  A0.1 ALARM "tool change timeout"
//! PRESET T1 5000                  ; timer preset, ms (the parameter page may change it)
//! INIT D30 1 8                    ; data register default: format (bytes), value
//! RD   F7.3
//! AND.NOT R40.0
//! TMR  1
//! WRT  A0.1
//! END1
//! ```
//!
//! The instruction set is the manual's (`000` §18.1): 14 basic and 42 functional instructions,
//! with FANUC PMC semantics where the manual is silent (decisions D39–D41 in
//! `docs/decisions.md`). A functional instruction takes its control inputs from the logic stack,
//! ACT in ST0 and the others below it in FANUC's order; a rung (from RD or RD.NOT) starts with an
//! empty stack, so inputs a rung does not push read 0.

use std::collections::{BTreeMap, HashMap, HashSet};

use crate::address::{
    self, Address, BitAddr, ByteAddr, Space, Unit, COUNTERS, EDGES, FIXED_COUNTERS, FIXED_TIMERS,
    LABELS, TIMERS,
};

/// The manual's program capacity.
mod checks;
mod operands;

pub const MAX_STEPS: usize = 10_000;
/// Depth of the logic stack: ST0–ST7.
pub const STACK_DEPTH: usize = 8;
/// Subroutine nesting (CALL within CALL).
pub const MAX_CALL_DEPTH: usize = 8;

/// A data operand: a constant or a byte address holding the value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Val {
    Const(i64),
    Addr(ByteAddr),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArithOp {
    Add,
    Sub,
    Mul,
    Div,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogicOp {
    Eor,
    And,
    Or,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Instr {
    Rd(BitAddr),
    RdNot(BitAddr),
    RdStk(BitAddr),
    RdNotStk(BitAddr),
    And(BitAddr),
    AndNot(BitAddr),
    Or(BitAddr),
    OrNot(BitAddr),
    AndStk,
    OrStk,
    Wrt(BitAddr),
    WrtNot(BitAddr),
    Set(BitAddr),
    Rst(BitAddr),
    End1,
    End2,
    /// End of the subroutine area (optional).
    End3,
    /// On-delay timer with its preset on the parameter page.
    Tmr {
        timer: u16,
    },
    /// On-delay timer with a fixed preset, ms.
    Tmrb {
        timer: u16,
        preset_ms: u32,
    },
    /// Decodes 8 consecutive values from `first` into the 8 bits of `out`.
    Decb {
        format: u8,
        code: ByteAddr,
        first: i64,
        out: ByteAddr,
    },
    Ctr {
        counter: u16,
    },
    Ctrb {
        counter: u16,
        preset: i64,
    },
    /// Counter with preset and count in data registers (2 bytes each).
    Ctrc {
        preset: ByteAddr,
        register: ByteAddr,
    },
    Rotb {
        format: u8,
        positions: Val,
        current: ByteAddr,
        target: ByteAddr,
        out: ByteAddr,
    },
    Codb {
        format: u8,
        index: ByteAddr,
        out: ByteAddr,
        table: Vec<i64>,
    },
    Move {
        mask: u8,
        src: ByteAddr,
        dst: ByteAddr,
    },
    Movor {
        src: ByteAddr,
        or: ByteAddr,
        dst: ByteAddr,
    },
    /// MOVB (1 byte), MOVW (2) and MOVN (n).
    Movn {
        bytes: u16,
        src: ByteAddr,
        dst: ByteAddr,
    },
    Pari {
        addr: ByteAddr,
    },
    Dcnvb {
        format: u8,
        src: ByteAddr,
        dst: ByteAddr,
    },
    Compb {
        format: u8,
        input: Val,
        compare: ByteAddr,
    },
    Sft {
        addr: ByteAddr,
    },
    Dschb {
        format: u8,
        count: Val,
        table: ByteAddr,
        key: Val,
        out: ByteAddr,
    },
    Xmovb {
        format: u8,
        count: Val,
        table: ByteAddr,
        data: ByteAddr,
        index: ByteAddr,
    },
    Arith {
        op: ArithOp,
        format: u8,
        a: ByteAddr,
        b: Val,
        out: ByteAddr,
    },
    Numeb {
        format: u8,
        value: i64,
        dst: ByteAddr,
    },
    Difu {
        edge: u16,
    },
    Difd {
        edge: u16,
    },
    Logic {
        op: LogicOp,
        format: u8,
        a: ByteAddr,
        b: Val,
        out: ByteAddr,
    },
    Notb {
        format: u8,
        src: ByteAddr,
        dst: ByteAddr,
    },
    /// Common line control: while ACT is 0, the next `coils` coils (0: up to COME) write 0.
    Com {
        coils: u16,
    },
    Come,
    Call(u16),
    Callu(u16),
    Jmpb(u16),
    Lbl(u16),
    Sp(u16),
    Spe,
    /// Spindle control (Huaxing): the spindle drive's speed command = S code × override %.
    Splcnt {
        speed: ByteAddr,
        override_percent: ByteAddr,
    },
}

impl Instr {
    /// Control inputs taken from the stack (ACT last); 0 for instructions that run
    /// unconditionally and leave the stack alone.
    pub fn inputs(&self) -> usize {
        use Instr::*;
        match self {
            Rd(_) | RdNot(_) | RdStk(_) | RdNotStk(_) | End1 | End2 | End3 | Come | Callu(_)
            | Lbl(_) | Sp(_) | Spe => 0,
            And(_) | AndNot(_) | Or(_) | OrNot(_) | Wrt(_) | WrtNot(_) | Set(_) | Rst(_) => 1,
            AndStk | OrStk => 2,
            Tmr { .. } | Tmrb { .. } | Decb { .. } | Move { .. } | Movor { .. } | Movn { .. } => 1,
            Compb { .. } | Numeb { .. } | Difu { .. } | Difd { .. } | Logic { .. } => 1,
            Notb { .. } | Com { .. } | Call(_) | Jmpb(_) | Splcnt { .. } => 1,
            Codb { .. } | Dschb { .. } | Arith { .. } => 2,
            Pari { .. } | Xmovb { .. } => 3,
            Ctr { .. } | Ctrb { .. } | Ctrc { .. } | Dcnvb { .. } | Sft { .. } => 4,
            Rotb { .. } => 5,
        }
    }

    /// Whether the instruction starts a new rung.
    pub fn starts_rung(&self) -> bool {
        matches!(self, Instr::Rd(_) | Instr::RdNot(_)) || self.inputs() == 0 && !self.is_stack()
    }

    fn is_stack(&self) -> bool {
        matches!(self, Instr::RdStk(_) | Instr::RdNotStk(_))
    }
}

/// One instruction with the line it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    pub line: u32,
    pub instr: Instr,
    /// The source text, for the ladder monitor.
    pub text: String,
}

/// How the PLC shows a message request (A bit).
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    pub text: String,
    /// An alarm stops the machine (by the program's own logic) and is kept in the alarm list;
    /// a message only informs.
    pub alarm: bool,
}

/// A checked program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    pub steps: Vec<Step>,
    /// Index of END1 and END2.
    pub end1: usize,
    pub end2: usize,
    /// Subroutine P number → index of its first step (after SP).
    pub subroutines: HashMap<u16, usize>,
    /// Label number → index of the LBL step, per scope (the scope's first step).
    pub labels: HashMap<(usize, u16), usize>,
    /// The scope (index of its first step) each step belongs to.
    pub scope: Vec<usize>,
    pub symbols: BTreeMap<String, Address>,
    pub messages: BTreeMap<(u16, u8), Message>,
    pub timer_presets: BTreeMap<u16, u32>,
    pub counter_presets: BTreeMap<u16, i64>,
    /// Default data: (address, format, value).
    pub init: Vec<(ByteAddr, u8, i64)>,
}

/// A program that cannot run: where and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadError {
    pub line: u32,
    pub reason: String,
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.reason)
    }
}

impl Program {
    /// Parses and checks a program. Nothing of a program with an error is used.
    pub fn parse(text: &str) -> Result<Program, LoadError> {
        let mut p = Program::default();
        // Symbols first, so a name may be used before the line that defines it.
        for (i, raw) in text.lines().enumerate() {
            let words = split(strip_comment(raw));
            if words.first().is_some_and(|w| w.eq_ignore_ascii_case("SYM")) {
                let line = i as u32 + 1;
                let err = |reason: String| LoadError { line, reason };
                let [_, name, addr] = words.as_slice() else {
                    return Err(err("SYM needs a name and an address".into()));
                };
                let a = address::parse(addr).map_err(err)?;
                if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    || name.starts_with(|c: char| c.is_ascii_digit())
                    || address::parse(name).is_ok()
                {
                    return Err(err(format!("{name:?} cannot be a symbol name")));
                }
                if p.symbols.insert(name.to_ascii_uppercase(), a).is_some() {
                    return Err(err(format!("symbol {name} defined twice")));
                }
            }
        }
        for (i, raw) in text.lines().enumerate() {
            let line = i as u32 + 1;
            let code = strip_comment(raw);
            let words = split(code);
            let Some(first) = words.first() else {
                continue;
            };
            let mnemonic = first.to_ascii_uppercase();
            let args = &words[1..];
            let parsed = match mnemonic.as_str() {
                "SYM" => continue,
                "MSG" => p.message(raw, args),
                "PRESET" => p.preset(args),
                "INIT" => p.init_data(args),
                _ => p.instruction(&mnemonic, args).map(|instr| {
                    p.steps.push(Step {
                        line,
                        instr,
                        text: code.trim().to_string(),
                    })
                }),
            };
            parsed.map_err(|reason| LoadError { line, reason })?;
            if p.steps.len() > MAX_STEPS {
                return Err(LoadError {
                    line,
                    reason: format!("more than {MAX_STEPS} steps"),
                });
            }
        }
        p.check_structure()?;
        p.check_stack()?;
        p.check_calls()?;
        Ok(p)
    }

    /// The steps of level 1 (before END1).
    pub fn level1(&self) -> std::ops::Range<usize> {
        0..self.end1
    }

    /// The steps of level 2 (between END1 and END2).
    pub fn level2(&self) -> std::ops::Range<usize> {
        self.end1 + 1..self.end2
    }

    /// The program as rungs for a ladder monitor: each rung's step indices.
    pub fn rungs(&self) -> Vec<std::ops::Range<usize>> {
        let mut out = Vec::new();
        let mut start = 0;
        for (i, s) in self.steps.iter().enumerate().skip(1) {
            if s.instr.starts_rung() {
                out.push(start..i);
                start = i;
            }
        }
        if start < self.steps.len() {
            out.push(start..self.steps.len());
        }
        out
    }
}

/// `name` is the address as written (a bit or a byte).
fn writable(b: ByteAddr, name: &str) -> Result<(), String> {
    if b.writable() {
        Ok(())
    } else {
        Err(format!(
            "{name} cannot be written by the program ({})",
            match b.space {
                Space::X => "X is the machine's inputs",
                Space::F => "F is written by the NC",
                _ => "system relays belong to the PLC",
            }
        ))
    }
}

fn strip_comment(line: &str) -> &str {
    // A `;` inside a quoted MSG text is part of the text.
    let mut quoted = false;
    for (i, c) in line.char_indices() {
        match c {
            '"' => quoted = !quoted,
            ';' if !quoted => return &line[..i],
            _ => {}
        }
    }
    line
}

/// Words of a line: split at commas and white space; a quoted text stays one word.
fn split(code: &str) -> Vec<&str> {
    let code = match code.find('"') {
        Some(i) => &code[..i],
        None => code,
    };
    code.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|w| !w.is_empty())
        .collect()
}

fn number(word: &str) -> Result<i64, String> {
    let w = word.trim_start_matches('+');
    let parsed = if let Some(b) = w.strip_prefix("0b").or_else(|| w.strip_prefix("0B")) {
        i64::from_str_radix(b, 2)
    } else if let Some(h) = w.strip_prefix("0x").or_else(|| w.strip_prefix("0X")) {
        i64::from_str_radix(h, 16)
    } else {
        w.parse::<i64>()
    };
    parsed.map_err(|_| format!("{word:?} is not a number"))
}

/// Whether `v` fits `format` bytes, as a signed value or as a bit pattern (masks, codes).
fn fits(v: i64, format: u8) -> Result<(), String> {
    let bits = u32::from(format) * 8;
    let (lo, hi) = (-(1i64 << (bits - 1)), (1i64 << bits) - 1);
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(format!("{v} does not fit in {format} byte(s)"))
    }
}
