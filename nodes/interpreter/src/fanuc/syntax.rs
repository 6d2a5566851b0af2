//! Program text → statements: one line is one block (`000` §3.3.2, `002` §4.1).
//!
//! A line is: optional `/` block skip (with an optional level digit), optional `N` sequence
//! number, then one statement: address words (`G01 X[#1+2] F100`), a macro assignment
//! (`#1=#1+20`), `GOTO n`, or `IF[cond]` followed by any of these. `;` ends the block and what
//! follows is a comment; `( … )` is a comment, also in full-width form `（ … ）`. Chinese text
//! after a space, behind the block's words, is a comment to the end of the line, as the manuals
//! print it (decisions D2, D55); any other non-ASCII character is an alarm: a block is never run
//! with the rest of its words cut off.
//! A `%` alone marks the start or end of the program text; `%NN` names a GTC2E program.

use super::expr::{BinOp, Expr, Func, UnOp};
use cnc_interpreter_core::Fault;
use std::borrow::Cow;

/// One address word; the value is evaluated when the block runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    pub letter: char,
    pub value: Expr,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    Empty,
    Words(Vec<Word>),
    Assign {
        var: Expr,
        value: Expr,
    },
    Goto(Expr),
    If {
        cond: Expr,
        then: Box<Stmt>,
    },
    /// `WHILE [cond] DO m`, or `DO m` alone (a loop without end condition; FANUC macro B).
    While {
        cond: Option<Expr>,
        id: u32,
    },
    /// `END m`: back to the `WHILE … DO m` that opened the loop.
    End(u32),
}

/// One parsed line.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Block skip level (1 for a plain `/`).
    pub skip: Option<u8>,
    pub number: Option<u32>,
    pub stmt: Stmt,
    /// A `%` mark (start or end of the program text).
    pub percent: bool,
    /// `O1234` or `%NN`: the program's name.
    pub name: Option<String>,
}

/// A syntax error: the fault and its text; the interpreter adds the line and the number.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    pub fault: Fault,
    pub text: String,
}

/// A character where an address letter should be: a number without its address (FANUC
/// P/S 004) or any other stray character (009).
fn stray_fault(c: u8) -> Fault {
    if c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.') {
        Fault::NoAddress
    } else {
        Fault::DataFormat
    }
}

fn err<T>(fault: Fault, text: impl Into<String>) -> Result<T, SyntaxError> {
    Err(SyntaxError {
        fault,
        text: text.into(),
    })
}

/// Longest number text accepted; longer is a data format error, not a slow parse.
const MAX_NUMBER_CHARS: usize = 24;
/// Deepest expression nesting accepted (the manual limits bracket levels, §5.27.5).
const MAX_DEPTH: usize = 32;

/// Strips comments (decision D2) and returns the ASCII code of the line.
pub fn code_part(text: &str) -> Result<Cow<'_, str>, SyntaxError> {
    // Most lines are plain upper-case ASCII without comments: they are their own code.
    let plain = |b: u8| {
        b.is_ascii() && !b.is_ascii_lowercase() && !matches!(b, b';' | b'(' | b'\t' | b'\r')
    };
    if text.bytes().all(plain) {
        return Ok(Cow::Borrowed(text));
    }
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        match c {
            ';' | '；' => break,
            '(' | '（' => {
                // Parentheses inside a comment nest (the fixtures' headers do this).
                let mut depth = 1;
                for c in chars.by_ref() {
                    match c {
                        '(' | '（' => depth += 1,
                        ')' | '）' => depth -= 1,
                        _ => {}
                    }
                    if depth == 0 {
                        break;
                    }
                }
                if depth != 0 {
                    return err(Fault::DataFormat, "comment not closed: ')' missing");
                }
                out.push(' ');
            }
            '\u{3000}' | '\t' | '\r' => out.push(' '),
            // Text in Chinese after a space, as the manuals print it behind a block, is a
            // comment to the end of the line (decision D55).
            c if is_cjk(c) && out.ends_with(' ') && !out.trim().is_empty() => break,
            c if !c.is_ascii() => {
                return err(
                    Fault::DataFormat,
                    format!(
                        "character {c:?} inside the block: the control reads only letters, \
                         digits and signs here (text after it would be lost)"
                    ),
                )
            }
            c => out.push(c.to_ascii_uppercase()),
        }
    }
    Ok(Cow::Owned(out))
}

