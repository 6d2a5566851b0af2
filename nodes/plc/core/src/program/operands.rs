//! A program line's words read: the mnemonic and its operands (addresses, constants, formats)
//! into an [`Instr`], and the data lines (messages, presets, initial data).

use super::*;

impl Program {
    pub(super) fn message(&mut self, raw: &str, args: &[&str]) -> Result<(), String> {
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

    pub(super) fn preset(&mut self, args: &[&str]) -> Result<(), String> {
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

    pub(super) fn init_data(&mut self, args: &[&str]) -> Result<(), String> {
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

    pub(super) fn address(&self, word: &str) -> Result<Address, String> {
        match self.symbols.get(&word.to_ascii_uppercase()) {
            Some(a) => Ok(*a),
            None => address::parse(word),
        }
    }

    pub(super) fn bit(&self, word: &str) -> Result<BitAddr, String> {
        match self.address(word)? {
            Address::Bit(b) => Ok(b),
            Address::Byte(_) => Err(format!("{word} is a byte; this instruction needs a bit")),
        }
    }

    pub(super) fn byte(&self, word: &str) -> Result<ByteAddr, String> {
        match self.address(word)? {
            Address::Byte(b) => Ok(b),
            Address::Bit(_) => Err(format!("{word} is a bit; this instruction needs a byte")),
        }
    }

    pub(super) fn out_bit(&self, word: &str) -> Result<BitAddr, String> {
        let b = self.bit(word)?;
        writable(b.byte, &b.to_string())?;
        Ok(b)
    }

    /// A destination of `count` bytes.
    pub(super) fn out_bytes(&self, word: &str, count: usize) -> Result<ByteAddr, String> {
        let b = self.byte(word)?;
        writable(b, &b.to_string())?;
        b.span(count)?;
        Ok(b)
    }

    pub(super) fn in_bytes(&self, word: &str, count: usize) -> Result<ByteAddr, String> {
        let b = self.byte(word)?;
        b.span(count)?;
        Ok(b)
    }

    pub(super) fn val(&self, word: &str, format: u8) -> Result<Val, String> {
        if word.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
            let v = number(word)?;
            fits(v, format)?;
            Ok(Val::Const(v))
        } else {
            self.in_bytes(word, usize::from(format)).map(Val::Addr)
        }
    }

    pub(super) fn format(&self, word: &str) -> Result<u8, String> {
        match word {
            "1" => Ok(1),
            "2" => Ok(2),
            "4" => Ok(4),
            _ => Err(format!("format {word:?}: 1, 2 or 4 bytes")),
        }
    }

    pub(super) fn instruction(&self, m: &str, args: &[&str]) -> Result<Instr, String> {
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
}
