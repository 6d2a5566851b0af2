//! Executes ladder steps over the memory: the logic stack, the basic instructions and the
//! functional instructions (FANUC PMC semantics, decisions D39–D41).
//!
//! The stack is a bit mask, ST0 in bit 0, with its depth. Entries a rung did not push read 0.

use crate::address::{BitAddr, ByteAddr, Space};
use crate::memory::{Counter, Memory};
use crate::program::{ArithOp, Instr, LogicOp, Program, Val, MAX_CALL_DEPTH};

/// Steps one scan may execute before the watchdog stops the PLC (a backward JMPB that never
/// ends would otherwise hang the machine logic).
pub const WATCHDOG_STEPS: usize = 200_000;

/// Operation result relays R9000 (zero, negative, overflow) and DIVB's remainder R9002–R9005.
const R9000: ByteAddr = ByteAddr {
    space: Space::R,
    index: 1000,
};
const R9002: ByteAddr = ByteAddr {
    space: Space::R,
    index: 1002,
};

#[derive(Debug, Default, Clone, Copy)]
struct Stack {
    bits: u8,
    depth: u8,
}

impl Stack {
    fn st0(&self) -> bool {
        self.bits & 1 == 1
    }
    fn st(&self, i: usize) -> bool {
        self.bits >> i & 1 == 1
    }
    fn set0(&mut self, v: bool) {
        self.bits = self.bits & !1 | u8::from(v);
    }
    fn start(&mut self, v: bool) {
        self.bits = u8::from(v);
        self.depth = 1;
    }
    fn push(&mut self, v: bool) {
        self.bits = self.bits << 1 | u8::from(v);
        self.depth = (self.depth + 1).min(8);
    }
    /// Drops `n` entries above ST0's replacement (the inputs of a functional instruction).
    fn pop(&mut self, n: usize) {
        let n = n.min(self.depth.saturating_sub(1) as usize);
        self.bits >>= n;
        self.depth -= n as u8;
    }
}

/// Why a scan could not finish.
#[derive(Debug, Clone, PartialEq)]
pub enum Fault {
    Watchdog,
}

/// The executor's state across steps of one scan.
pub struct Engine<'a> {
    pub prog: &'a Program,
    pub mem: &'a mut Memory,
    pub now_ms: u64,
    /// The spindle speed command SPLCNT writes, rpm.
    pub spindle_command: &'a mut f64,
    pub executed: usize,
    stack: Stack,
    /// Common line control: coils write 0 while set; `Some(n)` for n more coils.
    com_off: Option<u16>,
    depth: usize,
}

impl<'a> Engine<'a> {
    pub fn new(
        prog: &'a Program,
        mem: &'a mut Memory,
        now_ms: u64,
        spindle_command: &'a mut f64,
    ) -> Self {
        Engine {
            prog,
            mem,
            now_ms,
            spindle_command,
            executed: 0,
            stack: Stack::default(),
            com_off: None,
            depth: 0,
        }
    }

    /// Runs steps from `pc` until `end` (exclusive), or until `budget` steps have run and the
    /// next step starts a rung. Returns where it stopped.
    pub fn run(&mut self, mut pc: usize, end: usize, budget: usize) -> Result<usize, Fault> {
        let start_count = self.executed;
        while pc < end {
            let step = &self.prog.steps[pc];
            if self.executed - start_count >= budget && step.instr.starts_rung() {
                break;
            }
            self.executed += 1;
            if self.executed > WATCHDOG_STEPS {
                return Err(Fault::Watchdog);
            }
            pc = match self.step(pc)? {
                Some(next) => next,
                None => pc + 1,
            };
        }
        Ok(pc)
    }

    fn bit(&self, b: BitAddr) -> bool {
        self.mem.bit(b)
    }

    fn coil(&mut self, b: BitAddr, v: bool) {
        let v = if let Some(left) = self.com_off {
            if left == 1 {
                self.com_off = None;
            } else if left > 1 {
                self.com_off = Some(left - 1);
            }
            false
        } else {
            v
        };
        self.mem.set_bit(b, v);
    }

    fn val(&self, v: Val, format: u8) -> i64 {
        match v {
            Val::Const(c) => c,
            Val::Addr(a) => self.mem.read(a, format),
        }
    }