/// A character of Chinese text (ideographs, radicals, CJK punctuation, kana), not a
/// full-width letter or digit.
fn is_cjk(c: char) -> bool {
    matches!(c, '\u{2E80}'..='\u{9FFF}' | '\u{F900}'..='\u{FAFF}' | '\u{FF0C}' | '\u{FF1A}')
}

/// 10⁰ … 10¹⁵, each exact in an f64.
const POWERS_OF_TEN: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// Parses one line. `macros` says whether the dialect has macro statements (Huaxing does,
/// GTC2E does not: there `#`, `[` and `IF` are illegal commands).
pub fn parse_line(text: &str, macros: bool) -> Result<Line, SyntaxError> {
    let code = code_part(text)?;
    let mut p = Parser {
        s: code.as_bytes(),
        i: 0,
        macros,
        depth: 0,
    };
    p.line()
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    macros: bool,
    depth: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    fn skip_ws(&mut self) {
        while self.peek() == Some(b' ') {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        self.skip_ws();
        if self.peek() == Some(c) {
            self.i += 1;
            true
        } else {
            false
        }
    }

    fn at_end(&mut self) -> bool {
        self.skip_ws();
        self.i >= self.s.len()
    }

    /// An upper-case letter run starting here (without consuming it).
    fn ident(&self) -> &str {
        let start = self.i;
        let mut end = start;
        while end < self.s.len() && self.s[end].is_ascii_uppercase() {
            end += 1;
        }
        std::str::from_utf8(&self.s[start..end]).unwrap_or("")
    }

    fn line(&mut self) -> Result<Line, SyntaxError> {
        let mut line = Line {
            skip: None,
            number: None,
            stmt: Stmt::Empty,
            percent: false,
            name: None,
        };
        self.skip_ws();
        if self.peek() == Some(b'/') {
            self.i += 1;
            let mut level = 1u8;
            if let Some(d) = self.peek().filter(u8::is_ascii_digit) {
                level = d - b'0';
                self.i += 1;
            }
            line.skip = Some(level.max(1));
        }
        self.skip_ws();
        if self.peek() == Some(b'%') {
            self.i += 1;
            let start = self.i;
            while self.peek().is_some_and(|c| c.is_ascii_alphanumeric()) {
                self.i += 1;
            }
            if self.i > start {
                line.name = Some(String::from_utf8_lossy(&self.s[start..self.i]).into_owned());
            } else {
                line.percent = true;
            }
            if !self.at_end() {
                return err(Fault::DataFormat, "text after the % mark");
            }
            return Ok(line);
        }
        if self.peek() == Some(b'O') && self.s.get(self.i + 1).is_some_and(u8::is_ascii_digit) {
            self.i += 1;
            let n = self.unsigned("O")?;
            line.name = Some(format!("O{n:04}"));
        }
        self.skip_ws();
        if self.peek() == Some(b'N') && self.s.get(self.i + 1).is_some_and(u8::is_ascii_digit) {
            self.i += 1;
            line.number = Some(self.unsigned("N")?);
        }
        line.stmt = self.statement()?;
        // `N0120 %` ends the text after a numbered empty block.
        if self.eat(b'%') {
            line.percent = true;
        }
        if !self.at_end() {
            let rest = String::from_utf8_lossy(&self.s[self.i..]).into_owned();
            let fault = rest.bytes().next().map_or(Fault::DataFormat, stray_fault);
            return err(fault, format!("unexpected text {rest:?}"));
        }
        Ok(line)
    }

    fn unsigned(&mut self, what: &str) -> Result<u32, SyntaxError> {
        let start = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.i += 1;
        }
        let digits = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        if digits.is_empty() || digits.len() > 9 {
            return err(
                Fault::DataFormat,
                format!("{what} needs a number of 1–9 digits"),
            );
        }
        digits
            .parse()
            .or_else(|_| err(Fault::DataFormat, format!("bad {what} number")))
    }

    fn require_macros(&self, what: &str) -> Result<(), SyntaxError> {
        if self.macros {
            Ok(())
        } else {
            err(
                Fault::UndefinedCode,
                format!("{what}: this control has no macro statements"),
            )
        }
    }

    /// Runs `f` one nesting level deeper (`IF` after `IF`, `##…`, brackets, unary signs): a
    /// line can nest only so deep, so a hostile line cannot exhaust the stack.
    fn nested<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<T, SyntaxError>,
    ) -> Result<T, SyntaxError> {
        if self.depth >= MAX_DEPTH {
            return err(
                Fault::MacroBrackets,
                "statement or expression nested too deeply",
            );
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn statement(&mut self) -> Result<Stmt, SyntaxError> {
        self.nested(Self::statement_inner)
    }

    fn statement_inner(&mut self) -> Result<Stmt, SyntaxError> {
        self.skip_ws();
        match self.peek() {
            None | Some(b'%') => Ok(Stmt::Empty),
            Some(b'#') => {
                self.require_macros("#")?;
                self.assignment()
            }
            Some(c) if c.is_ascii_uppercase() => match self.ident() {
                "IF" => {
                    self.require_macros("IF")?;
                    self.i += 2;
                    let cond = self.condition("IF")?;
                    let then = self.statement()?;
                    if then == Stmt::Empty {
                        return err(Fault::Macro, "IF without GOTO, assignment or block");
                    }
                    Ok(Stmt::If {
                        cond,
                        then: Box::new(then),
                    })
                }
                "WHILE" => {
                    self.require_macros("WHILE")?;
                    self.i += 5;
                    let cond = self.condition("WHILE")?;
                    self.skip_ws();
                    if self.ident() != "DO" {
                        return err(Fault::Macro, "WHILE [...] needs DO and a loop number");
                    }
                    self.i += 2;
                    self.skip_ws();
                    let id = self.unsigned("DO")?;
                    Ok(Stmt::While {
                        cond: Some(cond),
                        id,
                    })
                }
                "DO" | "END" => {
                    let word = self.ident();
                    let end = word == "END";
                    self.require_macros(if end { "END" } else { "DO" })?;
                    self.i += word.len();
                    self.skip_ws();
                    let id = self.unsigned(if end { "END" } else { "DO" })?;
                    Ok(if end {
                        Stmt::End(id)
                    } else {
                        Stmt::While { cond: None, id }
                    })
                }
                "GOTO" => {
                    self.require_macros("GOTO")?;
                    self.i += 4;
                    Ok(Stmt::Goto(self.word_value("GOTO")?))
                }
                _ => self.words(),
            },
            Some(c) => err(
                stray_fault(c),
                format!("unexpected character {:?}", c as char),
            ),
        }
    }

    /// The `[condition]` after IF or WHILE.
    fn condition(&mut self, what: &str) -> Result<Expr, SyntaxError> {
        if !self.eat(b'[') {
            return err(Fault::Macro, format!("{what} needs a condition in [ ]"));
        }
        let cond = self.expr()?;
        if !self.eat(b']') {
            return err(
                Fault::Macro,
                format!("']' missing after the {what} condition"),
            );
        }
        Ok(cond)
    }

    fn assignment(&mut self) -> Result<Stmt, SyntaxError> {
        self.i += 1; // '#'
        let var = self.var_index()?;
        if !self.eat(b'=') {
            return err(Fault::Macro, "'=' missing in the assignment");
        }
        let value = self.expr()?;
        Ok(Stmt::Assign { var, value })
    }

    fn words(&mut self) -> Result<Stmt, SyntaxError> {
        let mut words = Vec::new();
        loop {
            self.skip_ws();
            let Some(c) = self.peek() else { break };
            if !c.is_ascii_uppercase() {
                return err(
                    stray_fault(c),
                    format!("unexpected character {:?}", c as char),
                );
            }
            let id = self.ident();
            if id.len() > 1 {
                return err(Fault::UndefinedCode, format!("unknown word {id:?}"));
            }
            self.i += 1;
            let letter = c as char;
            let value = self.word_value(&letter.to_string())?;
            words.push(Word { letter, value });
        }
        Ok(Stmt::Words(words))
    }

    /// A word's value: signed number, `#var` or `[expr]` (also `-#1`, `-[…]`).
    fn word_value(&mut self, letter: &str) -> Result<Expr, SyntaxError> {
        self.skip_ws();
        let mut negative = false;
        if let Some(sign @ (b'-' | b'+')) = self.peek() {
            negative = sign == b'-';
            self.i += 1;
            self.skip_ws();
            if matches!(self.peek(), Some(b'-' | b'+')) {
                return err(
                    Fault::IllegalMinus,
                    format!("address {letter}: a second sign"),
                );
            }
        }
        let value = match self.peek() {
            Some(b'#') => {
                self.require_macros("#")?;
                self.i += 1;
                Expr::Var(Box::new(self.var_index()?))
            }
            Some(b'[') => {
                self.require_macros("[")?;
                self.bracketed()?
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(letter)?,
            _ => return err(Fault::NoNumber, format!("address {letter} needs a number")),
        };
        Ok(if negative {
            match value {
                Expr::Num { value, point } => Expr::Num {
                    value: -value,
                    point,
                },
                e => Expr::Unary(UnOp::Neg, Box::new(e)),
            }
        } else {
            value
        })
    }

    fn number(&mut self, letter: &str) -> Result<Expr, SyntaxError> {
        let start = self.i;
        // Digits as an integer and how many follow the point, for the exact fast path.
        let (mut mantissa, mut digits, mut points, mut decimals) = (0_u64, 0_u32, 0_u32, 0_i32);
        while let Some(c) = self.peek().filter(|c| c.is_ascii_digit() || *c == b'.') {
            self.i += 1;
            if self.i - start > MAX_NUMBER_CHARS {
                return err(
                    Fault::TooManyDigits,
                    format!("number after {letter} too long"),
                );
            }
            if c == b'.' {
                points += 1;
            } else {
                mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(c - b'0'));
                digits += 1;
                decimals += i32::from(points > 0);
            }
        }
        let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        let point = points > 0;
        if points > 1 {
            return err(
                Fault::DecimalPoint,
                format!("address {letter}: {text:?} has two decimal points"),
            );
        }
        if digits == 0 {
            return err(
                Fault::NoNumber,
                format!("address {letter} needs a number, found {text:?}"),
            );
        }
        if digits <= 15 {
            // Both the integer and the power of ten are exact, and IEEE division rounds
            // correctly: the same value `parse` gives (Clinger's fast path).
            let value = mantissa as f64 / POWERS_OF_TEN[decimals as usize];
            return Ok(Expr::Num { value, point });
        }
        match text.parse::<f64>() {
            Ok(value) if value.is_finite() => Ok(Expr::Num { value, point }),
            _ => err(Fault::DataFormat, format!("bad number {text:?}")),
        }
    }

    /// What follows `#`: a number, another `#…`, or `[expr]`.
    fn var_index(&mut self) -> Result<Expr, SyntaxError> {
        self.nested(Self::var_index_inner)
    }

    fn var_index_inner(&mut self) -> Result<Expr, SyntaxError> {
        self.skip_ws();
        match self.peek() {
            Some(b'#') => {
                self.i += 1;
                Ok(Expr::Var(Box::new(self.var_index()?)))
            }
            Some(b'[') => self.bracketed(),
            Some(c) if c.is_ascii_digit() => self.number("#"),
            _ => err(Fault::Macro, "# needs a variable number"),
        }
    }

    /// `[expr]`, at the `[`.
    fn bracketed(&mut self) -> Result<Expr, SyntaxError> {
        self.i += 1;
        let e = self.expr()?;
        if !self.eat(b']') {
            return err(Fault::MacroBrackets, "']' missing");
        }
        Ok(e)
    }

    fn expr(&mut self) -> Result<Expr, SyntaxError> {
        self.nested(|p| p.binary(1))
    }

    fn binary(&mut self, min_prec: u8) -> Result<Expr, SyntaxError> {
        let mut lhs = self.unary()?;
        loop {
            self.skip_ws();
            let Some((op, len)) = self.operator() else {
                break;
            };
            if op.precedence() < min_prec {
                break;
            }
            self.i += len;
            let rhs = self.binary(op.precedence() + 1)?;
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn operator(&self) -> Option<(BinOp, usize)> {
        let two = self.s.get(self.i..self.i + 2).unwrap_or(&[]);
        let op2 = match two {
            b"==" => Some(BinOp::Eq),
            b"!=" => Some(BinOp::Ne),
            b">=" => Some(BinOp::Ge),
            b"<=" => Some(BinOp::Le),
            b"&&" => Some(BinOp::And),
            b"||" => Some(BinOp::Or),
            _ => None,
        };
        if let Some(op) = op2 {
            return Some((op, 2));
        }
        // FANUC macro B writes its operators as words (`003` inventory A.3).
        let word_end = self.s[self.i..]
            .iter()
            .position(|c| !c.is_ascii_uppercase())
            .unwrap_or(self.s.len() - self.i);
        let word = match &self.s[self.i..self.i + word_end] {
            b"EQ" => Some(BinOp::Eq),
            b"NE" => Some(BinOp::Ne),
            b"GT" => Some(BinOp::Gt),
            b"GE" => Some(BinOp::Ge),
            b"LT" => Some(BinOp::Lt),
            b"LE" => Some(BinOp::Le),
            b"AND" => Some(BinOp::BitAnd),
            b"OR" => Some(BinOp::BitOr),
            b"XOR" => Some(BinOp::BitXor),
            _ => None,
        };
        if let Some(op) = word {
            return Some((op, word_end));
        }
        let op = match self.peek()? {
            b'+' => BinOp::Add,
            b'-' => BinOp::Sub,
            b'*' => BinOp::Mul,
            b'/' => BinOp::Div,
            b'>' => BinOp::Gt,
            b'<' => BinOp::Lt,
            b'&' => BinOp::BitAnd,
            b'|' => BinOp::BitOr,
            b'^' => BinOp::BitXor,
            _ => return None,
        };
        Some((op, 1))
    }

    fn unary(&mut self) -> Result<Expr, SyntaxError> {
        self.skip_ws();
        let op = match self.peek() {
            Some(b'-') => Some(UnOp::Neg),
            Some(b'+') => None,
            Some(b'!') if self.s.get(self.i + 1) != Some(&b'=') => Some(UnOp::Not),
            Some(b'~') => Some(UnOp::BitNot),
            _ => return self.primary(),
        };
        self.i += 1;
        let inner = self.nested(Self::unary)?;
        Ok(match op {
            Some(op) => Expr::Unary(op, Box::new(inner)),
            None => inner,
        })
    }

    fn primary(&mut self) -> Result<Expr, SyntaxError> {
        self.skip_ws();
        match self.peek() {
            Some(b'#') => {
                self.i += 1;
                Ok(Expr::Var(Box::new(self.var_index()?)))
            }
            Some(b'[') => self.bracketed(),
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number("expression"),
            Some(c) if c.is_ascii_uppercase() => {
                let name = self.ident().to_string();
                let Some(f) = Func::from_name(&name) else {
                    return err(Fault::Macro, format!("unknown function {name}"));
                };
                self.i += name.len();
                let mut args = Vec::new();
                for k in 0..f.arity() {
                    if k == 1 && f == Func::Atan {
                        // FANUC macro B writes `ATAN[a]/[b]`, Huaxing `ATAN[a][b]`.
                        self.skip_ws();
                        self.eat(b'/');
                        self.skip_ws();
                    }
                    if !self.eat(b'[') {
                        return err(Fault::Macro, format!("{name} needs [argument]"));
                    }
                    args.push(self.expr()?);
                    if !self.eat(b']') {
                        return err(Fault::Macro, format!("']' missing after {name}"));
                    }
                }
                Ok(Expr::Call(f, args))
            }
            _ => err(Fault::Macro, "expression expected"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast decimal path gives exactly what `str::parse` gives.
    #[test]
    fn numbers_read_as_parse_reads_them() {
        let mut texts: Vec<String> = [
            "0",
            "0.1",
            ".5",
            "5.",
            "000123.4500",
            "123456789012345",
            "99999.999",
            "0.000001",
            "1.000000000000001",
            "12345678901234.5",
            "0.30000000000000004",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let digits = (x % 1_000_000_000_000_000).to_string();
            let at = (x >> 50) as usize % (digits.len() + 1);
            texts.push(format!("{}.{}", &digits[..at], &digits[at..]));
        }
        for t in texts {
            let line = parse_line(&format!("X{t}"), false).expect(&t);
            let Stmt::Words(w) = line.stmt else {
                panic!("{t}")
            };
            let Expr::Num { value, .. } = w[0].value else {
                panic!("{t}")
            };
            let expected: f64 = t.parse().expect(&t);
            assert_eq!(value.to_bits(), expected.to_bits(), "{t}");
        }
    }
    use crate::fanuc::expr::{EvalError, Value, Variables};

    struct Vars;
    impl Variables for Vars {
        fn read(&self, n: i64) -> Result<Value, EvalError> {
            Ok(match n {
                0 => None,
                n => Some(n as f64),
            })
        }
    }

    fn words(text: &str) -> Vec<(char, Option<f64>)> {
        match parse_line(text, true).unwrap().stmt {
            Stmt::Words(w) => w
                .iter()
                .map(|w| (w.letter, w.value.eval(&Vars).unwrap()))
                .collect(),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn words_comments_and_semicolons() {
        assert_eq!(
            words("N0040 W-32 F200; (从 B 点切削至 C 点)"),
            [('W', Some(-32.0)), ('F', Some(200.0))]
        );
        assert_eq!(words("N0025 M8 (开冷却液)"), [('M', Some(8.0))]);
        assert_eq!(
            words("g01 x.5 z-.25"),
            [('G', Some(1.0)), ('X', Some(0.5)), ('Z', Some(-0.25))]
        );
        assert_eq!(
            words("N10 G01 X10 直线插补"),
            [('G', Some(1.0)), ('X', Some(10.0))]
        );
        assert_eq!(words("G0X#1"), [('G', Some(0.0)), ('X', Some(1.0))]);
        assert_eq!(words("X[-#2]"), [('X', Some(-2.0))]);
        assert_eq!(words("U[-2*[#2]]"), [('U', Some(-4.0))]);
        let l = parse_line("N0010 M53.1K[#4]", true).unwrap();
        assert_eq!(l.number, Some(10));
    }

    #[test]
    fn macro_statements() {
        let l = parse_line("N0050IF[#1 < 100]GOTO30", true).unwrap();
        assert!(matches!(l.stmt, Stmt::If { .. }));
        let l = parse_line("N0010#1=1", true).unwrap();
        assert!(matches!(l.stmt, Stmt::Assign { .. }));
        let l = parse_line("N0010GOTO[#1+100]", true).unwrap();
        assert!(matches!(l.stmt, Stmt::Goto(_)));
        let l = parse_line("IF[#8==#3] M99", true).unwrap();
        assert!(matches!(l.stmt, Stmt::If { .. }));
    }

    #[test]
    fn precedence_as_printed() {
        let Stmt::Assign { value, .. } = parse_line("#1=2+3*4", true).unwrap().stmt else {
            panic!()
        };
        assert_eq!(value.eval(&Vars).unwrap(), Some(14.0));
        let Stmt::Assign { value, .. } = parse_line("#1=5&4==4", true).unwrap().stmt else {
            panic!()
        };
        // Bitwise binds loosest (D11): 5 & (4 == 4) = 5 & 1 = 1.
        assert_eq!(value.eval(&Vars).unwrap(), Some(1.0));
    }

    #[test]
    fn block_skip_percent_and_names() {
        assert_eq!(parse_line("/N10 X1", true).unwrap().skip, Some(1));
        assert_eq!(parse_line("/2 X1", true).unwrap().skip, Some(2));
        assert!(parse_line("N0120 %", true).unwrap().percent);
        assert_eq!(
            parse_line("O0001 ; (程序名)", true)
                .unwrap()
                .name
                .as_deref(),
            Some("O0001")
        );
        assert_eq!(
            parse_line("%12", false).unwrap().name.as_deref(),
            Some("12")
        );
    }

    #[test]
    fn malformed_text_is_an_error() {
        for bad in [
            "G01 X1..2",
            "G01 X",
            "G01 (open",
            "G01 X1 = 2",
            "#1=[2",
            "#1=SIN 2",
        ] {
            assert!(parse_line(bad, true).is_err(), "{bad}");
        }
        assert!(parse_line(&format!("X{}", "9".repeat(400)), true).is_err());
        assert!(parse_line(&format!("#1={}1{}", "[".repeat(100), "]".repeat(100)), true).is_err());
        // Nesting that would exhaust the stack is refused, not followed.
        assert!(parse_line(&format!("#1={}1", "#".repeat(100_000)), true).is_err());
        assert!(parse_line(&format!("{}G0", "IF[1]".repeat(100_000)), true).is_err());
        assert!(parse_line(&format!("#1={}1", "-".repeat(100_000)), true).is_err());
        assert_eq!(
            parse_line("#1=2", false).unwrap_err().fault,
            Fault::UndefinedCode
        );
    }
}
