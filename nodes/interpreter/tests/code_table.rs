//! The table of every G and M code of the two lathe manuals (issue 3, item 2) and the mill
//! manual (issue 7), kept true by this test: `docs/gm_codes.md` is generated from
//! - the codes the manuals list (the inventories' master tables, `000` §3.1/§4.1, `002`
//!   §3.1/§4.1 and `003` Tables 1.1/1.2, ranges expanded),
//! - what the dialect table and the interpreter do with each (a one-block probe program),
//! - the interpreter tests whose programs use the code (inline program text or the fixture file
//!   a test loads; comments and Rust code do not count).
//!
//! The test fails when a listed code is missing from its dialect table (nothing silently
//! missing) or when the committed table is stale. `CNC_BLESS=1 cargo test --workspace --test
//! code_table` rewrites it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cnc_interpreter::dialect::CodeStatus;
use cnc_interpreter::error::Fault;
use cnc_interpreter::syntax::code_part;
use cnc_interpreter::{check, Dialect, Setup};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shared() -> PathBuf {
    repo().join("../shared")
}

/// One code as the manual lists it: letter, value ×10 (G50.1 = 501), the manual's meaning.
#[derive(Debug, Clone)]
struct Listed {
    letter: char,
    x10: u32,
    meaning: String,
}

fn show(letter: char, x10: u32) -> String {
    if x10.is_multiple_of(10) {
        format!("{letter}{:02}", x10 / 10)
    } else {
        format!("{letter}{:02}.{}", x10 / 10, x10 % 10)
    }
}

/// Codes named in one table cell: `G02 / G03`, `G54–G59`, `G08, G08.1–G08.6`, `*M05`.
/// A range of more than 20 codes (`M9000–M9999`) gives its two ends only.
fn codes_in(cell: &str, letter: char) -> Vec<u32> {
    let mut out = Vec::new();
    let chars: Vec<char> = cell.chars().collect();
    let mut i = 0;
    let mut last: Option<u32> = None;
    let mut range_pending = false;
    while i < chars.len() {
        if chars[i] == letter && (i == 0 || !chars[i - 1].is_ascii_alphabetic()) {
            let mut j = i + 1;
            let mut text = String::new();
            while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
                text.push(chars[j]);
                j += 1;
            }
            if let Some(v) = x10_of(&text) {
                match (range_pending, last) {
                    (true, Some(a)) if v > a && (v - a) / step(a, v) <= 20 => {
                        let s = step(a, v);
                        let mut n = a + s;
                        while n <= v {
                            out.push(n);
                            n += s;
                        }
                    }
                    _ => out.push(v),
                }
                last = Some(v);
                range_pending = false;
            }
            i = j;
            continue;
        }
        if chars[i] == '–' {
            range_pending = true;
        }
        i += 1;
    }
    out
}

/// Step of a range: by tenths inside one number (G08.1–G08.6), else by whole codes.
fn step(a: u32, b: u32) -> u32 {
    if a / 10 == b / 10 {
        1
    } else {
        10
    }
}

fn x10_of(text: &str) -> Option<u32> {
    let text = text.trim_end_matches('.');
    let (int, dec) = text.split_once('.').unwrap_or((text, ""));
    let int: u32 = int.parse().ok()?;
    let dec: u32 = match dec.chars().next() {
        Some(c) => c.to_digit(10)?,
        None => 0,
    };
    Some(int * 10 + dec)
}

/// Rows of the markdown table that follows `heading` in `doc`: the code column and the
/// meaning column (0-based).
fn table(doc: &str, heading: &str, code_col: usize, meaning_col: usize) -> Vec<(String, String)> {
    let start = doc
        .find(heading)
        .unwrap_or_else(|| panic!("inventory heading {heading:?} not found"));
    let mut rows = Vec::new();
    let mut in_table = false;
    for line in doc[start..].lines().skip(1) {
        if line.starts_with('|') {
            in_table = true;
            let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
            if cells.len() > code_col.max(meaning_col) && !cells[0].starts_with("---") {
                rows.push((cells[code_col].to_string(), cells[meaning_col].to_string()));
            }
        } else if in_table {
            break;
        }
    }
    rows
}