    /// Sets R9000.0 (zero), R9000.1 (negative), R9000.5 (overflow).
    fn flags(&mut self, v: i64, overflow: bool) {
        let f = u8::from(v == 0) | u8::from(v < 0) << 1 | u8::from(overflow) << 5;
        self.mem.set_byte(R9000, f);
    }

    /// Executes one step; returns the next pc when it jumps.
    fn step(&mut self, pc: usize) -> Result<Option<usize>, Fault> {
        use Instr::*;
        let prog = self.prog;
        let instr = &prog.steps[pc].instr;
        let act = self.stack.st0();
        // W1 output of a functional instruction; None keeps ST0.
        let mut out: Option<bool> = None;
        match instr {
            Rd(b) => self.stack.start(self.bit(*b)),
            RdNot(b) => self.stack.start(!self.bit(*b)),
            RdStk(b) => self.stack.push(self.bit(*b)),
            RdNotStk(b) => self.stack.push(!self.bit(*b)),
            And(b) => self.stack.set0(act && self.bit(*b)),
            AndNot(b) => self.stack.set0(act && !self.bit(*b)),
            Or(b) => self.stack.set0(act || self.bit(*b)),
            OrNot(b) => self.stack.set0(act || !self.bit(*b)),
            AndStk | OrStk => {
                let v = if matches!(instr, AndStk) {
                    self.stack.st(1) && act
                } else {
                    self.stack.st(1) || act
                };
                self.stack.pop(1);
                self.stack.set0(v);
            }
            Wrt(b) => self.coil(*b, act),
            WrtNot(b) => self.coil(*b, !act),
            Set(b) => {
                if act && self.com_off.is_none() {
                    self.mem.set_bit(*b, true);
                }
            }
            Rst(b) => {
                if act && self.com_off.is_none() {
                    self.mem.set_bit(*b, false);
                }
            }
            End1 | End2 | End3 | Lbl(_) | Sp(_) | Spe => {}
            Tmr { timer } => {
                out = Some(self.mem.timers[*timer as usize].run(act, self.now_ms));
            }
            Tmrb { timer, preset_ms } => {
                let t = &mut self.mem.fixed_timers[*timer as usize];
                t.preset_ms = *preset_ms;
                out = Some(t.run(act, self.now_ms));
            }
            Decb {
                format,
                code,
                first,
                out: dst,
            } => {
                let v = if act {
                    let c = self.mem.read(*code, *format) - first;
                    if (0..8).contains(&c) {
                        1u8 << c
                    } else {
                        0
                    }
                } else {
                    0
                };
                self.mem.set_byte(*dst, v);
            }
            Ctr { counter } => {
                let mut c = self.mem.counters[*counter as usize];
                out = Some(self.count(pc, &mut c));
                self.mem.counters[*counter as usize] = c;
            }
            Ctrb { counter, preset } => {
                let mut c = self.mem.fixed_counters[*counter as usize];
                c.preset = *preset;
                out = Some(self.count(pc, &mut c));
                self.mem.fixed_counters[*counter as usize] = c;
            }
            Ctrc { preset, register } => {
                let mut c = Counter {
                    preset: self.mem.read(*preset, 2),
                    current: self.mem.read(*register, 2),
                };
                out = Some(self.count(pc, &mut c));
                self.mem.write(*register, 2, c.current);
            }
            Rotb {
                format,
                positions,
                current,
                target,
                out: dst,
            } => {
                if act {
                    let n = self.val(*positions, *format);
                    let (cur, tgt) = (
                        self.mem.read(*current, *format),
                        self.mem.read(*target, *format),
                    );
                    let (result, reverse) = rotate(
                        n,
                        cur,
                        tgt,
                        RotateMode {
                            from_one: self.stack.st(4),
                            shortest: self.stack.st(3),
                            one_before: self.stack.st(2),
                            steps: self.stack.st(1),
                        },
                    );
                    self.mem.write(*dst, *format, result);
                    out = Some(reverse);
                } else {
                    out = Some(false);
                }
            }
            Codb {
                format,
                index,
                out: dst,
                table,
            } => {
                let rst = self.stack.st(1);
                out = Some(if rst {
                    false
                } else if act {
                    match table.get(self.mem.byte(*index) as usize) {
                        Some(v) => {
                            self.mem.write(*dst, *format, *v);
                            false
                        }
                        None => true,
                    }
                } else {
                    false
                });
            }
            Move { mask, src, dst } => {
                if act {
                    self.mem.set_byte(*dst, self.mem.byte(*src) & mask);
                }
            }
            Movor { src, or, dst } => {
                if act {
                    self.mem
                        .set_byte(*dst, self.mem.byte(*src) | self.mem.byte(*or));
                }
            }
            Movn { bytes, src, dst } => {
                if act {
                    for k in 0..*bytes {
                        let s = ByteAddr {
                            index: src.index + k,
                            ..*src
                        };
                        let d = ByteAddr {
                            index: dst.index + k,
                            ..*dst
                        };
                        self.mem.set_byte(d, self.mem.byte(s));
                    }
                }
            }
            Pari { addr } => {
                // Inputs: O.E (ST2: 1 = odd parity expected), RST (ST1), ACT.
                let (odd, rst) = (self.stack.st(2), self.stack.st(1));
                out = Some(if rst || !act {
                    false
                } else {
                    let ones = self.mem.byte(*addr).count_ones();
                    (ones % 2 == 1) != odd
                });
            }
            Dcnvb { format, src, dst } => {
                // Inputs: SIN (ST3, sign of BCD data), CNV (ST2: 0 binary→BCD, 1 BCD→binary),
                // RST (ST1), ACT.
                let (sin, cnv, rst) = (self.stack.st(3), self.stack.st(2), self.stack.st(1));
                out = Some(if rst || !act {
                    false
                } else if cnv {
                    let mask = (1u64 << (8 * u32::from(*format))) - 1;
                    match from_bcd(self.mem.read(*src, *format) as u64 & mask, *format) {
                        Some(v) => {
                            self.mem.write(*dst, *format, if sin { -v } else { v });
                            false
                        }
                        None => true,
                    }
                } else {
                    let v = self.mem.read(*src, *format);
                    self.mem.set_bit(
                        BitAddr {
                            byte: R9000,
                            bit: 1,
                        },
                        v < 0,
                    );
                    match to_bcd(v.unsigned_abs(), *format) {
                        Some(b) => {
                            self.mem.write(*dst, *format, b as i64);
                            false
                        }
                        None => true,
                    }
                });
            }
            Compb {
                format,
                input,
                compare,
            } => {
                if act {
                    let (a, b) = (self.val(*input, *format), self.mem.read(*compare, *format));
                    self.mem
                        .set_byte(R9000, u8::from(a == b) | u8::from(a < b) << 1);
                }
            }
            Sft { addr } => {
                // Inputs: DIR (ST3: 0 left, 1 right), CONT (ST2: 1 keeps the shifted bit set),
                // RST (ST1), ACT (shifts on its rising edge).
                let (dir, cont, rst) = (self.stack.st(3), self.stack.st(2), self.stack.st(1));
                let edge = act && !self.mem.step_act[pc];
                self.mem.step_act[pc] = act;
                let v = self.mem.read(*addr, 2) as u16;
                out = Some(if rst {
                    self.mem.write(*addr, 2, 0);
                    false
                } else if edge {
                    let (shifted, lost) = if dir {
                        (v >> 1, v & 1 == 1)
                    } else {
                        (v << 1, v & 0x8000 != 0)
                    };
                    let kept = if cont { shifted | v } else { shifted };
                    self.mem.write(*addr, 2, i64::from(kept));
                    lost
                } else {
                    false
                });
            }
            Dschb {
                format,
                count,
                table,
                key,
                out: dst,
            } => {
                let rst = self.stack.st(1);
                out = Some(if rst || !act {
                    false
                } else {
                    let (n, k, f) = (self.val(*count, 2), self.val(*key, *format), *format);
                    let found = (0..n.max(0)).find(|i| {
                        self.table_entry(*table, f, *i)
                            .is_some_and(|a| self.mem.read(a, f) == k)
                    });
                    match found {
                        Some(i) => {
                            self.mem.write(*dst, f, i);
                            false
                        }
                        None => {
                            self.mem.write(*dst, f, -1);
                            true
                        }
                    }
                });
            }
            Xmovb {
                format,
                count,
                table,
                data,
                index,
            } => {
                // Inputs: RW (ST2: 0 read the table, 1 write it), RST (ST1), ACT.
                let (write, rst) = (self.stack.st(2), self.stack.st(1));
                out = Some(if rst || !act {
                    false
                } else {
                    let (n, i, f) = (self.val(*count, 2), self.mem.read(*index, *format), *format);
                    match self.table_entry(*table, f, i).filter(|_| i < n) {
                        Some(entry) => {
                            if write {
                                let v = self.mem.read(*data, f);
                                self.mem.write(entry, f, v);
                            } else {
                                let v = self.mem.read(entry, f);
                                self.mem.write(*data, f, v);
                            }
                            false
                        }
                        None => true,
                    }
                });
            }
            Arith {
                op,
                format,
                a,
                b,
                out: dst,
            } => {
                let rst = self.stack.st(1);
                out = Some(if rst {
                    self.mem.set_byte(R9000, 0);
                    false
                } else if act {
                    let (x, y) = (self.mem.read(*a, *format), self.val(*b, *format));
                    self.arith(*op, *format, x, y, *dst)
                } else {
                    false
                });
            }
            Numeb { format, value, dst } => {
                if act {
                    self.mem.write(*dst, *format, *value);
                }
            }
            Difu { edge } | Difd { edge } => {
                let before = std::mem::replace(&mut self.mem.edges[*edge as usize], act);
                out = Some(if matches!(instr, Difu { .. }) {
                    act && !before
                } else {
                    !act && before
                });
            }
            Logic {
                op,
                format,
                a,
                b,
                out: dst,
            } => {
                if act {
                    let (x, y) = (self.mem.read(*a, *format), self.val(*b, *format));
                    let v = match op {
                        LogicOp::Eor => x ^ y,
                        LogicOp::And => x & y,
                        LogicOp::Or => x | y,
                    };
                    self.mem.write(*dst, *format, v);
                }
            }
            Notb { format, src, dst } => {
                if act {
                    let v = !self.mem.read(*src, *format);
                    self.mem.write(*dst, *format, v);
                }
            }
            Com { coils } => {
                self.com_off = (!act).then_some(*coils);
            }
            Come => self.com_off = None,
            Call(p) | Callu(p) => {
                if act || matches!(instr, Callu(_)) {
                    self.call(*p)?;
                }
            }
            Jmpb(l) => {
                if act {
                    if let Some(target) = prog.labels.get(&(prog.scope[pc], *l)) {
                        return Ok(Some(target + 1));
                    }
                }
            }
            Splcnt {
                speed,
                override_percent,
            } => {
                *self.spindle_command = if act {
                    let s = self.mem.read(*speed, 4).max(0) as f64;
                    s * f64::from(self.mem.byte(*override_percent)) / 100.0
                } else {
                    0.0
                };
            }
        }
        if instr.inputs() > 1 && !matches!(instr, AndStk | OrStk) {
            self.stack.pop(instr.inputs() - 1);
        }
        if let Some(w1) = out {
            self.stack.set0(w1);
        }
        Ok(None)
    }

