//! The 802D's characters as tokens (`001` §9.1.3–§9.1.5, inventory §2.2, §2.9). Upper and
//! lower case are one letter; blanks separate words and are also accepted around `=`, before
//! `(` and `[` (as the manual's own examples print them, decision D78). A letter followed by
//! digits is an address word (`X20.5`, `G1`, `R10`, `L0128`): names of variables, labels and
//! programs begin with two letters, so they never look like one.

use std::borrow::Cow;
use std::fmt;

/// A token borrows its text from the line: lexing a block allocates only the token list (and
/// a name written in lower case).
#[derive(Debug, Clone, PartialEq)]
pub enum Tok<'s> {
    /// An address letter with digits: the letter, the digits as written (leading zeros are
    /// significant for `L`) and the value, with a fraction when one follows (`X20.5`).
    Word {
        letter: char,
        digits: &'s str,
        value: f64,
    },
    /// A name in upper case: a keyword, a multi-letter address, a variable, a label or a
    /// program.
    Name(Cow<'s, str>),
    Num(f64),
    Str(&'s str),
    Op(&'static str),
}

impl fmt::Display for Tok<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tok::Word { letter, digits, .. } => write!(f, "{letter}{digits}"),
            Tok::Name(n) => write!(f, "{n}"),
            Tok::Num(v) => write!(f, "{v}"),
            Tok::Str(s) => write!(f, "\"{s}\""),
            Tok::Op(o) => write!(f, "{o}"),
        }
    }
}

const OPS: [&str; 19] = [
    "==", "<>", "<=", ">=", "<<", "+", "-", "*", "/", "(", ")", "[", "]", ",", "=", "<", ">", ":",
    ".",
];

/// The line without its comment (`;` outside a string).
pub fn strip_comment(line: &str) -> &str {
    let mut in_str = false;
    for (i, c) in line.bytes().enumerate() {
        match c {
            b'"' => in_str = !in_str,
            b';' if !in_str => return &line[..i],
            _ => {}
        }
    }
    line
}

/// `name` in upper case, borrowed when it is written so.
pub fn upper(name: &str) -> Cow<'_, str> {
    if name.bytes().any(|b| b.is_ascii_lowercase()) {
        Cow::Owned(name.to_ascii_uppercase())
    } else {
        Cow::Borrowed(name)
    }
}

/// The tokens of a line (its comment already stripped); an error names the bad character.
/// Everything outside strings is ASCII, so the line is read byte by byte and every token
/// boundary is a character boundary.
pub fn tokens(line: &str) -> Result<Vec<Tok<'_>>, String> {
    let mut out = Vec::with_capacity(16);
    tokens_into(line, &mut out).map(|()| out)
}

/// [`tokens`] into `out` (emptied first), whose room a caller keeps from line to line.
pub fn tokens_into<'s>(line: &'s str, out: &mut Vec<Tok<'s>>) -> Result<(), String> {
    out.clear();
    let b = line.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b' ' || c == b'\t' || c == b'\r' {
            i += 1;
        } else if c == b'"' {
            let start = i + 1;
            let end = b[start..]
                .iter()
                .position(|&c| c == b'"')
                .ok_or("a string without its closing \"")?;
            out.push(Tok::Str(&line[start..start + end]));
            i = start + end + 1;
        } else if c.is_ascii_digit() || (c == b'.' && next_is_digit(b, i)) {
            let (v, next) = number(line, i)?;
            out.push(Tok::Num(v));
            i = next;
        } else if c.is_ascii_alphabetic() && next_is_digit(b, i) {
            // An address word: one letter, then its number (`X20.5`, `G1X20`, `L0128`).
            let mut end = i + 1;
            while end < b.len() && b[end].is_ascii_digit() {
                end += 1;
            }
            let (value, next) = number(line, i + 1)?;
            out.push(Tok::Word {
                letter: char::from(c.to_ascii_uppercase()),
                digits: &line[i + 1..end],
                value,
            });
            i = next;
        } else if c.is_ascii_alphabetic() || c == b'_' || c == b'$' {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push(Tok::Name(upper(&line[start..i])));
        } else {
            let rest = &b[i..b.len().min(i + 2)];
            let Some(op) = OPS.iter().find(|o| rest.starts_with(o.as_bytes())) else {
                let ch = line[i..].chars().next().unwrap_or('?');
                return Err(format!("character {ch:?} is not allowed here"));
            };
            out.push(Tok::Op(op));
            i += op.len();
        }
    }
    Ok(())
}

fn next_is_digit(b: &[u8], i: usize) -> bool {
    b.get(i + 1).is_some_and(|c| c.is_ascii_digit())
}

