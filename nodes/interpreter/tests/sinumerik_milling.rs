//! Issue 24: the 802D's milling cycles that are built — CYCLE90, thread milling — on the
//! manual's fixtures 116 and 117 and on threads of both kinds and hands. The checker knows
//! only the parameters and the cutter: it follows the cutter's centre through the command
//! stream, takes the arcs about the thread's centre as the helix, and asserts their lead (the
//! advance per turn), their direction, and the diameter the cutter's edge cuts
//! (path radius ± cutter radius), and that the helix covers the thread's length.

#[path = "support/sinumerik.rs"]
mod support;

#[path = "support/stock.rs"]
mod stock;

use std::f64::consts::TAU;

use cnc_interpreter::{Command, Library};
use stock::*;
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

/// The arcs about `centre` in the stream, as one helix.
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

#[test]
fn f115_pocket4_helical_roughing_clears_the_pocket_to_its_floor_and_wall() {
    // POCKET4(3, 0, 0, -20, 25, 50, 60, 6, 0, 0, 200, 100, 1, 21, 0, 0, 0, 2, 3): R25 at
    // X50 Y60 to Z−20, MID 6, no allowances, conventional milling under M3 (inside a pocket: G2), helical
    // insertion R2 at 3 mm a turn, with a 20 mm cutter (T1 D1) of length 0.
    let r = go(&fixture("115")).ok();
    let mut stock = Stock::new((50.0, 60.0), 40.0, 0.0, 10.0, circle((50.0, 60.0), 25.0));
    stock.follow(&r.out, [50.0, 50.0, 0.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the wall R25");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -20.0, "floor");
    assert_within(hi, -20.0, "floor everywhere inside");
    assert_within(min, -20.0, "nothing deeper");
    // Cutting levels at most MID apart from RFP down.
    stock.assert_infeeds_within(0.0, 6.0);
    // Conventional under M3 inside a pocket: clockwise rings (D87; the engagement itself is
    // `sinumerik_milling_direction.rs`'s).
    assert!(r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Arc { .. }))
        .all(|c| matches!(
            c,
            Command::Arc {
                clockwise: true,
                ..
            }
        )));
    assert!(near(&r.end(), &[50.0, 60.0, 3.0]));
}

