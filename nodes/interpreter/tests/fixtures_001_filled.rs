//! The 802D manual's template fixtures (`../shared/fixtures/001`, issue 23, must-show 1)
//! with their placeholders filled: every line the manual prints stays as printed, each
//! placeholder line (`...`, `X... Y...`, a lone `.`) is replaced, in order, by a line the
//! test gives (the comment says which), and the test asserts what the header's EXPECTED line
//! states, computed here on its own (angles, offsets, inches). As printed, each stops with
//! 12080 at its first placeholder (`fixtures_001::every_fixture_without_a_cycle_as_printed`).

#[path = "support/sinumerik.rs"]
mod support;

use std::collections::BTreeMap;

use cnc_interpreter::{Aux, Command, Library, Setup};
use cnc_interpreter_core::ToolOffset;
use support::*;

fn arcs(r: &Run) -> Vec<(Vec<f64>, Vec<f64>, bool)> {
    r.out
        .iter()
        .filter(|c| matches!(c, Command::Arc { .. }))
        .map(arc)
        .collect()
}

/// L10, the manual's contour subprogram of the frame figures: a line and a clockwise arc
/// from (10, 5) to (20, 15) about (20, 5).
fn l10() -> Library {
    let mut lib = Library::new();
    lib.insert_named(
        "L10",
        "L10.SPF",
        "G1 F200 X10 Y5\nG2 X20 Y15 I10 J0\nG0 X0 Y0\nM17\n",
    );
    lib
}

/// The mill with more cutting edges: offset entry (T×10+D), length, radius.
fn with_edges(mut s: Setup, edges: &[(u32, f64, f64)]) -> Setup {
    for &(entry, z, radius) in edges {
        s.offsets.tools.insert(
            entry,
            ToolOffset {
                z,
                radius,
                ..ToolOffset::default()
            },
        );
    }
    s
}

fn rotate(p: (f64, f64), deg: f64) -> (f64, f64) {
    let (s, c) = deg.to_radians().sin_cos();
    (p.0 * c - p.1 * s, p.0 * s + p.1 * c)
}

#[test]
fn f001_msg_shows_the_text_until_msg_clears_it() {
    // N20: a move; N...: nothing.
    let text = filled("001", &["N20 G0 X10 Y10", ""]);
    let r = run(&text).ok();
    assert_eq!(
        r.front.messages,
        [
            (line_of(&text, "N10"), "轮廓粗加工".to_string()),
            (line_of(&text, "N90"), String::new())
        ]
    );
    assert_eq!(r.front.message(), "");
    assert_eq!(r.moves().len(), 1);
}

#[test]
fn f002_msg_joins_text_and_the_x_position_read_from_aa_iw() {
    let text = filled("002", &["N20 G0 X10 Y10", ""]);
    let mut s = mill();
    s.start = vec![37.5, 0.0, 0.0];
    let r = run_with(&text, s, Library::new()).ok();
    assert_eq!(r.front.r(12), 37.5);
    assert_eq!(r.front.messages[0].1, "X 轴位置37.5检查");
    assert_eq!(r.front.message(), "");
}

#[test]
fn f008_g17_applies_the_tool_length_on_z() {
    // N10: T1 D1 (the machine changes tools on T); N20: G0 to X10 Y10 Z5.
    let text = filled("008", &["N10 G17 T1 D1", "N20 G0 X10 Y10 Z5"]);
    let r = run(&text).ok();
    // Machine Z = programmed 5 + T1 D1's length 50.
    assert!(near(&r.end(), &[10.0, 10.0, 55.0]), "{:?}", r.end());
}

#[test]
fn f010_g70_reads_inches_until_g71() {
    // As printed: G1 without F (14800, line 7). With F100 in front and the "..." empty:
    let text = format!("F100\n{}", filled("010", &[""]));
    let r = run(&text).ok();
    let e = r.ends();
    assert!(near(&e[0], &[254.0, 0.0, 762.0]), "{e:?}");
    assert!(near(&e[1], &[1016.0, 0.0, 1270.0]), "{e:?}");
    assert!(near(&e[2], &[19.0, 0.0, 17.3]), "{e:?}");
}

#[test]
fn f011_g112_sets_a_pole_relative_to_the_last_one() {
    // "...": G0 to the pole; N90/N100's "...": G0, and G1 F200.
    let text = filled(
        "011",
        &[
            "N30 G0 X17 Y36",
            "N90 G0 AP=12.5 RP=47.679",
            "N100 G1 F200 AP=26.3 RP=7.344 Z4",
        ],
    );
    let r = run(&text).ok();
    let pole1 = (17.0, 36.0);
    let d = rotate((27.8, 0.0), 45.0);
    let pole2 = (pole1.0 + d.0, pole1.1 + d.1);
    let p90 = rotate((47.679, 0.0), 12.5);
    let p100 = rotate((7.344, 0.0), 26.3);
    let e = r.ends();
    assert!(
        near(&e[1], &[pole2.0 + p90.0, pole2.1 + p90.1, 0.0]),
        "{e:?}"
    );
    assert!(
        near(&e[2], &[pole2.0 + p100.0, pole2.1 + p100.1, 4.0]),
        "{e:?}"
    );
}

#[test]
fn f012_trans_shifts_the_l10_contour_by_x20_y15() {
    // "...": nothing; after N70 a move to the workpiece zero.
    let text = format!("{}N80 G0 X0 Y0\n", filled("012", &[""]));
    let r = run_with(&text, mill(), l10()).ok();
    let a = arcs(&r);
    assert_eq!(a.len(), 1);
    assert!(near(&a[0].0[..2], &[40.0, 30.0]) && near(&a[0].1[..2], &[40.0, 20.0]));
    assert!(a[0].2, "clockwise as programmed");
    // N70 TRANS clears the shift: the last G0 X0 Y0 is the workpiece zero.
    assert!(near(&r.end(), &[0.0, 0.0, 0.0]));
}

