//! Issue 23, must-show 5: bad input is normal input for the 802D front end. Every example
//! program of the manual (`../shared/fixtures/001`), mutated by a seeded generator (bytes
//! from a G-code alphabet and arbitrary bytes, 802D tokens, whole lines duplicated, dropped
//! or moved), goes through what `cnc check` runs: the program to its end or first alarm
//! (`check_limited`) and every line's own errors (`Dialect::line_errors`), which together
//! are `diagnose`. Whatever the input: no panic,
//! no hang, and every rejection an alarm with a number, a text, the program it belongs to
//! (the main program or a subprogram of the library) and a block inside that program.
//! Deterministic (fixed seed), so a failure names a program that can be rerun.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::Duration;

use cnc_interpreter::interpreter::check_limited;
use cnc_interpreter::{Dialect, Library, Setup};
use cnc_interpreter_core::{ProgramError, ToolOffset};

#[path = "support/mutate.rs"]
mod mutate;
use mutate::Rng;

/// Mutants made of each fixture (`SINUMERIK_FUZZ_MUTANTS` and `SINUMERIK_FUZZ_SEED` change
/// the run for a longer search by hand).
const MUTANTS: usize = 20;
/// Commands a mutant may produce before the check stops it (an endless loop is an alarm).
const COMMAND_LIMIT: usize = 20_000;
/// Time the whole run may take before it counts as hanging (it takes seconds).
const DEADLINE: Duration = Duration::from_secs(300);

/// Pieces of 802D programs that make mutants reach deep into the front end.
const TOKENS: &[&str] = &[
    "R1=",
    "R[R0]=",
    "R299=1EX9 ",
    "DEF REAL A=",
    "DEF INT N[3,2]=SET(1,2) ",
    "DEF STRING[4] S=\"abcdef\" ",
    "N[5,0]=",
    "GOTOF ",
    "GOTOB ",
    "IF R1>2 GOTOB MARK ",
    "MARK: ",
    "L10 P3 ",
    "L785 ",
    "LRAHMEN7 ",
    "RET ",
    "M17 ",
    "M30 ",
    "TRANS X10 ",
    "ATRANS Y-5 ",
    "AROT RPL=30 ",
    "ROT X30 ",
    "SCALE X0 ",
    "ASCALE X2 Y3 ",
    "MIRROR X0 ",
    "AMIRROR Y0 ",
    "CR=-5 ",
    "AR=90 ",
    "AP=45 RP=10 ",
    "G110 X0 ",
    "G111 X0 Y0 ",
    "CIP I1=1 J1=2 ",
    "CT ",
    "TURN=2 ",
    "G2 I0 J0 ",
    "G3 ",
    "G41 ",
    "G42 ",
    "G40 ",
    "T1 D1 ",
    "D9 ",
    "M6 ",
    "$A_DBB[511]=",
    "$A_DBR[600]=",
    "$AA_IW[X]",
    "$P_TOOLNO",
    "$AC_TOTAL_PARTS=",
    "MSG(\"a\"<<R1<<\"b\")",
    "SIN(",
    "ATAN2(0,0)",
    "SQRT(-1)",
    "1/0",
    "POT(1EX300)",
    "=AC(",
    "=IC(",
    "(",
    ")",
    "[",
    "]",
    ":",
    "/",
    ";",
    "N10 ",
    "G54 ",
    "G507 ",
    "G500 ",
    "G53 ",
    "G70 ",
    "G71 ",
    "G91 ",
    "G4 F2 ",
    "G4 S-1 ",
    "F0 ",
    "S99999 ",
    "STOPRE ",
    "MCALL ",
    "CHF=2 ",
    "RND=3 ",
    "G25 X10 ",
    "WALIMON ",
    "SPOS=90 ",
    "G33 Z-10 K2 ",
    "CYCLE81(10,0,2,-5) ",
];

/// The 802D mill of the tests: X Y Z, T1 with D1 and D2, T2 with D1.
fn setup() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    for (key, length, radius) in [(11, 50.0, 10.0), (12, 48.0, 4.0), (21, 80.0, 3.0)] {
        s.offsets.tools.insert(
            key,
            ToolOffset {
                z: length,
                radius,
                ..ToolOffset::default()
            },
        );
    }
    s
}

/// The subprograms the fixtures call (012, 014: L10; 074: L785 and LRAHMEN7), each a small
/// program of its own whose lines a mutant's alarm may name.
const SUBPROGRAMS: &[(&str, &str)] = &[
    ("L10", "G1 F100 X0 Y0\nX10\nY10\nR1=R1+1\nX0\nY0\nM17\n"),
    (
        "L785",
        "G91 G0 X1\nG90\nIF R2>3 GOTOF END\nR2=R2+1\nEND:\nM17\n",
    ),
    ("LRAHMEN7", "G0 Y5\nTRANS X1\nRET\n"),
];

