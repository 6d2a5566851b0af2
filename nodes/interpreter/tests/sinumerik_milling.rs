//! Issue 24: the 802D's milling cycles that are built — CYCLE90, thread milling — on the
//! manual's fixtures 116 and 117 and on threads of both kinds and hands. The checker knows
//! only the parameters and the cutter: it follows the cutter's centre through the command
//! stream, takes the arcs about the thread's centre as the helix, and asserts their lead (the
//! advance per turn), their direction, and the diameter the cutter's edge cuts
//! (path radius ± cutter radius), and that the helix covers the thread's length.

#[path = "support/sinumerik.rs"]
mod support;

use std::f64::consts::TAU;

use cnc_interpreter::{Command, Library};
use support::*;

struct Helix {
    /// Radius of the cutter centre's path.
    radius: f64,
    /// Infeed-axis advance per turn (signed).
    lead: f64,
    ccw: bool,
    /// Lowest and highest level the helix reaches.
    span: (f64, f64),
    turns: f64,
}

/// The arcs about `centre` in the stream, as one helix.
/// The mill with T1 D1 a 20 mm cutter of length 0 (machine Z is the cutter's tip).
fn cutter() -> cnc_interpreter::Setup {
    let mut s = mill();
    s.offsets.tools.insert(
        11,
        cnc_interpreter_core::ToolOffset {
            radius: 10.0,
            ..Default::default()
        },
    );
    s
}

fn go(text: &str) -> Run {
    run_with(text, cutter(), Library::new())
}

fn helix(r: &Run, centre: (f64, f64)) -> Helix {
    let mut here = [0.0; 3];
    let (mut sweep, mut dz, mut radius, mut ccw) = (0.0, 0.0, None, None);
    let mut span = (f64::INFINITY, f64::NEG_INFINITY);
    for c in &r.out {
        if let Command::Arc {
            end,
            center,
            clockwise,
            ..
        } = c
        {
            if (center[0] - centre.0).abs() < 1e-9 && (center[1] - centre.1).abs() < 1e-9 {
                let a0 = (here[1] - centre.1).atan2(here[0] - centre.0);
                let a1 = (end[1] - centre.1).atan2(end[0] - centre.0);
                let mut d = if *clockwise { a0 - a1 } else { a1 - a0 };
                d = d.rem_euclid(TAU);
                if d < 1e-9 {
                    d = TAU;
                }
                sweep += d;
                dz += end[2] - here[2];
                let rs = (here[0] - centre.0).hypot(here[1] - centre.1);
                let re = (end[0] - centre.0).hypot(end[1] - centre.1);
                assert!((rs - re).abs() < 1e-6, "the helix keeps its radius");
                assert!(radius.is_none_or(|x: f64| (x - re).abs() < 1e-6));
                assert!(ccw.is_none_or(|x| x != *clockwise), "one direction");
                radius = Some(re);
                ccw = Some(!clockwise);
                span = (
                    span.0.min(here[2]).min(end[2]),
                    span.1.max(here[2]).max(end[2]),
                );
            }
        }
        if let Some(e) = c.end() {
            here = [e[0], e[1], e[2]];
        }
    }
    Helix {
        radius: radius.expect("a helix about the centre"),
        lead: dz / (sweep / TAU),
        ccw: ccw.unwrap_or(true),
        span,
        turns: sweep / TAU,
    }
}

#[test]
fn f116_internal_thread_from_the_printed_call() {
    let r = go(&fixture("116")).ok();
    // CYCLE90(8, -20, 0, -60, 0, 46, 40, 3, 800, 3, 0, 50, 50) with T1 D1 (radius 10):
    // internal M46 × 3 about X50 Y50, G3, from RFP −20 down to −60 (the call as printed;
    // the text's "bottom-up to 0" does not match it).
    let h = helix(&r, (50.0, 50.0));
    assert!((h.radius + 10.0 - 23.0).abs() < 1e-9, "the edge cuts Ø46");
    assert!((h.lead + 3.0).abs() < 1e-9, "3 mm per turn, downwards");
    assert!(h.ccw);
    // The whole thread and half a pitch beyond each end.
    assert!(
        h.span.0 <= -61.5 + 1e-9 && h.span.1 >= -18.5 - 1e-9,
        "{:?}",
        h.span
    );
    assert!((h.turns - 43.0 / 3.0).abs() < 1e-9);
    // Out at RTP over the centre.
    assert!(near(&r.end(), &[50.0, 50.0, 8.0]));
}