#[test]
fn pocket4_roughing_leaves_the_allowances_and_finishing_takes_them() {
    let head = "G17 G90 T1 D1 S800 M3\nG0 X0 Y0 Z10\n";
    // R30 to Z−12 from RFP 0, MID 5, FAL 1, FALD 0.5, climb (inside a pocket under M3: G3).
    let rough = "POCKET4(10, 0, 1, -12, 30, 0, 0, 5, 1, 0.5, 300, 100, 0, 11, 12)\n";
    let finish = "POCKET4(10, 0, 1, -12, 30, 0, 0, 5, 1, 0.5, 300, 100, 0, 12, 12)\n";
    let r = go(&format!("{head}{rough}")).ok();
    let mut stock = Stock::new((0.0, 0.0), 45.0, 0.0, 10.0, circle((0.0, 0.0), 29.0));
    stock.follow(&r.out, [0.0, 0.0, 10.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall, 1 mm inside R30");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -11.5, "the floor, 0.5 mm above DP");
    assert_within(hi, -11.5, "everywhere");
    assert_within(min, -11.5, "nothing deeper");
    assert!(r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Arc { .. }))
        .all(|c| matches!(
            c,
            Command::Arc {
                clockwise: false,
                ..
            }
        )));
    // Finishing after it: the wall and the floor on size, no rapid into what is left.
    let r = go(&format!("{head}{rough}{finish}")).ok();
    let mut stock = Stock::new((0.0, 0.0), 45.0, 0.0, 10.0, circle((0.0, 0.0), 30.0));
    stock.follow(&r.out, [0.0, 0.0, 10.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall R30");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -12.0, "the floor");
    assert_within(hi, -12.0, "everywhere");
    assert_within(min, -12.0, "nothing deeper");
}

#[test]
fn pocket4_alarms() {
    let head = "G17 G90 S800 M3\nG0 X0 Y0 Z10\n";
    let call = |vari: &str, prad: &str| {
        format!("POCKET4(10, 0, 1, -12, {prad}, 0, 0, 5, 0, 0, 300, 100, 0, {vari}, 0)\n")
    };
    // No cutting edge: 61000.
    assert_eq!(
        go(&format!("{head}{}", call("11", "30"))).alarm(),
        (61000, 3)
    );
    let head = format!("{head}T1 D1\n");
    // The cutter (R10) does not fit R9: 61105; VARI 13: 61002; CDIR 7: 61109.
    assert_eq!(
        go(&format!("{head}{}", call("11", "9"))).alarm(),
        (61105, 4)
    );
    assert_eq!(
        go(&format!("{head}{}", call("13", "30"))).alarm(),
        (61002, 4)
    );
    let r = go(&format!(
        "{head}POCKET4(10, 0, 1, -12, 30, 0, 0, 5, 0, 0, 300, 100, 7, 11, 0)\n"
    ));
    assert_eq!(r.alarm(), (61109, 4));
    // A helix wider than the pocket allows: 61108.
    let r = go(&format!(
        "{head}POCKET4(10, 0, 1, -12, 30, 0, 0, 5, 0, 0, 300, 100, 0, 21, 0, , , 25, 2)\n"
    ));
    assert_eq!(r.alarm(), (61108, 4));
}

/// The mill with T1 D1 a 10 mm cutter of length 0.
fn cutter5() -> cnc_interpreter::Setup {
    with_edge(11, 5.0)
}

#[test]
fn f114_pocket3_roughing_leaves_the_allowances_on_a_60_by_40_pocket() {
    // POCKET3(5, 0, 0.5, −17.5, 60, 40, 8, 60, 40, 0, 4, 0.75, 0.2, 1000, 750, 0, 11, 5):
    // 60 × 40 about X60 Y40, corners R8, to Z−17.5; MID 4, FAL 0.75, FALD 0.2, climb under
    // M4 (inside a pocket: G2), vertical insertion at F750, MIDA 5; a 10 mm cutter.
    let r = run_with(&fixture("114"), cutter5(), Library::new()).ok();
    let wall = rounded_rect((60.0, 40.0), 29.25, 19.25, 7.25, 0.0);
    let mut stock = Stock::new((60.0, 40.0), 40.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [60.0, 40.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the wall 0.75 inside");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -17.3, "the floor 0.2 above DP");
    assert_within(hi, -17.3, "everywhere");
    assert_within(min, -17.3, "nothing deeper");
    stock.assert_infeeds_within(0.0, 4.0);
    assert!(r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Arc { .. }))
        .all(|c| matches!(
            c,
            Command::Arc {
                clockwise: true,
                ..
            }
        )));
}

#[test]
fn pocket3_turned_helical_then_finished_on_size() {
    // 50 × 30 about X10 Y−5 turned 30°, corners R6, to Z−8 from RFP 0; helical insertion.
    let head = "G17 G90 T1 D1 S800 M3\nG0 X10 Y-5 Z10\n";
    let call = |vari: u32| {
        format!("POCKET3(10, 0, 1, -8, 50, 30, 6, 10, -5, 30, 3, 0.5, 0.3, 400, 150, 3, {vari}, 6, , , , 3, 1.5)\n")
    };
    let r = run_with(&format!("{head}{}", call(21)), cutter5(), Library::new()).ok();
    let stock = turned_pocket(&r.out, 0.5);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "roughed wall");
    let (lo, hi, _) = stock.floor_within(0.01);
    assert_within(lo, -7.7, "roughed floor");
    assert_within(hi, -7.7, "everywhere");
    let text = format!("{head}{}{}", call(21), call(22));
    let r = run_with(&text, cutter5(), Library::new()).ok();
    let stock = turned_pocket(&r.out, 0.0);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "finished wall");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -8.0, "finished floor");
    assert_within(hi, -8.0, "everywhere");
    assert_within(min, -8.0, "nothing deeper");
}

