//! The golden corpus: `cnc check --trace` of every program the project has as a file (the
//! manuals' fixtures 000, 002, 003, the LinuxCNC oracle programs, the examples), as a user
//! gets it, block stream and alarms, compared byte for byte with `tests/golden/`. It pins what
//! the interpreter does while its inside is reshaped: a difference is either a bug fix (bless
//! it and name it) or a regression.
//!
//! `GOLDEN_BLESS=1 cargo test --workspace --test golden` rewrites the files.

use std::path::{Path, PathBuf};
use std::process::Command;

const REPO: &str = env!("CARGO_MANIFEST_DIR");

/// The lines of a trace kept in the file; the rest is summed up by its count and hash, so an
/// endless program's five million commands do not fill the repository.
const KEPT_LINES: usize = 4000;

/// One set of programs: their folder, which files, the `cnc check` arguments.
struct Set {
    name: &'static str,
    folder: &'static str,
    extension: &'static str,
    args: &'static [&'static str],
}

const SETS: [Set; 8] = [
    Set {
        name: "000_huaxing",
        folder: "../shared/fixtures/000",
        extension: "nc",
        // On the turn-mill, so the C-axis fixtures (004, 015) trace too (D138).
        args: &["--config", "sim_turnmill", "--dialect", "huaxing-lathe"],
    },
    Set {
        name: "000_iso",
        folder: "../shared/fixtures/000",
        extension: "nc",
        args: &["--dialect", "iso-lathe"],
    },
    Set {
        name: "002_gtc2e",
        folder: "../shared/fixtures/002",
        extension: "nc",
        args: &["--dialect", "gtc2e-lathe"],
    },
    Set {
        name: "003_mill",
        folder: "../shared/fixtures/003",
        extension: "nc",
        args: &["--config", "sim_mill"],
    },
    Set {
        name: "003_mill_linuxcnc",
        folder: "../shared/fixtures/003",
        extension: "nc",
        args: &["--config", "sim_mill", "--format", "linuxcnc"],
    },
    Set {
        name: "oracle",
        folder: "tests/oracle",
        extension: "ngc",
        args: &["--config", "sim_mill", "--tools", "tools.tbl"],
    },
    Set {
        name: "oracle_linuxcnc",
        folder: "tests/oracle",
        extension: "ngc",
        args: &[
            "--config",
            "sim_mill",
            "--tools",
            "tools.tbl",
            "--format",
            "linuxcnc",
        ],
    },
    Set {
        name: "examples_lathe",
        folder: "examples/lathe",
        extension: "nc",
        args: &[],
    },
];

/// `cnc check --trace ARGS FILE` run in the program's folder (so alarms name the file alone
/// and subprograms come from its folder): stdout, then stderr after a `--` line, cut to
/// [`KEPT_LINES`] lines with a summary of the rest.
fn trace(folder: &Path, file: &str, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(folder)
        .env("HOME", std::env::temp_dir().join("cnc_golden_home"))
        .env_remove("XDG_DATA_HOME")
        .arg("check")
        .args(args)
        .arg("--trace")
        .arg(file)
        .output()
        .expect("cnc runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut text = String::new();
    let mut lines = 0usize;
    for l in stdout.lines() {
        lines += 1;
        if lines <= KEPT_LINES {
            text.push_str(l);
            text.push('\n');
        }
    }
    if lines > KEPT_LINES {
        text.push_str(&format!(
            "... {lines} lines in all, FNV-1a {:016x}\n",
            fnv1a(stdout.as_bytes())
        ));
    }
    text.push_str(&format!("-- exit {}\n", out.status.code().unwrap_or(-1)));
    text.push_str(&String::from_utf8_lossy(&out.stderr));
    text
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn programs(set: &Set) -> Vec<PathBuf> {
    let dir = Path::new(REPO).join(set.folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == set.extension))
        .collect();
    files.sort();
    files
}

#[test]
fn every_program_traces_as_the_golden_corpus_says() {
    let bless = std::env::var_os("GOLDEN_BLESS").is_some();
    let golden = Path::new(REPO).join("tests/golden");
    let mut differ = Vec::new();
    let mut count = 0;
    for set in &SETS {
        let files = programs(set);
        assert!(!files.is_empty(), "{}: no programs", set.folder);
        let dir = golden.join(set.name);
        if bless {
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
        }
        for program in files {
            let name = program.file_name().unwrap().to_str().unwrap();
            let got = trace(program.parent().unwrap(), name, set.args);
            let path = dir.join(format!("{name}.trace"));
            count += 1;
            if bless {
                std::fs::write(&path, &got).unwrap();
                continue;
            }
            let want = std::fs::read_to_string(&path).unwrap_or_default();
            if want != got {
                let line = want
                    .lines()
                    .zip(got.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or(want.lines().count().min(got.lines().count()));
                differ.push(format!(
                    "{}/{name}: line {}: golden {:?}, now {:?}",
                    set.name,
                    line + 1,
                    want.lines().nth(line).unwrap_or("<end>"),
                    got.lines().nth(line).unwrap_or("<end>")
                ));
            }
        }
    }
    println!("{count} traces compared");
    assert!(
        differ.is_empty(),
        "{} of {count} traces differ from tests/golden (GOLDEN_BLESS=1 rewrites them):\n{}",
        differ.len(),
        differ.join("\n")
    );
}