fn library() -> Library {
    let mut lib = Library::new();
    for (name, text) in SUBPROGRAMS {
        lib.insert_named(name, &format!("{name}.SPF"), text);
    }
    lib
}

/// Whether `e` names a program and a block inside it.
fn placed(e: &ProgramError, main_lines: u32) -> Result<(), String> {
    if e.number == 0 || e.text.is_empty() {
        return Err(format!("bare alarm {e:?}"));
    }
    let lines = if e.program.is_empty() {
        main_lines
    } else {
        match SUBPROGRAMS
            .iter()
            .find(|(name, _)| e.program.eq_ignore_ascii_case(&format!("{name}.SPF")))
        {
            Some((_, text)) => text.lines().count() as u32 + 1,
            None => return Err(format!("alarm in an unknown program: {e:?}")),
        }
    };
    if e.line == 0 || e.line > lines {
        return Err(format!("alarm outside its program's blocks: {e:?}"));
    }
    Ok(())
}

/// How one mutant ended: `Ok(true)` in an alarm, `Ok(false)` at its program end, `Err` with
/// what went wrong.
fn examine(text: &str) -> Result<bool, String> {
    let main_lines = text.lines().count() as u32 + 1;
    let run = catch_unwind(AssertUnwindSafe(|| {
        let ran = check_limited(
            Dialect::Sinumerik802d,
            text,
            setup(),
            library(),
            COMMAND_LIMIT,
        );
        // `diagnose` (check's list): each line's own errors and the run's, here with the
        // run's limit of commands (diagnose's own is 5 million: an endless loop of a mutant
        // would take minutes in a debug build).
        let mut all = Dialect::Sinumerik802d.line_errors(text);
        all.extend(ran.clone().err());
        (ran, all)
    }));
    let Ok((ran, all)) = run else {
        return Err("panicked".into());
    };
    for e in &all {
        placed(e, main_lines).map_err(|p| format!("check's list: {p}"))?;
    }
    match ran {
        // A program without M2/M30 ends at its last block, as the control runs it.
        Ok(_) => Ok(false),
        Err(e) => {
            placed(&e, main_lines)?;
            Ok(true)
        }
    }
}

/// One mutant in five also gets arbitrary bytes (any UTF-8 character, control characters)
/// over the G-code alphabet's mutations.
fn with_foreign_bytes(text: String, rng: &mut Rng) -> String {
    if rng.below(5) != 0 {
        return text;
    }
    let mut chars: Vec<char> = text.chars().collect();
    for _ in 0..rng.below(3) {
        let at = rng.below(chars.len() + 1);
        let c = char::from_u32((rng.next() % 0x3000) as u32).unwrap_or('\u{fffd}');
        chars.insert(at, c);
    }
    chars.into_iter().collect()
}

fn fixtures() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/fixtures/001");
    let mut seeds: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("fixtures 001")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mpf"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("fixture text");
            let body = match text.split_once("; ---- program text as printed below ----\n") {
                Some((_, body)) => body.to_string(),
                None => text,
            };
            (p.display().to_string(), body)
        })
        .collect();
    seeds.sort();
    // Most printed examples are templates (`...`) or fragments without a feed or tool: as
    // printed, a mutant stops at the first placeholder. Each also seeds a runnable form (a
    // feed, a plane and the tool in front, the placeholder lines left out), so mutations
    // reach the blocks after them.
    let runnable: Vec<(String, String)> = seeds
        .iter()
        .map(|(name, body)| {
            let kept: Vec<&str> = body.lines().filter(|l| !l.contains("...")).collect();
            (
                format!("{name} (runnable)"),
                format!("G17 G90 F200 T1 D1\n{}\n", kept.join("\n")),
            )
        })
        .collect();
    seeds.extend(runnable);
    seeds
}

#[test]
fn mutated_802d_fixtures_end_in_commands_or_an_alarm_with_program_and_block() {
    let seeds = fixtures();
    assert_eq!(
        seeds.len(),
        2 * 117,
        "the manual's 117 example programs, two forms each"
    );
    let (runs, alarms) = mutate::Search {
        seeds,
        tokens: TOKENS,
        mutants: MUTANTS,
        seed: 0x802d_5eed_0001,
        env: "SINUMERIK_FUZZ",
        extra: Some(with_foreign_bytes),
        examine,
        deadline: DEADLINE,
        stack_bytes: 16 << 20,
    }
    .run();
    println!("{runs} mutants, {alarms} ended in an alarm, none panicked or hung");
    // The mutations must reach the alarms, and leave programs runnable.
    assert!(alarms > runs / 10 && alarms < runs, "{alarms} of {runs}");
}
