//! The Huaxing turn-mill's C axis (`000` §4.2.6–4.2.7, §5.7; decision D138) on the canonical
//! stream: the manual's fixtures 004 and 015 block by block, and the section's alarms.

#[path = "support/huaxing.rs"]
mod huaxing;
use huaxing::{assert_alarms, fixture, hx, turn_mill, with_live_tool};

use cnc_interpreter::{Aux, Canon, Command, Setup, Turn};

/// A rotary move as (X, Z, degrees, way, rpm).
fn rotary(c: &Command) -> Option<(f64, f64, f64, Turn, f64)> {
    match c {
        Command::Rotary {
            end,
            degrees,
            way,
            rpm,
        } => Some((end[0], end[1], *degrees, *way, *rpm)),
        _ => None,
    }
}

fn position_mode(c: &Command) -> bool {
    matches!(
        c,
        Command::Aux(Aux::Orient {
            degrees,
            way: Turn::Incremental
        }) if *degrees == 0.0
    )
}

/// Fixture 004 as printed, run as one program: M14.6 puts the spindle in position mode where
/// it stands; G08 C100 turns it the positive way to 100° at 1000 r/min; C−750 the negative
/// way to −30°, 330° (the manual prints 320°: D138); H−750 750° back, turns included; the
/// three-axis G08 moves X by U−10 (diameter) and Z to 120 while C turns 100° at 800 r/min;
/// G08.6 is M14.6 and G08 in one.
#[test]
fn fixture_004_positions_c_and_turns_it_with_x_and_z() {
    let text = fixture("004_spindle_c_axis_position_m14_g08.nc");
    let cmds = hx(&text, turn_mill()).unwrap();
    let c: Vec<&Command> = cmds.iter().map(|c| &c.command).collect();
    assert!(position_mode(c[0]), "{:?}", c[0]);
    let want = [
        (200.0, 100.0, 100.0, Turn::Plus, 1000.0),
        (200.0, 100.0, 330.0, Turn::Minus, 1000.0),
        (200.0, 100.0, -750.0, Turn::Incremental, 1000.0),
        (190.0, 120.0, 100.0, Turn::Incremental, 800.0),
    ];
    for (k, w) in want.iter().enumerate() {
        assert_eq!(rotary(c[1 + k]), Some(*w), "block {}", k + 2);
    }
    assert!(position_mode(c[5]), "G08.6 positions first: {:?}", c[5]);
    assert_eq!(
        rotary(c[6]),
        Some((190.0, 120.0, 120.0, Turn::Plus, 1000.0))
    );
    assert_eq!(c.len(), 8, "{c:?}");
}

/// Fixture 015's first two listings: to C0, the infeed U−1.5 at the feed, then three turns
/// of C with Z 4.5 mm along (a 1.5 mm thread's three turns at 800 r/min); the G08.6 form
/// gives the same stream. Its third listing makes Y the spindle's axis (G08.2 Y100), for a
/// machine built so: this turn-mill has no Y (its address is alarm 7, as on any lathe
/// without one), and G08.2 C100 or M14.2 is alarm 74 ("rotary axis not defined"): its
/// spindle's axis is C.
#[test]
fn fixture_015_three_turns_of_c_with_z_along() {
    let text = fixture("015_g08_rotary_axis_examples.nc");
    let parts: Vec<&str> = text.split(".....").collect();
    let first = hx(parts[0], turn_mill()).unwrap();
    let second = hx(parts[1].split("(例:)").next().unwrap(), turn_mill()).unwrap();
    for cmds in [&first, &second] {
        let c: Vec<&Command> = cmds.iter().map(|c| &c.command).collect();
        assert!(position_mode(c[0]));
        assert_eq!(rotary(c[1]), Some((200.0, 100.0, 0.0, Turn::Plus, 1000.0)));
        assert!(
            matches!(c[2], Command::Linear { end, feed } if end[0] == 198.5 && *feed == 50.0),
            "{:?}",
            c[2]
        );
        assert_eq!(
            rotary(c[3]),
            Some((198.5, 4.5, 1080.0, Turn::Incremental, 800.0))
        );
    }
    let e = hx("G08.2 Y100 F1000\n", turn_mill()).unwrap_err();
    assert_eq!(e.number, 7, "{e}");
    assert!(e.text.contains("address Y"), "{e}");
    let e = hx("G08.2 C100 F1000\n", turn_mill()).unwrap_err();
    assert_eq!(e.number, 74, "{e}");
    assert!(e.text.contains("not axis Y"), "{e}");
    assert_eq!(hx("M14.2\n", turn_mill()).unwrap_err().number, 74);
}

