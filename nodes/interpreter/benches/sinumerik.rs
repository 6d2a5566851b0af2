//! The 802D front end's speed (issue 23, must-show 6), printed in one run of this binary:
//! 1. A generated 200,000-block 802D program (R-parameter arithmetic, frames TRANS/AROT/
//!    ATRANS, arcs by centre and by `CR=`, a subprogram called by name with `P` repetitions)
//!    against a FANUC 0-M mill program of the same work (macro arithmetic, G52 local shifts,
//!    arcs by R and I/J, M98 calls with L repetitions): blocks/s of each, best of five, and
//!    their ratio; peak heap of the 802D run for 20,000 and 200,000 blocks (working memory
//!    must not grow with the program).
//! 2. PyPI's `nc-gcode-interpreter` 0.1.9 (a Rust interpreter with Python bindings, in
//!    `target/venv`: `target/venv/bin/pip install nc-gcode-interpreter==0.1.9`) and ours on a
//!    generated program inside what it reads (G0/G1/G2/G3, DEF variables, TRANS/ATRANS):
//!    lines/s of each (its in-process time of `nc_to_dataframe`, without Python's start and
//!    import), their ratio, and the end position both reach (a weak cross-check: it keeps
//!    variables in 32-bit floats).

use std::process::Command;
use std::time::Instant;

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Dialect, Interpreter, Library, Setup};
use cnc_interpreter_core::{next_command, ToolOffset};

#[path = "support/heap.rs"]
mod heap;

const RUNS: usize = 5;

