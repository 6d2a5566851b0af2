//! The canonical block stream as stable text, one command per line, for `cnc check --trace`
//! and golden files:
//!
//! ```text
//! N<line> RAPID X100.0000 Z50.0000
//! N<line> LINEAR X50.0000 Z-30.0000 F200.0000
//! N<line> ARC_CW X26.0000 Z-31.0000 CX34.0000 CZ-31.0000 F900.0000
//! N<line> THREAD X48.8571 Z-72.0000 LEAD2.0000 Q0.000
//! N<line> PROBE X300.0000 Z-40.0000 F4000.0000 RISING STOP
//! N<line> DWELL 2.000
//! N<line> M3 | S600.0 | T1 | FEED_PER_REV | FEED_PER_MIN | EXACT_STOP | BLENDING | END
//! N<line> PROFILE_JERK_LIMITED | PROFILE_TRAPEZOIDAL
//! ```
//!
//! `<line>` is the source line (1-based), end points are machine coordinates (X as diameter).

use std::fmt::Write;

use crate::canon::{Aux, Canon, Command};
use cnc_interpreter_core::Turn;

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
            plane,
        } => {
            s.push_str(if *clockwise { "ARC_CW" } else { "ARC_CCW" });
            axes(&mut s, letters, end, "");
            axes(&mut s, letters, center, "C");
            let _ = write!(s, " F{feed:.4}");
            if let Some(p) = plane {
                let letter = |i: u8| letters.get(usize::from(i)).copied().unwrap_or('?');
                let _ = write!(s, " PLANE {}{}", letter(p[0]), letter(p[1]));
            }
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
        Command::Tap { end, lead, rpm } => {
            s.push_str("TAP");
            axes(&mut s, letters, end, "");
            let _ = write!(s, " LEAD{lead:.4} S{rpm:.1}");
        }
        Command::Rotary {
            end,
            degrees,
            way,
            rpm,
        } => {
            s.push_str("ROTARY");
            axes(&mut s, letters, end, "");
            // The spindle's angle to reach (TO) or its travel (BY, incremental), degrees.
            let to = if *way == Turn::Incremental {
                "BY"
            } else {
                "TO"
            };
            let _ = write!(s, " {to}{degrees:.3} {way:?} S{rpm:.1}");
        }
        Command::Probe {
            end,
            feed,
            rising,
            stop,
        } => {
            s.push_str("PROBE");
            axes(&mut s, letters, end, "");
            let edge = if *rising { "RISING" } else { "FALLING" };
            let rest = if *stop { "STOP" } else { "TO_END" };
            let _ = write!(s, " F{feed:.4} {edge} {rest}");
        }
        Command::FixedStop {
            axis,
            on,
            torque,
            window,
        } => {
            let letter = letters.get(usize::from(*axis)).copied().unwrap_or('?');
            if *on {
                let _ = write!(s, "FIXED_STOP {letter} TORQUE{torque}% WINDOW{window}");
            } else {
                let _ = write!(s, "FIXED_STOP_OFF {letter}");
            }
        }
        Command::Compressor { on } => s.push_str(if *on {
            "COMPRESSOR_ON"
        } else {
            "COMPRESSOR_OFF"
        }),
        Command::Fifo { fill } => s.push_str(if *fill { "FIFO_FILL" } else { "FIFO_RUN" }),
        Command::Sync => s.push_str("SYNC"),
        Command::Contour { on } => s.push_str(if *on { "C_CONTOUR_ON" } else { "C_CONTOUR_OFF" }),
        // The live tool turning at a speed (D143), or standing again in position control.
        Command::LiveTool { rpm } if *rpm > 0.0 => {
            let _ = write!(s, "LIVE_TOOL S{rpm:.1}");
        }
        Command::LiveTool { .. } => s.push_str("LIVE_TOOL_STOP"),
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
        Command::Profile { jerk_limited } => s.push_str(if *jerk_limited {
            "PROFILE_JERK_LIMITED"
        } else {
            "PROFILE_TRAPEZOIDAL"
        }),
        Command::Feedforward { on } => s.push_str(if *on {
            "FEEDFORWARD_ON"
        } else {
            "FEEDFORWARD_OFF"
        }),
        Command::Acceleration { axis, percent } => {
            let letter = match *axis {
                cnc_msgs::canon::SPINDLE_AXIS => 'S',
                a => letters.get(usize::from(a)).copied().unwrap_or('?'),
            };
            let _ = write!(s, "ACCELERATION {letter} {percent}%");
        }
        Command::Aux(Aux::M(m)) => {
            let _ = write!(s, "M{m}");
        }
        Command::Aux(Aux::S(v)) => {
            let _ = write!(s, "S{v:.1}");
        }
        Command::Aux(Aux::T(t)) => {
            let _ = write!(s, "T{t}");
        }
        Command::Aux(Aux::Orient { degrees, way }) => {
            let _ = write!(s, "SPINDLE_POSITION {degrees:.3} {way:?}");
        }
        Command::Aux(Aux::H { address, value }) => {
            let _ = write!(s, "H{address}={value}");
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

/// The canonical stream in the text of LinuxCNC 2.9's standalone interpreter `rs274`
/// (`../shared/notes/linuxcnc_oracle.md` §1.3), for `cnc check --trace --format linuxcnc`:
///
/// ```text
///     1 N..... STRAIGHT_TRAVERSE(10.0000, 5.0000, 2.0000, 0.0000, 0.0000, 0.0000)
///     2 N..... SET_FEED_RATE(200.0000)
///     3 N..... STRAIGHT_FEED(10.0000, 5.0000, -1.0000, 0.0000, 0.0000, 0.0000)
///     4 N..... ARC_FEED(20.0000, 5.0000, 15.0000, 5.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)
/// ```
///
/// Call names, argument order and `%.4f` are rs274's. Positions are machine coordinates:
/// our canonical commands carry the work offsets, G92 and tool length already applied, so
/// no `SET_G5X_OFFSET` / `SET_G92_OFFSET` / `USE_TOOL_LENGTH_OFFSET` lines are printed (rs274
/// prints positions in the program frame and those offsets beside them; the oracle test adds
/// them back). Diameter axes print as radius, as rs274 does in G7.
pub struct LinuxCnc {
    /// For each of x, y, z, a, b, c: the index of our axis with that letter.
    slots: [Option<usize>; 6],
    diameter: Vec<bool>,
    /// The arc plane as (first, second) axis letters of rs274's ARC_FEED (XY: X, Y; XZ: Z, X;
    /// YZ: Y, Z).
    plane: (usize, usize),
    feed: Option<f64>,
    tool: i32,
    seq: u64,
}

impl LinuxCnc {
    /// `letters`/`diameter`: the machine's axes; `arc_plane`: the two axes arcs turn in.
    pub fn new(letters: &[char], diameter: &[bool], arc_plane: [char; 2]) -> LinuxCnc {
        let mut slots = [None; 6];
        for (k, l) in ['X', 'Y', 'Z', 'A', 'B', 'C'].iter().enumerate() {
            slots[k] = letters.iter().position(|a| a == l);
        }
        let slot = |c: char| "XYZABC".find(c).unwrap_or(0);
        let plane = cyclic(slot(arc_plane[0]), slot(arc_plane[1]));
        LinuxCnc {
            slots,
            diameter: diameter.to_vec(),
            plane,
            feed: None,
            tool: 0,
            seq: 0,
        }
    }

    /// rs274's plane (slots of x..c) of an arc turning in our axes `a`, `b`.
    fn rs274_plane(&self, a: u8, b: u8) -> (usize, usize) {
        let slot = |i: u8| {
            self.slots
                .iter()
                .position(|s| *s == Some(usize::from(i)))
                .unwrap_or(0)
        };
        cyclic(slot(a), slot(b))
    }

    /// `SELECT_PLANE` when an arc turns in another plane than the last one printed.
    fn select_plane(&mut self, out: &mut String, plane: (usize, usize)) {
        if plane != self.plane {
            self.plane = plane;
            let name = match plane {
                (2, 0) => "CANON_PLANE_XZ",
                (1, 2) => "CANON_PLANE_YZ",
                _ => "CANON_PLANE_XY",
            };
            self.call(out, "SELECT_PLANE(");
            out.push_str(name);
            out.push_str(")\n");
        }
    }

    /// The value of rs274 slot `k` (x..c) of a machine position.
    fn value(&self, p: &[f64], k: usize) -> f64 {
        match self.slots[k] {
            Some(i) => {
                let v = p.get(i).copied().unwrap_or(0.0);
                if self.diameter.get(i) == Some(&true) {
                    v / 2.0
                } else {
                    v
                }
            }
            None => 0.0,
        }
    }

    /// `name(x, y, z, a, b, c)` of a position, with its line's start and end.
    fn six(&mut self, out: &mut String, name: &str, p: &[f64]) {
        self.call(out, name);
        for k in 0..6 {
            if k > 0 {
                out.push_str(", ");
            }
            write_num(out, self.value(p, k));
        }
        out.push_str(")\n");
    }

    /// Starts a line: sequence number, rs274's `N.....`, and `head` (the call's name and
    /// whatever fixed text follows it). The caller writes the rest and the newline.
    fn call(&mut self, out: &mut String, head: &str) {
        self.seq += 1;
        push_uint(out, self.seq, 5);
        out.push_str(" N..... ");
        out.push_str(head);
    }

    /// A whole line of fixed text.
    fn push(&mut self, out: &mut String, call: &str) {
        self.call(out, call);
        out.push('\n');
    }

    fn set_feed(&mut self, out: &mut String, feed: f64) {
        if self.feed != Some(feed) {
            self.feed = Some(feed);
            self.call(out, "SET_FEED_RATE(");
            write_num(out, feed);
            out.push_str(")\n");
        }
    }

    /// Appends the rs274 lines of one command to `out` (none for commands rs274 has no call
    /// for): a long trace reuses one buffer and formats every number in place.
    pub fn write(&mut self, c: &Canon, out: &mut String) {
        match &c.command {
            Command::Rapid { end } => self.six(out, "STRAIGHT_TRAVERSE(", end),
            Command::Linear { end, feed } => {
                self.set_feed(out, *feed);
                self.six(out, "STRAIGHT_FEED(", end);
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                plane,
            } => {
                self.set_feed(out, *feed);
                if let Some([a, b]) = plane {
                    self.select_plane(out, self.rs274_plane(*a, *b));
                }
                let (p, q) = self.plane;
                let normal = 3 - p - q;
                self.call(out, "ARC_FEED(");
                for v in [
                    self.value(end, p),
                    self.value(end, q),
                    self.value(center, p),
                    self.value(center, q),
                ] {
                    write_num(out, v);
                    out.push_str(", ");
                }
                out.push_str(if *clockwise { "-1" } else { "1" });
                for k in [normal, 3, 4, 5] {
                    out.push_str(", ");
                    write_num(out, self.value(end, k));
                }
                out.push_str(")\n");
            }
            Command::Thread { end, lead, .. } => {
                self.push(out, &format!("START_SPEED_FEED_SYNCH(0, {lead:.6}, 0)"));
                self.six(out, "STRAIGHT_FEED(", end);
                self.push(out, "STOP_SPEED_FEED_SYNCH()");
            }
            // LinuxCNC's G33.1: the pitch synchronised, the end point in the plane's three
            // axes (its retraction is part of the call; ours is a second tap).
            Command::Tap { end, lead, .. } => {
                self.push(out, &format!("START_SPEED_FEED_SYNC({:.6},0)", lead.abs()));
                self.call(out, "RIGID_TAP(");
                for k in 0..3 {
                    if k > 0 {
                        out.push_str(", ");
                    }
                    write_num(out, self.value(end, k));
                }
                out.push_str(")\n");
                self.push(out, "STOP_SPEED_FEED_SYNCH()");
            }
            // rs274 has no spindle-positioned move: the axes' end as a feed at the rotary
            // speed's share is no honest equivalent, so nothing is written (D138).
            Command::Rotary { .. } => {}
            // rs274 has one spindle: the live tool's speed has no call of its own (D143).
            Command::LiveTool { .. } => {}
            // LinuxCNC's G38.2: a straight probe at the feed.
            Command::Probe { end, feed, .. } => {
                self.set_feed(out, *feed);
                self.six(out, "STRAIGHT_PROBE(", end);
            }
            Command::Dwell { seconds } => {
                self.call(out, "DWELL(");
                write_num(out, *seconds);
                out.push_str(")\n");
            }
            Command::FeedMode { per_rev } => {
                self.push(out, &format!("SET_FEED_MODE(0, {})", u8::from(*per_rev)));
            }
            Command::PathMode { exact_stop } => {
                let mode = if *exact_stop {
                    "CANON_EXACT_STOP"
                } else {
                    "CANON_CONTINUOUS"
                };
                self.push(out, &format!("SET_MOTION_CONTROL_MODE({mode}, 0.000000)"));
            }
            Command::Aux(Aux::S(v)) => {
                self.call(out, "SET_SPINDLE_SPEED(0, ");
                write_num(out, *v);
                out.push_str(")\n");
            }
            Command::Aux(Aux::T(t)) => {
                self.tool = *t;
                self.push(out, &format!("SELECT_TOOL({t})"));
            }
            Command::Aux(Aux::M(m)) => {
                let call = match m {
                    0 => "PROGRAM_STOP()".to_string(),
                    1 => "OPTIONAL_PROGRAM_STOP()".to_string(),
                    3 => "START_SPINDLE_CLOCKWISE(0)".to_string(),
                    4 => "START_SPINDLE_COUNTERCLOCKWISE(0)".to_string(),
                    5 => "STOP_SPINDLE_TURNING(0)".to_string(),
                    6 => format!("CHANGE_TOOL({})", self.tool),
                    7 => "MIST_ON()".to_string(),
                    8 => "FLOOD_ON()".to_string(),
                    9 => "FLOOD_OFF()".to_string(),
                    30 => "PALLET_SHUTTLE()".to_string(),
                    2 => return,
                    other => format!("COMMENT(\"M{other}\")"),
                };
                self.push(out, &call);
            }
            // LinuxCNC's M19: the angle and 0 either way, 1 clockwise (M3), 2 counter-clockwise;
            // it has no incremental positioning.
            Command::Aux(Aux::Orient { degrees, way }) => match way {
                Turn::Incremental => {
                    self.push(out, &format!("COMMENT(\"SPOS=IC({degrees})\")"));
                }
                _ => {
                    self.call(out, "ORIENT_SPINDLE(0, ");
                    write_num(out, *degrees);
                    out.push_str(&format!(", {})\n", *way as u8));
                }
            },
            // rs274 has no second auxiliary function: a comment, as for an M code it does not know.
            Command::Aux(Aux::H { address, value }) => {
                self.push(out, &format!("COMMENT(\"H{address}={value}\")"));
            }
            Command::ProgramEnd => self.push(out, "PROGRAM_END()"),
            // rs274 has no call for the acceleration profile (its planner's is fixed), the
            // drives' feedforward, an acceleration override, a fixed stop, the compressor or
            // the look-ahead buffer, a preprocessing stop that reads the machine, or a spindle
            // in contour control.
            Command::Profile { .. }
            | Command::Contour { .. }
            | Command::Sync
            | Command::Feedforward { .. }
            | Command::Acceleration { .. }
            | Command::FixedStop { .. }
            | Command::Compressor { .. }
            | Command::Fifo { .. } => {}
        }
    }
}

/// rs274 orders a plane's axes cyclically: XY, ZX (G18 prints Z first), YZ.
fn cyclic(p: usize, q: usize) -> (usize, usize) {
    match (p.min(q), p.max(q)) {
        (0, 2) => (2, 0),
        (a, b) => (a, b),
    }
}

/// Appends `n` in decimal, right-aligned in `width` characters (`%5d`), without going
/// through the formatting machinery: a trace writes millions of them.
fn push_uint(out: &mut String, n: u64, width: usize) {
    let mut buf = [b' '; 24];
    let start = uint_digits(&mut buf, n).min(buf.len().saturating_sub(width));
    out.push_str(std::str::from_utf8(&buf[start..]).unwrap_or(""));
}

/// Writes `n`'s digits at the end of `buf`; returns where they start.
fn uint_digits(buf: &mut [u8; 24], mut n: u64) -> usize {
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            return i;
        }
    }
}