fn listed(doc: &str, heading: &str, letter: char, code_col: usize, mean_col: usize) -> Vec<Listed> {
    let mut out: Vec<Listed> = Vec::new();
    for (cell, meaning) in table(doc, heading, code_col, mean_col) {
        for x10 in codes_in(&cell, letter) {
            if !out.iter().any(|l| l.x10 == x10) {
                out.push(Listed {
                    letter,
                    x10,
                    meaning: meaning.replace('|', "/"),
                });
            }
        }
    }
    out
}

/// The tests of this crate whose programs use each code, per dialect.
fn coverage() -> BTreeMap<(&'static str, char, u32), Vec<String>> {
    let tests_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&tests_dir)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            // The property test runs every code without asserting what it does.
            name.ends_with(".rs") && !["fuzz.rs", "mill_fuzz.rs", "code_table.rs"].contains(&name)
        })
        .collect();
    files.sort();
    let mut out: BTreeMap<(&'static str, char, u32), Vec<String>> = BTreeMap::new();
    for file in files {
        let source = std::fs::read_to_string(&file).unwrap();
        let file_name = file.file_name().unwrap().to_string_lossy().to_string();
        for (name, body) in test_functions(&source) {
            let dialect = if body.contains("FanucMill")
                || file_name.contains("003")
                || file_name.contains("mill")
                || file_name.contains("fanuc")
            {
                Dialect::FanucMill
            } else if body.contains("Gtc2eLathe") || file_name.contains("002") {
                Dialect::Gtc2eLathe
            } else if body.contains("HuaxingLathe")
                || body.contains("hx(")
                || body.contains("assert_alarms(")
                || file_name.contains("000")
            {
                Dialect::HuaxingLathe
            } else {
                continue;
            };
            let mut program = string_literals(&body);
            for fixture in fixture_names(&body) {
                for dir in ["000", "002", "003"] {
                    let path = shared().join("fixtures").join(dir).join(&fixture);
                    if let Ok(text) = std::fs::read_to_string(path) {
                        for line in text.lines() {
                            program.push_str(&code_part(line).unwrap_or_default());
                            program.push('\n');
                        }
                    }
                }
            }
            for letter in ['G', 'M'] {
                for x10 in codes_in(&program, letter) {
                    let tests = out.entry((dialect.name(), letter, x10)).or_default();
                    if !tests.contains(&name) {
                        tests.push(name.clone());
                    }
                }
            }
        }
    }
    out
}

