//! Issue 23: threads, tapping and the positioned spindle on the 802D mill: G33 with its lead
//! as I/J/K and SF= (`001` §9.3.7, fixture 028), G63 tapping with a compensating chuck
//! (§9.3.8, fixture 029), SPOS (§9.4.3, fixture 051) and G153 (§9.2.10). The fixtures are
//! templates: their placeholders are filled here (`support::filled`), every printed line
//! kept. Decisions D93, D100.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Aux, Command, Library};
use cnc_interpreter_core::Turn;
use support::*;

/// The thread moves of a run as (end, lead, start angle).
fn threads(r: &Run) -> Vec<(Vec<f64>, f64, f64)> {
    r.out
        .iter()
        .filter_map(|c| match c {
            Command::Thread {
                end,
                lead,
                start_angle,
            } => Some((end.clone(), *lead, *start_angle)),
            _ => None,
        })
        .collect()
}

fn index(r: &Run, c: &Command) -> usize {
    r.out
        .iter()
        .position(|x| x == c)
        .unwrap_or_else(|| panic!("{c:?} in {:?}", r.out))
}

#[test]
fn f028_g33_taps_m5_down_to_z_minus_25_and_back_with_m4() {
    // N50 G0 X... Y... Z... filled: away to X0 Y0 Z50.
    let text = filled("028", &["N50 G0 X0 Y0 Z50"]);
    let r = run_with(&text, mill(), Library::new()).ok();
    // The tool T0 (none) of mill(): machine Z is the program's Z, G54 is zero.
    let t = threads(&r);
    assert_eq!(t.len(), 2, "{:?}", r.out);
    assert!(near(&t[0].0, &[10.0, 10.0, -25.0]));
    assert!(near(&t[1].0, &[10.0, 10.0, 5.0]));
    for (_, lead, angle) in &t {
        assert_eq!(*lead, 0.8);
        assert_eq!(*angle, 0.0);
    }
    // 600 rpm × 0.8 mm = 480 mm/min along Z (the header's figure).
    assert!((600.0 * t[0].1 - 480.0).abs() < 1e-9);
    // M3 and S600 before the approach, M4 before the way back, then the rapid away.
    let down = r
        .out
        .iter()
        .position(|c| matches!(c, Command::Thread { .. }))
        .unwrap();
    let approach = index(
        &r,
        &Command::Rapid {
            end: vec![10.0, 10.0, 5.0],
        },
    );
    assert!(index(&r, &Command::Aux(Aux::M(3))) < approach);
    assert!(index(&r, &Command::Aux(Aux::S(600.0))) < approach);
    let m4 = index(&r, &Command::Aux(Aux::M(4)));
    assert!(down < m4 && m4 < down + 2, "M4 between the two threads");
    assert_eq!(r.end(), vec![0.0, 0.0, 50.0]);
}

#[test]
fn f029_g63_taps_at_f480_locked_to_the_spindle_and_the_old_interpolation_returns() {
    let text = filled("029", &["N50 X0 Y0 Z50"]);
    let r = run_with(&text, mill(), Library::new()).ok();
    let t = threads(&r);
    assert_eq!(t.len(), 2, "{:?}", r.out);
    // F480 at S600: 0.8 mm per revolution, down and (M4) back.
    assert!(near(&t[0].0, &[10.0, 10.0, -25.0]));
    assert!(near(&t[1].0, &[10.0, 10.0, 5.0]));
    assert!((t[0].1 - 0.8).abs() < 1e-12 && (t[1].1 - 0.8).abs() < 1e-12);
    // G63 is non-modal: N50 runs in G0 again, as N10 left it.
    assert_eq!(
        r.moves().last().copied(),
        Some(&Command::Rapid {
            end: vec![0.0, 0.0, 50.0]
        })
    );
    let m4 = index(&r, &Command::Aux(Aux::M(4)));
    let second = r
        .out
        .iter()
        .rposition(|c| matches!(c, Command::Thread { .. }))
        .unwrap();
    assert!(m4 < second);
}

