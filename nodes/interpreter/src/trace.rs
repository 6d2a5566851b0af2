//! The canonical block stream as stable text, one command per line, for `cnc check --trace`
//! and golden files:
//!
//! ```text
//! N<line> RAPID X100.0000 Z50.0000
//! N<line> LINEAR X50.0000 Z-30.0000 F200.0000
//! N<line> ARC_CW X26.0000 Z-31.0000 CX34.0000 CZ-31.0000 F900.0000
//! N<line> THREAD X48.8571 Z-72.0000 LEAD2.0000 Q0.000
//! N<line> DWELL 2.000
//! N<line> M3 | S600.0 | T1 | FEED_PER_REV | FEED_PER_MIN | EXACT_STOP | BLENDING | END
//! ```
//!
//! `<line>` is the source line (1-based), end points are machine coordinates (X as diameter).

use std::fmt::Write;

use crate::canon::{Aux, Canon, Command};

fn axes(out: &mut String, letters: &[char], values: &[f64], prefix: &str) {
    for (l, v) in letters.iter().zip(values) {
        let v = if v.abs() < 5e-5 { 0.0 } else { *v };
        let _ = write!(out, " {prefix}{l}{v:.4}");
    }
}

/// One command as a trace line.
pub fn line(letters: &[char], c: &Canon) -> String {
    let mut s = format!("L{} ", c.line);
    match &c.command {
        Command::Rapid { end } => {
            s.push_str("RAPID");
            axes(&mut s, letters, end, "");
        }
        Command::Linear { end, feed } => {
            s.push_str("LINEAR");
            axes(&mut s, letters, end, "");
            let _ = write!(s, " F{feed:.4}");
        }
        Command::Arc {
            end,
            center,
            clockwise,
            feed,
        } => {
            s.push_str(if *clockwise { "ARC_CW" } else { "ARC_CCW" });
            axes(&mut s, letters, end, "");
            axes(&mut s, letters, center, "C");
            let _ = write!(s, " F{feed:.4}");
        }
        Command::Thread {
            end,
            lead,
            start_angle,
        } => {
            s.push_str("THREAD");
            axes(&mut s, letters, end, "");
            let _ = write!(s, " LEAD{lead:.4} Q{start_angle:.3}");
        }
        Command::Dwell { seconds } => {
            let _ = write!(s, "DWELL {seconds:.3}");
        }
        Command::FeedMode { per_rev } => s.push_str(if *per_rev {
            "FEED_PER_REV"
        } else {
            "FEED_PER_MIN"
        }),
        Command::PathMode { exact_stop } => s.push_str(if *exact_stop {
            "EXACT_STOP"
        } else {
            "BLENDING"
        }),
        Command::Aux(Aux::M(m)) => {
            let _ = write!(s, "M{m}");
        }
        Command::Aux(Aux::S(v)) => {
            let _ = write!(s, "S{v:.1}");
        }
        Command::Aux(Aux::T(t)) => {
            let _ = write!(s, "T{t}");
        }
        Command::ProgramEnd => s.push_str("END"),
    }
    s
}

/// A whole stream, one line per command, ending with a newline.
pub fn format(letters: &[char], commands: &[Canon]) -> String {
    let mut out = String::new();
    for c in commands {
        out.push_str(&line(letters, c));
        out.push('\n');
    }
    out
}