/// `(name, body)` of every `#[test]` function in a source file.
fn test_functions(source: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let parts: Vec<&str> = source.split("#[test]").collect();
    for part in parts.iter().skip(1) {
        let Some(at) = part.find("fn ") else { continue };
        let name: String = part[at + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        out.push((name, part.to_string()));
    }
    out
}

/// The contents of the string literals in Rust source (program text written inline).
fn string_literals(source: &str) -> String {
    let mut out = String::new();
    let mut chars = source.chars().peekable();
    let mut in_comment = false;
    while let Some(c) = chars.next() {
        if in_comment {
            if c == '\n' {
                in_comment = false;
            }
            continue;
        }
        if c == '/' && chars.peek() == Some(&'/') {
            in_comment = true;
            continue;
        }
        if c == '\'' {
            // A char literal such as '"' is not the start of a string.
            let rest: String = chars.clone().take(3).collect();
            if rest.starts_with("\"'") || rest.starts_with("\\\"") {
                chars.nth(if rest.starts_with("\\\"") { 2 } else { 1 });
            }
            continue;
        }
        if c == '"' {
            while let Some(c) = chars.next() {
                match c {
                    '\\' => match chars.next() {
                        Some('n') => out.push('\n'),
                        Some(other) => out.push(other),
                        None => {}
                    },
                    '"' => break,
                    other => out.push(other),
                }
            }
            out.push('\n');
        }
    }
    out
}

/// Fixture file names a test loads (`"029_g71_type1_example1.nc"`).
fn fixture_names(body: &str) -> Vec<String> {
    let mut out = Vec::new();
    for piece in body.split('"') {
        let b = piece.as_bytes();
        if b.len() > 7
            && b[..3].iter().all(u8::is_ascii_digit)
            && b[3] == b'_'
            && piece.ends_with(".nc")
        {
            out.push(piece.to_string());
        }
    }
    out
}

/// What the interpreter does with a block holding only this code.
fn status(dialect: Dialect, l: &Listed) -> Result<String, String> {
    let known = match l.letter {
        'G' => dialect.g_code(l.x10).is_some(),
        _ => dialect.m_code(l.x10).is_some(),
    };
    if !known {
        return Err(format!(
            "{} is listed in the manual but missing from the {} table",
            show(l.letter, l.x10),
            dialect.name()
        ));
    }
    let program = format!("{}\n", show(l.letter, l.x10));
    let not_supported = dialect.alarm(Fault::NotSupported);
    let setup = if dialect == Dialect::FanucMill {
        Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3])
    } else {
        Setup::lathe([100.0, 50.0])
    };
    // The dialect table marks what is not built; a code the interpreter refuses at run time
    // counts too where the alarm number says so unambiguously (on FANUC, P/S 010 is also a
    // code missing its words).
    let table_says = match l.letter {
        'G' => matches!(dialect.g_code(l.x10), Some(CodeStatus::Unsupported(_))),
        _ => matches!(dialect.m_code(l.x10), Some(CodeStatus::Unsupported(_))),
    };
    let number_says = dialect.alarm(Fault::MissingWord) != not_supported;
    match check(dialect, &program, setup) {
        Err(e)
            if e.number == not_supported
                && (table_says || number_says)
                && !e.text.contains("undefined")
                && !e.text.contains("no such word") =>
        {
            Ok(format!(
                "not supported (alarm {}): {}",
                e.number,
                e.text.replace('|', "/")
            ))
        }
        _ => Ok("runs".to_string()),
    }
}

fn section(
    out: &mut String,
    dialect: Dialect,
    title: &str,
    codes: &[Listed],
    covered: &BTreeMap<(&'static str, char, u32), Vec<String>>,
    missing: &mut Vec<String>,
) {
    out.push_str(&format!("\n## {title}\n\n"));
    out.push_str("| code | the manual's meaning | status | tests |\n|---|---|---|---|\n");
    for l in codes {
        let st = match status(dialect, l) {
            Ok(s) => s,
            Err(e) => {
                missing.push(e.clone());
                e
            }
        };
        let tests = covered
            .get(&(dialect.name(), l.letter, l.x10))
            .map(|t| {
                let mut names: Vec<String> = t.iter().take(3).map(|n| format!("`{n}`")).collect();
                if t.len() > 3 {
                    names.push(format!("+{} more", t.len() - 3));
                }
                names.join(", ")
            })
            .unwrap_or_else(|| "—".into());
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            show(l.letter, l.x10),
            l.meaning,
            st,
            tests
        ));
    }
}