#[test]
fn f013_trans_then_arot_turns_l10_by_45_degrees_about_the_new_zero() {
    let text = filled("013", &["N10 G17 G0 X0 Y0", "N80 G0 X0 Y0"]);
    let r = run_with(&text, mill(), l10()).ok();
    let a = arcs(&r);
    assert_eq!(a.len(), 2);
    assert!(near(&a[0].0[..2], &[40.0, 25.0]));
    let end = rotate((20.0, 15.0), 45.0);
    let centre = rotate((20.0, 5.0), 45.0);
    assert!(near(&a[1].0[..2], &[30.0 + end.0, 26.0 + end.1]), "{a:?}");
    assert!(near(&a[1].1[..2], &[30.0 + centre.0, 26.0 + centre.1]));
    assert!(a[1].2, "a rotation keeps the direction");
}

#[test]
fn f015_mirror_replaces_amirror_adds_and_each_mirror_reverses_the_arc() {
    let text = filled("015", &["G0 X0 Y0", "N100 G0 X0 Y0"]);
    let r = run_with(&text, mill(), l10()).ok();
    let a = arcs(&r);
    assert_eq!(a.len(), 4);
    // Original, mirrored in X, in Y (replacing), in Y and X (added).
    let expect = [
        ((20.0, 15.0), (20.0, 5.0), true),
        ((-20.0, 15.0), (-20.0, 5.0), false),
        ((20.0, -15.0), (20.0, -5.0), false),
        ((-20.0, -15.0), (-20.0, -5.0), true),
    ];
    for (k, (end, centre, cw)) in expect.iter().enumerate() {
        assert!(near(&a[k].0[..2], &[end.0, end.1]), "{k}: {a:?}");
        assert!(near(&a[k].1[..2], &[centre.0, centre.1]), "{k}: {a:?}");
        assert_eq!(a[k].2, *cw, "{k}");
    }
    assert!(near(&r.end(), &[0.0, 0.0, 0.0]));
}

#[test]
fn f016_four_workpieces_under_g54_to_g57_then_g500() {
    let text = filled(
        "016",
        &[
            "N10 G54 G0 X0 Y0",
            "N30 G55 G0 X0 Y0",
            "N50 G56 G0 X0 Y0",
            "N70 G57 G0 X0 Y0",
            "N90 G500 G0 X0",
        ],
    );
    let mut s = mill();
    for (i, (x, y)) in [(100.0, 50.0), (200.0, 50.0), (100.0, 150.0), (200.0, 150.0)]
        .into_iter()
        .enumerate()
    {
        s.offsets
            .work
            .insert(i as u8, BTreeMap::from([('X', x), ('Y', y), ('Z', 0.0)]));
    }
    let mut lib = Library::new();
    lib.insert_named("L47", "L47.SPF", "G1 F100 X10 Y10\nG0 X0 Y0\nRET\n");
    let r = run_with(&text, s, lib).ok();
    let e = r.ends();
    let corners: Vec<&Vec<f64>> = e.iter().filter(|p| p[0] % 100.0 == 10.0).collect();
    assert_eq!(corners.len(), 4, "{e:?}");
    for (c, (x, y)) in
        corners
            .iter()
            .zip([(110.0, 60.0), (210.0, 60.0), (110.0, 160.0), (210.0, 160.0)])
    {
        assert!(near(&c[..2], &[x, y]), "{e:?}");
    }
    // G500: no settable offset; X0 is the machine zero, Y stays where G57 left it.
    assert!(near(&r.end(), &[0.0, 150.0, 0.0]), "{e:?}");
}

#[test]
fn f018_rapid_by_polar_coordinates_about_the_workpiece_zero() {
    let text = filled("018", &[""]);
    let r = run(&text).ok();
    let e = r.ends();
    assert!(near(&e[0], &[100.0, 150.0, 65.0]));
    let p = rotate((16.78, 0.0), 45.0);
    assert!(near(&e[1], &[p.0, p.1, 65.0]), "{e:?}");
    assert!(matches!(r.moves()[1], Command::Rapid { .. }));
}

#[test]
fn f026_ct_continues_the_line_tangentially() {
    let text = filled("026", &["N20 CT X40 Y10"]);
    let r = run(&text).ok();
    // Tangent +X at (20, 0): the centre lies on X20, equally far from (20, 0) and (40, 10).
    let a = arcs(&r);
    assert!(
        near(&a[0].0[..2], &[40.0, 10.0]) && near(&a[0].1[..2], &[20.0, 25.0]),
        "{a:?}"
    );
    assert!(!a[0].2, "counter-clockwise");
}

#[test]
fn f027_helix_with_turn_3_makes_three_turns_and_a_half_to_z33() {
    let text = filled("027", &["N20 G0 Z0", ""]);
    let r = run(&text).ok();
    let a = arcs(&r);
    assert_eq!(a.len(), 4, "three full turns, then the half: {a:?}");
    for (end, centre, cw) in &a {
        assert!(!cw && near(&centre[..2], &[0.0, 25.0]));
        assert!(f64::hypot(end[0], end[1] - 25.0) - 25.0 < 1e-9);
    }
    assert!(near(&a[3].0, &[0.0, 0.0, 33.0]));
    // Z climbs in proportion to the angle: 3.5 turns to 33, each full turn 33/3.5.
    assert!(near(&a[0].0, &[0.0, 50.0, 33.0 / 3.5]), "{a:?}");
}

#[test]
fn f034_feed_per_minute_then_per_revolution() {
    let text = filled("034", &["N20 G1 X10"]);
    let r = run(&text).ok();
    let feeds: Vec<f64> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::Linear { feed, .. } => Some(*feed),
            _ => None,
        })
        .collect();
    assert_eq!(feeds, [310.0]);
    let per_rev = r
        .out
        .iter()
        .position(|c| *c == Command::FeedMode { per_rev: true })
        .expect("G95");
    let s200 = r.out.iter().position(|c| *c == Command::Aux(Aux::S(200.0)));
    assert!(s200.is_some_and(|s| s < per_rev));
    // F15.5 is now mm/rev: a move after it carries 15.5.
    let r = run(&format!("{text}G1 X20\n")).ok();
    assert!(
        matches!(r.out.iter().rev().find(|c| c.end().is_some()), Some(Command::Linear { feed, .. }) if *feed == 15.5)
    );
}