    /// The `i`-th entry of a table of `format`-byte values, if it lies in the table.
    fn table_entry(&self, table: ByteAddr, format: u8, i: i64) -> Option<ByteAddr> {
        let index = i64::from(table.index) + i * i64::from(format);
        let entry = ByteAddr {
            index: u16::try_from(index).ok()?,
            ..table
        };
        (i >= 0 && entry.span(format.into()).is_ok()).then_some(entry)
    }

    fn arith(&mut self, op: ArithOp, format: u8, x: i64, y: i64, dst: ByteAddr) -> bool {
        let (lo, hi) = match format {
            1 => (0, 255),
            2 => (i64::from(i16::MIN), i64::from(i16::MAX)),
            _ => (i64::from(i32::MIN), i64::from(i32::MAX)),
        };
        let v = match op {
            ArithOp::Add => x + y,
            ArithOp::Sub => x - y,
            ArithOp::Mul => x.saturating_mul(y),
            ArithOp::Div => {
                if y == 0 {
                    // Division by zero: error out, result unchanged.
                    self.flags(0, true);
                    return true;
                }
                self.mem.write(R9002, format, x % y);
                x / y
            }
        };
        let overflow = !(lo..=hi).contains(&v);
        self.mem.write(dst, format, v);
        self.flags(self.mem.read(dst, format), overflow);
        overflow
    }

