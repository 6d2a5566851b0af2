//! The mill dialect checked line by line against LinuxCNC 2.9's standalone interpreter
//! `rs274` (Debian `linuxcnc-uspace`, installed by `scripts/setup.sh`; notes in
//! `../shared/notes/linuxcnc_oracle.md`). Every program in `tests/oracle/` is run through
//! both: `rs274 -g` and our interpreter with `trace::LinuxCnc` (what `cnc check --trace
//! --format linuxcnc` prints). What the machine would do must agree in order, kind and every
//! number (to 1e-4 mm): the moves (STRAIGHT_TRAVERSE, STRAIGHT_FEED with its feed rate,
//! ARC_FEED), dwells, spindle speed and direction, coolant, tool selection and change,
//! program stops and the program end. A straight move to where the tool already is counts as
//! none (rs274 emits some inside canned cycles), and so does a dwell of 0 s.
//!
//! rs274 prints positions in the program frame and units (inches after G20) and the work
//! offset, G92 offset and tool length offset beside them (SET_G5X_OFFSET, SET_G92_OFFSET,
//! USE_TOOL_LENGTH_OFFSET); our canonical stream is in machine millimetres. The comparison
//! adds rs274's offsets back and converts its inches. Where the two differ by design of the
//! calls, not of what the machine does, they are made alike: rs274's M6 prints START_CHANGE
//! and a spindle stop before CHANGE_TOOL (the tool change stops the spindle; on the FANUC
//! machine the PLC does), its M9 turns mist and flood off (one coolant off), and its M2/M30
//! resets spindle and coolant before the end (the reset between its last SET_G5X_OFFSET and
//! PROGRAM_END is left out).
//!
//! A program may name its tool table in a comment `(tools: FILE)` (default `tools.tbl`,
//! millimetres; `units inch` tables are read in inches); rs274 always gets it in inches.
//!
//! Where FANUC and LinuxCNC differ by design the programs keep to the common subset, or a
//! line carries `(rs274: …)` with what LinuxCNC needs for the same path (`|` separates
//! lines), and the FANUC behaviour of the original line is asserted elsewhere
//! (`nodes/interpreter/tests/mill_dialect.rs` unless named):
//! - LinuxCNC has no G09 (`fixtures_000.rs`, 024) and no G44;
//! - its G04 P and the cycles' P are seconds, FANUC's milliseconds (`fixtures_003.rs`);
//! - its G86 demands P; it forgets R (and Z) when the cycle changes, FANUC keeps hole data;
//! - after a G99 hole, a G98 hole moves over at the R level on FANUC, LinuxCNC climbs to
//!   the initial level on the way;
//! - G91 G10 L2 adds to the offset on FANUC and replaces it on LinuxCNC;
//! - LinuxCNC compensates the cutter radius only in G17 and G18, FANUC in G19 too
//!   (`dialect_defects.rs`);
//! - an M05 or M09 in a block with motion acts after the motion on FANUC (D6, D56), before
//!   it in LinuxCNC: such a line gives rs274 the motion, then the M code (`… | M5`);
//! - it rejects U/W words, G65 and FANUC T-word forms (notes §"What rs274 accepts and
//!   rejects"), and WHILE/IF/GOTO: it has O-word control flow instead, so a WHILE … DO m
//!   and its END m carry `(rs274: oN while […])` and `(rs274: oN endwhile)`, and a G65 call
//!   `(rs274: oN call [a] [b])` with the macro written as an O-word subroutine for it
//!   (`dialect_defects.rs` asserts G65 on its own);
//! - numbers without a decimal point are least input increments on the 0-M (D52) and
//!   millimetres in LinuxCNC: the programs write their lengths with a decimal point, as
//!   shops do.

use std::path::{Path, PathBuf};
use std::process::Command as Process;

const TOLERANCE: f64 = 1e-4;

/// The calls that move the tool; the others are auxiliary (dwells included).
const MOVES: [&str; 3] = ["STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED"];

/// One call, in machine coordinates and millimetres: kind, numbers, feed in effect, and how
/// closely its numbers are known (rs274 prints 4 decimals of its program unit: 0.0001 inch is
/// 2.54 µm).
#[derive(Debug, Clone, PartialEq)]
struct Call {
    name: String,
    args: Vec<f64>,
    feed: f64,
    tolerance: f64,
}

/// Splits `   12 N..... NAME(a, b, c)` into the name and its argument text.
fn split(line: &str) -> Option<(&str, &str)> {
    let rest = line.trim_start();
    let rest = rest.split_once(' ')?.1.trim_start();
    let rest = rest.split_once(' ')?.1.trim_start();
    let (name, args) = rest.split_once('(')?;
    Some((name, args.strip_suffix(')')?))
}