#[test]
fn f043_dwell_in_seconds_and_in_spindle_revolutions() {
    let text = filled("043", &["N40 X10"]);
    let r = run(&text).ok();
    let dwells: Vec<f64> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::Dwell { seconds } => Some(*seconds),
            _ => None,
        })
        .collect();
    // 30 revolutions at S300: 0.1 min.
    assert_eq!(dwells.len(), 2);
    assert!(
        (dwells[0] - 2.5).abs() < 1e-9 && (dwells[1] - 6.0).abs() < 1e-9,
        "{dwells:?}"
    );
    // F and S keep their values: N40 moves at F200, the spindle still at 300.
    assert!(matches!(r.moves().last(), Some(Command::Linear { feed, .. }) if *feed == 200.0));
}

#[test]
fn f049_spindle_before_the_move_and_m5_with_the_last_rapid() {
    let text = filled("049", &["", "N80 S450 G1 X80", ""]);
    let r = run(&text).ok();
    let pos = |c: &Command| r.out.iter().position(|x| x == c).expect("emitted");
    let first_move = r.out.iter().position(|c| c.end().is_some()).unwrap();
    assert!(pos(&Command::Aux(Aux::S(270.0))) < first_move);
    assert!(pos(&Command::Aux(Aux::M(3))) < first_move);
    assert!(pos(&Command::Aux(Aux::S(450.0))) > first_move);
    // M5 is output with N170's move (before it: M5 does not wait for the spindle).
    let last_move = r.out.iter().rposition(|c| c.end().is_some()).unwrap();
    assert_eq!(last_move, pos(&Command::Aux(Aux::M(5))) + 1);
    assert!(near(&r.end(), &[80.0, 0.0, 180.0]));
}

#[test]
fn f055_t_without_m6_changes_the_tool_at_once() {
    // The first half (without M6): the "..." empty.
    let text = filled("055", &["", "", ""]);
    let first: String = text
        .lines()
        .take_while(|l| !l.contains("N10 T14"))
        .collect::<Vec<_>>()
        .join("\n");
    let r = run(&first).ok();
    let tools: Vec<&Command> = r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Aux(Aux::T(_))))
        .collect();
    assert_eq!(
        tools,
        [&Command::Aux(Aux::T(1)), &Command::Aux(Aux::T(588))]
    );
    assert_eq!(r.front.tool_edge().0, 588);
    // With M6 (the machine's setting): T14 goes to the PLC as the preselection, the change
    // is M6's at N15; before it the old tool stays active.
    let mut s = mill();
    s.tool_change_with_m6 = true;
    let r = run_with("N10 T14\nG0 X1\n", s.clone(), Library::new()).ok();
    assert_eq!(r.front.tool_edge().0, 0, "preselected only");
    let r = run_with("N10 T14\nG0 X1\nN15 M6\n", s, Library::new()).ok();
    let at = |c: Command| r.out.iter().position(|x| *x == c).expect("emitted");
    let mv = r.out.iter().position(|c| c.end().is_some()).unwrap();
    assert!(at(Command::Aux(Aux::T(14))) < mv && at(Command::Aux(Aux::M(6))) > mv);
    assert_eq!(r.front.tool_edge(), (14, 1));
}

#[test]
fn f056_d_switches_the_length_of_the_active_tool() {
    let text = filled("056", &["N11 G0 Z10", "", "N70 G0 Z10 D1"]);
    let s = with_edges(mill(), &[(42, 30.0, 0.0), (41, 20.0, 0.0)]);
    let r = run_with(&text, s, Library::new()).ok();
    let e = r.ends();
    // N11 with T1 D1 (50); N70 with T4 D1 (20).
    assert!(near(&e[0], &[0.0, 0.0, 60.0]), "{e:?}");
    assert!(near(&e[1], &[0.0, 0.0, 30.0]), "{e:?}");
}

#[test]
fn f066_incremental_moves_by_r_values() {
    let text = filled("066", &[""]);
    let mut s = mill();
    for (k, v) in [(1, 10.0), (2, 20.0), (3, 5.0), (4, 2.0), (5, 0.5)] {
        s.kept.insert(10_000 + k, v);
    }
    // The mill has no X/Z lathe plane: X and Z are axes all the same.
    let r = run_with(&text, s, Library::new()).ok();
    let e = r.ends();
    let z4 = 25.0 + 25.3f64.to_radians().sin() - 0.5;
    assert!(near(&e[0], &[10.0, 0.0, 20.0]));
    assert!(near(&e[1], &[10.0, 0.0, 25.0]));
    assert!(near(&e[2], &[8.0, 0.0, 25.0]));
    assert!(near(&e[3], &[8.0, 0.0, z4]), "{e:?}");
}

#[test]
fn f080_and_f081_a_counter_limit_jumps_to_the_message_and_m0() {
    for (number, label, msg) in [
        ("080", "WZZEIT", "刀具作用时间: 达到极限值"),
        ("081", "SIST", "达到额定工件数"),
    ] {
        // As printed the limits are 0: reached at once, the jump skips the placeholder.
        let text = fixture(number);
        let r = run(&text).ok();
        assert_eq!(r.front.message(), msg, "{number}");
        assert_eq!(
            r.out
                .iter()
                .filter(|c| **c == Command::Aux(Aux::M(0)))
                .count(),
            1
        );
        // Not reached (R10/R15 = 5): the block after the IF runs and the label is passed.
        let mut s = mill();
        s.kept
            .insert(10_000 + if number == "080" { 10 } else { 15 }, 5.0);
        let text = filled(number, &["G0 X1 M30"]);
        let r = run_with(&text, s, Library::new()).ok();
        assert_eq!(r.front.message(), "", "{number} {label}");
        assert!(near(&r.end(), &[1.0, 0.0, 0.0]));
    }
}

#[test]
fn f069_plc_data_bytes_written_in_order() {
    let r = run(&fixture("069")).ok();
    for k in 1..=4 {
        assert_eq!(r.front.plc_byte(k), Some(k as u8), "$A_DBB[{k}]");
    }
}

