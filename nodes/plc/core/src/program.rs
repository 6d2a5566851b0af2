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

    fn message(&mut self, raw: &str, args: &[&str]) -> Result<(), String> {
        let usage = "MSG needs an A address, ALARM or MESSAGE, and a quoted text";
        let (Some(addr), Some(kind)) = (args.first(), args.get(1)) else {
            return Err(usage.into());
        };
        let Address::Bit(b) = self.address(addr)? else {
            return Err(format!("{addr} is not a bit"));
        };
        if b.byte.space != Space::A {
            return Err(format!("{addr}: messages are A bits"));
        }
        let alarm = match kind.to_ascii_uppercase().as_str() {
            "ALARM" => true,
            "MESSAGE" => false,
            _ => return Err(usage.into()),
        };
        let text = raw
            .split_once('"')
            .and_then(|(_, rest)| rest.rsplit_once('"'))
            .map(|(t, _)| t.to_string())
            .ok_or(usage)?;
        self.messages
            .insert((b.byte.index, b.bit), Message { text, alarm });
        Ok(())
    }

    fn preset(&mut self, args: &[&str]) -> Result<(), String> {
        let [unit, value] = args else {
            return Err("PRESET needs Tn or Cn and a value".into());
        };
        let v = number(value)?;
        let u = Unit::parse(unit)?;
        if !u.preset_ok(v) {
            return Err(format!("PRESET {unit} {value}: out of range"));
        }
        match u {
            Unit::Timer(n) => self.timer_presets.insert(n, v as u32).map(|_| ()),
            Unit::Counter(n) => self.counter_presets.insert(n, v).map(|_| ()),
        };
        Ok(())
    }

    fn init_data(&mut self, args: &[&str]) -> Result<(), String> {
        let [addr, format, value] = args else {
            return Err("INIT needs an address, a format (1, 2 or 4) and a value".into());
        };
        let a = self.byte(addr)?;
        if !matches!(a.space, Space::D | Space::K) {
            return Err(format!("INIT sets D or K registers, not {addr}"));
        }
        let f = self.format(format)?;
        a.span(usize::from(f))?;
        let v = number(value)?;
        fits(v, f)?;
        self.init.push((a, f, v));
        Ok(())
    }

    fn address(&self, word: &str) -> Result<Address, String> {
        match self.symbols.get(&word.to_ascii_uppercase()) {
            Some(a) => Ok(*a),
            None => address::parse(word),
        }
    }

    fn bit(&self, word: &str) -> Result<BitAddr, String> {
        match self.address(word)? {
            Address::Bit(b) => Ok(b),
            Address::Byte(_) => Err(format!("{word} is a byte; this instruction needs a bit")),
        }
    }

    fn byte(&self, word: &str) -> Result<ByteAddr, String> {
        match self.address(word)? {
            Address::Byte(b) => Ok(b),
            Address::Bit(_) => Err(format!("{word} is a bit; this instruction needs a byte")),
        }
    }

    fn out_bit(&self, word: &str) -> Result<BitAddr, String> {
        let b = self.bit(word)?;
        writable(b.byte, &b.to_string())?;
        Ok(b)
    }

    /// A destination of `count` bytes.
    fn out_bytes(&self, word: &str, count: usize) -> Result<ByteAddr, String> {
        let b = self.byte(word)?;
        writable(b, &b.to_string())?;
        b.span(count)?;
        Ok(b)
    }

    fn in_bytes(&self, word: &str, count: usize) -> Result<ByteAddr, String> {
        let b = self.byte(word)?;
        b.span(count)?;
        Ok(b)
    }

    fn val(&self, word: &str, format: u8) -> Result<Val, String> {
        if word.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
            let v = number(word)?;
            fits(v, format)?;
            Ok(Val::Const(v))
        } else {
            self.in_bytes(word, usize::from(format)).map(Val::Addr)
        }
    }

    fn format(&self, word: &str) -> Result<u8, String> {
        match word {
            "1" => Ok(1),
            "2" => Ok(2),
            "4" => Ok(4),
            _ => Err(format!("format {word:?}: 1, 2 or 4 bytes")),
        }
    }

    fn instruction(&self, m: &str, args: &[&str]) -> Result<Instr, String> {
        use Instr::*;
        let want = |n: usize| -> Result<(), String> {
            if args.len() == n {
                Ok(())
            } else {
                Err(format!(
                    "{m} takes {n} operand{}, found {}",
                    if n == 1 { "" } else { "s" },
                    args.len()
                ))
            }
        };
        let arg = |i: usize| args[i];
        let n_in = |i: usize, max: u16, what: &str| -> Result<u16, String> {
            let v = number(args[i])?;
            if (0..i64::from(max)).contains(&v) {
                Ok(v as u16)
            } else {
                Err(format!("{what} {v} outside 0–{}", max - 1))
            }
        };
        let label = |i: usize, letter: char| -> Result<u16, String> {
            let w = args[i];
            let digits = w
                .strip_prefix(letter)
                .or_else(|| w.strip_prefix(letter.to_ascii_lowercase()))
                .unwrap_or(w);
            match digits.parse::<u16>() {
                Ok(v) if (1..=LABELS).contains(&v) => Ok(v),
                _ => Err(format!("{w:?} is not a label {letter}1–{letter}{LABELS}")),
            }
        };
        let instr = match m {
            "RD" | "RD.NOT" | "RD.STK" | "RD.NOT.STK" | "AND" | "AND.NOT" | "OR" | "OR.NOT" => {
                want(1)?;
                let b = self.bit(arg(0))?;
                match m {
                    "RD" => Rd(b),
                    "RD.NOT" => RdNot(b),
                    "RD.STK" => RdStk(b),
                    "RD.NOT.STK" => RdNotStk(b),
                    "AND" => And(b),
                    "AND.NOT" => AndNot(b),
                    "OR" => Or(b),
                    _ => OrNot(b),
                }
            }
            "WRT" | "WRT.NOT" | "SET" | "RST" => {
                want(1)?;
                let b = self.out_bit(arg(0))?;
                match m {
                    "WRT" => Wrt(b),
                    "WRT.NOT" => WrtNot(b),
                    "SET" => Set(b),
                    _ => Rst(b),
                }
            }
            "AND.STK" => want(0).map(|_| AndStk)?,
            "OR.STK" => want(0).map(|_| OrStk)?,
            "END1" => want(0).map(|_| End1)?,
            "END2" => want(0).map(|_| End2)?,
            "END3" | "END" => want(0).map(|_| End3)?,
            "TMR" => {
                want(1)?;
                Tmr {
                    timer: n_in(0, TIMERS, "timer")?,
                }
            }
            "TMRB" => {
                want(2)?;
                let v = number(arg(1))?;
                if !(0..=i64::from(u32::MAX)).contains(&v) {
                    return Err(format!("timer preset {v} ms out of range"));
                }
                Tmrb {
                    timer: n_in(0, FIXED_TIMERS, "fixed timer")?,
                    preset_ms: v as u32,
                }
            }
            "DECB" => {
                want(4)?;
                let format = self.format(arg(0))?;
                let first = number(arg(2))?;
                fits(first, format)?;
                Decb {
                    format,
                    code: self.in_bytes(arg(1), format.into())?,
                    first,
                    out: self.out_bytes(arg(3), 1)?,
                }
            }
            "CTR" => {
                want(1)?;
                Ctr {
                    counter: n_in(0, COUNTERS, "counter")?,
                }
            }
            "CTRB" => {
                want(2)?;
                let preset = number(arg(1))?;
                if !(0..=32767).contains(&preset) {
                    return Err(format!("counter preset {preset} outside 0–32767"));
                }
                Ctrb {
                    counter: n_in(0, FIXED_COUNTERS, "fixed counter")?,
                    preset,
                }
            }
            "CTRC" => {
                want(2)?;
                Ctrc {
                    preset: self.in_bytes(arg(0), 2)?,
                    register: self.out_bytes(arg(1), 2)?,
                }
            }
            "ROTB" => {
                want(5)?;
                let format = self.format(arg(0))?;
                let f = usize::from(format);
                Rotb {
                    format,
                    positions: self.val(arg(1), format)?,
                    current: self.in_bytes(arg(2), f)?,
                    target: self.in_bytes(arg(3), f)?,
                    out: self.out_bytes(arg(4), f)?,
                }
            }
            "CODB" => {
                if args.len() < 5 {
                    return Err(
                        "CODB takes a format, the table size, index and output addresses, \
                         and the table"
                            .into(),
                    );
                }
                let format = self.format(arg(0))?;
                let size = number(arg(1))?;
                if !(1..=256).contains(&size) || args.len() != 4 + size as usize {
                    return Err(format!(
                        "CODB table of {size} entries needs {size} values, found {}",
                        args.len() - 4
                    ));
                }
                let table = args[4..]
                    .iter()
                    .map(|w| number(w).and_then(|v| fits(v, format).map(|_| v)))
                    .collect::<Result<Vec<_>, _>>()?;
                Codb {
                    format,
                    index: self.in_bytes(arg(2), 1)?,
                    out: self.out_bytes(arg(3), format.into())?,
                    table,
                }
            }
            "MOVE" => {
                want(3)?;
                let mask = number(arg(0))?;
                if !(0..=255).contains(&mask) {
                    return Err(format!("MOVE mask {mask} outside 0–255"));
                }
                Move {
                    mask: mask as u8,
                    src: self.in_bytes(arg(1), 1)?,
                    dst: self.out_bytes(arg(2), 1)?,
                }
            }
            "MOVOR" => {
                want(3)?;
                Movor {
                    src: self.in_bytes(arg(0), 1)?,
                    or: self.in_bytes(arg(1), 1)?,
                    dst: self.out_bytes(arg(2), 1)?,
                }
            }
            "MOVB" | "MOVW" => {
                want(2)?;
                let n = if m == "MOVB" { 1 } else { 2 };
                Movn {
                    bytes: n,
                    src: self.in_bytes(arg(0), n.into())?,
                    dst: self.out_bytes(arg(1), n.into())?,
                }
            }
            "MOVN" => {
                want(3)?;
                let n = number(arg(0))?;
                if !(1..=200).contains(&n) {
                    return Err(format!("MOVN of {n} bytes: 1–200"));
                }
                Movn {
                    bytes: n as u16,
                    src: self.in_bytes(arg(1), n as usize)?,
                    dst: self.out_bytes(arg(2), n as usize)?,
                }
            }
            "PARI" => {
                want(1)?;
                Pari {
                    addr: self.in_bytes(arg(0), 1)?,
                }
            }
            "DCNVB" => {
                want(3)?;
                let format = self.format(arg(0))?;
                Dcnvb {
                    format,
                    src: self.in_bytes(arg(1), format.into())?,
                    dst: self.out_bytes(arg(2), format.into())?,
                }
            }
            "COMPB" => {
                want(3)?;
                let format = self.format(arg(0))?;
                Compb {
                    format,
                    input: self.val(arg(1), format)?,
                    compare: self.in_bytes(arg(2), format.into())?,
                }
            }
            "SFT" => {
                want(1)?;
                Sft {
                    addr: self.out_bytes(arg(0), 2)?,
                }
            }
            "DSCHB" => {
                want(5)?;
                let format = self.format(arg(0))?;
                Dschb {
                    format,
                    count: self.val(arg(1), 2)?,
                    table: self.in_bytes(arg(2), format.into())?,
                    key: self.val(arg(3), format)?,
                    out: self.out_bytes(arg(4), format.into())?,
                }
            }
            "XMOVB" => {
                want(5)?;
                let format = self.format(arg(0))?;
                let f = usize::from(format);
                Xmovb {
                    format,
                    count: self.val(arg(1), 2)?,
                    table: self.out_bytes(arg(2), f)?,
                    data: self.out_bytes(arg(3), f)?,
                    index: self.in_bytes(arg(4), f)?,
                }
            }
            "ADDB" | "SUBB" | "MULB" | "DIVB" | "EORB" | "ANDB" | "ORB" => {
                want(4)?;
                let format = self.format(arg(0))?;
                let f = usize::from(format);
                let (a, b, out) = (
                    self.in_bytes(arg(1), f)?,
                    self.val(arg(2), format)?,
                    self.out_bytes(arg(3), f)?,
                );
                let arith = |op| Arith {
                    op,
                    format,
                    a,
                    b,
                    out,
                };
                let logic = |op| Logic {
                    op,
                    format,
                    a,
                    b,
                    out,
                };
                match m {
                    "ADDB" => arith(ArithOp::Add),
                    "SUBB" => arith(ArithOp::Sub),
                    "MULB" => arith(ArithOp::Mul),
                    "DIVB" => arith(ArithOp::Div),
                    "EORB" => logic(LogicOp::Eor),
                    "ANDB" => logic(LogicOp::And),
                    _ => logic(LogicOp::Or),
                }
            }
            "NUMEB" => {
                want(3)?;
                let format = self.format(arg(0))?;
                let value = number(arg(1))?;
                fits(value, format)?;
                Numeb {
                    format,
                    value,
                    dst: self.out_bytes(arg(2), format.into())?,
                }
            }
            "NOTB" => {
                want(3)?;
                let format = self.format(arg(0))?;
                Notb {
                    format,
                    src: self.in_bytes(arg(1), format.into())?,
                    dst: self.out_bytes(arg(2), format.into())?,
                }
            }
            "DIFU" | "DIFD" => {
                want(1)?;
                let v = number(arg(0))?;
                if !(1..=i64::from(EDGES)).contains(&v) {
                    return Err(format!("edge number {v} outside 1–{EDGES}"));
                }
                let edge = v as u16 - 1;
                if m == "DIFU" {
                    Difu { edge }
                } else {
                    Difd { edge }
                }
            }
            "COM" => {
                if args.len() > 1 {
                    return Err("COM takes at most the number of coils".into());
                }
                let coils = match args.first() {
                    None => 0,
                    Some(w) => match number(w)? {
                        v @ 0..=9999 => v as u16,
                        v => return Err(format!("COM of {v} coils")),
                    },
                };
                Com { coils }
            }
            "COME" => want(0).map(|_| Come)?,
            "CALL" => want(1).and_then(|_| label(0, 'P')).map(Call)?,
            "CALLU" => want(1).and_then(|_| label(0, 'P')).map(Callu)?,
            "SP" => want(1).and_then(|_| label(0, 'P')).map(Sp)?,
            "SPE" => want(0).map(|_| Spe)?,
            "JMPB" => want(1).and_then(|_| label(0, 'L')).map(Jmpb)?,
            "LBL" => want(1).and_then(|_| label(0, 'L')).map(Lbl)?,
            "SPLCNT" => {
                want(2)?;
                Splcnt {
                    speed: self.in_bytes(arg(0), 4)?,
                    override_percent: self.in_bytes(arg(1), 1)?,
                }
            }
            _ => return Err(format!("unknown instruction {m:?}")),
        };
        Ok(instr)
    }

    /// END1 then END2 once each; subroutines only after END2, each SP closed by SPE; labels
    /// unique in their scope and jumps within it.
    fn check_structure(&mut self) -> Result<(), LoadError> {
        let last_line = self.steps.last().map(|s| s.line).unwrap_or(1);
        let err = |line: u32, reason: String| LoadError { line, reason };
        let mut end1 = None;
        let mut end2 = None;
        let mut end3 = None;
        let mut open_sp: Option<(u16, u32)> = None;
        let mut scope = 0usize;
        self.scope = Vec::with_capacity(self.steps.len());
        for (i, s) in self.steps.iter().enumerate() {
            let line = s.line;
            if end3.is_some() {
                return Err(err(line, "instruction after END3".into()));
            }
            match s.instr {
                Instr::End1 if end1.is_some() => return Err(err(line, "second END1".into())),
                Instr::End1 => {
                    end1 = Some(i);
                    scope = i + 1;
                }
                Instr::End2 if end1.is_none() => return Err(err(line, "END2 before END1".into())),
                Instr::End2 if end2.is_some() => return Err(err(line, "second END2".into())),
                Instr::End2 => {
                    end2 = Some(i);
                    scope = i + 1;
                }
                Instr::End3 if open_sp.is_some() => {
                    return Err(err(line, "END3 inside a subroutine".into()))
                }
                Instr::End3 => end3 = Some(i),
                Instr::Sp(_) if end2.is_none() => {
                    return Err(err(line, "subroutines (SP) come after END2".into()))
                }
                Instr::Sp(_) if open_sp.is_some() => {
                    return Err(err(
                        line,
                        "SP inside a subroutine: close it with SPE".into(),
                    ))
                }
                Instr::Sp(n) => {
                    if self.subroutines.insert(n, i + 1).is_some() {
                        return Err(err(line, format!("subroutine P{n} defined twice")));
                    }
                    open_sp = Some((n, line));
                    scope = i + 1;
                }
                Instr::Spe if open_sp.is_none() => return Err(err(line, "SPE without SP".into())),
                Instr::Spe => open_sp = None,
                _ if end2.is_some() && open_sp.is_none() => {
                    return Err(err(
                        line,
                        "after END2 only subroutines (SP … SPE) may follow".into(),
                    ))
                }
                Instr::Lbl(n) if self.labels.contains_key(&(scope, n)) => {
                    return Err(err(line, format!("label L{n} twice in one level")));
                }
                Instr::Lbl(n) => {
                    self.labels.insert((scope, n), i);
                }
                _ => {}
            }
            self.scope.push(scope);
        }
        if let Some((n, line)) = open_sp {
            return Err(err(line, format!("subroutine P{n} has no SPE")));
        }
        self.end1 = end1.ok_or_else(|| err(last_line, "no END1".into()))?;
        self.end2 = end2.ok_or_else(|| err(last_line, "no END2".into()))?;
        for (i, s) in self.steps.iter().enumerate() {
            match s.instr {
                Instr::Jmpb(n) if !self.labels.contains_key(&(self.scope[i], n)) => {
                    return Err(err(
                        s.line,
                        format!("JMPB L{n}: no such label in this level"),
                    ))
                }
                Instr::Call(n) | Instr::Callu(n) if !self.subroutines.contains_key(&n) => {
                    return Err(err(s.line, format!("CALL P{n}: no such subroutine")))
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Follows the stack depth along each rung: no instruction may need more entries than the
    /// rung pushed (ACT must exist), and no rung may push more than ST0–ST7.
    fn check_stack(&self) -> Result<(), LoadError> {
        let mut depth = 0usize;
        for s in &self.steps {
            let err = |reason: String| LoadError {
                line: s.line,
                reason,
            };
            match &s.instr {
                Instr::Rd(_) | Instr::RdNot(_) => depth = 1,
                Instr::RdStk(_) | Instr::RdNotStk(_) => {
                    if depth == 0 {
                        return Err(err("RD.STK without a rung to push (start with RD)".into()));
                    }
                    depth += 1;
                    if depth > STACK_DEPTH {
                        return Err(err(format!(
                            "logic stack deeper than ST0–ST{}",
                            STACK_DEPTH - 1
                        )));
                    }
                }
                Instr::AndStk | Instr::OrStk => {
                    if depth < 2 {
                        return Err(err(format!("{} needs two stack entries", s.text)));
                    }
                    depth -= 1;
                }
                i if i.inputs() == 0 => depth = 0,
                i => {
                    if depth == 0 {
                        return Err(err(format!(
                            "{}: no logic before it (start the rung with RD)",
                            s.text
                        )));
                    }
                    // Inputs below ACT are taken if the rung pushed them; the output is in ST0.
                    depth -= depth.min(i.inputs()) - 1;
                }
            }
        }
        Ok(())
    }

    /// Subroutine calls must not recurse.
    fn check_calls(&self) -> Result<(), LoadError> {
        // Calls made by each subroutine (by P number) and from the levels.
        let mut calls: HashMap<u16, Vec<(u16, u32)>> = HashMap::new();
        let owner: HashMap<usize, u16> = self
            .subroutines
            .iter()
            .map(|(p, first)| (*first, *p))
            .collect();
        for (i, s) in self.steps.iter().enumerate() {
            if let (Instr::Call(n) | Instr::Callu(n), Some(p)) =
                (&s.instr, owner.get(&self.scope[i]))
            {
                calls.entry(*p).or_default().push((*n, s.line));
            }
        }
        fn visit(
            p: u16,
            calls: &HashMap<u16, Vec<(u16, u32)>>,
            path: &mut Vec<u16>,
            done: &mut HashSet<u16>,
        ) -> Result<(), LoadError> {
            if done.contains(&p) {
                return Ok(());
            }
            path.push(p);
            for (q, line) in calls.get(&p).into_iter().flatten() {
                if path.contains(q) {
                    return Err(LoadError {
                        line: *line,
                        reason: format!("subroutine P{q} calls itself (through P{p})"),
                    });
                }
                if path.len() >= MAX_CALL_DEPTH {
                    return Err(LoadError {
                        line: *line,
                        reason: format!("subroutines nested deeper than {MAX_CALL_DEPTH}"),
                    });
                }
                visit(*q, calls, path, done)?;
            }
            path.pop();
            done.insert(p);
            Ok(())
        }
        let mut done = HashSet::new();
        let mut keys: Vec<u16> = self.subroutines.keys().copied().collect();
        keys.sort_unstable();
        for p in keys {
            visit(p, &calls, &mut Vec::new(), &mut done)?;
        }
        Ok(())
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
