//! The golden mutants: seeded mutants of every fixture and oracle program, in each dialect,
//! interpreted through the library API; each mutant's whole outcome (every command as a trace
//! line, then the alarm with number, program, line and text) is hashed and compared with
//! `tests/golden/mutants.txt`. Mutants reach the error paths and odd states that the printed
//! programs never do, so a reshaped interpreter that behaves differently anywhere shows here.
//!
//! `GOLDEN_BLESS=1 cargo test --workspace --test golden_mutants` rewrites the file;
//! `GOLDEN_SHOW="mill 36_slot_with_length_change.ngc 6" cargo test … -- --nocapture` prints that
//! mutant and its trace, to see what a difference is.

use std::fmt::Write;
use std::path::Path;

use cnc_interpreter::interpreter::check_limited;
use cnc_interpreter::{trace, Dialect, Library, Setup};

#[path = "support/mutate.rs"]
mod mutate;
use mutate::Rng;

/// Commands a mutant may produce (an endless loop ends in an alarm).
const LIMIT: usize = 20_000;

const MILL_TOKENS: &[&str] = &[
    "G41 D1 ",
    "G42 D2 ",
    "G40 ",
    "G0 ",
    "G1 ",
    "G2 ",
    "G3 ",
    "G17 ",
    "G18 ",
    "G19 ",
    "G43 H1 ",
    "G49 ",
    "G52 X5 ",
    "G53 ",
    "G92 X0 ",
    "G28 Z0 ",
    "G30 Z0 ",
    "G29 X0 ",
    "G81 ",
    "G83 Q1 ",
    "G84 ",
    "G87 ",
    "G80 ",
    "G98 ",
    "G99 ",
    "G91 ",
    "G90 ",
    "G10 L2 P1 X1 ",
    "G65 P6006 A1 ",
    "G66 P6006 A1 ",
    "G67 ",
    "G63 ",
    "M29 S300 ",
    "M98 P6006 ",
    "M99 ",
    "M06 ",
    "WHILE [#1 LT 5] DO1",
    "END1",
    "GOTO 10",
    "IF [#1 GT 2] GOTO 5",
    "#1 = #1 + 1",
    "#5221 = 1",
    "#2001 = -5",
    "R0 ",
    "R-5 ",
    "I0 J0 ",
    "L0 ",
    "K5 ",
    "F0 ",
    "X1e9 ",
    "P-1 ",
    "Q0 ",
    "%",
    "O2002",
    "N10 ",
    "/",
    "(",
    ")",
    "G09 ",
    "G61 ",
    "G64 ",
];

const LATHE_TOKENS: &[&str] = &[
    "G71 ", "G72 ", "G73 ", "G70 ", "G74 ", "G75 ", "G76 ", "G92 ", "G90 ", "G94 ", "G32 ", "G33 ",
    "G34 ", "G22 ", "G80 ", "G24 ", "G77 ", "G83 ", "G87 ", "G25 ", "G26 ", "G27 ", "G50 ", "G52 ",
    "G54 ", "G96 ", "G97 ", "G99 ", "G99.1 ", "G02 ", "G03 ", "G05 ", "G07 ", "G09 ", "G41 ",
    "G42 ", "G40 ", "M98 ", "M99 ", "M97 ", "M30 ", "M03 ", "M05 ", "P", "Q", "R", "U", "W", "X",
    "Z", "I", "K", "L", "E", "F", "S", "T0101", "T0202", "#1=", "#200=[", "]", "[", "GOTO", "IF",
    "EQ", "/", ";", ",L1 ", ",R2 ", "C1 ", "D2 ", "G08 ", "G08.6 ", "M14.6 ", "M15 ", "C", "H",
    "G31 ", "K11.5 ", "L11.5 ", "G12.1 ", "G13.1 ", "G00 C0 ", "G14.4 ", "M29 ", "G84 ", "G88 ",
    "M65 S900", "M66 ", "M65 ", "G87 C90",
];

/// A set of seed programs and how they are read.
struct Set {
    name: &'static str,
    folder: &'static str,
    extension: &'static str,
    dialect: Dialect,
    mutants: usize,
    seed: u64,
}

const SETS: [Set; 4] = [
    Set {
        name: "huaxing",
        folder: "../../../shared/fixtures/000",
        extension: "nc",
        dialect: Dialect::HuaxingLathe,
        mutants: 15,
        seed: 0x9e37_79b9_7f4a_7c15,
    },
    Set {
        name: "iso",
        folder: "../../../shared/fixtures/000",
        extension: "nc",
        dialect: Dialect::IsoLathe,
        mutants: 5,
        seed: 0x2545_f491_4f6c_dd1d,
    },
    Set {
        name: "gtc2e",
        folder: "../../../shared/fixtures/002",
        extension: "nc",
        dialect: Dialect::Gtc2eLathe,
        mutants: 20,
        seed: 0x5851_f42d_4c95_7f2d,
    },
    Set {
        name: "mill",
        folder: "../../tests/oracle",
        extension: "ngc",
        dialect: Dialect::FanucMill,
        mutants: 15,
        seed: 0x5eed_cafe_f00d_0001,
    },
];