/// Appends lines until `blocks` are written: `head` once, then `section` over and over, then
/// `tail`.
fn generate(blocks: usize, head: &[&str], section: &[&str], tail: &[&str]) -> String {
    let mut out = String::with_capacity(blocks * 24);
    let mut n = 0;
    for l in head {
        out.push_str(l);
        out.push('\n');
        n += 1;
    }
    while n + tail.len() < blocks {
        out.push_str(section[(n - head.len()) % section.len()]);
        out.push('\n');
        n += 1;
    }
    for l in tail {
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// The 802D program: R parameters, frames, arcs, a named subprogram (library `SEITE`).
fn program_802d(blocks: usize) -> String {
    generate(
        blocks,
        &["G17 G90 G500 G0 X0 Y0 Z5", "T1 D1", "R1=0", "G1 Z-1 F600"],
        &[
            "R1=R1+0.001",
            "R2=SIN(R1*30)*2+R1/4",
            "R3=SQRT(R2*R2+1)",
            "G1 X=10+R2 Y=R2*2",
            "TRANS X5 Y5",
            "AROT RPL=15",
            "G1 X20 Y5",
            "G2 X30 Y5 I5 J0",
            "G3 X20 Y5 CR=5",
            "ATRANS X=R3",
            "G1 X20 Y0",
            "SEITE P2",
            "TRANS",
            "G0 X0 Y0",
        ],
        &["G0 Z5", "M30"],
    )
}

/// The FANUC mill program of the same work: macro variables, G52 shifts for the frames (the
/// 0-M's programmable rotation is an option this controller does not run), M98 calls.
fn program_fanuc(blocks: usize) -> String {
    generate(
        blocks,
        &["O0001", "G17 G90 G54 G0 X0 Y0 Z5", "#1=0", "G1 Z-1 F600"],
        &[
            "#1=#1+0.001",
            "#2=SIN[#1*30]*2+#1/4",
            "#3=SQRT[#2*#2+1]",
            "G1 X[10+#2] Y[#2*2]",
            "G52 X5 Y5",
            "G1 X20 Y5",
            "G2 X30 Y5 I5 J0",
            "G3 X20 Y5 R5",
            "G52 X[5+#3] Y5",
            "G1 X20 Y0",
            "M98 P2002 L2",
            "G52 X0 Y0",
            "G0 X0 Y0",
            "G1 X0 Y0",
        ],
        &["G0 Z5", "M30"],
    )
}

fn mill() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    s.offsets.tools.insert(
        11,
        ToolOffset {
            z: 50.0,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    s
}

fn library_802d() -> Library {
    let mut lib = Library::new();
    lib.insert_named("SEITE", "SEITE.SPF", "G91 G1 X1\nY1\nG90\nRET\n");
    lib
}

fn library_fanuc() -> Library {
    let mut lib = Library::new();
    lib.insert(2002, "O2002", "O2002\nG91 G1 X1\nY1\nG90\nM99\n");
    lib
}

/// Interprets the 802D program; the number of commands and the last move's end.
fn run_802d(text: &str, library: Library) -> (usize, Vec<f64>) {
    let mut front = Sinumerik::new(text, mill(), library);
    let (mut n, mut last) = (0, Vec::new());
    loop {
        match next_command(&mut front) {
            Ok(Some(c)) => {
                n += 1;
                if let Some(end) = c.command.end() {
                    last = end.to_vec();
                }
            }
            Ok(None) => return (n, last),
            Err(e) => panic!("generated 802D program rejected: {e}"),
        }
    }
}

fn run_fanuc(text: &str) -> usize {
    let mut interp = Interpreter::with_library(Dialect::FanucMill, text, mill(), library_fanuc());
    let mut n = 0;
    loop {
        match interp.next_command() {
            Ok(Some(_)) => n += 1,
            Ok(None) => return n,
            Err(e) => panic!("generated FANUC program rejected: {e}"),
        }
    }
}

/// Best of `RUNS`: seconds and the run's result (the machine is shared; the best run is the
/// one least disturbed).
fn best_of<T>(f: impl Fn() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut result = None;
    for _ in 0..RUNS {
        let t = Instant::now();
        let r = std::hint::black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
        result = Some(r);
    }
    (best, result.expect("RUNS > 0"))
}

/// The program for the peer: what 0.1.9 reads (no R parameters, functions or labels; every
/// TRANS names both plane axes, since it does not clear the ones a TRANS leaves out).
fn program_peer(blocks: usize) -> String {
    generate(
        blocks,
        &["DEF REAL VAL=0", "G17 G90 G0 X0 Y0 Z5", "G1 Z-1 F600"],
        &[
            "VAL=VAL+0.001",
            "G1 X=10+VAL Y=VAL*2",
            "TRANS X5 Y5",
            "G1 X20 Y5",
            "G2 X30 Y5 I5 J0",
            "G3 X20 Y5 I-5 J0",
            "ATRANS X=VAL Y1",
            "G1 X20 Y0",
            "G0 X0 Y0",
            "TRANS X0 Y0",
        ],
        &["G0 X=VAL Y=VAL*3 Z5", "M30"],
    )
}

const PEER: &str = r#"
import sys, time, json
import nc_gcode_interpreter as n
text = open(sys.argv[1]).read()
best = None
for _ in range(int(sys.argv[2])):
    t = time.perf_counter()
    df, state = n.nc_to_dataframe(text, iteration_limit=10**9)
    dt = time.perf_counter() - t
    best = dt if best is None else min(best, dt)
last = df.tail(1)
print(json.dumps({"seconds": best, "rows": df.height,
                  "end": [last["X"][0], last["Y"][0], last["Z"][0]]}))
"#;

fn python() -> String {
    std::env::var("CNC_PYTHON").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/venv/bin/python").to_string()
    })
}

fn peer_bench() {
    let text = program_peer(200_000);
    let lines = text.lines().count();
    let file = std::env::temp_dir().join(format!("cnc_802d_peer_{}.mpf", std::process::id()));
    std::fs::write(&file, &text).expect("peer program written");
    let out = Command::new(python())
        .args(["-c", PEER])
        .arg(&file)
        .arg(RUNS.to_string())
        .output();
    let _ = std::fs::remove_file(&file);
    let out = match out {
        Ok(o) if o.status.success() => o,
        Ok(o) => {
            eprintln!(
                "nc-gcode-interpreter failed (install it: target/venv/bin/pip install \
                 nc-gcode-interpreter==0.1.9):\n{}",
                String::from_utf8_lossy(&o.stderr)
            );
            std::process::exit(1);
        }
        Err(e) => {
            eprintln!("{}: {e} (scripts/setup.sh makes target/venv)", python());
            std::process::exit(1);
        }
    };
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("the peer's report is JSON");
    let t_peer = report["seconds"].as_f64().expect("seconds");
    let (t_ours, (commands, end)) = best_of(|| run_802d(&text, Library::new()));
    println!(
        "peer program: {lines} lines (G0/G1/G2/G3, DEF REAL, TRANS/ATRANS), {} bytes",
        text.len()
    );
    println!(
        "nc-gcode-interpreter 0.1.9: {t_peer:.3} s, {:.0} lines/s ({} rows)",
        lines as f64 / t_peer,
        report["rows"]
    );
    println!(
        "ours (sinumerik-802d): {t_ours:.3} s, {:.0} lines/s ({commands} commands)",
        lines as f64 / t_ours
    );
    println!("ratio ours/peer lines per second: {:.2}", t_peer / t_ours);
    println!(
        "end position: peer {}, ours {:?} (the peer keeps DEF REAL in 32 bits)",
        report["end"], end
    );
}

fn main() {
    let text = program_802d(200_000);
    let fanuc = program_fanuc(200_000);
    let blocks = text.lines().count();
    let (t_802d, (commands, _)) = best_of(|| run_802d(&text, library_802d()));
    let (t_fanuc, fanuc_commands) = best_of(|| run_fanuc(&fanuc));
    println!("802D program: {blocks} blocks, {} bytes", text.len());
    println!(
        "sinumerik-802d: {t_802d:.3} s, {:.0} blocks/s ({commands} commands)",
        blocks as f64 / t_802d
    );
    println!(
        "fanuc-mill, the same work: {t_fanuc:.3} s, {:.0} blocks/s ({fanuc_commands} commands)",
        fanuc.lines().count() as f64 / t_fanuc
    );
    println!(
        "ratio 802D/FANUC blocks per second: {:.2}",
        (blocks as f64 / t_802d) / (fanuc.lines().count() as f64 / t_fanuc)
    );
    let small = program_802d(20_000);
    let peak =
        |t: &str| heap::peak_heap(|| drop(std::hint::black_box(run_802d(t, library_802d()))));
    let (peak_small, peak_large) = (peak(&small), peak(&text));
    println!(
        "peak heap while interpreting: 20000 blocks {peak_small} bytes (text {} + working {}); \
         200000 blocks {peak_large} bytes (text {} + working {})",
        small.len(),
        peak_small.saturating_sub(small.len()),
        text.len(),
        peak_large.saturating_sub(text.len()),
    );
    peer_bench();
}