#[test]
fn f109_cycle76_clears_the_blank_round_a_turned_spigot() {
    // CYCLE76(10, 0, 2, −17.5, , 60, 40, 15, 80, 60, 10, 11, , , 900, 800, 0, 1, 80, 50):
    // 60 × 40, corners R15, about X80 Y60 turned 10°, to Z−17.5 in levels within 11, from a
    // blank 80 × 50, climb under M3 (round a spigot: G2); T20 D1 a 12 mm cutter.
    let r = run_with(&fixture("109"), with_edge(201, 6.0), Library::new()).ok();
    let spigot = rounded_rect((80.0, 60.0), 30.0, 20.0, 15.0, 10.0);
    let blank = rounded_rect((80.0, 60.0), 40.0, 25.0, 0.0, 10.0);
    // The cutter may go anywhere outside the spigot: the "wall" is the spigot, inside out.
    let mut stock = Stock::new((80.0, 60.0), 60.0, 0.0, 6.0, move |p| -spigot(p));
    stock.follow(&r.out, [100.0, 100.0, 0.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the spigot's wall");
    let spigot = rounded_rect((80.0, 60.0), 30.0, 20.0, 15.0, 10.0);
    let (lo, hi) = stock.floor_where(|q| spigot(q) >= 0.01 && blank(q) <= 0.0);
    assert_within(lo, -17.5, "the blank cleared to the floor");
    assert_within(hi, -17.5, "everywhere round the spigot");
    let (lo, _) = stock.floor_where(|q| spigot(q) <= -0.01);
    assert!(lo >= 0.0 - 1e-9, "nothing cut inside the spigot");
    assert!(r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Arc { center, .. } if (center[0] - 80.0).abs() < 40.0))
        .any(|c| matches!(
            c,
            Command::Arc {
                clockwise: true,
                ..
            }
        )));
}

