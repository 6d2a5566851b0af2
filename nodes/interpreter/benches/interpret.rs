//! Interpreter throughput and memory on a generated lathe program (issue 3, item 4).
//!
//! The program is Huaxing lathe G code of 200,000 blocks: macro arithmetic, linear moves with
//! expressions, G02/G03 arcs by R and by I/K, G90 single cycles and G71 roughing cycles with
//! their contours. Figures printed:
//! - blocks/s and canonical commands/s of the whole interpreter, best of seven runs;
//! - the same program through the block parser alone (`syntax::parse_line`), the reference
//!   measured in the same run, and the ratio of the two;
//! - peak heap during interpretation, for a 20,000- and a 200,000-block program: the
//!   interpreter streams, so its working memory must not grow with the program.

use std::time::Instant;

use cnc_interpreter::syntax::parse_line;
use cnc_interpreter::{Dialect, Interpreter, Setup};

#[path = "support/heap.rs"]
mod heap;

/// A Huaxing lathe program of at least `blocks` blocks (and fewer than `blocks` + 40).
fn program(blocks: usize) -> String {
    let mut out = String::with_capacity(blocks * 24);
    let mut n = 0usize;
    let push = |out: &mut String, line: &str, n: &mut usize| {
        out.push_str(line);
        out.push('\n');
        *n += 1;
    };
    push(&mut out, "O0001", &mut n);
    push(&mut out, "G00 X100 Z5", &mut n);
    push(&mut out, "M03 S800", &mut n);
    push(&mut out, "#1=0", &mut n);
    let mut section = 0u32;
    while n < blocks {
        section += 1;
        let s = section % 1000;
        // Macro arithmetic and moves whose words are expressions.
        push(&mut out, "#1=#1+0.001", &mut n);
        push(&mut out, "#2=SIN[#1*30]*2+#1/4", &mut n);
        push(&mut out, "#3=SQRT[#2*#2+1]", &mut n);
        push(&mut out, "G01 X[60+#2] Z[-#3] F0.2", &mut n);
        push(&mut out, "G01 X60 Z-5", &mut n);
        // Arcs by radius and by centre.
        push(&mut out, "G02 X70 Z-10 R5", &mut n);
        push(&mut out, "G03 U-10 W-5 I-5 K0", &mut n);
        push(&mut out, "G00 X100 Z5", &mut n);
        // A single cycle (four moves per block) and its follow-up blocks.
        push(&mut out, "G90 X[80-#2] Z-30 F0.2", &mut n);
        push(&mut out, "X76", &mut n);
        push(&mut out, "X72", &mut n);
        push(&mut out, "G00 X100 Z5", &mut n);
        if section.is_multiple_of(4) {
            // A roughing cycle over a five-block contour.
            push(&mut out, "G71 U1.5 R0.5", &mut n);
            let p = format!("G71 P{} Q{} U0.4 W0.1 F0.25", 10 + s * 2, 11 + s * 2);
            push(&mut out, &p, &mut n);
            push(&mut out, &format!("N{} G00 X40", 10 + s * 2), &mut n);
            push(&mut out, "G01 Z-10", &mut n);
            push(&mut out, "X60 Z-20", &mut n);
            push(&mut out, "G02 X80 Z-30 R10", &mut n);
            push(&mut out, &format!("N{} G01 X100", 11 + s * 2), &mut n);
            push(&mut out, "G00 X100 Z5", &mut n);
        }
    }
    push(&mut out, "M05", &mut n);
    push(&mut out, "M30", &mut n);
    out
}

/// Timed runs per figure.
const RUNS: usize = 7;

fn blocks_of(text: &str) -> usize {
    text.lines().filter(|l| !l.trim().is_empty()).count()
}

/// Interprets the whole program; returns the number of canonical commands.
fn interpret(text: &str) -> usize {
    let mut interp = Interpreter::new(Dialect::HuaxingLathe, text, Setup::lathe([100.0, 5.0]));
    let mut commands = 0;
    loop {
        match interp.next_command() {
            Ok(Some(_)) => commands += 1,
            Ok(None) => return commands,
            Err(e) => panic!("generated program rejected: {e}"),
        }
    }
}

/// Parses every block, the reference the interpreter is compared with.
fn parse_only(text: &str) -> usize {
    text.lines()
        .map(|l| parse_line(l, true).map(|_| 1).unwrap_or(0))
        .sum()
}

/// Best of `RUNS`: seconds and the run's result (the machine is shared; the best run is the
/// one least disturbed).
fn best_of(f: impl Fn() -> usize) -> (f64, usize) {
    let mut best = f64::INFINITY;
    let mut result = 0;
    for _ in 0..RUNS {
        let t = Instant::now();
        result = std::hint::black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, result)
}

/// Peak heap, above what was live before, while interpreting `text`.
fn peak_heap(text: &str) -> usize {
    heap::peak_heap(|| {
        std::hint::black_box(interpret(text));
    })
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument is a filter this binary ignores.
    let text = program(200_000);
    let blocks = blocks_of(&text);
    let (t_parse, parsed) = best_of(|| parse_only(&text));
    let (t_run, commands) = best_of(|| interpret(&text));
    assert_eq!(parsed, text.lines().count(), "every block parses");
    println!("program: {blocks} blocks, {} bytes", text.len());
    println!(
        "reference, block parser only: {:.3} s, {:.0} blocks/s",
        t_parse,
        blocks as f64 / t_parse
    );
    println!(
        "interpreter: {:.3} s, {:.0} blocks/s, {:.0} commands/s ({commands} commands)",
        t_run,
        blocks as f64 / t_run,
        commands as f64 / t_run
    );
    println!("ratio interpreter/parser time: {:.2}", t_run / t_parse);

    let small = program(20_000);
    let (peak_small, peak_large) = (peak_heap(&small), peak_heap(&text));
    // The interpreter keeps one copy of the program text (program memory); the rest is its
    // working memory.
    println!(
        "peak heap while interpreting: {} blocks {} bytes (text {} + working {}); {} blocks {} bytes (text {} + working {})",
        blocks_of(&small),
        peak_small,
        small.len(),
        peak_small.saturating_sub(small.len()),
        blocks,
        peak_large,
        text.len(),
        peak_large.saturating_sub(text.len()),
    );
}