/// Appends rs274's `%.4f` of `v`, without a negative zero.
fn write_num(out: &mut String, v: f64) {
    let v = if v.abs() < 5e-5 { 0.0 } else { v };
    // Fast path: the value in ten-thousandths as an integer, unless it lies so near a
    // rounding tie that only the exact decimal expansion can decide (the formatter's slow
    // exact algorithm dominated a 200,000-line trace).
    let scaled = v * 10_000.0;
    let k = scaled.round();
    if k.abs() < 1e15 && ((scaled - k).abs() - 0.5).abs() > 1e-6 {
        let k = k as i64;
        // Ten-thousandths with at least five digits, then the point four from the end.
        let mut buf = [b'0'; 24];
        let start = uint_digits(&mut buf, k.unsigned_abs()).min(buf.len() - 5);
        let mut text = [0u8; 26];
        let mut n = 0;
        if k < 0 {
            text[0] = b'-';
            n = 1;
        }
        let whole = &buf[start..buf.len() - 4];
        text[n..n + whole.len()].copy_from_slice(whole);
        n += whole.len();
        text[n] = b'.';
        text[n + 1..n + 5].copy_from_slice(&buf[buf.len() - 4..]);
        out.push_str(std::str::from_utf8(&text[..n + 5]).unwrap_or(""));
        return;
    }
    let _ = write!(out, "{v:.4}");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// rs274's `%.4f`, without a negative zero.
    fn num(v: f64) -> String {
        let mut s = String::new();
        write_num(&mut s, v);
        s
    }

    /// `push_uint` prints as `%{width}d` does.
    #[test]
    fn integers_as_printf_pads_them() {
        for (n, width) in [
            (0_u64, 0),
            (7, 5),
            (12345, 5),
            (123456, 5),
            (u64::MAX, 5),
            (40, 1),
        ] {
            let mut s = String::new();
            push_uint(&mut s, n, width);
            assert_eq!(s, format!("{n:width$}"));
        }
    }

    /// The fast `%.4f` agrees with the exact formatter, ties and signs included.
    #[test]
    fn four_decimals_as_rs274_prints_them() {
        for v in [
            0.0_f64,
            1.0,
            -1.0,
            0.00004,
            -0.00004,
            0.00005,
            0.00015,
            1.00005,
            -2.50005,
            12.34565,
            123456.78915,
            -0.5,
            99999.99995,
            0.1 + 0.2,
            -7.0 / 3.0,
            1e9 / 7.0,
            1e20,
        ] {
            let exact = if v.abs() < 5e-5 { 0.0 } else { v };
            assert_eq!(num(v), format!("{exact:.4}"), "{v}");
        }
        for k in -20_000..20_000 {
            let v = f64::from(k) * 0.012_345_67;
            let exact = if v.abs() < 5e-5 { 0.0 } else { v };
            assert_eq!(num(v), format!("{exact:.4}"), "{v}");
        }
    }
}
