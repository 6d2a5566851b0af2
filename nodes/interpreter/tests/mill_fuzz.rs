//! Bad input is normal input: the mill programs of the oracle suite (`tests/oracle/`),
//! mutated byte- and token-wise by a seeded generator, must each end in commands or in an
//! alarm with a number, a line inside the program and a text, never in a panic or a hang.
//! The run is deterministic (fixed seed), so a failure names a program that can be rerun.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Duration;

use cnc_interpreter::interpreter::check_limited;
use cnc_interpreter::{Command, Dialect, Library, Setup};

#[path = "support/mutate.rs"]
mod mutate;

/// Mutants made of each seed program (`MILL_FUZZ_MUTANTS` and `MILL_FUZZ_SEED` change the
/// run for a longer search by hand).
const MUTANTS: usize = 60;
/// Commands a mutant may produce before the check stops it (an endless loop is an alarm).
const COMMAND_LIMIT: usize = 20_000;
/// Time the whole run may take before it counts as hanging (it takes seconds).
const DEADLINE: Duration = Duration::from_secs(240);

/// Pieces of FANUC mill programs that make mutants reach deep into the interpreter.
const TOKENS: &[&str] = &[
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
    "G64 ",
    "M29 S300 ",
    "M29 ",
    "S500 ",
    "M98 P6006 ",
    "M99 ",
    "WHILE [#1 LT 5] DO1",
    "END1",
    "DO2",
    "END2",
    "GOTO 10",
    "IF [#1 GT 2] GOTO 5",
    "#3000 = 3",
    "#1 = #1 + 1",
    "#[#2] = 4",
    "#5221 = 1",
    "#2001 = -5",
    "[",
    "]",
    "R0 ",
    "R-5 ",
    "I0 J0 ",
    "L0 ",
    "L999 ",
    "K5 ",
    "F0 ",
    "X1e9 ",
    "Z-99999 ",
    "P-1 ",
    "Q0 ",
    "%",
    "O2002",
    "N10 ",
    "/",
    "(",
    ")",
    "ATAN[1]/[0]",
    "SQRT[-1]",
    "1/0",
    "ROUND[#1]",
];

fn setup() -> Setup {
    let mut setup = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    for (n, length, radius) in [(1, 120.0, 5.0), (2, 85.5, 3.0), (3, 150.25, 10.0)] {
        let t = setup.offsets.tools.entry(n).or_default();
        t.z = length;
        t.radius = radius;
    }
    setup
}

/// How one mutant ended: `Ok(true)` in an alarm, `Ok(false)` at its program end, `Err` with
/// what went wrong.
fn examine(text: &str) -> Result<bool, String> {
    let run = catch_unwind(AssertUnwindSafe(|| {
        check_limited(
            Dialect::FanucMill,
            text,
            setup(),
            Library::new(),
            COMMAND_LIMIT,
        )
    }));
    let lines = text.lines().count() as u32 + 1;
    match run {
        Err(_) => Err("panicked".into()),
        Ok(Ok(commands)) => match commands.last().map(|c| &c.command) {
            Some(Command::ProgramEnd) => Ok(false),
            other => Err(format!("ended without ProgramEnd: {other:?}")),
        },
        Ok(Err(e)) if e.number == 0 || e.text.is_empty() => Err(format!("bare alarm {e:?}")),
        // Lines count within the program that raised it; a subprogram of the tape is shorter.
        Ok(Err(e)) if e.line > lines => Err(format!("alarm beyond the last line: {e}")),
        Ok(Err(_)) => Ok(true),
    }
}

#[test]
fn mutated_mill_programs_end_in_commands_or_an_alarm() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/oracle");
    let mut seeds: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("tests/oracle")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "ngc"))
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("oracle program");
            (p.display().to_string(), text)
        })
        .collect();
    seeds.sort();
    assert!(seeds.len() >= 40, "{} seed programs", seeds.len());
    let (runs, alarms) = mutate::Search {
        seeds,
        tokens: TOKENS,
        mutants: MUTANTS,
        seed: 0x5eed_cafe_f00d_0001,
        env: "MILL_FUZZ",
        extra: None,
        examine,
        deadline: DEADLINE,
        stack_bytes: 2 << 20,
    }
    .run();
    println!("{runs} mutants, {alarms} ended in an alarm, none panicked or hung");
    // The mutations must reach the alarms, and leave many programs runnable.
    assert!(alarms > runs / 10 && alarms < runs, "{alarms} of {runs}");
}