#[test]
fn g33_start_angle_inches_taper_and_its_alarms() {
    // SF= shifts the start (modal); under G70 the lead is in inches; a taper takes the lead
    // of its longer axis.
    let r = run("G0 X0 Y0 Z5 S500 M3\nG33 Z-20 K1.5 SF=90\nG0 Z5\nG33 Z-20 K1.5\nG70 G33 Z-1 K0.05\nG71 G33 X4 Z-30 K2\n").ok();
    let t = threads(&r);
    assert_eq!(t.len(), 4);
    assert_eq!((t[0].1, t[0].2), (1.5, 90.0));
    assert_eq!(t[1].2, 90.0, "SF stays");
    assert!((t[2].1 - 0.05 * 25.4).abs() < 1e-12);
    assert!(near(&t[2].0, &[0.0, 0.0, -25.4]));
    assert_eq!(t[3].1, 2.0);
    // Alarms: no lead word of the long axis, a circle word, an angle outside 0…360, no end.
    assert_eq!(run("S500 M3\nG33 Z-20 I1.5\n").alarm(), (12080, 2));
    assert_eq!(run("S500 M3\nG33 Z-20 K1 CR=5\n").alarm(), (12080, 2));
    assert_eq!(run("S500 M3\nG33 Z-20 K1 SF=400\n").alarm(), (17020, 2));
    assert_eq!(run("S500 M3\nG33 K1\n").alarm(), (12080, 2));
    assert_eq!(run("S500 M3\nG33 Z-20 K0\n").alarm().1, 2);
    // G63 without S has no pitch; with a lead word it is refused.
    assert_eq!(run("G63 Z-20 F480\n").alarm(), (14800, 1));
    assert_eq!(run("S600 M3\nG63 Z-20 F480 K0.8\n").alarm(), (12080, 2));
    // Under G95 F is the pitch itself.
    let r = run("S600 M3 G95\nG63 Z-20 F0.8\n").ok();
    assert_eq!(threads(&r)[0].1, 0.8);
}

#[test]
fn g153_is_g53_without_a_basic_frame() {
    let mut s = mill();
    s.offsets
        .work
        .insert(0, [('X', 100.0), ('Y', 50.0)].into_iter().collect());
    let a = run_with("G54 G0 X0 Y0\nG153 X10 Y20\n", s.clone(), Library::new()).ok();
    let b = run_with("G54 G0 X0 Y0\nG53 X10 Y20\n", s, Library::new()).ok();
    assert_eq!(a.out, b.out);
    assert_eq!(a.end(), vec![10.0, 20.0, 0.0]);
}

fn orient(degrees: f64, way: Turn) -> Command {
    Command::Aux(Aux::Orient { degrees, way })
}

/// 051 (§9.4.3): N10 positions the spindle at 14.3°; N80 positions it at 25.6° with its
/// axes (before them, D100) and N81 moves only after both. The placeholder is filled with
/// the spindle turning at S800, so N80's positioning starts from M3.
#[test]
fn f051_spos_positions_the_spindle_before_the_axes_of_its_block_move() {
    let text = filled("051", &["N20 S800 M3 G0 X10 Z100"]);
    let r = run_with(&text, mill(), Library::new()).ok();
    let first = index(&r, &orient(14.3, Turn::Shortest));
    let second = index(&r, &orient(25.6, Turn::Shortest));
    let m3 = index(&r, &Command::Aux(Aux::M(3)));
    let n80 = index(
        &r,
        &Command::Rapid {
            end: vec![89.0, 0.0, 300.0],
        },
    );
    let n81 = index(
        &r,
        &Command::Rapid {
            end: vec![200.0, 0.0, 300.0],
        },
    );
    assert!(
        first < m3 && m3 < second && second < n80 && n80 < n81,
        "{:?}",
        r.out
    );
    assert_eq!(r.lines[second], line_of(&text, "N80"));
    assert_eq!(r.end(), vec![200.0, 0.0, 300.0]);
}