/// A number from `i`: digits, an optional fraction, an optional `EX` exponent
/// (`-0.1EX-5`, §9.9.1). Returns the value and where it ends.
fn number(line: &str, mut i: usize) -> Result<(f64, usize), String> {
    let b = line.as_bytes();
    let start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i < b.len() && b[i] == b'.' {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
    }
    let mantissa = &line[start..i];
    let mut value: f64 = match decimal(mantissa) {
        Some(v) => v,
        None => mantissa
            .parse()
            .map_err(|_| format!("number {mantissa:?} is malformed"))?,
    };
    let ex = b.len() >= i + 2
        && b[i].eq_ignore_ascii_case(&b'E')
        && b[i + 1].eq_ignore_ascii_case(&b'X');
    if ex {
        let mut j = i + 2;
        let neg = b.get(j) == Some(&b'-');
        if matches!(b.get(j), Some(b'-') | Some(b'+')) {
            j += 1;
        }
        let digits_from = j;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        let e: i32 = line[digits_from..j]
            .parse()
            .map_err(|_| "EX without its exponent".to_string())?;
        if e > 300 {
            return Err(format!("exponent EX{e} beyond ±300"));
        }
        // Parsed as one decimal number: `0.1EX-5` is exactly 1e-6.
        let sign = if neg { "-" } else { "" };
        value = format!("{mantissa}e{sign}{e}")
            .parse()
            .map_err(|_| format!("number {mantissa}EX{e} is malformed"))?;
        i = j;
    }
    Ok((value, i))
}

/// Powers of ten that are exact in an f64.
const POW10: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// `digits[.digits]` with at most 15 digits, as `str::parse` reads it but without its general
/// algorithm (most of a block's numbers are like `20.5`): the digits as an integer and the
/// power of ten are both exact, and one IEEE division of exact operands is correctly
/// rounded, so the result is the same number. `None` for anything else.
fn decimal(text: &str) -> Option<f64> {
    let (mut m, mut digits, mut fraction, mut dot) = (0u64, 0usize, 0usize, false);
    for b in text.bytes() {
        if b == b'.' && !dot {
            dot = true;
        } else if b.is_ascii_digit() {
            m = m * 10 + u64::from(b - b'0');
            digits += 1;
            fraction += usize::from(dot);
            if digits > 15 {
                return None;
            }
        } else {
            return None;
        }
    }
    (digits > 0).then(|| m as f64 / POW10[fraction])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn word(letter: char, digits: &str, value: f64) -> Tok<'_> {
        Tok::Word {
            letter,
            digits,
            value,
        }
    }

    /// The fast path reads every number exactly as the standard parser does.
    #[test]
    fn decimals_are_read_as_the_standard_parser_reads_them() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut fast = 0;
        for _ in 0..200_000 {
            let len = 1 + (next() % 16) as usize;
            let mut t: String = (0..len)
                .map(|_| char::from(b'0' + (next() % 10) as u8))
                .collect();
            if next() % 4 != 0 {
                t.insert((next() % (len as u64 + 1)) as usize, '.');
            }
            if let Some(v) = decimal(&t) {
                assert_eq!(Some(v), t.parse::<f64>().ok(), "{t}");
                fast += 1;
            }
        }
        assert!(fast > 150_000, "{fast}");
        for t in [
            "0.1",
            "0.001",
            "12.207",
            "99999999",
            "5.",
            ".5",
            "123456789012345",
        ] {
            assert_eq!(decimal(t), t.parse::<f64>().ok(), "{t}");
        }
        assert_eq!(decimal("."), None);
        assert_eq!(
            decimal("1234567890123456"),
            None,
            "16 digits: the standard parser"
        );
    }

    #[test]
    fn words_names_numbers_and_operators() {
        let t = tokens("n10 g2 X20.5 cr=-12.207 Z=IC(-32) MA1: r1=1.874EX8").unwrap();
        assert_eq!(t[0], word('N', "10", 10.0));
        assert_eq!(t[2], word('X', "20", 20.5));
        assert_eq!(t[3], Tok::Name("CR".into()));
        assert_eq!(t[5], Tok::Op("-"));
        assert_eq!(t[6], Tok::Num(12.207));
        assert_eq!(t[14], Tok::Name("MA1".into()));
        assert!(
            matches!(&t[3], Tok::Name(Cow::Owned(_))),
            "written in lower case"
        );
        assert!(matches!(&t[14], Tok::Name(Cow::Borrowed(_))));
        assert_eq!(t[15], Tok::Op(":"));
        assert_eq!(t[18], Tok::Num(187_400_000.0));
        assert_eq!(tokens("L0128").unwrap(), [word('L', "0128", 128.0)]);
        assert_eq!(tokens("R0=-0.1EX-5").unwrap()[3], Tok::Num(0.1e-5));
    }

    #[test]
    fn comments_and_strings() {
        assert_eq!(strip_comment("MSG(\"a;b\") ; note"), "MSG(\"a;b\") ");
        assert!(tokens("MSG(\"open").is_err());
        assert!(tokens("X10 ?").is_err());
        assert!(tokens("R1=2EX999").is_err());
    }
}