fn numbers(args: &str) -> Vec<f64> {
    args.split([',', ' '])
        .filter(|s| !s.is_empty())
        .filter_map(|s| s.parse().ok())
        .collect()
}

/// What the machine would do, from a canon listing: the moves with the offsets added and in
/// millimetres, dwells, and the auxiliary calls, made alike where only the call names
/// differ (see the module text).
fn calls(listing: &str) -> Vec<Call> {
    let mut g5x = [0.0; 6];
    let mut g92 = [0.0; 6];
    let mut tlo = [0.0; 6];
    // Millimetres per program unit (25.4 after USE_LENGTH_UNITS(CANON_UNITS_INCHES)).
    let mut unit = 1.0;
    // rs274's ARC_FEED plane: (first, second, normal) as indices of x..c.
    let mut plane = (0, 1, 2);
    let mut feed = 0.0;
    // Where the last move ended (NaN before the first).
    let mut here = [f64::NAN; 6];
    let mut out: Vec<Call> = Vec::new();
    // Where the last rigid tap started (its return is no call), and the pitch of the last
    // speed-feed synchronisation, mm per revolution.
    let mut tap_from: Option<Vec<f64>> = None;
    let mut pitch = 0.0;
    let lines: Vec<(&str, &str)> = listing.lines().filter_map(split).collect();
    // rs274's M2/M30 reset: from its last SET_G5X_OFFSET before PROGRAM_END.
    let end = lines.iter().position(|(n, _)| *n == "PROGRAM_END");
    let reset = end.and_then(|e| lines[..e].iter().rposition(|(n, _)| *n == "SET_G5X_OFFSET"));
    let aux = |name: &str, args: Vec<f64>| Call {
        name: name.to_string(),
        args,
        feed: 0.0,
        tolerance: TOLERANCE,
    };
    for (k, &(name, args)) in lines.iter().enumerate() {
        let n = numbers(args);
        let in_reset = reset.is_some_and(|r| k > r) && end.is_some_and(|e| k < e);
        // Lengths in mm: positions (x, y, z) convert, angles (a, b, c) do not.
        let mm = |v: f64, k: usize| if k < 3 { v * unit } else { v };
        // Half the last printed digit, in mm, plus our own rounding.
        let tolerance = if unit > 1.0 {
            TOLERANCE + 0.00005 * unit
        } else {
            TOLERANCE
        };
        let offset = |k: usize| g5x[k] + g92[k] + tlo[k];
        match name {
            "USE_LENGTH_UNITS" => {
                unit = if args.contains("INCHES") { 25.4 } else { 1.0 };
            }
            "SET_G5X_OFFSET" if n.len() == 7 => {
                for k in 0..6 {
                    g5x[k] = mm(n[k + 1], k);
                }
            }
            "SET_G92_OFFSET" if n.len() == 6 => {
                for k in 0..6 {
                    g92[k] = mm(n[k], k);
                }
            }
            "USE_TOOL_LENGTH_OFFSET" if n.len() >= 6 => {
                for k in 0..6 {
                    tlo[k] = mm(n[k], k);
                }
            }
            "SELECT_PLANE" => {
                plane = match args {
                    "CANON_PLANE_XZ" => (2, 0, 1),
                    "CANON_PLANE_YZ" => (1, 2, 0),
                    _ => (0, 1, 2),
                }
            }
            "SET_FEED_RATE" if n.len() == 1 => feed = n[0] * unit,
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" if n.len() == 6 => {
                let end: Vec<f64> = (0..6).map(|k| mm(n[k], k) + offset(k)).collect();
                // A move to where the tool already is moves nothing (rs274 emits some
                // inside canned cycles).
                let still = end
                    .iter()
                    .zip(&here)
                    .all(|(a, b)| (a - b).abs() <= TOLERANCE);
                here.copy_from_slice(&end);
                if !still {
                    out.push(Call {
                        name: name.to_string(),
                        args: end,
                        feed: if name == "STRAIGHT_FEED" { feed } else { 0.0 },
                        tolerance,
                    })
                }
            }
            "ARC_FEED" if n.len() == 9 => {
                let (p, q, r) = plane;
                here[p] = n[0] * unit + offset(p);
                here[q] = n[1] * unit + offset(q);
                here[r] = n[5] * unit + offset(r);
                for k in 3..6 {
                    here[k] = n[k + 3] + offset(k);
                }
                out.push(Call {
                    name: name.to_string(),
                    args: vec![
                        n[0] * unit + offset(p),
                        n[1] * unit + offset(q),
                        n[2] * unit + offset(p),
                        n[3] * unit + offset(q),
                        n[4],
                        n[5] * unit + offset(r),
                        n[6] + offset(3),
                        n[7] + offset(4),
                        n[8] + offset(5),
                    ],
                    feed,
                    tolerance,
                })
            }
            // A rigid tap (G33.1 in rs274, our `Tap`): its end. rs274's tap retracts to where
            // it started on its own; ours is a second tap back to that point, which is no call
            // here. The tool ends where it started in both.
            "START_SPEED_FEED_SYNC" if n.len() == 2 => pitch = n[0] * unit,
            "RIGID_TAP" if n.len() == 3 => {
                let end: Vec<f64> = (0..3).map(|k| mm(n[k], k) + offset(k)).collect();
                let back = tap_from.as_ref().is_some_and(|s: &Vec<f64>| {
                    s.iter().zip(&end).all(|(a, b)| (a - b).abs() <= TOLERANCE)
                });
                if back {
                    tap_from = None;
                } else {
                    tap_from = Some(here[..3].to_vec());
                    // The pitch stands in the feed's place.
                    out.push(Call {
                        name: name.to_string(),
                        args: end,
                        feed: pitch,
                        tolerance,
                    });
                }
            }
            // A dwell of no time is none (rs274's G86 demands P, FANUC's has none).
            "DWELL" if n.len() == 1 && n[0] > 0.0 => out.push(aux(name, n)),
            _ if in_reset => {}
            "SET_SPINDLE_SPEED" if n.len() == 2 => out.push(aux("SPEED", vec![n[1]])),
            "START_SPINDLE_CLOCKWISE" | "START_SPINDLE_COUNTERCLOCKWISE" => {
                out.push(aux(name, Vec::new()))
            }
            // The spindle stop rs274 prints inside a tool change (before CHANGE_TOOL).
            "STOP_SPINDLE_TURNING"
                if lines.get(k + 1).is_some_and(|(m, _)| *m == "CHANGE_TOOL") => {}
            "STOP_SPINDLE_TURNING" => out.push(aux(name, Vec::new())),
            "FLOOD_ON" | "MIST_ON" => out.push(aux("COOLANT_ON", Vec::new())),
            // M9 turns mist and flood off: one coolant off.
            "FLOOD_OFF" | "MIST_OFF" if out.last().is_none_or(|c| c.name != "COOLANT_OFF") => {
                out.push(aux("COOLANT_OFF", Vec::new()))
            }
            "SELECT_TOOL" => out.push(aux(name, n)),
            // rs274 numbers the change by the table's entry, we by the tool: SELECT_TOOL
            // names it.
            "CHANGE_TOOL" => out.push(aux(name, Vec::new())),
            "PROGRAM_STOP" | "OPTIONAL_PROGRAM_STOP" | "PROGRAM_END" => {
                out.push(aux(name, Vec::new()))
            }
            _ => {}
        }
    }
    out
}

