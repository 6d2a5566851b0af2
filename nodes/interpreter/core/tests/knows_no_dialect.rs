//! The core knows no dialect: no dialect's name, manual or control appears anywhere in its
//! source (code, messages or comments), and the crate depends on no front end. A front end
//! that needs the core to behave its way passes a rule (`Rules`, `Plane`, `CssRule`,
//! `CompRules`) or does the work itself.

use std::path::Path;

/// Names of the dialects, their controls and their manuals (`000`–`003` are the seeds'
/// numbers), lower case.
const FORBIDDEN: &[&str] = &[
    "huaxing",
    "gtc",
    "fanuc",
    "sinumerik",
    "siemens",
    "802d",
    "iso-lathe",
    "isolathe",
    "fanuc-mill",
    "0-m",
    "`000`",
    "`001`",
    "`002`",
    "`003`",
    "dialect::",
];

fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("core source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_dialect_is_named_in_the_core() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    sources(&root.join("tests"), &mut files);
    assert!(files.len() >= 10, "{files:?}");
    let mut found = Vec::new();
    for file in &files {
        if file.ends_with("knows_no_dialect.rs") {
            continue; // the list itself
        }
        let text = std::fs::read_to_string(file).expect("source");
        for (n, line) in text.lines().enumerate() {
            let lower = line.to_lowercase();
            for word in FORBIDDEN.iter().filter(|w| lower.contains(**w)) {
                found.push(format!("{}:{}: {word}: {line}", file.display(), n + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "the core names a dialect:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_core_depends_on_no_front_end() {
    let manifest =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml"))
            .expect("Cargo.toml");
    let deps = manifest
        .split("[dependencies]")
        .nth(1)
        .expect("a dependencies table");
    for line in deps.lines().filter(|l| l.contains('=')) {
        let name = line.split(['=', '.']).next().unwrap_or("").trim();
        assert!(
            ["cnc_msgs", "serde"].contains(&name),
            "the core depends on {name}: only the message types and serde are allowed"
        );
    }
}
