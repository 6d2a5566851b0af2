//! Splits a program line into words.
//!
//! A line is one block: optional `/` (block skip), optional `O`/`N` number, then words
//! (address letter + number). `;` ends the block; what follows is a comment. `( … )` is a comment,
//! also in full-width form `（ … ）`. Non-ASCII text outside parentheses starts a comment to the end
//! of the line: the control's keyboard types only letters and digits, so such text can only be a
//! comment written on a PC (`000` §3.3.2; decision D2 in docs/decisions.md). A line that is only
//! `%` ends the program text.

use crate::error::{alarm, ProgramError};

/// One address word, e.g. `X-23.7`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Word {
    pub letter: char,
    pub value: f64,
}

/// The words of one line.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Line {
    pub number: u32,
    pub block_skip: bool,
    /// The line is a `%` end-of-text mark.
    pub end_of_text: bool,
    pub words: Vec<Word>,
}

/// Longest number text accepted; longer is a data format error, not a slow parse.
const MAX_NUMBER_CHARS: usize = 24;

/// Lexes one line. `number` is its 1-based line number, used in errors.
pub fn lex_line(text: &str, number: u32) -> Result<Line, ProgramError> {
    let mut line = Line {
        number,
        ..Line::default()
    };
    let mut chars = text.char_indices().peekable();
    let mut first = true;
    while let Some(&(_, c)) = chars.peek() {
        match c {
            ' ' | '\t' | '\r' | '\u{3000}' => {
                chars.next();
            }
            ';' | '；' => break,
            '(' | '（' => {
                chars.next();
                let mut closed = false;
                for (_, c) in chars.by_ref() {
                    if c == ')' || c == '）' {
                        closed = true;
                        break;
                    }
                }
                if !closed {
                    return Err(ProgramError::new(
                        alarm::DATA_FORMAT,
                        number,
                        "comment not closed: ')' missing",
                    ));
                }
            }
            '/' if first => {
                chars.next();
                line.block_skip = true;
                // Optional skip level digit, e.g. `/2`.
                while matches!(chars.peek(), Some(&(_, d)) if d.is_ascii_digit()) {
                    chars.next();
                }
            }
            '%' => {
                chars.next();
                line.end_of_text = true;
            }
            c if c.is_ascii_alphabetic() => {
                chars.next();
                let letter = c.to_ascii_uppercase();
                let mut num = String::new();
                while let Some(&(_, d)) = chars.peek() {
                    if d.is_ascii_digit() || d == '.' || ((d == '-' || d == '+') && num.is_empty())
                    {
                        num.push(d);
                        chars.next();
                        if num.len() > MAX_NUMBER_CHARS {
                            return Err(ProgramError::new(
                                alarm::DATA_FORMAT,
                                number,
                                format!("number after {letter} too long"),
                            ));
                        }
                    } else if d == ' '
                        && !num.is_empty()
                        && num.chars().all(|x| x == '-' || x == '+')
                    {
                        chars.next();
                    } else {
                        break;
                    }
                }
                let value = parse_number(&num).ok_or_else(|| {
                    ProgramError::new(
                        alarm::DATA_FORMAT,
                        number,
                        format!("address {letter} needs a number, found {:?}", num),
                    )
                })?;
                line.words.push(Word { letter, value });
            }
            c if !c.is_ascii() => break,
            c => {
                return Err(ProgramError::new(
                    alarm::DATA_FORMAT,
                    number,
                    format!("unexpected character {c:?}"),
                ));
            }
        }
        first = false;
    }
    Ok(line)
}

fn parse_number(text: &str) -> Option<f64> {
    if text.is_empty() || text.matches('.').count() > 1 || !text.chars().any(|c| c.is_ascii_digit())
    {
        return None;
    }
    let value: f64 = text.parse().ok()?;
    value.is_finite().then_some(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn letters(l: &Line) -> String {
        l.words
            .iter()
            .map(|w| format!("{}{}", w.letter, w.value))
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn words_comments_and_semicolons() {
        let l = lex_line("N0040 W-32 F200; (从 B 点切削至 C 点)", 7).unwrap();
        assert_eq!(letters(&l), "N40 W-32 F200");
        let l = lex_line("N0025 M8 (开冷却液)", 1).unwrap();
        assert_eq!(letters(&l), "N25 M8");
        let l = lex_line("g01 x.5 z-.25", 1).unwrap();
        assert_eq!(letters(&l), "G1 X0.5 Z-0.25");
        let l = lex_line("N10 G01 X10 直线插补", 1).unwrap();
        assert_eq!(letters(&l), "N10 G1 X10");
    }

    #[test]
    fn block_skip_and_percent() {
        assert!(lex_line("/N10 X1", 1).unwrap().block_skip);
        assert!(lex_line("N0120 %", 1).unwrap().end_of_text);
    }

    #[test]
    fn malformed_text_is_an_error_with_line() {
        let e = lex_line("G01 X1..2", 5).unwrap_err();
        assert_eq!((e.number, e.line), (alarm::DATA_FORMAT, 5));
        assert_eq!(lex_line("G01 X", 2).unwrap_err().number, alarm::DATA_FORMAT);
        assert_eq!(
            lex_line("G01 (open", 3).unwrap_err().number,
            alarm::DATA_FORMAT
        );
        assert_eq!(
            lex_line("G01 X1 = 2", 3).unwrap_err().number,
            alarm::DATA_FORMAT
        );
        assert_eq!(
            lex_line(&format!("X{}", "9".repeat(400)), 1)
                .unwrap_err()
                .number,
            alarm::DATA_FORMAT
        );
    }
}
