//! Property test over both lathe dialects (issue 3, item 3): every fixture program of the two
//! manuals, mutated many ways, is fed to both `huaxing-lathe` and `gtc2e-lathe`. Whatever the
//! input, the interpreter must return (no panic, no hang) and every rejection must be an alarm
//! with a number and a program line inside the program.
//!
//! The mutations are deterministic (xorshift from a fixed seed), so a failure reproduces; the
//! failing program is printed in full.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use cnc_interpreter::interpreter::check_limited;
use cnc_interpreter::{Dialect, Library, Setup};

/// Mutated variants per fixture and dialect; `CNC_FUZZ_VARIANTS` runs more (a longer search).
fn variants() -> usize {
    std::env::var("CNC_FUZZ_VARIANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100)
}
/// Commands after which a run counts as long enough (a looping program ends in an alarm).
const LIMIT: usize = 20_000;
/// A case that has not returned by then is a hang.
const WATCHDOG: Duration = Duration::from_secs(20);

/// Words and fragments that reach the parser's and cycles' corners.
const TOKENS: &[&str] = &[
    "G71", "G72", "G73", "G70", "G74", "G75", "G76", "G92", "G90", "G94", "G32", "G33", "G34",
    "G22", "G80", "G24", "G77", "G83", "G25", "G26", "G27", "G50", "G52", "G54", "G96", "G99",
    "G99.1", "G02", "G03", "G05", "G41", "G42", "M98", "M99", "M97", "M30", "P", "Q", "R", "U",
    "W", "X", "Z", "I", "K", "L", "E", "F", "S", "T0101", "#1=", "#100=[", "]", "[", "GOTO", "IF",
    "EQ", "/", "(", ")", ";", "N", "O", "%", "-", ".", "0", "9", "99999999", "1E9", "SQRT", "ATAN",
    "#[#1]", "/2", "*", "H", "A", "D", "J", "\n", " ", "G08", "G08.6", "M14.6", "M15", "C", "G31",
    "K11.5", "G12.1", "G13.1", "G14.4", "M29", "G84", "G88", "M65", "M66", "G87",
];

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn fixtures() -> Vec<(PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/fixtures");
    let mut out = Vec::new();
    for dir in ["000", "002"] {
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| Some(e.ok()?.path())).collect();
        paths.sort();
        for p in paths {
            if let Ok(text) = std::fs::read_to_string(&p) {
                out.push((p, text));
            }
        }
    }
    out
}

/// One mutation of `text`: a byte overwritten, a token inserted, a line deleted or
/// duplicated, a number's digit changed, or the text cut short.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        lines.push(String::new());
    }
    for _ in 0..1 + rng.below(3) {
        let i = rng.below(lines.len());
        match rng.below(6) {
            0 => {
                let mut b = lines[i].clone().into_bytes();
                if !b.is_empty() {
                    let at = rng.below(b.len());
                    b[at] = (rng.next() >> 24) as u8;
                }
                lines[i] = String::from_utf8_lossy(&b).into_owned();
            }
            1 => {
                let at = floor_char_boundary(&lines[i], rng.below(lines[i].len() + 1));
                let tok = TOKENS[rng.below(TOKENS.len())];
                lines[i].insert_str(at, tok);
            }
            2 if lines.len() > 1 => {
                lines.remove(i);
            }
            3 => {
                let copy = lines[i].clone();
                lines.insert(rng.below(lines.len() + 1), copy);
            }
            4 => {
                let digits: Vec<usize> = lines[i]
                    .char_indices()
                    .filter(|(_, c)| c.is_ascii_digit())
                    .map(|(at, _)| at)
                    .collect();
                if !digits.is_empty() {
                    let at = digits[rng.below(digits.len())];
                    let d = (b'0' + rng.below(10) as u8) as char;
                    lines[i].replace_range(at..at + 1, &d.to_string());
                }
            }
            _ => lines.truncate(i + 1),
        }
    }
    lines.join("\n") + "\n"
}

fn floor_char_boundary(s: &str, mut at: usize) -> usize {
    while at > 0 && !s.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// Runs one case on a worker thread: `Ok(true)` when the program was rejected with a proper
/// alarm, `Ok(false)` when it ran, `Err` for a panic, a hang or an alarm without a line.
fn run_case(dialect: Dialect, text: String) -> Result<bool, String> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            let lines = text.lines().count().max(1) as u32;
            let outcome = std::panic::catch_unwind(|| {
                // The Huaxing lathe as the turn-mill, its C axis and live tool fuzzed too (D138,
                // D142).
                let turn_mill = dialect == Dialect::HuaxingLathe;
                let lathe = Setup::lathe([100.0, 50.0]);
                let setup = Setup {
                    skip_input: turn_mill.then_some((11, 5)),
                    ..match turn_mill {
                        true => lathe.with_spindle_c_axis().with_live_tool('A', 4, 2500.0),
                        false => lathe,
                    }
                };
                check_limited(dialect, &text, setup, Library::new(), LIMIT)
            });
            let verdict = match outcome {
                Err(_) => Err("panicked".to_string()),
                Ok(Ok(_)) => Ok(false),
                Ok(Err(e)) if e.number == 0 || e.line == 0 || e.line > lines + 1 => {
                    Err(format!("alarm without number or line in the program: {e}"))
                }
                Ok(Err(_)) => Ok(true),
            };
            let _ = tx.send(verdict);
        })
        .map_err(|e| format!("thread: {e}"))?;
    match rx.recv_timeout(WATCHDOG) {
        Ok(v) => v,
        Err(_) => Err(format!("no answer within {} s (hang)", WATCHDOG.as_secs())),
    }
}