#[test]
fn f057_with_m6_the_new_tool_and_its_edge_take_effect_at_m6() {
    // "...": nothing; N16/N20: Z10; the last "...": a Z10 move under T4 D3.
    let text = filled(
        "057",
        &["", "N16 G0 Z10", "", "N20 G0 Z10 D2", "", "G0 Z10"],
    );
    let mut s = with_edges(mill(), &[(12, 45.0, 0.0), (43, 20.0, 0.0)]);
    s.tool_change_with_m6 = true;
    let r = run_with(&text, s, Library::new()).ok();
    let e = r.ends();
    // N16: T1 D1 (50); N20: T1 D2 (45); after N55 M6: T4 D3 (20).
    assert!(near(&e[0], &[0.0, 0.0, 60.0]), "{e:?}");
    assert!(near(&e[1], &[0.0, 0.0, 55.0]), "{e:?}");
    assert!(near(&e[2], &[0.0, 0.0, 30.0]), "{e:?}");
    assert_eq!(r.front.tool_edge(), (4, 3));
}

/// Issue 46 item 4 (D127): on a machine that changes tools with M6, the tool it holds is the
/// start state, and the edge a preselecting block names is the new tool's, active at M6
/// unless the M6 block names another; without either the new tool comes with D1. A D in any
/// other block is the active tool's edge.
#[test]
fn the_edge_named_with_the_preselected_tool_takes_effect_at_m6() {
    let mut s = with_edges(
        mill(),
        &[
            (12, 45.0, 0.0),
            (31, 10.0, 0.0),
            (32, 12.0, 0.0),
            (33, 14.0, 0.0),
        ],
    );
    s.tool_change_with_m6 = true;
    let z = |text: &str, holding: u32| {
        let mut s = s.clone();
        s.active_tool = holding;
        let r = run_with(text, s, Library::new()).ok();
        (r.end()[2], r.front.tool_edge())
    };
    // The spindle empty: `T3 D2` then M6 runs (it stopped with 17190) and cuts with T3 D2.
    assert_eq!(
        z(
            "T3 D2
M6
G0 Z0
",
            0
        ),
        (12.0, (3, 2))
    );
    // The spindle holding T1: the same, T1's length not touched by the D meanwhile.
    assert_eq!(
        z(
            "T3 D2
G0 Z0
",
            1
        ),
        (50.0, (1, 1)),
        "before M6 T1 D1"
    );
    assert_eq!(
        z(
            "T3 D2
M6
G0 Z0
",
            1
        ),
        (12.0, (3, 2))
    );
    // The M6 block's D wins; without any, D1.
    assert_eq!(
        z(
            "T3 D2
D3 M6
G0 Z0
",
            1
        ),
        (14.0, (3, 3))
    );
    assert_eq!(
        z(
            "T3
M6
G0 Z0
",
            1
        ),
        (10.0, (3, 1))
    );
    // A D between the preselection and M6 is the active tool's edge.
    assert_eq!(
        z(
            "T3
D2
G0 Z0
",
            1
        ),
        (45.0, (1, 2))
    );
    assert_eq!(
        z(
            "T3
D2
M6
G0 Z0
",
            1
        ),
        (10.0, (3, 1))
    );
    // The tool the machine holds is the start state: D2 of T1 at once.
    assert_eq!(
        z(
            "D2
G0 Z0
",
            1
        ),
        (45.0, (1, 2))
    );
    // And the run leaves the tool it changed to in the machine's memory.
    let mut s1 = s.clone();
    s1.active_tool = 1;
    let mut interp = cnc_interpreter::Interpreter::with_library(
        cnc_interpreter::Dialect::Sinumerik802d,
        "T3
M6
G0 Z0
M30
",
        s1,
        Library::new(),
    );
    while let Ok(Some(_)) = interp.next_command() {}
    assert_eq!(interp.memory().spindle_tool, 3);
}

/// 035 (§9.3.15): G42 with a cutter of radius 5 right of a clockwise arc (the cutter inside,
/// radius 15) and a counter-clockwise one (outside, radius 25), then after N70 CFTCP another
/// clockwise arc (appended). CFC is also the program-start setting (D98).
#[test]
fn f035_cfc_holds_f_on_the_contour_of_compensated_arcs_and_cftcp_at_the_centre() {
    let arc_feeds = |n20: &str| -> Vec<(f64, f64)> {
        let text = format!(
            "T1 D1\nG0 X0 Y-20 Z5\n{}N80 G2 X140 Y0 I20 J0\nN90 G40 G1 X160 Y-20\nM2\n",
            filled(
                "035",
                &[
                    "N10 G1 G42 X0 Y0 F500",
                    n20,
                    "N30 G2 X40 Y0 I20 J0 F350",
                    "N40 G3 X80 Y0 I20 J0",
                    "N50 G1 X100",
                ],
            )
        );
        let r = run_with(&text, with_edge(11, 5.0), Library::new()).ok();
        r.out
            .iter()
            .filter_map(|c| match c {
                Command::Arc { center, feed, .. } => Some((center[0], *feed)),
                _ => None,
            })
            .collect()
    };
    let want = [
        // N30 inside: 350 · 15/20; N40 outside: 350 · 25/20.
        (20.0, 262.5),
        (60.0, 437.5),
        // N80's outer corner arc (radius 5 about X100 Y0) and N80 itself: at the centre.
        (100.0, 350.0),
        (120.0, 350.0),
    ];
    // As the manual writes it, and with CFC left to the program start.
    for n20 in ["N20 CFC", "N20"] {
        let got = arc_feeds(n20);
        assert_eq!(got.len(), want.len(), "{n20}: {got:?}");
        for ((c, f), (wc, wf)) in got.iter().zip(want) {
            assert!(
                (c - wc).abs() < 1e-9 && (f - wf).abs() < 1e-9,
                "{n20}: {got:?}"
            );
        }
    }
    // CFTCP from the start: every arc at the programmed feed.
    let got = arc_feeds("N20 CFTCP");
    assert!(got.iter().all(|(_, f)| (f - 350.0).abs() < 1e-9), "{got:?}");
}