/// §9.4.3, §9.2.1 (AC/IC/DC/ACP/ACN): every form of SPOS; a value outside its range stops
/// with the range alarm (17020, as SF= does) and the reason.
#[test]
fn spos_takes_each_way_and_refuses_an_angle_out_of_range() {
    let r = run(
        "SPOS=DC(33.1)\nSPOS=ACP(33.1)\nSPOS=ACN(33.1)\nSPOS=IC(-720.5)\nG91 SPOS=AC(10)\nSPOS=359.999\nR1=90 SPOS=R1/2\n",
    )
    .ok();
    let spos: Vec<&Command> = r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Aux(Aux::Orient { .. })))
        .collect();
    assert_eq!(
        spos,
        [
            &orient(33.1, Turn::Shortest),
            &orient(33.1, Turn::Plus),
            &orient(33.1, Turn::Minus),
            &orient(-720.5, Turn::Incremental),
            &orient(10.0, Turn::Shortest),
            &orient(359.999, Turn::Shortest),
            &orient(45.0, Turn::Shortest),
        ]
    );
    for bad in [
        "SPOS=360",
        "SPOS=-1",
        "SPOS=ACP(400)",
        "SPOS=IC(100000)",
        "SPOS=DC(-0.5)",
    ] {
        let r = run(&format!("G0 X1\n{bad}\n"));
        let e = r.error.as_ref().unwrap_or_else(|| panic!("{bad} refused"));
        assert_eq!((e.number, e.line), (17020, 2), "{bad}: {e:?}");
        assert!(e.text.contains("spindle position"), "{bad}: {}", e.text);
    }
    // A rotary mode on a linear axis is refused with its reason (D109).
    assert_eq!(run("X=DC(10)\n").alarm().0, 12080);
}

fn taps(r: &Run) -> Vec<(Vec<f64>, f64, f64)> {
    r.out
        .iter()
        .filter_map(|c| match c {
            Command::Tap { end, lead, rpm } => Some((end.clone(), *lead, *rpm)),
            _ => None,
        })
        .collect()
}

/// 030 (§9.3.9): SPOS=0 puts the spindle in position control, G331 taps M5 (K0.8, the way M3
/// turns) to Z−25 at S600, G332 comes back to Z5 turning the other way at the same pitch
/// (D101). The placeholder is filled with the rapid away.
#[test]
fn f030_g331_taps_to_z_minus_25_with_the_positioned_spindle_and_g332_reverses() {
    let text = filled("030", &["N50 G0 X0 Y0 Z50"]);
    let r = run_with(&text, mill(), Library::new()).ok();
    let t = taps(&r);
    assert_eq!(
        t,
        [
            (vec![10.0, 10.0, -25.0], 0.8, 600.0),
            (vec![10.0, 10.0, 5.0], -0.8, 600.0),
        ]
    );
    let spos = index(&r, &orient(0.0, Turn::Shortest));
    let down = r
        .out
        .iter()
        .position(|c| matches!(c, Command::Tap { .. }))
        .unwrap();
    assert!(spos < down);
    assert_eq!(r.lines[down], line_of(&text, "N20"));
    // No M3/M4: the spindle turns only as the tap's positioning.
    assert!(!r
        .out
        .iter()
        .any(|c| matches!(c, Command::Aux(Aux::M(3 | 4)))));
    assert_eq!(r.end(), vec![0.0, 0.0, 50.0]);
}

/// G331's K sign is its direction and G332 reverses the last G331's; both need the spindle
/// in position control and S; a thread lead word of the long axis is required.
#[test]
fn g331_g332_directions_and_their_alarms() {
    let r = run("SPOS=0\nG0 Z5\nG331 Z-10 K-1.25 S300\nG332 Z5 K1.25\nG70 G331 Z-0.5 K0.05\n").ok();
    let t = taps(&r);
    assert_eq!((t[0].1, t[0].2), (-1.25, 300.0));
    assert_eq!((t[1].1, t[1].2), (1.25, 300.0));
    assert!(
        (t[2].1 - 0.05 * 25.4).abs() < 1e-12,
        "G70: the lead in inches"
    );
    assert!(near(&t[2].0, &[0.0, 0.0, -12.7]));
    // Without SPOS, after M3 let the spindle go, G332 with no G331 before it.
    for (text, line) in [
        ("G0 Z5\nG331 Z-10 K1 S300\n", 2),
        ("SPOS=0\nS300 M3\nG331 Z-10 K1\n", 3),
        ("SPOS=0\nS300\nG332 Z5 K1\n", 3),
    ] {
        let r = run(text);
        let e = r.error.as_ref().expect("refused");
        assert_eq!((e.number, e.line), (12080, line), "{text}: {e:?}");
    }
    // No S, no lead word of the long axis.
    assert_eq!(run("SPOS=0\nG331 Z-10 K1\n").alarm().1, 2);
    assert_eq!(run("SPOS=0\nS300\nG331 Z-10 I1\n").alarm(), (12080, 3));
}