#[test]
fn f110_cycle77_roughs_with_an_allowance_then_finishes_to_50() {
    // T1 D1 roughs Ø50 at X60 Y70 from a Ø55 blank to Z−20 leaving 0.5; T2 D1 finishes.
    let mut s = with_edge(11, 8.0);
    s.offsets.tools.insert(
        21,
        cnc_interpreter_core::ToolOffset {
            radius: 5.0,
            ..Default::default()
        },
    );
    let text = fixture("110");
    let rough: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    let r = run_with(&rough, s.clone(), Library::new()).ok();
    let mut stock = Stock::new((60.0, 70.0), 45.0, 0.0, 8.0, circle((60.0, 70.0), -1.0));
    stock.wall = Box::new(|p| 25.5 - (p.0 - 60.0).hypot(p.1 - 70.0));
    stock.follow(&r.out, [0.0, 0.0, 10.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall 0.5 outside Ø50");
    let ring = |q: (f64, f64)| {
        let d = (q.0 - 60.0).hypot(q.1 - 70.0);
        (25.51..=27.5).contains(&d)
    };
    let (lo, hi) = stock.floor_where(ring);
    assert_within(lo, -20.0, "floor");
    assert_within(hi, -20.0, "floor all round");
    // Conventional under M3 round a spigot: G3.
    assert!(r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Arc { center, .. } if (center[0] - 60.0).abs() < 1e-9 && (center[1] - 70.0).abs() < 1e-9))
        .all(|c| matches!(c, Command::Arc { clockwise: false, .. })));
    let r = run_with(&text, s, Library::new()).ok();
    let mut stock = Stock::new((60.0, 70.0), 45.0, 0.0, 8.0, circle((60.0, 70.0), -1.0));
    stock.wall = Box::new(|p| 25.0 - (p.0 - 60.0).hypot(p.1 - 70.0));
    // Both cutters: the stock follows the first with R8, then the second with R5.
    let split = r.lines.iter().position(|l| *l >= 4).unwrap();
    stock.follow(&r.out[..split], [0.0, 0.0, 10.0]);
    stock.radius = 5.0;
    let here = r.out[..split]
        .iter()
        .rev()
        .find_map(|c| c.end())
        .unwrap()
        .to_vec();
    stock.follow(&r.out[split..], [here[0], here[1], here[2]]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall at Ø50");
    let (lo, hi) = stock.floor_where(|q| {
        let d = (q.0 - 60.0).hypot(q.1 - 70.0);
        (25.01..=27.5).contains(&d)
    });
    assert_within(lo, -20.0, "floor");
    assert_within(hi, -20.0, "floor all round");
}

#[test]
fn f106_cycle71_faces_a_turned_rectangle_in_two_levels() {
    // CYCLE71(10, 0, 2, −11, 100, 100, 60, 40, 10, 6, 10, 5, 0, 4000, 31, 2): the face from
    // the corner X100 Y100, 60 × 40 turned 10°, to Z−11 within MID 6, passes along the 1st
    // axis back and forth at most MIDA 10 apart, overrun 2; T2 D2 a 20 mm cutter.
    let r = run_with(&fixture("106"), with_edge(22, 10.0), Library::new()).ok();
    // The rectangle's centre in its frame is (30, 20) from the corner.
    let (s, c) = 10f64.to_radians().sin_cos();
    let centre = (100.0 + 30.0 * c - 20.0 * s, 100.0 + 30.0 * s + 20.0 * c);
    let face = rounded_rect(centre, 30.0, 20.0, 0.0, 10.0);
    let inside = move |q: (f64, f64)| face(q) <= 0.0;
    let mut stock = Stock::new(centre, 70.0, 0.0, 10.0, |_| -1.0).only(inside);
    stock.follow(&r.out, [0.0, 0.0, 20.0]);
    assert_eq!(stock.rapid_cuts, 0, "down and across only outside the face");
    let face = rounded_rect(centre, 30.0, 20.0, 0.0, 10.0);
    let (lo, hi) = stock.floor_where(|q| face(q) <= 0.0);
    assert_within(lo, -11.0, "the face at Z−11");
    assert_within(hi, -11.0, "everywhere");
    let levels = stock.assert_infeeds_within(0.0, 6.0);
    assert_eq!(levels.len(), 2, "{levels:?}");
    assert_within(levels[0], -5.5, "half way");
    assert!(
        near(&r.end(), &[0.0, 0.0, 10.0]),
        "N40 G0 X0 Y0 (Z stays at RTP): {:?}",
        r.end()
    );
}

#[test]
fn cycle71_finishing_one_way_and_its_alarms() {
    // Roughing leaving FALD 0.4, then finishing along the 2nd axis one way.
    let head = "G17 G90 T1 D1 S2000 M3\nG0 X-50 Y-50 Z20\n";
    let rough = "CYCLE71(20, 5, 2, -3, 0, 0, 80, -50, 0, 4, 12, 3, 0.4, 3000, 11, 3)\n";
    let finish = "CYCLE71(20, 5, 2, -3, 0, 0, 80, -50, 0, 4, 12, 3, 0.4, 3000, 22, 3)\n";
    let s = with_edge(11, 8.0);
    let r = run_with(&format!("{head}{rough}"), s.clone(), Library::new()).ok();
    let face = rounded_rect((40.0, -25.0), 40.0, 25.0, 0.0, 0.0);
    let mut stock =
        Stock::new((40.0, -25.0), 70.0, 5.0, 8.0, |_| -1.0).only(move |q| face(q) <= 0.0);
    stock.follow(&r.out, [-50.0, -50.0, 20.0]);
    assert_eq!(stock.rapid_cuts, 0);
    let face = rounded_rect((40.0, -25.0), 40.0, 25.0, 0.0, 0.0);
    let (lo, hi) = stock.floor_where(|q| face(q) <= 0.0);
    assert_within(lo, -2.6, "roughed, FALD left");
    assert_within(hi, -2.6, "everywhere");
    let r = run_with(&format!("{head}{rough}{finish}"), s.clone(), Library::new()).ok();
    let face = rounded_rect((40.0, -25.0), 40.0, 25.0, 0.0, 0.0);
    let mut stock =
        Stock::new((40.0, -25.0), 70.0, 5.0, 8.0, |_| -1.0).only(move |q| face(q) <= 0.0);
    stock.follow(&r.out, [-50.0, -50.0, 20.0]);
    assert_eq!(stock.rapid_cuts, 0);
    let face = rounded_rect((40.0, -25.0), 40.0, 25.0, 0.0, 0.0);
    let (lo, hi) = stock.floor_where(|q| face(q) <= 0.0);
    assert_within(lo, -3.0, "finished");
    assert_within(hi, -3.0, "everywhere");
    // VARI 15: 61002; MIDA wider than the cutter: 61111; a face of no width: 61118.
    for (call, alarm) in [
        (
            "CYCLE71(20, 5, 2, -3, 0, 0, 80, -50, 0, 4, 12, 3, 0.4, 3000, 15, 3)",
            61002,
        ),
        (
            "CYCLE71(20, 5, 2, -3, 0, 0, 80, -50, 0, 4, 20, 3, 0.4, 3000, 11, 3)",
            61111,
        ),
        (
            "CYCLE71(20, 5, 2, -3, 0, 0, 80, 0, 0, 4, 12, 3, 0.4, 3000, 11, 3)",
            61118,
        ),
    ] {
        let r = run_with(&format!("{head}{call}\n"), s.clone(), Library::new());
        assert_eq!(r.alarm(), (alarm, 3), "{call}");
    }
}

#[test]
fn f111_longhole_in_g19_mills_four_holes_along_x() {
    // LONGHOLE(5, 0, 1, , 23, 4, 30, 40, 45, 20, 45, 90, 100, 320, 6) in G19: four holes 30
    // long on the circle R20 about Y40 Z45 from 45° every 90°, 23 deep along −X, MID 6;
    // T10 D9 a 12 mm cutter (the hole's width).
    let r = run_with(&fixture("111"), with_edge(109, 6.0), Library::new()).ok();
    let wall = slots_wall(
        (40.0, 45.0),
        20.0,
        vec![45.0, 135.0, 225.0, 315.0],
        15.0,
        6.0,
    );
    let mut stock = Stock::new((40.0, 45.0), 45.0, 0.0, 6.0, wall);
    stock.follow_axes(&r.out, [50.0, 25.0, 5.0], (1, 2, 0));
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the holes' walls");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -23.0, "floor");
    assert_within(hi, -23.0, "every hole to the floor");
    assert_within(min, -23.0, "nothing deeper");
    // Plunges at most MID 6: four of 5.75.
    let plunges: Vec<f64> = r
        .out
        .windows(2)
        .filter_map(|w| match (&w[0], &w[1]) {
            (_, Command::Linear { end, feed }) if *feed == 100.0 => Some(end[0]),
            _ => None,
        })
        .collect();
    assert!(plunges.len() >= 16, "{plunges:?}");
}

#[test]
fn f112_slot1_roughs_and_finishes_four_slots() {
    // SLOT1(5, 0, 1, −23, , 4, 30, 15, 40, 45, 20, 45, 90, 100, 320, 6, 2, 0.5, 0, , 0, ):
    // four slots 30 × 15 on R20 about X40 Y45 from 45° every 90°, to Z−23 within MID 6, G2,
    // FAL 0.5, roughing and finishing; T1 D1 a 10 mm cutter.
    let r = run_with(&fixture("112"), cutter5(), Library::new()).ok();
    let wall = slots_wall(
        (40.0, 45.0),
        20.0,
        vec![45.0, 135.0, 225.0, 315.0],
        15.0,
        7.5,
    );
    let mut stock = Stock::new((40.0, 45.0), 45.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [20.0, 50.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the slots' walls");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -23.0, "floor");
    assert_within(hi, -23.0, "every slot to the floor");
    assert_within(min, -23.0, "nothing deeper");
    // Roughing alone stops 0.5 inside the wall.
    let rough = fixture("112").replace(", 0.5, 0, , 0, )", ", 0.5, 1, , 0, )");
    let r = run_with(&rough, cutter5(), Library::new()).ok();
    let wall = slots_wall(
        (40.0, 45.0),
        20.0,
        vec![45.0, 135.0, 225.0, 315.0],
        14.5,
        7.0,
    );
    let mut stock = Stock::new((40.0, 45.0), 45.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [20.0, 50.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "0.5 inside the walls");
    // Slots that overlap: 61104; a cutter as wide as the slot: 61105.
    let r = run_with(
        &fixture("112").replace(
            "SLOT1(5, 0, 1, -23, , 4, 30, 15, 40, 45, 20, 45, 90",
            "SLOT1(5, 0, 1, -23, , 4, 30, 15, 40, 45, 5, 45, 90",
        ),
        cutter5(),
        Library::new(),
    );
    assert_eq!(r.alarm().0, 61104);
    let r = run_with(&fixture("112"), with_edge(11, 7.5), Library::new());
    assert_eq!(r.alarm().0, 61105);
}

#[test]
fn f113_slot2_mills_three_slots_along_the_circle() {
    // SLOT2(2, 0, 2, −23, , 3, 70, 15, 60, 60, 42, , 120, 100, 300, 6, 2, 0.5, 0, , 0, ):
    // three slots 15 wide over 70° of the circle R42 about X60 Y60, from 0° every 120°, to
    // Z−23 within MID 6, G2, FAL 0.5, roughed and finished; a 10 mm cutter.
    let r = run_with(&fixture("113"), cutter5(), Library::new()).ok();
    let wall = arc_slots_wall((60.0, 60.0), 42.0, vec![0.0, 120.0, 240.0], 70.0, 7.5);
    let mut stock = Stock::new((60.0, 60.0), 55.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [60.0, 60.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the slots' walls");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -23.0, "floor");
    assert_within(hi, -23.0, "every slot to the floor");
    assert_within(min, -23.0, "nothing deeper");
    // Roughing alone stops 0.5 inside.
    let rough = fixture("113").replace(", 0.5, 0, , 0, )", ", 0.5, 1, , 0, )");
    let r = run_with(&rough, cutter5(), Library::new()).ok();
    let wall = arc_slots_wall((60.0, 60.0), 42.0, vec![0.0, 120.0, 240.0], 70.0, 7.0);
    let mut stock = Stock::new((60.0, 60.0), 55.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [60.0, 60.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "0.5 inside the walls");
    // Slots that would overlap (over 120° each, 120° apart): 61104.
    let r = run_with(
        &fixture("113").replace(", 3, 70, 15,", ", 3, 115, 15,"),
        cutter5(),
        Library::new(),
    );
    assert_eq!(r.alarm().0, 61104);
}

#[test]
fn f107_f108_cycle72_mills_round_the_contour_from_a_subprogram_or_labels() {
    // CYCLE72(…, 250, 200, 3, 175, 10, 1, 1.5, 800, 400, VARI, 41, 2, 20, 1000, 2, 20): the
    // contour from outside (G41 on a clockwise contour), quarter circles R20 in and out,
    // roughing to Z175 + 1.5 within 10 mm, 1 mm left in the plane; T3 D1 a 14 mm cutter.
    let text = fixture("107");
    let (main, sub) = text.split_once("%_N_EX72CONTOUR_SPF").unwrap();
    let sub = sub.split_once('\n').unwrap().1;
    let mut lib = Library::new();
    lib.insert_named("EX72CONTOUR", "EX72CONTOUR.SPF", sub);
    // The listing as printed, in the transfer format: its EX72CONTOUR section is the
    // subprogram (D95).
    for (program, library) in [
        (main.to_string(), lib),
        (fixture("108"), Library::new()),
        (fixture("107"), Library::new()),
    ] {
        let r = run_with(&program, with_edge(31, 7.0), library).ok();
        let out = outside_of(contour_107());
        let mut stock = Stock::new((180.0, 120.0), 90.0, 200.0, 7.0, move |p| 1.0 - out(p));
        stock.follow(&r.out, [100.0, 200.0, 250.0]);
        assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
        assert_within(stock.reach, 0.0, "the contour 1 mm out");
        let out = outside_of(contour_107());
        let (lo, hi) = stock.floor_where(|q| (1.01..=8.0).contains(&out(q)));
        assert_within(lo, 176.5, "down to Z175 + 1.5");
        assert_within(hi, 176.5, "all round");
        let levels = stock.assert_infeeds_within(200.0, 10.0);
        assert_eq!(levels.len(), 3, "{levels:?}");
        assert!(near(&r.end(), &[100.0, 200.0, 250.0]), "{:?}", r.end());
    }
}

#[test]
fn variants_slot1_finishing_alone_cycle71_along_the_2nd_axis_cycle72_finishing_and_g40() {
    // SLOT1 roughed (VARI 1), then finished by a call of its own (VARI 2): the walls on size.
    let rough = fixture("112").replace(", 0.5, 0, , 0, )", ", 0.5, 1, , 0, )");
    let finish = fixture("112")
        .replace(", 0.5, 0, , 0, )", ", 0.5, 2, , 0, )")
        .replace("N40 M02", "");
    let text = format!(
        "{}{}",
        rough.replace("N40 M02", ""),
        finish
            .lines()
            .skip(2)
            .map(|l| format!("{l}\n"))
            .collect::<String>()
    );
    let r = run_with(&text, cutter5(), Library::new()).ok();
    let wall = slots_wall(
        (40.0, 45.0),
        20.0,
        vec![45.0, 135.0, 225.0, 315.0],
        15.0,
        7.5,
    );
    let mut stock = Stock::new((40.0, 45.0), 45.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [20.0, 50.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "finished walls");
    let (lo, hi, _) = stock.floor_within(0.01);
    assert_within(lo, -23.0, "floor");
    assert_within(hi, -23.0, "floor");
    // CYCLE71 roughing along the 2nd axis one way (21) and back and forth (41).
    for vari in [21, 41] {
        let text = format!(
            "G17 G90 T1 D1 S2000 M3\nG0 X-50 Y-50 Z20\nCYCLE71(20, 5, 2, -3, 0, 0, 60, 40, 0, 4, 12, 3, 0, 3000, {vari}, 3)\n"
        );
        let r = run_with(&text, with_edge(11, 8.0), Library::new()).ok();
        let face = rounded_rect((30.0, 20.0), 30.0, 20.0, 0.0, 0.0);
        let mut stock =
            Stock::new((30.0, 20.0), 60.0, 5.0, 8.0, |_| -1.0).only(move |q| face(q) <= 0.0);
        stock.follow(&r.out, [-50.0, -50.0, 20.0]);
        assert_eq!(stock.rapid_cuts, 0, "VARI {vari}");
        let face = rounded_rect((30.0, 20.0), 30.0, 20.0, 0.0, 0.0);
        let (lo, hi) = stock.floor_where(|q| face(q) <= 0.0);
        assert_within(lo, -3.0, "faced");
        assert_within(hi, -3.0, "everywhere");
        stock.assert_infeeds_within(5.0, 4.0);
    }
    // CYCLE72 roughed (VARI 111) then finished (VARI 212: retract by SDIS between levels),
    // the contour of 108 on size all round at Z175.
    let text = fixture("108");
    let finish = text.replace(
        ", 11, 41, 2, 20, 1000, 2, 20)",
        ", 212, 41, 2, 20, 1000, 2, 20)",
    );
    let both = text.replace(
        "N50 X100 Y200",
        &finish
            .lines()
            .find(|l| l.contains("CYCLE72"))
            .unwrap()
            .replace("N40", "N45"),
    );
    let r = run_with(&both, with_edge(31, 7.0), Library::new()).ok();
    let out = outside_of(contour_107());
    let mut stock = Stock::new((180.0, 120.0), 90.0, 200.0, 7.0, move |p| -out(p));
    stock.follow(&r.out, [100.0, 200.0, 250.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the contour on size");
    let out = outside_of(contour_107());
    let (lo, hi) = stock.floor_where(|q| (0.01..=7.0).contains(&out(q)));
    assert_within(lo, 175.0, "finished down to DP");
    assert_within(hi, 175.0, "all round");
    // RL 40: the centre on the contour, straight approach only; a quarter circle is 61115.
    let g40 = text.replace(
        ", 11, 41, 2, 20, 1000, 2, 20)",
        ", 11, 40, 1, 20, 1000, 1, 20)",
    );
    let r = run_with(&g40, with_edge(31, 7.0), Library::new()).ok();
    let ends: Vec<(f64, f64)> = r
        .moves()
        .iter()
        .filter_map(|c| c.end().map(|e| (e[0], e[1])))
        .collect();
    for corner in contour_107().iter().take(6) {
        assert!(
            ends.iter().any(|e| dist(*e, *corner) < 1e-6),
            "the cutter's centre at {corner:?}"
        );
    }
    let bad = text.replace(
        ", 11, 41, 2, 20, 1000, 2, 20)",
        ", 11, 40, 2, 20, 1000, 2, 20)",
    );
    assert_eq!(
        run_with(&bad, with_edge(31, 7.0), Library::new()).alarm().0,
        61115
    );
}

/// Issue 46 item 3: where each milling cycle leaves the tool, where its section says. CYCLE72
/// (§10.6.3): after roughing above the departure point at RTP, after finishing at the
/// contour's start point at RTP. CYCLE71 (§10.6.2), LONGHOLE (§10.6.6), SLOT1 (§10.6.7),
/// SLOT2 (§10.6.8), CYCLE76/77 (§10.6.4–5) and CYCLE90 external (§10.6.11): at G0 from the
/// last position in the plane back to RTP. CYCLE90 internal: to the thread's centre, then to
/// RTP.
#[test]
fn each_milling_cycle_ends_where_its_section_says() {
    let cutter = || with_edge(11, 5.0);
    let head = "G17 G90 T1 D1 S1000 M3\nG0 X0 Y0 Z20\n";
    // The last cutting move's end in the plane, and where the run ends.
    let ends = |r: &Run| {
        let last_cut = r
            .out
            .iter()
            .rev()
            .find(|c| matches!(c, Command::Linear { .. } | Command::Arc { .. }))
            .and_then(|c| c.end())
            .expect("a cut")
            .to_vec();
        (last_cut, r.end())
    };
    let above_the_last_cut = |what: &str, r: &Run, rtp: f64| {
        let (cut, end) = ends(r);
        assert!(
            near(&end, &[cut[0], cut[1], rtp]),
            "{what}: ends at {end:?}, its last cut at {cut:?}"
        );
    };
    for (what, call) in [
        (
            "CYCLE71",
            "CYCLE71(10, 0, 2, -2, 0, 0, 60, 40, 0, 2, 8, 5, 0, 300, 31, 5)",
        ),
        (
            "LONGHOLE",
            "LONGHOLE(10, 0, 2, -6, , 2, 30, 40, 45, 20, 45, 90, 100, 320, 6)",
        ),
        (
            "SLOT1",
            "SLOT1(10, 0, 2, -6, , 2, 30, 15, 40, 45, 20, 45, 90, 100, 320, 6, 2, 0.5, 0, , 0, )",
        ),
        (
            "SLOT2",
            "SLOT2(10, 0, 2, -6, , 2, 70, 15, 60, 60, 42, 0, 120, 100, 300, 6, 2, 0.5, 0, , 0, )",
        ),
        (
            "CYCLE77",
            "CYCLE77(10, 0, 2, -6, , 40, 50, 40, 6, 0, 0, 300, 100, 0, 1, 56)",
        ),
        (
            "CYCLE76",
            "CYCLE76(10, 0, 2, -6, , 40, 30, 6, 50, 40, 20, 6, 0, 0, 300, 100, 0, 1, 60, 50)",
        ),
        (
            "CYCLE90 external",
            "CYCLE90(10, 0, 2, -10, , 20, 17.3, 2.5, 200, 2, 1, 50, 40)",
        ),
    ] {
        let r = run_with(&format!("{head}{call}\nM30\n"), cutter(), Library::new()).ok();
        above_the_last_cut(what, &r, 10.0);
    }
    let r = run_with(
        &format!("{head}CYCLE90(10, 0, 2, -10, , 20, 17.3, 2.5, 200, 2, 0, 50, 40)\nM30\n"),
        cutter(),
        Library::new(),
    )
    .ok();
    assert!(
        near(&r.end(), &[50.0, 40.0, 10.0]),
        "CYCLE90 internal: {:?}",
        r.end()
    );
    // CYCLE72 round a 40 × 30 block from X30 Y40.
    let contour = || {
        let mut lib = Library::new();
        lib.insert_named(
            "BLOCK",
            "BLOCK.SPF",
            "G1 X30 Y40\nY55\nX70\nY25\nX30\nY40\nM2\n",
        );
        lib
    };
    let cycle72 = |vari: u32| {
        format!(
            "{head}CYCLE72(\"BLOCK\", 10, 0, 2, -6, 6, 0, 0, 300, 100, {vari}, 41, 2, 12, 300, 2, 12)\nM30\n"
        )
    };
    let r = run_with(&cycle72(1), cutter(), contour()).ok();
    above_the_last_cut("CYCLE72 roughing", &r, 10.0);
    let r = run_with(&cycle72(2), cutter(), contour()).ok();
    assert!(
        near(&r.end(), &[30.0, 40.0, 10.0]),
        "CYCLE72 finishing: at the contour's start at RTP, not {:?}",
        r.end()
    );
}