#[test]
fn mutated_fixtures_never_panic_or_hang_and_every_rejection_has_a_line() {
    let fixtures = fixtures();
    assert!(
        fixtures.len() >= 70,
        "fixtures not found: {} files",
        fixtures.len()
    );
    // The verdict carries a panic; the default hook would print one message per case.
    std::panic::set_hook(Box::new(|_| {}));
    let mut rng = Rng(std::env::var("CNC_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x2545_f491_4f6c_dd1d));
    let (mut cases, mut rejected) = (0, 0);
    let mut failures = Vec::new();
    for (path, text) in &fixtures {
        for dialect in [Dialect::HuaxingLathe, Dialect::Gtc2eLathe] {
            // The fixture as printed, then its mutations.
            for v in 0..=variants() {
                let program = match v {
                    0 => text.clone(),
                    _ => mutate(text, &mut rng),
                };
                cases += 1;
                match run_case(dialect, program.clone()) {
                    Ok(r) => rejected += r as usize,
                    Err(why) => failures.push(format!(
                        "{} ({}) variant {v}: {why}\n--- program ---\n{program}",
                        path.display(),
                        dialect.name()
                    )),
                }
            }
        }
    }
    let _ = std::panic::take_hook();
    assert!(
        failures.is_empty(),
        "{} of {cases} cases failed; first:\n{}",
        failures.len(),
        failures[0]
    );
    // Both outcomes occur, so the mutations reach the interpreter's checks and its runs.
    assert!(
        rejected > cases / 10 && rejected < cases * 9 / 10,
        "{rejected} of {cases} rejected"
    );
    eprintln!("{cases} cases, {rejected} rejected with an alarm and a line");
}

/// Random contours through tool-nose compensation and chamfers (the two features that hold
/// an element back): no panic, no hang, every rejection an alarm on a program line.
#[test]
fn random_compensated_and_chamfered_contours_never_panic() {
    std::panic::set_hook(Box::new(|_| {}));
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut failures = Vec::new();
    let (mut cases, mut ran) = (0, 0);
    for _ in 0..1500 {
        let mut p = String::from("T0101\nG00 X120 Z20\n");
        let side = if rng.below(2) == 0 { "G41" } else { "G42" };
        let mut x = 60.0 + rng.below(40) as f64;
        let mut z = 10.0;
        p.push_str(&format!("{side} G01 X{x} Z{z} F100\n"));
        for _ in 0..2 + rng.below(8) {
            x = (x + rng.below(41) as f64 - 20.0).clamp(2.0, 200.0);
            z -= rng.below(30) as f64;
            let extra = match rng.below(6) {
                0 => format!(" L{}", 1 + rng.below(5)),
                1 => format!(" D{}", 1 + rng.below(5)),
                _ => String::new(),
            };
            match rng.below(4) {
                0 => p.push_str(&format!("G02 X{x} Z{z} R{}\n", 5 + rng.below(60))),
                1 => p.push_str(&format!("G03 X{x} Z{z} R{}\n", 5 + rng.below(60))),
                _ => p.push_str(&format!("G01 X{x} Z{z}{extra}\n")),
            }
        }
        p.push_str("G40 G01 X150 Z30\nM30\n");
        let radius = 0.1 + rng.below(50) as f64 / 10.0;
        let tip = rng.below(10) as u8;
        let front = rng.below(2) == 0;
        cases += 1;
        let program = p.clone();
        let lines = program.lines().count() as u32;
        let outcome = std::panic::catch_unwind(|| {
            let mut setup = Setup::lathe([200.0, 50.0]);
            setup.front_tool_post = front;
            setup.offsets.tools.insert(
                1,
                cnc_interpreter::setup::ToolOffset {
                    radius,
                    tip,
                    ..Default::default()
                },
            );
            check_limited(
                Dialect::HuaxingLathe,
                &program,
                setup,
                Library::new(),
                LIMIT,
            )
        });
        match outcome {
            Err(_) => failures.push(format!("panicked (R{radius} tip {tip}):\n{p}")),
            Ok(Err(e)) if e.line == 0 || e.line > lines || e.number == 0 => {
                failures.push(format!("{e}:\n{p}"))
            }
            Ok(Ok(cmds)) => {
                ran += 1;
                // Every move of a finished run ends at a finite point.
                let finite = cmds
                    .iter()
                    .filter_map(|c| c.command.end())
                    .all(|end| end.iter().all(|v| v.is_finite()));
                if !finite {
                    failures.push(format!("non-finite point:\n{p}"));
                }
            }
            Ok(Err(_)) => {}
        }
    }
    let _ = std::panic::take_hook();
    assert!(
        failures.is_empty(),
        "{} of {cases} failed; first:\n{}",
        failures.len(),
        failures[0]
    );
    assert!(ran > cases / 10, "only {ran} of {cases} ran");
    eprintln!("{cases} contours, {ran} ran to the end");
}
