//! Issue 24, must-show 5: fuzz over the 802D's cycle calls. Seeded random calls of every
//! cycle of chapter 10, with parameters random, omitted (`,,` or a list cut short), negative,
//! zero, huge or out of range, and one too many now and then; drilling cycles also called
//! modally and under HOLES1/HOLES2. Each program sets the machine's travel as the working area
//! (G25/G26, WALIMON), so no move outside it is ever sent. Every call must end, or stop with a
//! numbered alarm on its line: no panic, no endless output (a command limit; a cycle's own
//! moves are bounded by its budget, 12140), nothing outside the travel.
//! `SINUMERIK_CYCLE_FUZZ_SEED` and `SINUMERIK_CYCLE_FUZZ_CALLS` widen the search by hand.

#[path = "support/mutate.rs"]
mod mutate;

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Library, Setup};
use cnc_interpreter_core::{next_command, ToolOffset};
use mutate::Rng;

/// Each cycle with its number of parameters.
const CYCLES: [(&str, usize); 22] = [
    ("CYCLE81", 5),
    ("CYCLE82", 6),
    ("CYCLE83", 12),
    ("CYCLE84", 12),
    ("CYCLE840", 12),
    ("CYCLE85", 8),
    ("CYCLE86", 11),
    ("CYCLE87", 6),
    ("CYCLE88", 7),
    ("CYCLE89", 6),
    ("HOLES1", 6),
    ("HOLES2", 6),
    ("CYCLE71", 16),
    ("CYCLE72", 17),
    ("CYCLE76", 20),
    ("CYCLE77", 16),
    ("LONGHOLE", 15),
    ("SLOT1", 22),
    ("SLOT2", 22),
    ("POCKET3", 23),
    ("POCKET4", 19),
    ("CYCLE90", 13),
];

/// The sim_mill_802d's travel (`launch_configs/sim_mill_802d.yaml`).
const TRAVEL: [(f64, f64); 3] = [(-500.0, 500.0), (-400.0, 400.0), (-400.0, 400.0)];

/// Commands one call may produce before the run is cut (a cycle makes at most 200,000).
const LIMIT: usize = 400_000;

fn value(rng: &mut Rng) -> String {
    match rng.below(10) {
        0 => String::new(),
        1 => "0".into(),
        2 => format!("{}", rng.below(5)),
        3 => format!("-{}", rng.below(200)),
        4 => format!("{}.{}", rng.below(100), rng.below(1000)),
        5 => format!("{}", 1 + rng.below(60)),
        6 => ["1EX9", "-1EX9", "0.000001", "99999.999", "1EX-9"][rng.below(5)].into(),
        7 => format!("{}", rng.below(20) as i64 - 10),
        _ => format!("{}", 2 + rng.below(30)),
    }
}

fn call(rng: &mut Rng) -> String {
    let (name, n) = CYCLES[rng.below(CYCLES.len())];
    // Sometimes cut short, sometimes one too many.
    let count = match rng.below(6) {
        0 => rng.below(n + 1),
        1 => n + 1,
        _ => n,
    };
    let mut params: Vec<String> = (0..count).map(|_| value(rng)).collect();
    if name == "CYCLE72" && !params.is_empty() {
        // The contour: the library's K1 mostly, else none or a random one.
        params[0] = ["\"K1\"", "\"K1\"", "\"NONE\"", "\"A:B\""][rng.below(4)].into();
        // Often plausible modes, so the contour itself is reached.
        if params.len() >= 17 && rng.below(2) == 0 {
            params[10] = ["11", "12", "111", "211", "311", "1"][rng.below(6)].into();
            params[11] = ["40", "41", "42"][rng.below(3)].into();
            params[12] = ["1", "2", "3"][rng.below(3)].into();
            params[15] = ["1", "2", "3"][rng.below(3)].into();
        }
    }
    let call = format!("{name}({})", params.join(", "));
    if name.starts_with("CYCLE8") && rng.below(3) == 0 {
        let (pattern, pn) = if rng.below(2) == 0 {
            ("HOLES1", 6)
        } else {
            ("HOLES2", 6)
        };
        let p: Vec<String> = (0..pn).map(|_| value(rng)).collect();
        return format!("MCALL {call}\n{pattern}({})\nMCALL", p.join(", "));
    }
    call
}

fn mill() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    s.offsets.tools.insert(
        11,
        ToolOffset {
            radius: 4.0,
            ..ToolOffset::default()
        },
    );
    s
}

#[test]
fn random_cycle_calls_end_or_stop_with_a_numbered_alarm_inside_the_travel() {
    let seed = std::env::var("SINUMERIK_CYCLE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(24u64);
    let calls = std::env::var("SINUMERIK_CYCLE_FUZZ_CALLS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1500usize);
    let mut rng = Rng(seed);
    let head = "G17 G90 T1 D1 S1000 M3 F200\nG25 X-500 Y-400 Z-400\nG26 X500 Y400 Z200\n\
        WALIMON\nG0 X0 Y0 Z50\n";
    let (mut alarms, mut ran) = (0, 0);
    let mut by_number = std::collections::BTreeMap::new();
    for _ in 0..calls {
        let text = format!("{head}{}\nM30\n", call(&mut rng));
        let result = std::panic::catch_unwind(|| {
            let mut lib = Library::new();
            lib.insert_named(
                "K1",
                "K1.SPF",
                "G1 X20 Y20\nX60 CHF=3\nY50 RND=5\nG3 X20 Y50 CR=20\nG1 Y20\nM17\n",
            );
            let mut front = Sinumerik::new(&text, mill(), lib);
            let mut moves = Vec::new();
            let mut n = 0;
            loop {
                match next_command(&mut front) {
                    Ok(Some(c)) => {
                        if let Some(end) = c.command.end() {
                            moves.push(end.to_vec());
                        }
                        n += 1;
                        if n > LIMIT {
                            return (moves, None, true);
                        }
                    }
                    Ok(None) => return (moves, None, false),
                    Err(e) => return (moves, Some(e), false),
                }
            }
        });
        let Ok((moves, error, cut)) = result else {
            panic!("panic on\n{text}");
        };
        assert!(!cut, "more than {LIMIT} commands from one call:\n{text}");
        for m in &moves {
            for (i, (lo, hi)) in TRAVEL.iter().enumerate() {
                assert!(
                    m[i] >= lo - 1e-6 && m[i] <= hi + 1e-6,
                    "a move to {m:?} outside the travel:\n{text}"
                );
            }
        }
        match error {
            Some(e) => {
                assert!(e.number >= 10_000, "{e}\n{text}");
                assert!(e.line >= 1 && e.line <= 9, "{e}\n{text}");
                assert!(!e.text.is_empty());
                *by_number.entry(e.number).or_insert(0) += 1;
                alarms += 1;
            }
            None => ran += 1,
        }
    }
    eprintln!(
        "{calls} cycle calls: {ran} ran, {alarms} stopped with a numbered alarm: {by_number:?}"
    );
    assert_eq!(ran + alarms, calls);
    assert!(ran > 0 && alarms > 0, "the search reaches both outcomes");
}