#[test]
fn every_code_of_the_manuals_is_in_the_table_with_its_status_and_tests() {
    let hx = std::fs::read_to_string(shared().join("spec/000_lathe_huaxing.md")).unwrap();
    let gt = std::fs::read_to_string(shared().join("spec/002_lathe_gtc2e.md")).unwrap();
    let fm = std::fs::read_to_string(shared().join("spec/003_fanuc_mill.md")).unwrap();
    let fm_g = listed(&fm, "## 3. G codes (Table 1.1)", 'G', 0, 2);
    let fm_m = listed(&fm, "### 4.1 M codes (Table 1.2)", 'M', 0, 1);
    // The inventory's counts: 51 G codes and G63, 15 M codes.
    assert_eq!(fm_g.len(), 52, "FANUC mill G codes read from the inventory");
    assert_eq!(fm_m.len(), 15, "FANUC mill M codes read from the inventory");
    let hx_g = listed(&hx, "### 3.1 Grouping", 'G', 0, 4);
    let hx_m = listed(&hx, "### 4.1 M codes", 'M', 0, 1);
    let gt_g = listed(&gt, "### 3.1 Instruction table", 'G', 2, 3);
    let gt_m = listed(&gt, "### 4.1 M codes", 'M', 1, 2);
    // The inventories' own counts: 32 G and 25 M codes for GTC2E.
    assert_eq!(gt_g.len(), 32, "GTC2E G codes read from the inventory");
    assert_eq!(gt_m.len(), 25, "GTC2E M codes read from the inventory");
    assert!(
        hx_g.len() >= 60 && hx_m.len() >= 40,
        "{} G, {} M",
        hx_g.len(),
        hx_m.len()
    );

    let covered = coverage();
    let mut missing = Vec::new();
    let mut doc = String::from(
        "# G and M codes of the lathe and mill manuals\n\n\
         Generated by `nodes/interpreter/tests/code_table.rs`; do not edit. It lists every code \
         in the master tables of the manuals' inventories (`../shared/spec/000_lathe_huaxing.md` \
         §3.1 and §4.1, `../shared/spec/002_lathe_gtc2e.md` §3.1 and §4.1, \
         `../shared/spec/003_fanuc_mill.md` Tables 1.1 and 1.2; ranges expanded, \
         except `M9000–M9999`: its two ends), what this controller does with it, and the interpreter \
         tests whose programs use it. `CNC_BLESS=1 cargo test --workspace --test code_table` \
         regenerates it; the test fails when it is stale or when a listed code is missing from \
         its dialect table.\n\n\
         - **runs**: the interpreter executes the code (its rules are in `docs/decisions.md` and \
         the tests).\n\
         - **not supported (alarm N)**: a block with the code is rejected with that alarm, its \
         line and the reason, before any motion of the block.\n\
         - **tests**: test functions in `nodes/interpreter/tests/` whose program text (inline or \
         the fixture file they load, comments excluded) contains the code in that dialect; `—` \
         where none does yet.\n",
    );
    section(
        &mut doc,
        Dialect::HuaxingLathe,
        "huaxing-lathe: G codes (`000` §3.1)",
        &hx_g,
        &covered,
        &mut missing,
    );
    section(
        &mut doc,
        Dialect::HuaxingLathe,
        "huaxing-lathe: M codes (`000` §4.1)",
        &hx_m,
        &covered,
        &mut missing,
    );
    section(
        &mut doc,
        Dialect::Gtc2eLathe,
        "gtc2e-lathe: G codes (`002` §3.1)",
        &gt_g,
        &covered,
        &mut missing,
    );
    section(
        &mut doc,
        Dialect::Gtc2eLathe,
        "gtc2e-lathe: M codes (`002` §4.1)",
        &gt_m,
        &covered,
        &mut missing,
    );

    section(
        &mut doc,
        Dialect::FanucMill,
        "fanuc-mill: G codes (`003` Table 1.1)",
        &fm_g,
        &covered,
        &mut missing,
    );
    section(
        &mut doc,
        Dialect::FanucMill,
        "fanuc-mill: M codes (`003` Table 1.2)",
        &fm_m,
        &covered,
        &mut missing,
    );

    let path = repo().join("docs/gm_codes.md");
    if std::env::var("CNC_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &doc).unwrap();
    }
    assert!(
        missing.is_empty(),
        "codes missing from the dialect tables:\n{}",
        missing.join("\n")
    );
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == doc,
        "docs/gm_codes.md is stale: run CNC_BLESS=1 cargo test --workspace --test code_table"
    );
}