#[test]
fn f117_an_undefined_dp_stops_the_call() {
    // The manual's program passes DP, which it never defines.
    let r = run(&fixture("117"));
    let e = r.error.expect("DP undefined");
    assert_eq!(e.number, 12550);
    assert!(e.text.contains("DP"));
    // Defined (0: DPR counts), the thread is milled: internal M60 × 2, G2, 40 deep from
    // RFP 40, with T5 D1's radius.
    let text = fixture("117").replace("DEF REAL PIT", "DEF REAL DP=0, PIT");
    let mut s = mill();
    s.offsets.tools.insert(
        51,
        cnc_interpreter_core::ToolOffset {
            z: 0.0,
            radius: 6.0,
            ..Default::default()
        },
    );
    let r = run_with(&text, s, Library::new()).ok();
    let h = helix(&r, (60.0, 50.0));
    assert!((h.radius + 6.0 - 30.0).abs() < 1e-9);
    assert!((h.lead + 2.0).abs() < 1e-9 && !h.ccw);
    assert!(
        h.span.0 <= -1.0 + 1e-9 && h.span.1 >= 41.0 - 1e-9,
        "{:?}",
        h.span
    );
    assert!(near(&r.end(), &[60.0, 50.0, 100.0]));
}

#[test]
fn external_threads_and_bottom_up_milling() {
    // External M30 × 1.5 on a spigot at X0 Y0, G2, 20 long from Z0, cutter radius 10: the
    // centre runs on R25; the approach comes from outside.
    let text = "G17 G90 T1 D1 S1000 M3\nG0 X40 Y40 Z10\nCYCLE90(10, 0, 2, -20, , 30, 26, 1.5, 300, 2, 1, 0, 0)\n";
    let r = go(text).ok();
    let h = helix(&r, (0.0, 0.0));
    assert!((h.radius - 10.0 - 15.0).abs() < 1e-9);
    assert!((h.lead + 1.5).abs() < 1e-9 && !h.ccw);
    // No feed move comes closer to the spigot's axis than the cutter's edge allows.
    let mut here = [40.0, 40.0, 10.0];
    for c in &r.out {
        if let Some(e) = c.end() {
            if matches!(c, Command::Linear { .. } | Command::Arc { .. }) {
                assert!(e[0].hypot(e[1]) >= 25.0 - 1e-9);
            }
            here = [e[0], e[1], e[2]];
        }
    }
    assert!((here[2] - 10.0).abs() < 1e-9, "out at RTP");
    // Bottom-up: RTP below the thread; the helix climbs from DP to RFP.
    let text = "G17 G90 T1 D1 S1000 M3\nG0 X0 Y0 Z-30\nCYCLE90(-30, 0, 0, -20, , 46, 40, 2, 300, 3, 0, 0, 0)\n";
    let r = go(text).ok();
    let h = helix(&r, (0.0, 0.0));
    assert!((h.lead - 2.0).abs() < 1e-9 && h.ccw, "upwards");
    assert!(h.span.0 <= -21.0 + 1e-9 && h.span.1 >= 1.0 - 1e-9);
}

#[test]
fn thread_milling_alarms() {
    let head = "G17 G90 S1000 M3\nG0 X0 Y0 Z10\n";
    // No cutting edge active: 61000.
    let r = go(&format!(
        "{head}CYCLE90(10, 0, 2, -20, , 46, 40, 2, 300, 3, 0, 0, 0)\n"
    ));
    assert_eq!(r.alarm(), (61000, 3));
    // A cutter too big for the core hole: 61105.
    let r = go(&format!(
        "{head}T1 D1\nCYCLE90(10, 0, 2, -20, , 24, 20, 2, 300, 3, 0, 0, 0)\n"
    ));
    assert_eq!(r.alarm(), (61105, 4));
    // No pitch: 61001; TYPTH 5: 61002.
    let r = go(&format!(
        "{head}T1 D1\nCYCLE90(10, 0, 2, -20, , 46, 40, 0, 300, 3, 0, 0, 0)\n"
    ));
    assert_eq!(r.alarm(), (61001, 4));
    let r = go(&format!(
        "{head}T1 D1\nCYCLE90(10, 0, 2, -20, , 46, 40, 2, 300, 3, 5, 0, 0)\n"
    ));
    assert_eq!(r.alarm(), (61002, 4));
}
