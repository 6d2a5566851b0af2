//! Program libraries of the FANUC family's program numbers: a program is found by the `O`
//! number on its first line or by a file name like `O2011.nc` (issue 3), and a tape of several
//! programs is split at its program heads.

use std::path::Path;

use cnc_interpreter_core::{read_line, Library, Pos};

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

/// Adds one stored program to `lib`: by its program number (the `O` number on its first line
/// or in its file name), and by its name, the file name without its extension (`L10.SPF` is
/// called as `L10`, `RAHMEN7.SPF` as `RAHMEN7`: the programs of controls that call by
/// name). The first program of a number or name wins; a later one with a taken number is
/// the error.
pub fn add_program(lib: &mut Library, file_name: &str, text: &str) -> Result<(), String> {
    let path = Path::new(file_name);
    if let Some(stem) = path.file_stem().and_then(|s| s.to_str()) {
        lib.insert_named(stem, file_name, text);
    }
    match declared_number(text).or_else(|| file_number(path)) {
        Some(n) if lib.get(n).is_none() => lib.insert(n, file_name, text),
        Some(n) => return Err(format!("{file_name}: O{n:04} already taken")),
        None => {}
    }
    Ok(())
}

/// The name EXTCALL gives a program: `d:/Externe_UP/bohrung.spf ` → `D:\EXTERNE_UP\BOHRUNG`.
pub fn external_name(path: &str) -> String {
    let mut name = path.trim().replace('/', "\\").to_ascii_uppercase();
    for ext in [".SPF", ".MPF"] {
        if let Some(stem) = name.strip_suffix(ext) {
            name = stem.to_string();
        }
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stored_program_is_found_by_number_and_by_name() {
        let mut lib = Library::new();
        assert!(add_program(&mut lib, "L10.SPF", "G1 X1\nM17\n").is_ok());
        assert!(add_program(&mut lib, "O2011.nc", "O2011\nM99\n").is_ok());
        assert_eq!(lib.get_named("l10").map(|(f, _)| f), Some("L10.SPF"));
        assert_eq!(lib.get(2011).map(|(f, _)| f), Some("O2011.nc"));
        // `L0010` is another program than `L10`; a taken number is the error, the name stays.
        assert!(lib.get_named("L0010").is_none());
        let taken = add_program(&mut lib, "SECOND.nc", "O2011\nM99\n");
        assert_eq!(taken, Err("SECOND.nc: O2011 already taken".to_string()));
        assert_eq!(lib.get_named("SECOND").map(|(f, _)| f), Some("SECOND.nc"));
    }

    #[test]
    fn program_numbers_and_tapes() {
        assert_eq!(declared_number("\n O0010 ;x\nN1"), Some(10));
        // A tape: main program, then two subprograms; `%` and the program heads delimit them.
        let tape = "%\nO1002 (MAIN)\nG0 X1\nM30\nO2002\nX2\nM99\no3 (x)\nX3\nM99\n%\n";
        let (main, others) = split_programs(tape);
        assert_eq!(&tape[..main], "%\nO1002 (MAIN)\nG0 X1\nM30\n");
        assert_eq!(
            others,
            vec![(2002, "O2002\nX2\nM99\n"), (3, "o3 (x)\nX3\nM99\n%\n")]
        );
        assert_eq!(split_programs("G0 X1\nOR\nO12345\n"), (16, vec![]));
        assert_eq!(file_number(Path::new("lib/O2011.nc")), Some(2011));
        assert_eq!(file_number(Path::new("lib/part.nc")), None);
        assert_eq!(file_number(Path::new("052_sphere_sub_O0010.nc")), Some(10));
    }
}