fn mill_setup() -> Setup {
    let mut setup = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    for (n, length, radius) in [(1, 120.0, 5.0), (2, 85.5, 3.0), (3, 150.25, 10.0)] {
        let t = setup.offsets.tools.entry(n).or_default();
        t.z = length;
        t.radius = radius;
    }
    setup
}

fn lathe_setup() -> Setup {
    let mut setup = Setup::lathe([100.0, 50.0]);
    for (n, radius, tip) in [(1, 0.4, 3), (2, 0.8, 2)] {
        let t = setup.offsets.tools.entry(n).or_default();
        t.radius = radius;
        t.tip = tip;
    }
    setup
}

/// The machine a dialect's programs run on: the Huaxing lathe as the turn-mill
/// (`sim_turnmill`), so its C axis is mutated too.
fn setup_for(dialect: Dialect) -> Setup {
    match dialect {
        Dialect::FanucMill => mill_setup(),
        // The Huaxing lathe as the turn-mill: C, the live tool (A, G14.4), the skip input.
        Dialect::HuaxingLathe => Setup {
            skip_input: Some((11, 5)),
            ..lathe_setup()
                .with_spindle_c_axis()
                .with_live_tool('A', 4, 2500.0)
        },
        _ => lathe_setup(),
    }
}

fn fnv1a(h: u64, bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(h, |h, b| (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3))
}

/// One mutant's outcome as a line: commands produced, the hash of everything, how it ended.
fn outcome(dialect: Dialect, text: &str) -> String {
    let setup = setup_for(dialect);
    let letters = setup.axes.clone();
    let mut h = 0xcbf2_9ce4_8422_2325;
    let result = check_limited(dialect, text, setup, Library::new(), LIMIT);
    let (count, end) = match &result {
        Ok(commands) => {
            for c in commands {
                h = fnv1a(h, trace::line(&letters, c).as_bytes());
                h = fnv1a(h, b"\n");
            }
            (commands.len(), "end".to_string())
        }
        Err(e) => {
            h = fnv1a(h, format!("{e:?}").as_bytes());
            (0, format!("alarm {} line {}", e.number, e.line))
        }
    };
    format!("{count} {h:016x} {end}")
}

fn corpus() -> String {
    let mut out = String::new();
    for set in &SETS {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(set.folder);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .filter_map(|e| Some(e.ok()?.path()))
            .filter(|p| p.extension().is_some_and(|x| x == set.extension))
            .collect();
        files.sort();
        let tokens = if set.dialect == Dialect::FanucMill {
            MILL_TOKENS
        } else {
            LATHE_TOKENS
        };
        let mut rng = Rng(set.seed | 1);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            let _ = writeln!(out, "{} {name} 0 {}", set.name, outcome(set.dialect, &text));
            for k in 1..=set.mutants {
                let m = mutate::mutate(&text, tokens, &mut rng);
                show(&format!("{} {name} {k}", set.name), set.dialect, &m);
                let _ = writeln!(out, "{} {name} {k} {}", set.name, outcome(set.dialect, &m));
            }
        }
    }
    out
}

/// Prints the mutant `id` names (see the module text) and what it gives.
fn show(id: &str, dialect: Dialect, text: &str) {
    if std::env::var("GOLDEN_SHOW").ok().as_deref() != Some(id) {
        return;
    }
    let setup = setup_for(dialect);
    let letters = setup.axes.clone();
    println!("--- {id}\n{text}---");
    match check_limited(dialect, text, setup, Library::new(), LIMIT) {
        Ok(c) => c
            .iter()
            .for_each(|c| println!("{}", trace::line(&letters, c))),
        Err(e) => println!("{e}"),
    }
}

#[test]
fn every_mutant_ends_as_the_golden_file_says() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mutants.txt");
    let got = corpus();
    if std::env::var_os("GOLDEN_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &got).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap_or_default();
    let differ: Vec<String> = want
        .lines()
        .zip(got.lines())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| format!("golden {a}\n   now {b}"))
        .collect();
    println!("{} mutants compared", got.lines().count());
    assert!(
        differ.is_empty() && want.lines().count() == got.lines().count(),
        "{} of {} mutants differ (GOLDEN_BLESS=1 rewrites tests/golden/mutants.txt):\n{}",
        differ.len(),
        got.lines().count(),
        differ
            .iter()
            .take(20)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}
