//! Program text as the interpreter reads it: a cursor over lines, the search for a sequence
//! number, and the program library that subprograms come from.
//!
//! Reading is streaming: only the current line is parsed, and a jump target is found by
//! scanning from the top of the text, as the Huaxing manual says GOTO does (`000` §5.27.8). So
//! memory does not grow with the program's length beyond its text.

use std::collections::HashMap;
use std::path::Path;
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

/// The program number a line starts (`O2002`, `O2002 (SUB)`), if it is a program head.
fn program_head(line: &str) -> Option<u32> {
    let rest = line.trim_start().strip_prefix(['O', 'o'])?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    let after = rest[digits.len()..].chars().next();
    if digits.is_empty() || digits.len() > 4 || after.is_some_and(|c| c.is_ascii_alphanumeric()) {
        return None;
    }
    digits.parse().ok()
}

/// A file that holds several programs, as a FANUC tape does (`%`, `O1002` … M30, `O2002` …
/// M99, `%`): the byte length of the first program (from the top to the next program head)
/// and each following program as (number, its text). A file of one program gives its whole
/// length and no others.
pub fn split_programs(text: &str) -> (usize, Vec<(u32, &str)>) {
    let mut heads = Vec::new();
    let mut pos = Pos::default();
    let mut seen_block = false;
    while let Some((line, next)) = read_line(text, pos) {
        let t = line.trim();
        match program_head(t) {
            Some(n) if seen_block => heads.push((n, pos.offset)),
            _ => {}
        }
        if !t.is_empty() && t != "%" && !t.starts_with('(') && !t.starts_with(';') {
            seen_block = true;
        }
        pos = next;
    }
    let main_end = heads.first().map_or(text.len(), |h| h.1);
    let others = heads
        .iter()
        .enumerate()
        .map(|(k, &(n, start))| {
            let end = heads.get(k + 1).map_or(text.len(), |h| h.1);
            (n, &text[start..end])
        })
        .collect();
    (main_end, others)
}

/// Programs the interpreter can call by number: the library folder's programs, found by the
/// `O` number on their first line or by a file name like `O2011.nc` (issue 3).
#[derive(Debug, Clone, Default)]
pub struct Library {
    programs: HashMap<u32, (String, Arc<str>)>,
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

    pub fn get(&self, number: u32) -> Option<(&str, Arc<str>)> {
        self.programs
            .get(&number)
            .map(|(n, t)| (n.as_str(), t.clone()))
    }

    pub fn len(&self) -> usize {
        self.programs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.programs.is_empty()
    }

    /// The program number a text declares: `O1234` on its first non-empty line.
    pub fn declared_number(text: &str) -> Option<u32> {
        let first = text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && *l != "%" && !l.starts_with('(') && !l.starts_with(';'))?;
        let rest = first.strip_prefix(['O', 'o'])?;
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        digits.parse().ok()
    }

    /// The program number a file name gives: `O2011.nc`, `o2011.txt`, `2011.nc`.
    pub fn file_number(path: &Path) -> Option<u32> {
        let stem = path.file_stem()?.to_str()?;
        // `O2011.nc`, `2011.nc`, or a descriptive name ending in `_O2011`.
        let stem = stem.rsplit('_').next().unwrap_or(stem);
        let stem = stem.strip_prefix(['O', 'o']).unwrap_or(stem);
        if stem.is_empty() || !stem.chars().all(|c| c.is_ascii_digit()) || stem.len() > 4 {
            return None;
        }
        stem.parse().ok()
    }

    /// Reads every program of a folder (the shell's job; the core never touches files).
    /// Unreadable or nameless files are skipped and listed in the second value.
    pub fn load_dir(dir: &Path) -> std::io::Result<(Library, Vec<String>)> {
        let mut lib = Library::new();
        let mut skipped = Vec::new();
        let mut entries: Vec<_> = std::fs::read_dir(dir)?.filter_map(Result::ok).collect();
        entries.sort_by_key(|e| e.path());
        for entry in entries {
            let path = entry.path();
            if !path.is_file() {
                continue;
            }
            let Ok(bytes) = std::fs::read(&path) else {
                skipped.push(format!("{}: unreadable", path.display()));
                continue;
            };
            let Ok(text) = String::from_utf8(bytes) else {
                skipped.push(format!("{}: not UTF-8 text", path.display()));
                continue;
            };
            let number = Library::declared_number(&text).or_else(|| Library::file_number(&path));
            let name = path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("?")
                .to_string();
            match number {
                // The first file wins; a later one with the same number is reported.
                Some(n) if lib.get(n).is_none() => lib.insert(n, &name, &text),
                Some(n) => skipped.push(format!("{name}: O{n:04} already taken")),
                None => {}
            }
        }
        Ok((lib, skipped))
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
        assert_eq!(Library::declared_number("\n O0010 ;x\nN1"), Some(10));
        // A tape: main program, then two subprograms; `%` and the program heads delimit them.
        let tape = "%\nO1002 (MAIN)\nG0 X1\nM30\nO2002\nX2\nM99\no3 (x)\nX3\nM99\n%\n";
        let (main, others) = split_programs(tape);
        assert_eq!(&tape[..main], "%\nO1002 (MAIN)\nG0 X1\nM30\n");
        assert_eq!(
            others,
            vec![(2002, "O2002\nX2\nM99\n"), (3, "o3 (x)\nX3\nM99\n%\n")]
        );
        assert_eq!(split_programs("G0 X1\nOR\nO12345\n"), (16, vec![]));
        assert_eq!(Library::file_number(Path::new("lib/O2011.nc")), Some(2011));
        assert_eq!(Library::file_number(Path::new("lib/part.nc")), None);
        assert_eq!(
            Library::file_number(Path::new("052_sphere_sub_O0010.nc")),
            Some(10)
        );
    }
}
