//! The mill dialect checked line by line against LinuxCNC 2.9's standalone interpreter
//! `rs274` (Debian `linuxcnc-uspace`, installed by `scripts/test.sh`; notes in
//! `../shared/notes/linuxcnc_oracle.md`). Every program in `tests/oracle/` is run through
//! both: `rs274 -g` and our interpreter with `trace::LinuxCnc` (what `cnc check --trace
//! --format linuxcnc` prints). The motion calls (STRAIGHT_TRAVERSE, STRAIGHT_FEED,
//! ARC_FEED, DWELL) must agree in order, kind and every number to 1e-4 mm, each feed move
//! with the same feed rate. A straight move to where the tool already is counts as none
//! (rs274 emits some inside canned cycles), and so does a dwell of 0 s.
//!
//! rs274 prints positions in the program frame and the work offset, G92 offset and tool
//! length offset beside them (SET_G5X_OFFSET, SET_G92_OFFSET, USE_TOOL_LENGTH_OFFSET); our
//! canonical stream is in machine coordinates. The comparison adds rs274's offsets back.
//!
//! Where FANUC and LinuxCNC differ by design the programs keep to the common subset, or a
//! line carries `(rs274: …)` with what LinuxCNC needs for the same path, and the FANUC
//! behaviour is asserted elsewhere (`nodes/interpreter/tests/mill_dialect.rs` unless named):
//! - LinuxCNC has no G09 (`fixtures_000.rs`, 024) and no G44;
//! - its G04 P and the cycles' P are seconds, FANUC's milliseconds (`fixtures_003.rs`);
//! - its G86 demands P; it forgets R (and Z) when the cycle changes, FANUC keeps hole data;
//! - after a G99 hole, a G98 hole moves over at the R level on FANUC, LinuxCNC climbs to
//!   the initial level on the way;
//! - G91 G10 L2 adds to the offset on FANUC and replaces it on LinuxCNC;
//! - LinuxCNC compensates the cutter radius only in G17 and G18, FANUC in G19 too;
//! - it rejects U/W words, G65 and FANUC T-word forms (notes §"What rs274 accepts and
//!   rejects"), and WHILE/IF/GOTO: it has O-word control flow instead, so a WHILE … DO m
//!   and its END m carry `(rs274: oN while […])` and `(rs274: oN endwhile)`.

use std::path::{Path, PathBuf};
use std::process::Command as Process;

const TOLERANCE: f64 = 1e-4;