fn oracle_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracle")
}

/// A scratch file for this test run.
fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("cnc_oracle_{}_{name}", std::process::id()))
}

/// The program as rs274 gets it: a line that ends in `(rs274: …)` is replaced by the text in
/// those brackets, `|` separating lines. That is how a program names a FANUC/LinuxCNC
/// difference by design (a dwell P in ms for FANUC, in seconds for LinuxCNC) and still runs
/// on both.
fn rs274_text(fanuc: &str) -> String {
    fanuc
        .lines()
        .map(|l| match l.split_once("(rs274:") {
            Some((_, alt)) => {
                let alt = alt.trim_end().strip_suffix(')').unwrap_or(alt);
                alt.split('|').map(str::trim).collect::<Vec<_>>().join("\n")
            }
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// The tool table a program names in a comment `(tools: FILE)`, else `tools.tbl`.
fn tool_table_of(program: &str) -> PathBuf {
    let name = program
        .lines()
        .find_map(|l| {
            let rest = l.split_once("(tools:")?.1;
            Some(rest.split_once(')')?.0.trim().to_string())
        })
        .unwrap_or_else(|| "tools.tbl".into());
    oracle_dir().join(name)
}

/// Our tool table (`number length diameter`, mm or after `units inch` inches) as a LinuxCNC
/// tool table, which standalone rs274 reads in inches (notes §1.2).
fn rs274_tool_table(ours: &str) -> String {
    let mut out = String::new();
    let mut inches_per_unit = 1.0 / 25.4;
    for line in ours.lines() {
        let body = line.split('#').next().unwrap_or("");
        match body.split_whitespace().collect::<Vec<_>>()[..] {
            ["units", "inch"] => inches_per_unit = 1.0,
            ["units", "mm"] => inches_per_unit = 1.0 / 25.4,
            _ => {}
        }
        let f: Vec<f64> = body
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        if let [n, length, diameter] = f[..] {
            out.push_str(&format!(
                "T{n} P{n} Z{:.9} D{:.9}\n",
                length * inches_per_unit,
                diameter * inches_per_unit
            ));
        }
    }
    out
}

fn rs274(program: &Path) -> Result<String, String> {
    let stem = program.file_stem().and_then(|s| s.to_str()).unwrap_or("p");
    let fanuc = std::fs::read_to_string(program).map_err(|e| e.to_string())?;
    let input = scratch(&format!("{stem}.ngc"));
    let tools = scratch(&format!("{stem}.tbl"));
    let out = scratch(&format!("{stem}.canon"));
    let table = std::fs::read_to_string(tool_table_of(&fanuc)).map_err(|e| e.to_string())?;
    std::fs::write(&input, rs274_text(&fanuc)).map_err(|e| e.to_string())?;
    std::fs::write(&tools, rs274_tool_table(&table)).map_err(|e| e.to_string())?;
    let run = Process::new("rs274")
        .arg("-g")
        .arg("-t")
        .arg(&tools)
        .arg(&input)
        .arg(&out)
        .output()
        .map_err(|e| format!("rs274: {e} (Debian linuxcnc-uspace; scripts/test.sh installs it)"))?;
    let text = std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()));
    for f in [&input, &tools, &out] {
        let _ = std::fs::remove_file(f);
    }
    let text = text?;
    if !run.status.success() {
        return Err(format!(
            "rs274 rejected {}: {}",
            program.display(),
            String::from_utf8_lossy(&run.stderr)
        ));
    }
    Ok(text)
}

/// `cnc check --trace --format linuxcnc` on the simulated mill with the oracle's tool table
/// (X, Y, Z from the machine zero, as rs274 starts).
fn ours(program: &Path) -> Result<String, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(program).map_err(|e| e.to_string())?;
    let run = Process::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(root)
        .args(["check", "--config", "launch_configs/sim_mill.yaml"])
        .arg("--tools")
        .arg(tool_table_of(&text))
        .args(["--trace", "--format", "linuxcnc"])
        .arg(program)
        .output()
        .map_err(|e| format!("cnc check: {e}"))?;
    if !run.status.success() {
        return Err(format!(
            "cnc check refused {}: {}",
            program.display(),
            String::from_utf8_lossy(&run.stderr)
        ));
    }
    String::from_utf8(run.stdout).map_err(|e| e.to_string())
}

