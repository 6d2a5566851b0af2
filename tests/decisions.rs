//! The decisions documents stay findable (issue 47): each decision is recorded once, in one
//! area file under `docs/decisions/`, the index `docs/decisions.md` lists every number with
//! the file that holds it, and every number the code or the documents cite exists.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The decision numbers an area file records (`- **Dn — …`), in order.
fn recorded(text: &str) -> Vec<u32> {
    text.lines()
        .filter_map(|line| line.strip_prefix("- **D"))
        .filter_map(|rest| {
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            digits.parse().ok()
        })
        .collect()
}

/// Every area file's decisions: number → file stem.
fn areas() -> BTreeMap<u32, String> {
    let mut found: BTreeMap<u32, String> = BTreeMap::new();
    let dir = repo().join("docs/decisions");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("docs/decisions")
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    for path in files {
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(&path).expect("area file");
        for n in recorded(&text) {
            if let Some(other) = found.insert(n, stem.clone()) {
                panic!("D{n} is recorded twice: in {other}.md and {stem}.md");
            }
        }
    }
    found
}

/// The index's lines `- Dn — title → [area](decisions/area.md)`: number → area.
fn index() -> BTreeMap<u32, String> {
    let text = std::fs::read_to_string(repo().join("docs/decisions.md")).expect("index");
    let mut listed = BTreeMap::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("- D") else {
            continue;
        };
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        let n: u32 = digits.parse().expect("a number after - D");
        let area = line
            .rsplit_once("(decisions/")
            .and_then(|(_, tail)| tail.strip_suffix(".md)"))
            .unwrap_or_else(|| panic!("index line without its file: {line}"));
        assert!(
            listed.insert(n, area.to_string()).is_none(),
            "D{n} listed twice in the index"
        );
    }
    listed
}

/// The numbers a text cites: "decision(s) D41", "decisions D84, D86–D90" (each number
/// written), "(D101)" and "[D67](…)".
fn cited(text: &str) -> Vec<u32> {
    let mut numbers = Vec::new();
    let bytes = text.as_bytes();
    for (i, _) in text.match_indices('D') {
        let digits: String = text[i + 1..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        let Ok(n) = digits.parse::<u32>() else {
            continue;
        };
        let before = &text[..i];
        let after = bytes.get(i + 1 + digits.len()).copied();
        let bracketed = (before.ends_with('(') && after == Some(b')'))
            || (before.ends_with('[') && after == Some(b']'));
        let start = before.char_indices().rev().nth(29).map_or(0, |(at, _)| at);
        let window = &before[start..];
        let after_word = window.rfind("ecision").is_some_and(|at| {
            let tail = &window[at + "ecision".len()..];
            let tail = tail.strip_prefix('s').unwrap_or(tail);
            tail.chars().all(|c| !c.is_alphabetic() || c == 'D')
        });
        if (bracketed && digits.len() >= 2) || after_word {
            numbers.push(n);
        }
    }
    numbers
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            if name != "target"
                && name != "vendor"
                && name != "node_modules"
                && !name.starts_with('.')
            {
                sources(&path, out);
            }
        } else if name.ends_with(".rs") || name.ends_with(".md") {
            out.push(path);
        }
    }
}

#[test]
fn every_decision_is_recorded_once_and_listed_with_its_file() {
    let areas = areas();
    let index = index();
    assert!(areas.len() > 120, "only {} decisions found", areas.len());
    for (n, area) in &areas {
        assert_eq!(
            index.get(n),
            Some(area),
            "D{n} is in {area}.md; the index says otherwise"
        );
    }
    for n in index.keys() {
        assert!(
            areas.contains_key(n),
            "the index lists D{n}, which no area file records"
        );
    }
}

#[test]
fn every_cited_decision_exists() {
    let areas = areas();
    let root = repo();
    let mut files = Vec::new();
    for dir in [
        "nodes", "src", "msgs", "tests", "docs", "crates", "benches", "scripts",
    ] {
        sources(&root.join(dir), &mut files);
    }
    files.push(root.join("README.md"));
    files.push(root.join("ARCHITECTURE.md"));
    let mut citations = 0;
    for path in files {
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        for n in cited(&text) {
            citations += 1;
            assert!(
                areas.contains_key(&n),
                "{} cites D{n}, which no decisions file records",
                path.display()
            );
        }
    }
    assert!(
        citations > 150,
        "only {citations} citations found: the scanner lost its pattern"
    );
}

#[test]
fn the_citation_scanner_reads_the_ways_the_code_cites() {
    assert_eq!(cited("(decisions D84, D86–D90 in x)"), vec![84, 86, 90]);
    assert_eq!(cited("see decision D30."), vec![30]);
    assert_eq!(cited("edge (D1) and [D67](docs) and (D101)"), vec![67, 101]);
    assert_eq!(cited("the tool's D2 edge, then T3 D4"), Vec::<u32>::new());
}