/// 038 (§9.3.17): SOFT makes N10's move jerk-limited, BRISK from N90 on trapezoidal again;
/// each switch goes to motion before its block's move (D99).
#[test]
fn f038_soft_then_brisk_switch_the_profile_before_their_moves() {
    let text = filled("038", &["N20 Y20", "N100 Y0"]);
    let r = run(&text).ok();
    let profile_or_move: Vec<String> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::Profile { jerk_limited } => Some(format!("soft {jerk_limited}")),
            Command::Linear { end, feed } => {
                Some(format!("X{} Y{} Z{} F{feed}", end[0], end[1], end[2]))
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        profile_or_move,
        [
            "soft true",
            "X30 Y0 Z84 F650",
            "X30 Y20 Z84 F650",
            "soft false",
            "X87 Y20 Z104 F650",
            "X87 Y0 Z104 F650",
        ],
        "{:?}",
        r.out
    );
}

/// TRC of fixtures 058–060 on one contour: P0 (0, 0), P1 (20, 10) where G42/G41 starts,
/// the first contour element along +X to (60, 10), then G40 back to P2 (80, 40); cutter
/// radius 10 (T1 D1).
#[test]
fn f058_to_f060_radius_compensation_selected_held_and_cancelled() {
    // 058: G42 selected on the approach to P1; the first contour element along +X.
    let text = filled(
        "058",
        &[
            "N10 T1",
            "N25 G0 X0 Y0",
            "N30 G1 G42 X20 Y10",
            "N31 X60 Y10",
        ],
    );
    let s = with_edges(mill(), &[(12, 50.0, 10.0)]);
    let r = run_with(&text, s, Library::new()).ok();
    let e = r.ends();
    // Right of a path going +X: the centre 10 below it, at P1 normal to the element.
    assert!(near(&e[1][..2], &[20.0, 0.0]), "{e:?}");
    assert!(near(&e[2][..2], &[60.0, 0.0]), "{e:?}");
    // 059: G41 selected, a Z infeed in between (no contour), then the contour at N22.
    let text = format!(
        "T1 D1 F300\nG0 X0 Y0 Z5\n{}G40 G1 X100 Y10\n",
        filled("059", &["N20 G1 G41 X20 Y10", "N21 Z-5", "N22 X60 Y10"])
    );
    let r = run(&text).ok();
    let e = r.ends();
    let z = e
        .iter()
        .position(|p| (p[2] - 45.0).abs() < 1e-9)
        .expect("the infeed to Z-5");
    // Left of +X: 10 above; the infeed keeps X/Y where the selection ended.
    assert!(near(&e[z][..2], &[20.0, 20.0]), "{e:?}");
    assert!(near(&e[z + 1][..2], &[60.0, 20.0]), "{e:?}");
    // 060: the last contour element ends with the offset normal to it; G40 goes to P2.
    let text = format!(
        "T1 D1 F300\nG0 X0 Y0\nG41 G1 X20 Y10\n{}",
        filled("060", &["X40 Y10", "N100 X60 Y10", "N110 G40 G1 X80 Y40"])
    );
    let r = run(&text).ok();
    let e = r.ends();
    let n = e.len();
    assert!(near(&e[n - 2][..2], &[60.0, 20.0]), "{e:?}");
    assert!(
        near(&e[n - 1][..2], &[80.0, 40.0]),
        "the cutter centre on P2: {e:?}"
    );
}

#[test]
fn f062_m3_before_the_move_and_five_m_functions_in_one_block() {
    let text = filled("062", &["N10 S500", "N20 G0 X10 M3"]);
    let r = run(&text).ok();
    let pos = |c: Command| r.out.iter().position(|x| *x == c).expect("emitted");
    let mv = r.out.iter().position(|c| c.end().is_some()).unwrap();
    assert!(pos(Command::Aux(Aux::S(500.0))) < mv && pos(Command::Aux(Aux::M(3))) < mv);
    let last: Vec<Command> = [78, 67, 10, 12, 37]
        .map(|m| Command::Aux(Aux::M(m)))
        .to_vec();
    let at = pos(Command::Aux(Aux::M(78)));
    assert_eq!(r.out[at..at + 5], last[..]);
    // A sixth M in one block: 14750, too many auxiliary functions (at most five, §9.7).
    let r = run("M78 M67 M10 M12 M37 M8\n");
    assert_eq!(r.alarm(), (14750, 1));
}

#[test]
fn f036_f037_exact_stop_modal_and_per_block_and_continuous_path() {
    let text = filled(
        "036",
        &[
            "N10 G0 G60 X10",
            "N20 X20 Y10",
            "",
            "N50 G1 G601 X30 F200",
            "N80 G64 X40",
            "",
            "N100 G0 G9 X50",
            "N111 X60",
        ],
    );
    let r = run(&text).ok();
    let modes: Vec<bool> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::PathMode { exact_stop } => Some(*exact_stop),
            _ => None,
        })
        .collect();
    // Power-on G60, N80 G64, N100's G9 for its block only, then G64 again.
    assert_eq!(modes, [true, false, true, false], "{:?}", r.out);
    let g9 = r
        .out
        .iter()
        .rposition(|c| *c == Command::PathMode { exact_stop: true })
        .unwrap();
    assert!(matches!(&r.out[g9 + 1], Command::Rapid { end } if end[0] == 50.0));
    // 037: G64 from N10, G60 at N180.
    let text = filled(
        "037",
        &["N10 G64 G1 X10 F300", "N20 Y10", "", "N180 G60 X20"],
    );
    let r = run(&text).ok();
    let modes: Vec<bool> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::PathMode { exact_stop } => Some(*exact_stop),
            _ => None,
        })
        .collect();
    assert_eq!(modes, [true, false, true]);
}

#[test]
fn f071_and_f072_jumps_filled() {
    // 071: R1=0 does not jump at N10, nor R1>1 at N100; N1000 jumps back to LABEL3 while
    // R45 == R7+1 (R7=0): once, at R45=1.
    let text = filled(
        "071",
        &[
            "R7=0 R45=0",
            "N90 LABEL1: G0 X1",
            "",
            "N150 LABEL2: G0 Y1",
            "",
            "N800 LABEL3: R45=R45+1 G0 X=IC(1)",
            "",
            "",
        ],
    );
    let r = run(&text).ok();
    // LABEL3's block runs twice.
    assert_eq!(r.front.r(45), 2.0);
    assert!(near(&r.end(), &[3.0, 1.0, 0.0]), "{:?}", r.end());
    // 072 filled: R1=2 takes the second jump of N20, to MA2, after the block's own move to
    // X5 (D83); X99 is jumped over.
    let text = format!(
        "R1=2\n{}",
        filled(
            "072",
            &[
                "N10 MA1: G0 X1",
                "",
                "N20 IF R1==1 GOTOB MA1 IF R1==2 GOTOF MA2 G0 X5",
                "G0 X99",
                "N50 MA2: G0 Y7"
            ]
        )
    );
    let r = run(&text).ok();
    assert!(near(&r.end(), &[5.0, 7.0, 0.0]), "{:?}", r.end());
    assert!(r.ends().iter().all(|p| p[0] != 99.0));
}