/// The section's alarms: G08 without C or H is 80; C and H together 9; the first G08
/// without F 23; F above 3000 r/min 13; a C word outside G08 74; on a lathe whose spindle
/// is no C axis G08 and M14.6 are 74, and so is M14.3 (Z as the spindle's axis) on this one.
#[test]
fn the_c_axis_alarms() {
    let cases = [
        ("M14.6\nG08 Z10 F100\n", turn_mill(), 80, 2),
        ("M14.6\nG08 C10 H10 F100\n", turn_mill(), 9, 2),
        ("M14.6\nG08 C10\n", turn_mill(), 23, 2),
        ("M14.6\nG08 C10 F4000\n", turn_mill(), 13, 2),
        ("G01 Z10 C10 F100\n", turn_mill(), 74, 1),
        ("G08 C10 F100\n", Setup::lathe([200.0, 100.0]), 74, 1),
        ("M14.6\n", Setup::lathe([200.0, 100.0]), 74, 1),
        ("M14.3\n", turn_mill(), 74, 1),
    ];
    assert_alarms(cases);
}

/// G31 (§5.17, D139): a measuring move that brakes at the skip input's edge, rising with K
/// (or without a word), falling with L; the input must be the machine's skip input (S#46):
/// another is 13, K and L together 13, a machine without a skip input 7. Without a machine
/// the skip is taken as coming at the end, so the program reads on from there.
#[test]
fn g31_skips_on_the_machines_skip_input() {
    let with_skip = || Setup {
        skip_input: Some((11, 5)),
        ..turn_mill()
    };
    let cmds = hx(
        "G31 Z50 F100\nG31 W-5 K11.5 F50\nG31 W-5 L11.5\nG00 Z60\n",
        with_skip(),
    )
    .unwrap();
    let probes: Vec<(f64, f64, bool, bool)> = cmds
        .iter()
        .filter_map(|c| match &c.command {
            Command::Probe {
                end,
                feed,
                rising,
                stop,
            } => Some((end[1], *feed, *rising, *stop)),
            _ => None,
        })
        .collect();
    assert_eq!(
        probes,
        [
            (50.0, 100.0, true, true),
            (45.0, 50.0, true, true),
            (40.0, 50.0, false, true)
        ]
    );
    for (text, setup, number) in [
        ("G31 Z50 K3.2 F100\n", with_skip(), 13),
        ("G31 Z50 K11.5 L11.5 F100\n", with_skip(), 13),
        ("G31 Z50 F100\n", turn_mill(), 7),
    ] {
        let e = hx(text, setup).unwrap_err();
        assert_eq!((e.number, e.line), (number, 1), "{text}: {e}");
    }
}

/// The live tool's taps as (X, Z, tool degrees, feed) of each line that turns it.
fn taps(cmds: &[Canon]) -> Vec<(f64, f64, f64, f64)> {
    cmds.iter()
        .filter_map(|c| match &c.command {
            Command::Linear { end, feed } if end.len() == 4 => {
                Some((end[0], end[1], end[3], *feed))
            }
            _ => None,
        })
        .collect()
}