/// The first difference of two call lists, if any.
fn compare(theirs: &[Call], ours: &[Call]) -> Option<String> {
    for (k, (a, b)) in theirs.iter().zip(ours).enumerate() {
        let tolerance = a.tolerance.max(b.tolerance);
        let same = a.name == b.name
            && a.args.len() == b.args.len()
            && a.args
                .iter()
                .zip(&b.args)
                .all(|(x, y)| (x - y).abs() <= tolerance)
            && (a.feed - b.feed).abs() <= tolerance;
        if !same {
            return Some(format!("call {k}: rs274 {a:?}\n            ours  {b:?}"));
        }
    }
    (theirs.len() != ours.len())
        .then(|| format!("rs274 made {} calls, ours {}", theirs.len(), ours.len()))
}

#[test]
fn every_oracle_program_agrees_with_rs274() {
    let mut programs: Vec<PathBuf> = std::fs::read_dir(oracle_dir())
        .expect("tests/oracle")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ngc"))
        .collect();
    programs.sort();
    assert!(programs.len() >= 70, "{} programs", programs.len());
    let mut failures = Vec::new();
    let (mut count, mut aux) = (0, 0);
    for p in &programs {
        let result = rs274(p).and_then(|theirs| Ok((theirs, ours(p)?)));
        match result {
            Ok((theirs, ours)) => {
                let (t, o) = (calls(&theirs), calls(&ours));
                assert!(!t.is_empty(), "{}: no motion from rs274", p.display());
                count += t.len();
                aux += t
                    .iter()
                    .filter(|c| !MOVES.contains(&c.name.as_str()))
                    .count();
                if let Some(diff) = compare(&t, &o) {
                    failures.push(format!("{}: {diff}", p.display()));
                }
            }
            Err(e) => failures.push(e),
        }
    }
    println!(
        "{} programs, {count} calls compared ({aux} auxiliary), {} mismatches",
        programs.len(),
        failures.len()
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
