//! Program text as the interpreter reads it: a cursor over lines, the search for a block
//! number, and the program library that subprograms come from.
//!
//! Reading is streaming: only the current line is parsed, and a jump target is found by
//! scanning the text (decision D28). So memory does not grow with the program's length beyond
//! its text.

use std::collections::HashMap;
use std::sync::Arc;

/// A position in a program text: byte offset of a line start and its 1-based line number
/// minus one (the number of lines before it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pos {
    pub offset: usize,
    pub line: u32,
}

/// Returns the line at `pos` and the position after it, or `None` at the end.
pub fn read_line(text: &str, pos: Pos) -> Option<(&str, Pos)> {
    if pos.offset >= text.len() {
        return None;
    }
    let rest = &text[pos.offset..];
    let (line, advance) = match rest.bytes().position(|b| b == b'\n') {
        Some(i) => (&rest[..i], i + 1),
        None => (rest, rest.len()),
    };
    Some((
        line,
        Pos {
            offset: pos.offset + advance,
            line: pos.line + 1,
        },
    ))
}

/// The sequence number a line starts with (`N0040` → 40), without parsing the rest.
pub fn line_number(line: &str) -> Option<u32> {
    let mut t = line.trim_start_matches([' ', '\t', '\u{3000}']);
    if let Some(rest) = t.strip_prefix('/') {
        t = rest
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start();
    }
    let mut chars = t.chars();
    match chars.next() {
        Some('N') | Some('n') => {}
        _ => return None,
    }
    let digits: String = chars.take_while(char::is_ascii_digit).collect();
    if digits.is_empty() || digits.len() > 9 {
        return None;
    }
    digits.parse().ok()
}

/// Finds the line numbered `n`, searching forward from `from` to the end of the program and
/// then from the top, as a sequence-number search on the control does (decision D28). A
/// target just ahead is found without reading the whole program, and of two blocks with the
/// same number the next one ahead is taken.
pub fn find_number(text: &str, from: Pos, n: u32) -> Option<Pos> {
    let scan = |mut pos: Pos, end: usize| {
        while let Some((line, next)) = read_line(text, pos) {
            if pos.offset >= end {
                break;
            }
            if line_number(line) == Some(n) {
                return Some(pos);
            }
            pos = next;
        }
        None
    };
    scan(from, usize::MAX).or_else(|| scan(Pos::default(), from.offset))
}

/// Programs the interpreter can call by number; the front end decides how a program's
/// number is written, the shell where programs come from.
#[derive(Debug, Clone, Default)]
pub struct Library {
    programs: HashMap<u32, (String, Arc<str>)>,
    /// Programs called by name (upper case), for controls whose programs have names.
    named: HashMap<String, (String, Arc<str>)>,
}

impl Library {
    pub fn new() -> Library {
        Library::default()
    }

    /// Adds a program under its number; `name` is what errors call it.
    pub fn insert(&mut self, number: u32, name: &str, text: &str) {
        self.programs
            .insert(number, (name.to_string(), Arc::from(text)));
    }

    /// The text of the program the library calls `name` (by number or by name), if any.
    pub fn text_of(&self, name: &str) -> Option<Arc<str>> {
        self.programs
            .values()
            .chain(self.named.values())
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.clone())
    }

    pub fn get(&self, number: u32) -> Option<(&str, Arc<str>)> {
        self.programs
            .get(&number)
            .map(|(n, t)| (n.as_str(), t.clone()))
    }

    /// Adds a program under its name (case is not distinguished); the first one wins.
    pub fn insert_named(&mut self, name: &str, file: &str, text: &str) {
        self.named
            .entry(name.to_ascii_uppercase())
            .or_insert_with(|| (file.to_string(), Arc::from(text)));
    }

    /// Adds a program under its name, in place of one stored under it before.
    pub fn replace_named(&mut self, name: &str, file: &str, text: &str) {
        self.named.insert(
            name.to_ascii_uppercase(),
            (file.to_string(), Arc::from(text)),
        );
    }

    /// The program called `name` (any case): what errors call it, and its text.
    pub fn get_named(&self, name: &str) -> Option<(&str, Arc<str>)> {
        // Names are mostly written in capitals already: no copy to look them up.
        let hit = if name.bytes().any(|b| b.is_ascii_lowercase()) {
            self.named.get(&name.to_ascii_uppercase())
        } else {
            self.named.get(name)
        };
        hit.map(|(n, t)| (n.as_str(), t.clone()))
    }

    pub fn len(&self) -> usize {
        self.programs.len() + self.named.len()
    }

    pub fn is_empty(&self) -> bool {
        self.programs.is_empty() && self.named.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_search() {
        assert_eq!(line_number("N0040 G01"), Some(40));
        assert_eq!(line_number("/N10 X1"), Some(10));
        assert_eq!(line_number("G01 N10"), None);
        let text = "N10 X1\nN20 X2\nN0030 X3\n";
        let top = Pos::default();
        assert_eq!(find_number(text, top, 30).map(|p| p.line), Some(2));
        assert_eq!(find_number(text, top, 40), None);
        // Forward from the current block first, then from the top; the next of two N10s wins.
        let text = "N10 X1\nN20 X2\nN10 X3\nN30 X4\n";
        let at = |line| find_number(text, top, line).unwrap();
        let third = find_number(text, at(20), 10).unwrap();
        assert_eq!(third.line, 2);
        assert_eq!(find_number(text, at(30), 10).map(|p| p.line), Some(0));
        assert_eq!(find_number(text, at(30), 20).map(|p| p.line), Some(1));
    }
}
