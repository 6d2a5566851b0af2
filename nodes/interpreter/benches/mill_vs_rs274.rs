//! The mill interpreter against LinuxCNC 2.9's standalone `rs274` on the same generated
//! 200,000-line FANUC/RS274 program (issue 7, item 3): G01 moves, arcs by I/J and helices,
//! and macro arithmetic whose results are the moves' words. Both do the same work: read the
//! file's text, interpret it, and write the canonical calls in rs274's format to a file.
//! Printed, best of five runs each, in one run of this binary:
//! - lines/s of rs274 (`rs274 -g prog out`, wall time of the process) and of ours
//!   (`Interpreter` + `trace::LinuxCnc` into a buffered file, in process), and their ratio;
//! - peak memory: rs274's maximum resident set, and our peak heap for a 20,000- and a
//!   200,000-line program (working memory must not grow with the program).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use cnc_interpreter::trace::LinuxCnc;
use cnc_interpreter::{Dialect, Interpreter, Setup};

#[path = "support/heap.rs"]
mod heap;

const RUNS: usize = 5;
const XYZ: [char; 3] = ['X', 'Y', 'Z'];

/// A program of exactly `lines` lines that both controls accept.
fn program(lines: usize) -> String {
    let head = ["G21 G90 G54 G17", "G0 X0 Y0 Z5", "#1 = 0"];
    let section = [
        "#1 = [#1 + 0.001]",
        "#2 = [SIN[#1 * 30] * 2 + #1 / 4]",
        "G1 X[10 + #2] Y[#2 * 2] Z-1 F600",
        "G1 X20 Y5",
        "G2 X30 Y5 I5 J0",
        "G3 X20 Y5 I-5 J0",
        "G1 X20 Y0",
        "G2 X20 Y0 Z-1.5 I5 J0",
        "G1 X[20 + #1] Z-1",
        "G0 Z5",
    ];
    let mut out = String::with_capacity(lines * 24);
    let mut n = 0;
    for l in head {
        out.push_str(l);
        out.push('\n');
        n += 1;
    }
    while n + 1 < lines {
        let l = section[(n - head.len()) % section.len()];
        out.push_str(l);
        out.push('\n');
        n += 1;
    }
    out.push_str("M2\n");
    out
}

fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("cnc_mill_bench_{}_{name}", std::process::id()))
}

/// One rs274 run: seconds of wall time.
fn rs274(program: &Path, out: &Path) -> Result<f64, String> {
    let t = Instant::now();
    let run = Command::new("rs274")
        .arg("-g")
        .arg(program)
        .arg(out)
        .output()
        .map_err(|e| format!("rs274: {e} (install Debian's linuxcnc-uspace)"))?;
    let seconds = t.elapsed().as_secs_f64();
    if !run.status.success() {
        return Err(format!(
            "rs274 rejected the program: {}",
            String::from_utf8_lossy(&run.stderr)
        ));
    }
    Ok(seconds)
}

/// Our interpreter on the same file, writing rs274's canon format: seconds and the number of
/// canonical calls written.
fn ours(program: &Path, out: &Path) -> Result<(f64, usize), String> {
    let t = Instant::now();
    let text = std::fs::read_to_string(program).map_err(|e| e.to_string())?;
    let file = std::fs::File::create(out).map_err(|e| e.to_string())?;
    let calls = interpret(&text, std::io::BufWriter::new(file))?;
    Ok((t.elapsed().as_secs_f64(), calls))
}

fn interpret(text: &str, mut sink: impl Write) -> Result<usize, String> {
    let setup = Setup::new(&XYZ, &[false; 3], &[0.0; 3]);
    let mut interp = Interpreter::new(Dialect::FanucMill, text, setup);
    let mut fmt = LinuxCnc::new(&XYZ, &[false; 3], ['X', 'Y']);
    let mut calls = 0;
    // One buffer for the whole trace, written out whenever it holds 64 KiB.
    let mut buf = String::with_capacity(1 << 17);
    let mut flush = |buf: &mut String, sink: &mut dyn Write| -> Result<(), String> {
        calls += buf.bytes().filter(|&b| b == b'\n').count();
        sink.write_all(buf.as_bytes()).map_err(|e| e.to_string())?;
        buf.clear();
        Ok(())
    };
    while let Some(c) = interp.next_command().map_err(|e| e.to_string())? {
        fmt.write(&c, &mut buf);
        if buf.len() >= 1 << 16 {
            flush(&mut buf, &mut sink)?;
        }
    }
    flush(&mut buf, &mut sink)?;
    sink.flush().map_err(|e| e.to_string())?;
    Ok(calls)
}

/// The largest resident set of the children waited for so far, bytes.
fn children_max_rss() -> u64 {
    // SAFETY: getrusage fills the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: a valid pointer to a rusage struct.
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    usage.ru_maxrss.max(0) as u64 * 1024
}

fn main() -> Result<(), String> {
    let lines = 200_000;
    let text = program(lines);
    let path = scratch("prog.ngc");
    let (theirs_out, ours_out) = (scratch("rs274.canon"), scratch("ours.canon"));
    std::fs::write(&path, &text).map_err(|e| e.to_string())?;
    let mut t_rs274 = f64::INFINITY;
    let mut t_ours = f64::INFINITY;
    let mut calls = 0;
    // Alternate the two so both see the same machine load.
    for _ in 0..RUNS {
        t_rs274 = t_rs274.min(rs274(&path, &theirs_out)?);
        let (t, c) = ours(&path, &ours_out)?;
        t_ours = t_ours.min(t);
        calls = c;
    }
    let rs274_calls = std::fs::read_to_string(&theirs_out)
        .map_err(|e| e.to_string())?
        .lines()
        .count();
    let rss = children_max_rss();
    for f in [&path, &theirs_out, &ours_out] {
        let _ = std::fs::remove_file(f);
    }
    println!("program: {lines} lines, {} bytes", text.len());
    println!(
        "rs274: {t_rs274:.3} s, {:.0} lines/s ({rs274_calls} canon lines), peak RSS {:.1} MB",
        lines as f64 / t_rs274,
        rss as f64 / 1e6
    );
    println!(
        "ours:  {t_ours:.3} s, {:.0} lines/s ({calls} canon lines)",
        lines as f64 / t_ours
    );
    println!("ratio ours/rs274 lines per second: {:.2}", t_rs274 / t_ours);
    let small = program(20_000);
    let peak = |text: &str| {
        heap::peak_heap(|| {
            let _ = std::hint::black_box(interpret(text, std::io::sink()));
        })
    };
    let (peak_small, peak_large) = (peak(&small), peak(&text));
    println!(
        "our peak heap: 20000 lines {} bytes (working {}), {lines} lines {} bytes (working {}); the text is held once",
        peak_small,
        peak_small.saturating_sub(small.len()),
        peak_large,
        peak_large.saturating_sub(text.len()),
    );
    Ok(())
}