#[test]
fn f042_the_fourth_axis_a_moves_with_rapid_with_a_feed_and_alone() {
    // The simulated mill with the optional 4th axis A (as printed it has none: 12550).
    let mut s = Setup::new(&['X', 'Y', 'Z', 'A'], &[false; 4], &[0.0; 4]);
    s.offsets.tools = mill().offsets.tools;
    let r = run_with(&fixture("042"), s, Library::new()).ok();
    let m = r.moves();
    assert!(matches!(m[0], Command::Rapid { end } if near(end, &[10.0, 20.0, 30.0, 45.0])));
    // F400 holds for X, Y, Z; A follows in the same time: the feed along all four axes is
    // 400 × √(14 + 15²)/√14 (D109).
    let along_all = 400.0 * (239.0f64 / 14.0).sqrt();
    assert!(
        matches!(m[1], Command::Linear { end, feed } if near(end, &[12.0, 21.0, 33.0, 60.0]) && (*feed - along_all).abs() < 1e-9),
        "{:?}",
        m[1]
    );
    assert!(
        matches!(m[2], Command::Linear { end, feed } if near(end, &[12.0, 21.0, 33.0, 90.0]) && *feed == 3000.0)
    );
}

#[test]
fn f017_walimon_keeps_every_move_inside_the_g25_g26_area() {
    // Inside the area (the tool tip: T1's 50 mm length is taken off machine Z).
    let text = filled("017", &["N60 G1 F500 X50 Y50 Z100"]);
    let r = run(&text).ok();
    assert!(near(&r.end(), &[50.0, 50.0, 150.0]), "{:?}", r.end());
    // Leaving it in X: 10730 at that block, none of its moves sent.
    let text = filled("017", &["N60 G1 F500 X150"]);
    let r = run(&text);
    assert_eq!(r.alarm(), (10730, line_of(&text, "N60")));
    assert!(near(&r.end(), &[90.0, 100.0, 230.0]), "{:?}", r.end());
    // An arc whose end lies inside but whose bulge crosses Y110: refused too.
    let text = filled("017", &["N60 G3 F500 X50 Y100 CR=20"]);
    let r = run(&text);
    assert_eq!(r.alarm(), (10730, line_of(&text, "N60")));
    // Below Z30 with the tip (machine Z 79 = tip 29).
    let r = run(&filled("017", &["N60 G1 F500 Z29"]));
    assert_eq!(r.alarm().0, 10730);
    // After WALIMOF the area is no longer watched.
    let text = format!("{}G0 X200\n", filled("017", &["N60 G1 F500 X50"]));
    let r = run(&text).ok();
    assert!(near(&r.end(), &[200.0, 100.0, 230.0]));
}

#[test]
fn f050_g25_g26_s_hold_the_spindle_between_12_and_700_rpm() {
    let text = format!("{}S1000 M3\nS5\nS350\n", fixture("050"));
    let r = run(&text).ok();
    let speeds: Vec<f64> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::Aux(Aux::S(s)) => Some(*s),
            _ => None,
        })
        .collect();
    assert_eq!(speeds, [700.0, 12.0, 350.0]);
}

/// The moves' ends and kinds after `skip` moves, as (end X/Y, centre X/Y if an arc, ccw, feed).
type Piece = ((f64, f64), Option<(f64, f64)>, bool, f64);

fn pieces(r: &Run) -> Vec<Piece> {
    r.moves()
        .iter()
        .map(|c| match c {
            Command::Linear { end, feed } => ((end[0], end[1]), None, false, *feed),
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                ..
            } => (
                (end[0], end[1]),
                Some((center[0], center[1])),
                !clockwise,
                *feed,
            ),
            Command::Rapid { end } => ((end[0], end[1]), None, false, 0.0),
            _ => unreachable!(),
        })
        .collect()
}

fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

#[test]
fn f052_chamfers_by_length_and_by_legs_with_their_feed() {
    let text = filled(
        "052",
        &[
            "N5 G17 G94 F300 G1 X0 Y0",
            "N10 G1 X40 CHF=5",
            "N20 X40 Y40",
            "",
            "N100 G1 X0 CHR=7",
            "N110 X0 Y0",
            "",
            "N200 G1 FRC=200 X40 CHR=4",
            "N210 X40 Y-40",
        ],
    );
    let r = run(&text).ok();
    let p = pieces(&r);
    let ends: Vec<(f64, f64)> = p.iter().map(|q| q.0).collect();
    // CHF=5 at a right angle: legs of 5/√2; the chamfer itself 5 long.
    let leg = 5.0 / 2f64.sqrt();
    let k = ends
        .iter()
        .position(|e| dist(*e, (40.0 - leg, 0.0)) < 1e-6)
        .expect("cut back");
    assert!(dist(ends[k + 1], (40.0, leg)) < 1e-6);
    assert!((dist(ends[k], ends[k + 1]) - 5.0).abs() < 1e-6);
    // CHR=7: legs of 7 at (0, 40).
    let k = ends
        .iter()
        .position(|e| dist(*e, (7.0, 40.0)) < 1e-6)
        .expect("CHR=7");
    assert!(dist(ends[k + 1], (0.0, 33.0)) < 1e-6);
    // CHR=4 at F200 (FRC), the lines at F300.
    let k = ends
        .iter()
        .position(|e| dist(*e, (36.0, 0.0)) < 1e-6)
        .expect("CHR=4");
    assert!(dist(ends[k + 1], (40.0, -4.0)) < 1e-6);
    assert_eq!((p[k].3, p[k + 1].3, p[k + 2].3), (300.0, 200.0, 300.0));
    assert!(near(&r.end(), &[40.0, -40.0, 0.0]));
}