    /// A ring counter (FANUC CTR): inputs CN0 (ST3: count from 1), UPDOWN (ST2: 1 down), RST
    /// (ST1), ACT (counts rising edges). The contact is on while the count stands at its end.
    fn count(&mut self, pc: usize, c: &mut Counter) -> bool {
        let (cn0, down, rst, act) = (
            self.stack.st(3),
            self.stack.st(2),
            self.stack.st(1),
            self.stack.st0(),
        );
        let edge = act && !self.mem.step_act[pc];
        self.mem.step_act[pc] = act;
        let first = i64::from(cn0);
        if rst {
            c.current = if down { c.preset } else { first };
            return false;
        }
        if edge {
            if down {
                c.current = if c.current <= first {
                    c.preset
                } else {
                    c.current - 1
                };
            } else {
                c.current = if c.current >= c.preset {
                    first
                } else {
                    c.current + 1
                };
            }
        }
        if down {
            c.current == first
        } else {
            c.current == c.preset
        }
    }

    fn call(&mut self, p: u16) -> Result<(), Fault> {
        let Some(&first) = self.prog.subroutines.get(&p) else {
            return Ok(());
        };
        if self.depth >= MAX_CALL_DEPTH {
            return Ok(());
        }
        let end = self.prog.steps[first..]
            .iter()
            .position(|s| matches!(s.instr, Instr::Spe))
            .map_or(self.prog.steps.len(), |k| first + k);
        self.depth += 1;
        let saved = (self.stack, self.com_off);
        self.com_off = None;
        let r = self.run(first, end, usize::MAX);
        (self.stack, self.com_off) = saved;
        self.depth -= 1;
        r.map(|_| ())
    }
}

