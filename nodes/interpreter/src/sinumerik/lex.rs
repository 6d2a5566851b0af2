//! The 802D's characters as tokens (`001` §9.1.3–§9.1.5, inventory §2.2, §2.9). Upper and
//! lower case are one letter; blanks separate words and are also accepted around `=`, before
//! `(` and `[` (as the manual's own examples print them, decision D78). A letter followed by
//! digits is an address word (`X20.5`, `G1`, `R10`, `L0128`): names of variables, labels and
//! programs begin with two letters, so they never look like one.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// An address letter with digits: the letter, the digits as written (leading zeros are
    /// significant for `L`) and the value, with a fraction when one follows (`X20.5`).
    Word {
        letter: char,
        digits: String,
        value: f64,
    },
    /// A name: a keyword, a multi-letter address, a variable, a label or a program.
    Name(String),
    Num(f64),
    Str(String),
    Op(&'static str),
}

impl fmt::Display for Tok {
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

const OPS: [&str; 17] = [
    "==", "<>", "<=", ">=", "<<", "+", "-", "*", "/", "(", ")", "[", "]", ",", "=", "<", ">",
];
const OPS_TAIL: [&str; 2] = [":", "."];

/// The line without its comment (`;` outside a string).
pub fn strip_comment(line: &str) -> &str {
    let mut in_str = false;
    for (i, c) in line.char_indices() {
        match c {
            '"' => in_str = !in_str,
            ';' if !in_str => return &line[..i],
            _ => {}
        }
    }
    line
}

/// The tokens of a line (its comment already stripped); an error names the bad character.
pub fn tokens(line: &str) -> Result<Vec<Tok>, String> {
    let chars: Vec<char> = line.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c == ' ' || c == '\t' || c == '\r' {
            i += 1;
        } else if c == '"' {
            let start = i + 1;
            let end = chars[start..]
                .iter()
                .position(|&c| c == '"')
                .ok_or("a string without its closing \"")?;
            out.push(Tok::Str(chars[start..start + end].iter().collect()));
            i = start + end + 1;
        } else if c.is_ascii_digit() || (c == '.' && next_is_digit(&chars, i)) {
            let (v, next) = number(&chars, i)?;
            out.push(Tok::Num(v));
            i = next;
        } else if c.is_ascii_alphabetic() && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()) {
            // An address word: one letter, then its number (`X20.5`, `G1X20`, `L0128`).
            let mut end = i + 1;
            while end < chars.len() && chars[end].is_ascii_digit() {
                end += 1;
            }
            let (value, next) = number(&chars, i + 1)?;
            out.push(Tok::Word {
                letter: c.to_ascii_uppercase(),
                digits: chars[i + 1..end].iter().collect(),
                value,
            });
            i = next;
        } else if c.is_ascii_alphabetic() || c == '_' || c == '$' {
            let start = i;
            i += 1;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Tok::Name(
                chars[start..i].iter().collect::<String>().to_uppercase(),
            ));
        } else {
            let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
            let op = OPS
                .iter()
                .chain(OPS_TAIL.iter())
                .find(|o| rest.starts_with(**o))
                .ok_or_else(|| format!("character {c:?} is not allowed here"))?;
            out.push(Tok::Op(op));
            i += op.len();
        }
    }
    Ok(out)
}

fn next_is_digit(chars: &[char], i: usize) -> bool {
    chars.get(i + 1).is_some_and(|c| c.is_ascii_digit())
}

/// A number from `i`: digits, an optional fraction, an optional `EX` exponent
/// (`-0.1EX-5`, §9.9.1). Returns the value and where it ends.
fn number(chars: &[char], mut i: usize) -> Result<(f64, usize), String> {
    let start = i;
    while i < chars.len() && chars[i].is_ascii_digit() {
        i += 1;
    }
    if i < chars.len() && chars[i] == '.' {
        i += 1;
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
    }
    let mantissa: String = chars[start..i].iter().collect();
    let mut value: f64 = mantissa
        .parse()
        .map_err(|_| format!("number {mantissa:?} is malformed"))?;
    let ex = chars.len() >= i + 2
        && chars[i].eq_ignore_ascii_case(&'E')
        && chars[i + 1].eq_ignore_ascii_case(&'X');
    if ex {
        let mut j = i + 2;
        let neg = chars.get(j) == Some(&'-');
        if matches!(chars.get(j), Some('-') | Some('+')) {
            j += 1;
        }
        let digits_from = j;
        while j < chars.len() && chars[j].is_ascii_digit() {
            j += 1;
        }
        let digits: String = chars[digits_from..j].iter().collect();
        let e: i32 = digits
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

#[cfg(test)]
mod tests {
    use super::*;

    fn word(letter: char, digits: &str, value: f64) -> Tok {
        Tok::Word {
            letter,
            digits: digits.into(),
            value,
        }
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