/// Issue 46 item 2 (D126): without FRC/FRCM an inserted chamfer or rounding is cut at the feed
/// of the block leaving the corner (§9.5.1: "normally the F of the following block"), whether
/// that block is a line or an arc; FRC still wins.
#[test]
fn a_corner_element_takes_the_feed_of_the_block_leaving_the_corner() {
    let r = run("G17 G94 G90 G1 X0 Y0 F300\nX40 CHF=5\nY40 F150\nX0 RND=4 F200\n        G2 X-10 Y30 I-10 J0 F120\nG1 X-10 Y0 RND=3\nX-30 F90 FRC=60\nM30\n")
        .ok();
    let p = pieces(&r);
    let feed_to = |at: (f64, f64)| {
        p.iter()
            .find(|q| dist(q.0, at) < 1e-6)
            .unwrap_or_else(|| panic!("no piece ends at {at:?}: {p:?}"))
            .3
    };
    let leg = 5.0 / 2f64.sqrt();
    // The line into the corner keeps its own F300; the chamfer and the line after it F150.
    assert_eq!(feed_to((40.0 - leg, 0.0)), 300.0);
    assert_eq!(
        feed_to((40.0, leg)),
        150.0,
        "the chamfer at the leaving block's F"
    );
    assert_eq!(feed_to((40.0, 40.0)), 150.0);
    // A rounding into an arc (about (−10, 40), leaving (0, 40) downwards): the arc's F120.
    let rounding = p
        .iter()
        .position(|q| q.1.is_some_and(|c| dist(c, (3.4, 36.0)) < 0.1))
        .unwrap_or_else(|| panic!("the rounding at (0, 40): {p:?}"));
    assert_eq!(p[rounding - 1].3, 200.0, "the line into it keeps F200");
    assert_eq!(p[rounding].3, 120.0, "the rounding at the arc's F");
    // The last rounding takes the leaving block's F90: FRC=60 there is that block's own
    // corner feed (it has none), not this one's.
    let last = p
        .iter()
        .rposition(|q| q.1.is_some())
        .expect("the last rounding");
    assert_eq!(p[last].3, 90.0);
}

#[test]
fn f053_roundings_single_and_modal_between_lines_and_arcs() {
    let text = filled(
        "053",
        &[
            "N5 G17 G94 F300 G1 X0 Y0",
            "N10 G1 X40 RND=8",
            "N20 X40 Y40",
            "",
            "N50 G1 X60 FRCM= 200 RNDM=7.3",
            "N60 G3 X80 Y60 I20 J0",
            "N70 G1 X80 Y80 RNDM=0",
            "N80 X100 Y80",
        ],
    );
    let r = run(&text).ok();
    let p = pieces(&r);
    let fillets: Vec<&Piece> = p
        .iter()
        .enumerate()
        .filter(|(i, q)| {
            q.1.is_some() && *i > 0 && {
                let c = q.1.unwrap();
                let start = p[i - 1].0;
                (dist(start, c) - dist(q.0, c)).abs() < 1e-6 && dist(q.0, c) < 10.0
            }
        })
        .map(|(_, q)| q)
        .collect();
    assert_eq!(fillets.len(), 3, "{p:?}");
    // RND=8 at (40, 0), +X into +Y: centre (32, 8), counter-clockwise, at F300.
    assert!(dist(fillets[0].1.unwrap(), (32.0, 8.0)) < 1e-6 && fillets[0].2);
    assert_eq!(fillets[0].3, 300.0);
    // RNDM 7.3 at FRCM 200 where N50 (+X) meets the arc about (80, 40) going down at
    // (60, 40): a right turn; the centre 7.3 below the line and 20 + 7.3 from the arc's.
    let c = fillets[1].1.unwrap();
    assert!((c.1 - 32.7).abs() < 1e-6, "{c:?}");
    assert!((dist(c, (80.0, 40.0)) - 27.3).abs() < 1e-6, "{c:?}");
    assert!(!fillets[1].2 && fillets[1].3 == 200.0);
    // And where the arc leaves (80, 60) going −X into N70's +Y: a right turn again, the
    // centre 7.3 right of the line (X 87.3) and 27.3 from the arc's centre.
    let c = fillets[2].1.unwrap();
    assert!((c.0 - 87.3).abs() < 1e-6, "{c:?}");
    assert!((dist(c, (80.0, 40.0)) - 27.3).abs() < 1e-6, "{c:?}");
    // RNDM=0 in N70: the corner at its end stays sharp.
    assert!(p.iter().any(|q| dist(q.0, (80.0, 80.0)) < 1e-9));
    assert!(near(&r.end(), &[100.0, 80.0, 0.0]));
}

#[test]
fn roundings_and_chamfers_under_radius_compensation_are_offset_like_the_contour() {
    // A 40 mm square traversed counter-clockwise, cut outside (G42) by T1 D1 (radius 10),
    // three corners rounded R5 and one chamfered: the cutter centre runs 10 mm outside, the
    // roundings on arcs of R15 about the contour's rounding centres.
    let text = "G17 G90 T1 D1 F300\nG0 X-20 Y-20 Z5\nG1 Z-5\nG42 G1 X0 Y0\n\
        X40 RND=5\nY40 RND=5\nX0 CHR=5\nY0\nG40 G1 X-20 Y-20\nM30\n";
    let r = run(text).ok();
    let p = pieces(&r);
    let arcs: Vec<((f64, f64), bool)> = p.iter().filter_map(|q| q.1.map(|c| (c, q.2))).collect();
    for centre in [(35.0, 5.0), (35.0, 35.0)] {
        let k = arcs
            .iter()
            .position(|a| dist(a.0, centre) < 1e-6)
            .unwrap_or_else(|| panic!("an arc about {centre:?}: {p:?}"));
        assert!(arcs[k].1, "counter-clockwise");
        let end = p.iter().find(|q| q.1 == Some(arcs[k].0)).unwrap().0;
        assert!((dist(end, centre) - 15.0).abs() < 1e-6, "R15: {end:?}");
    }
    // The chamfer (5, 40)–(0, 35) offset 10 mm outward along its normal (−1, 1)/√2.
    let s = 10.0 / 2f64.sqrt();
    let ends: Vec<(f64, f64)> = p.iter().map(|q| q.0).collect();
    assert!(
        ends.iter().any(|e| dist(*e, (0.0 - s, 35.0 + s)) < 1e-6),
        "{ends:?}"
    );
    // The straight sides 10 mm out: X50 on the right, Y50 on top, X−10 on the left.
    assert!(ends
        .iter()
        .any(|e| (e.0 - 50.0).abs() < 1e-6 && (e.1 - 35.0).abs() < 1e-6));
    assert!(ends
        .iter()
        .any(|e| (e.0 + 10.0).abs() < 1e-6 && e.1.abs() < 1e-6));
}