/// Fixture 017 as printed (`000` §5.9, D142): G14.4 taps Z0 → −10 at 1 mm a turn with the live
/// tool at 500 r/min — ten turns, 3600°, in 1.2 s, the line's feed the one that turns the tool
/// at R — dwells D2 s at the bottom and comes back turning the other way to Z0 and 0°; then
/// G0 X100 Z100. G14 is modal: a following Z taps again from where the tool stands.
#[test]
fn fixture_017_taps_with_the_live_tool_and_back() {
    let text = fixture("017_g14_4_flying_cutter_tapping.nc");
    let cmds = hx(&text, with_live_tool()).unwrap();
    let t = taps(&cmds);
    let feed = 10.0f64.hypot(3600.0) / (10.0 / 500.0);
    assert_eq!(t.len(), 2, "{t:?}");
    for (k, want) in [(0.0, -10.0, 3600.0), (0.0, 0.0, 0.0)].iter().enumerate() {
        let (x, z, a, f) = t[k];
        assert!(
            (x, z) == (want.0, want.1) && (a - want.2).abs() < 1e-9 && (f - feed).abs() < 1e-6,
            "tap line {k}: {:?}",
            t[k]
        );
    }
    let dwell = cmds
        .iter()
        .find_map(|c| match c.command {
            Command::Dwell { seconds } => Some(seconds),
            _ => None,
        })
        .expect("D2");
    assert_eq!(dwell, 2.0);
    let last_rapid = cmds
        .iter()
        .rev()
        .find_map(|c| match &c.command {
            Command::Rapid { end } => Some(end.clone()),
            _ => None,
        })
        .expect("G0 X100 Z100");
    assert_eq!(last_rapid, vec![100.0, 100.0, 0.0, 0.0]);
    // Modal, a slanted thread by X and Z, a left-hand one by F−, inch by I.
    let modal = hx(
        "G0 X20 Z0\nG14.4 Z-5 R1000 F0.5\nU-6 W-8 F-1.5\nW-4 I20\nG0 X100\nM30\n",
        with_live_tool(),
    )
    .unwrap();
    let t = taps(&modal);
    let want = [
        (20.0, -5.0, 3600.0),
        (20.0, 0.0, 0.0),
        // U−6 (diameter: 3 mm) and W−8: √73 mm at 1.5 mm a turn the negative way.
        (14.0, -8.0, -360.0 * 73f64.sqrt() / 1.5),
        (20.0, 0.0, 0.0),
        (20.0, -4.0, 360.0 * 4.0 / (25.4 / 20.0)),
        (20.0, 0.0, 0.0),
    ];
    assert_eq!(t.len(), want.len(), "{t:?}");
    for (got, want) in t.iter().zip(want) {
        assert!(
            (got.0 - want.0).abs() < 1e-9
                && (got.1 - want.1).abs() < 1e-9
                && (got.2 - want.2).abs() < 1e-6,
            "{got:?} is not {want:?}"
        );
    }
}

/// G14's alarms: no live tool on the machine or not axis n (74), R 0 or above S#122's 2500
/// (73), no pitch (2) or no R (23, a missing word), the live tool's address as a word (74).
#[test]
fn live_tool_tap_alarms() {
    let cases = [
        ("G14.4 Z-10 R500 F1\n", turn_mill(), 74, 1),
        ("G14.3 Z-10 R500 F1\n", with_live_tool(), 74, 1),
        ("G14.4 Z-10 R0 F1\n", with_live_tool(), 73, 1),
        ("G14.4 Z-10 R3000 F1\n", with_live_tool(), 73, 1),
        ("G14.4 Z-10 R500\n", with_live_tool(), 2, 1),
        ("G14.4 Z-10 F1\n", with_live_tool(), 23, 1),
        ("G00 A90\n", with_live_tool(), 74, 1),
        ("G14.4 Z-10 R500 F1 I20\n", with_live_tool(), 2, 1),
    ];
    assert_alarms(cases);
}