/// ROTB's control inputs.
#[derive(Debug, Clone, Copy, Default)]
pub struct RotateMode {
    /// RN0: positions are numbered from 1 (else from 0).
    pub from_one: bool,
    /// DIR: take the shorter way (else always forward).
    pub shortest: bool,
    /// POS: the position one before the target (to slow down there).
    pub one_before: bool,
    /// INC: the result is a number of steps (else a position number).
    pub steps: bool,
}

/// Rotation control (FANUC ROTB) on a rotor of `n` positions: the result (position or steps)
/// and whether the rotor turns in reverse (toward lower numbers).
pub fn rotate(n: i64, current: i64, target: i64, m: RotateMode) -> (i64, bool) {
    if n <= 0 {
        return (0, false);
    }
    let base = i64::from(m.from_one);
    let (c, t) = (
        (current - base).rem_euclid(n),
        (target - base).rem_euclid(n),
    );
    let forward = (t - c).rem_euclid(n);
    let backward = (c - t).rem_euclid(n);
    let reverse = m.shortest && backward < forward;
    let distance = if reverse { backward } else { forward };
    if m.steps {
        ((distance - i64::from(m.one_before)).max(0), reverse)
    } else {
        let before = if !m.one_before || distance == 0 {
            t
        } else if reverse {
            (t + 1).rem_euclid(n)
        } else {
            (t - 1).rem_euclid(n)
        };
        (before + base, reverse)
    }
}

fn to_bcd(mut v: u64, format: u8) -> Option<u64> {
    let digits = 2 * u32::from(format);
    let mut out = 0u64;
    for k in 0..digits {
        out |= (v % 10) << (4 * k);
        v /= 10;
    }
    (v == 0).then_some(out)
}

fn from_bcd(v: u64, format: u8) -> Option<i64> {
    let mut out = 0i64;
    for k in (0..2 * u32::from(format)).rev() {
        let d = (v >> (4 * k)) & 0xf;
        if d > 9 {
            return None;
        }
        out = out * 10 + d as i64;
    }
    Some(out)
}