/// One motion call, in machine coordinates: kind, numbers, feed in effect.
#[derive(Debug, Clone, PartialEq)]
struct Call {
    name: String,
    args: Vec<f64>,
    feed: f64,
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

/// The motion calls of a canon listing, with the offsets added to every position.
fn motion_calls(listing: &str) -> Vec<Call> {
    let mut g5x = [0.0; 6];
    let mut g92 = [0.0; 6];
    let mut tlo = [0.0; 6];
    // rs274's ARC_FEED plane: (first, second, normal) as indices of x..c.
    let mut plane = (0, 1, 2);
    let mut feed = 0.0;
    // Where the last move ended (NaN before the first).
    let mut here = [f64::NAN; 6];
    let mut out = Vec::new();
    for line in listing.lines() {
        let Some((name, args)) = split(line) else {
            continue;
        };
        let n = numbers(args);
        let offset = |k: usize| g5x[k] + g92[k] + tlo[k];
        match name {
            "SET_G5X_OFFSET" if n.len() == 7 => g5x.copy_from_slice(&n[1..7]),
            "SET_G92_OFFSET" if n.len() == 6 => g92.copy_from_slice(&n),
            "USE_TOOL_LENGTH_OFFSET" if n.len() >= 6 => tlo.copy_from_slice(&n[..6]),
            "SELECT_PLANE" => {
                plane = match args {
                    "CANON_PLANE_XZ" => (2, 0, 1),
                    "CANON_PLANE_YZ" => (1, 2, 0),
                    _ => (0, 1, 2),
                }
            }
            "SET_FEED_RATE" if n.len() == 1 => feed = n[0],
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" if n.len() == 6 => {
                let end: Vec<f64> = (0..6).map(|k| n[k] + offset(k)).collect();
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
                    })
                }
            }
            "ARC_FEED" if n.len() == 9 => {
                let (p, q, r) = plane;
                here[p] = n[0] + offset(p);
                here[q] = n[1] + offset(q);
                here[r] = n[5] + offset(r);
                for k in 3..6 {
                    here[k] = n[k + 3] + offset(k);
                }
                out.push(Call {
                    name: name.to_string(),
                    args: vec![
                        n[0] + offset(p),
                        n[1] + offset(q),
                        n[2] + offset(p),
                        n[3] + offset(q),
                        n[4],
                        n[5] + offset(r),
                        n[6] + offset(3),
                        n[7] + offset(4),
                        n[8] + offset(5),
                    ],
                    feed,
                })
            }
            // A dwell of no time is none (rs274's G86 demands P, FANUC's has none).
            "DWELL" if n.len() == 1 && n[0] > 0.0 => out.push(Call {
                name: name.to_string(),
                args: n,
                feed: 0.0,
            }),
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
/// those brackets. That is how a program names a FANUC/LinuxCNC difference by design (a
/// dwell P in ms for FANUC, in seconds for LinuxCNC) and still runs on both.
fn rs274_text(fanuc: &str) -> String {
    fanuc
        .lines()
        .map(|l| match l.split_once("(rs274:") {
            Some((_, alt)) => alt.trim_end().strip_suffix(')').unwrap_or(alt).trim(),
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// The metric tool table (`number length_mm diameter_mm`) as a LinuxCNC tool table, which
/// standalone rs274 reads in inches (notes §1.2).
fn rs274_tool_table(metric: &str) -> String {
    let mut out = String::new();
    for line in metric.lines() {
        let f: Vec<f64> = line
            .split('#')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        if let [n, length, diameter] = f[..] {
            out.push_str(&format!(
                "T{n} P{n} Z{:.9} D{:.9}\n",
                length / 25.4,
                diameter / 25.4
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
    let metric =
        std::fs::read_to_string(oracle_dir().join("tools.tbl")).map_err(|e| e.to_string())?;
    std::fs::write(&input, rs274_text(&fanuc)).map_err(|e| e.to_string())?;
    std::fs::write(&tools, rs274_tool_table(&metric)).map_err(|e| e.to_string())?;
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
    let run = Process::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(root)
        .args(["check", "--config", "launch_configs/sim_mill.yaml"])
        .arg("--tools")
        .arg(oracle_dir().join("tools.tbl"))
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
        let same = a.name == b.name
            && a.args.len() == b.args.len()
            && a.args
                .iter()
                .zip(&b.args)
                .all(|(x, y)| (x - y).abs() <= TOLERANCE)
            && (a.feed - b.feed).abs() <= TOLERANCE;
        if !same {
            return Some(format!("call {k}: rs274 {a:?}\n            ours  {b:?}"));
        }
    }
    (theirs.len() != ours.len()).then(|| {
        format!(
            "rs274 made {} motion calls, ours {}",
            theirs.len(),
            ours.len()
        )
    })
}

#[test]
fn every_oracle_program_agrees_with_rs274() {
    let mut programs: Vec<PathBuf> = std::fs::read_dir(oracle_dir())
        .expect("tests/oracle")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ngc"))
        .collect();
    programs.sort();
    assert!(programs.len() >= 40, "{} programs", programs.len());
    let mut failures = Vec::new();
    let mut calls = 0;
    for p in &programs {
        let result = rs274(p).and_then(|theirs| Ok((theirs, ours(p)?)));
        match result {
            Ok((theirs, ours)) => {
                let (t, o) = (motion_calls(&theirs), motion_calls(&ours));
                assert!(!t.is_empty(), "{}: no motion from rs274", p.display());
                calls += t.len();
                if let Some(diff) = compare(&t, &o) {
                    failures.push(format!("{}: {diff}", p.display()));
                }
            }
            Err(e) => failures.push(e),
        }
    }
    println!(
        "{} programs, {calls} motion calls compared, {} mismatches",
        programs.len(),
        failures.len()
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