/// What a rigid tapping program queues, in short: rapids and rotaries by their ends, taps as
/// (X, Z, C, tool degrees), M codes, dwells.
fn steps(cmds: &[Canon]) -> Vec<String> {
    cmds.iter()
        .filter_map(|c| match &c.command {
            Command::Rapid { end } => Some(format!("G00 X{} Z{}", end[0], end[1])),
            Command::Rotary {
                degrees, way, rpm, ..
            } => Some(format!("C {degrees} {way:?} {rpm}")),
            Command::Linear { end, .. } if end.len() == 4 => Some(format!(
                "TAP X{} Z{} C{} A{:.3}",
                end[0], end[1], end[2], end[3]
            )),
            Command::Aux(Aux::M(m)) => Some(format!("M{m}")),
            Command::Dwell { seconds } => Some(format!("DWELL {seconds}")),
            _ => None,
        })
        .collect()
}

/// `000` §5.23.4 on the turn-mill (D142): M29 S800 makes the live tool the tapping spindle;
/// G84 taps a face hole at X20, C0 to Z−10 at 1.25 mm a turn (12 turns from Z5: 4320°), the
/// clamp M20 around it (M21 unclamps) and P500 at the bottom; `H90 K3 M20` taps three more
/// holes 90° apart, each clamped;
/// G00 ends rigid tapping (another group-01 code), so M29 again before G88, which taps a
/// side hole at Z−10, C45 from X60 to X30 (15 mm, 15 turns at F1), no clamp; G80 ends it
/// and G00 moves again.
#[test]
fn g84_and_g88_tap_face_and_side_holes_with_the_live_tool() {
    let text = "T0101\nG00 X60 Z5\nM14.6\nM29 S800\nG84 X20 C0 Z-10 P500 F1.25 M20\nH90 K3 M20\n\
                G00 X60 Z-10\nM29 S800\nG88 Z-10 C45 X30 F1 P0\nG80\nG00 X100\nM30\n";
    let cmds = hx(text, with_live_tool()).unwrap();
    let s = steps(&cmds);
    let hole = |c: f64, rotary: &str| {
        vec![
            rotary.to_string(),
            "M20".to_string(),
            format!("TAP X20 Z-10 C{c} A4320.000"),
            "DWELL 0.5".to_string(),
            format!("TAP X20 Z5 C{c} A0.000"),
            "M21".to_string(),
        ]
    };
    let mut want = vec!["G00 X60 Z5".to_string(), "G00 X20 Z5".to_string()];
    want.extend(hole(0.0, "C 0 Plus 100"));
    for c in [90.0, 180.0, 270.0] {
        want.extend(hole(c, "C 90 Incremental 100"));
    }
    want.extend([
        "G00 X60 Z-10".to_string(),
        "C 45 Plus 100".to_string(),
        "TAP X30 Z-10 C45 A5400.000".to_string(),
        "TAP X60 Z-10 C45 A0.000".to_string(),
        "G00 X100 Z-10".to_string(),
    ]);
    let s: Vec<String> = s.into_iter().filter(|l| l != "M14" && l != "M30").collect();
    assert_eq!(s, want);
}

/// Rigid tapping's alarms: M29 on a lathe without a live tool (74), G84 without M29 (23) or
/// without a pitch (2) or a bottom (23), M29 without S (23), a tap speed above the live
/// tool's 2500 r/min (73), K out of range (13), G84 after a G00 ended rigid tapping (23).
#[test]
fn rigid_tapping_alarms() {
    let cases = [
        ("M29 S800\n", turn_mill(), 74, 1),
        ("G84 X20 C0 Z-10 F1\n", with_live_tool(), 23, 1),
        ("M29 S800\nG84 X20 C0 Z-10\n", with_live_tool(), 2, 2),
        ("M29 S800\nG84 X20 C0 F1\n", with_live_tool(), 23, 2),
        ("M29\n", with_live_tool(), 23, 1),
        ("M29 S3000\nG84 X20 Z-10 F1\n", with_live_tool(), 73, 2),
        ("M29 S800\nG84 X20 Z-10 F1 K0\n", with_live_tool(), 13, 2),
        (
            "M29 S800\nG84 X20 C0 Z-10 F1\nG00 X30\nG84 X20 Z-10\n",
            with_live_tool(),
            23,
            4,
        ),
    ];
    assert_alarms(cases);
}