#[test]
fn an_m_function_between_rounded_compensated_blocks_keeps_its_place() {
    let text = "G17 G90 T1 D1 F300\nG0 X-20 Y-20 Z5\nG1 Z-5\nG42 G1 X0 Y0\n\
        X40 RND=5\nY40 RND=5\nM8\nX0 RND=5\nY0\nG40 G1 X-20 Y-20\nM30\n";
    let r = run(text).ok();
    let m8 = r
        .out
        .iter()
        .position(|c| *c == Command::Aux(Aux::M(8)))
        .unwrap();
    let moves_of = |line: u32| -> Vec<usize> {
        (0..r.out.len())
            .filter(|&i| r.lines[i] == line && r.out[i].end().is_some())
            .collect()
    };
    // Y40's moves and its rounding (line 6) before M8 (line 7); X0's (line 8) after.
    assert!(moves_of(6).iter().all(|&i| i < m8) && !moves_of(6).is_empty());
    assert!(moves_of(8).iter().all(|&i| i > m8) && !moves_of(8).is_empty());
}

/// Where the line from `p` at `a1` degrees meets the line through `q` at `a2` degrees,
/// worked out by Cramer's rule.
fn crossing(p: (f64, f64), a1: f64, q: (f64, f64), a2: f64) -> (f64, f64) {
    let (d1, d2) = (
        (a1.to_radians().cos(), a1.to_radians().sin()),
        (a2.to_radians().cos(), a2.to_radians().sin()),
    );
    // p + t·d1 = q + u·d2
    let det = d1.0 * (-d2.1) - d1.1 * (-d2.0);
    let (rx, ry) = (q.0 - p.0, q.1 - p.1);
    let t = (rx * (-d2.1) - ry * (-d2.0)) / det;
    (p.0 + t * d1.0, p.1 + t * d1.1)
}

/// Distance from `c` to the line through `p` at `a` degrees.
fn to_line(c: (f64, f64), p: (f64, f64), a: f64) -> f64 {
    let (s, co) = a.to_radians().sin_cos();
    ((c.0 - p.0) * s - (c.1 - p.1) * co).abs()
}

#[test]
fn f054_contour_definitions_with_ang() {
    // As printed the angles are placeholders (its first alarm: N10 without a feed). Filled:
    // Fig. 9-41 a and b, one coordinate and the angle.
    let r = run("F100\nN10 G1 X10 Y10\nN20 X40 ANG=30\n").ok();
    assert!(near(
        &r.end(),
        &[40.0, 10.0 + 30.0 * 30f64.to_radians().tan(), 0.0]
    ));
    let r = run("F100\nN10 G1 X10 Y10\nN20 Y40 ANG=60\n").ok();
    assert!(near(
        &r.end(),
        &[10.0 + 30.0 / 60f64.to_radians().tan(), 40.0, 0.0]
    ));
    // Fig. 9-42: the end of N20 unknown, found where its line meets N30's.
    let r = run("F100\nN10 G1 X10 Y10\nN20 ANG=30\nN30 X60 Y20 ANG=-45\n").ok();
    let c = crossing((10.0, 10.0), 30.0, (60.0, 20.0), -45.0);
    let ends: Vec<(f64, f64)> = pieces(&r).iter().map(|q| q.0).collect();
    assert_eq!(ends.len(), 3, "{ends:?}");
    assert!(
        dist(ends[1], c) < 1e-9 && dist(ends[2], (60.0, 20.0)) < 1e-9,
        "{ends:?}"
    );
    // With a rounding at that corner, and a second rounding at N30's end.
    let r = run("F100\nN10 G1 X10 Y10\nN20 ANG=30 RND=4\nN30 X60 Y20 ANG=-45 RND=3\nN40 X80 Y60\n")
        .ok();
    let p = pieces(&r);
    let arcs: Vec<&Piece> = p.iter().filter(|q| q.1.is_some()).collect();
    assert_eq!(arcs.len(), 2, "{p:?}");
    let c1 = arcs[0].1.unwrap();
    assert!((to_line(c1, (10.0, 10.0), 30.0) - 4.0).abs() < 1e-9);
    assert!((to_line(c1, (60.0, 20.0), -45.0) - 4.0).abs() < 1e-9);
    let c2 = arcs[1].1.unwrap();
    assert!((to_line(c2, (60.0, 20.0), -45.0) - 3.0).abs() < 1e-9);
    let a3 = (60.0f64 - 20.0).atan2(80.0 - 60.0).to_degrees();
    assert!((to_line(c2, (80.0, 60.0), a3) - 3.0).abs() < 1e-9);
    // A chamfer instead: its legs 2 mm either side of the crossing.
    let r = run("F100\nN10 G1 X10 Y10\nN20 ANG=30 CHR=2\nN30 X60 Y20 ANG=-45\n").ok();
    let ends: Vec<(f64, f64)> = pieces(&r).iter().map(|q| q.0).collect();
    assert!((dist(ends[1], c) - 2.0).abs() < 1e-9 && (dist(ends[2], c) - 2.0).abs() < 1e-9);
    // Refused: both coordinates and an angle with no waiting line; parallel lines; an arc
    // after a waiting line.
    assert_eq!(run("F100\nG1 X10 Y10 ANG=30\n").alarm(), (12080, 2));
    assert_eq!(run("F100\nG1 ANG=30\nX50 Y50 ANG=30\n").alarm().0, 14040);
    assert_eq!(run("F100\nG1 ANG=30\nG2 X50 Y50 CR=40\n").alarm().0, 12080);
}
