//! Smooth approach and retraction, WAB (`001` §9.14, fixtures 087–090, decision D114): the
//! manual's four programs with their placeholders filled, each cutter path compared with
//! points computed here from the manual's definitions (DISR the cutter edge's distance on a
//! line, the radius of the cutter centre's path on a circle; DISCL the height of P2 above
//! the contour's plane; FAD the slow infeed), and the alarms of a WAB that cannot be made.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Command, Library};
use support::*;

/// The cutter of these tests: T1 D1, radius 5, length 0 (machine Z is the cutter's tip).
const R: f64 = 5.0;

fn run_r5(text: &str) -> Run {
    run_with(text, with_edge(11, R), Library::new())
}

type V = (f64, f64);

/// A move: kind, end, centre (arcs), feed.
type Step = (char, Vec<f64>, Option<Vec<f64>>, f64);

fn add(a: V, b: V, k: f64) -> V {
    (a.0 + k * b.0, a.1 + k * b.1)
}

fn unit(a: V, b: V) -> V {
    let l = (b.0 - a.0).hypot(b.1 - a.1);
    ((b.0 - a.0) / l, (b.1 - a.1) / l)
}

fn left(t: V) -> V {
    (-t.1, t.0)
}

fn right(t: V) -> V {
    (t.1, -t.0)
}

/// The moves as (kind, end, centre, feed): kind R rapid, L line, A counter-clockwise arc,
/// C clockwise arc.
fn path(r: &Run) -> Vec<Step> {
    r.out
        .iter()
        .filter_map(|c| match c {
            Command::Rapid { end } => Some(('R', end.clone(), None, 0.0)),
            Command::Linear { end, feed } => Some(('L', end.clone(), None, *feed)),
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                ..
            } => Some((
                if *clockwise { 'C' } else { 'A' },
                end.clone(),
                Some(center.clone()),
                *feed,
            )),
            _ => None,
        })
        .collect()
}

fn p3(p: V, z: f64) -> Vec<f64> {
    vec![p.0, p.1, z]
}

/// Asserts the path move by move: kind, end, centre (arcs) and feed.
fn assert_path(got: &[Step], want: &[Step]) {
    assert_eq!(got.len(), want.len(), "moves: {got:#?}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.0, w.0, "move {k}: kind, {got:#?}");
        assert!(near(&g.1, &w.1), "move {k}: end {:?}, want {:?}", g.1, w.1);
        match (&g.2, &w.2) {
            (Some(a), Some(b)) => assert!(near(a, b), "move {k}: centre {a:?}, want {b:?}"),
            (None, None) => {}
            other => panic!("move {k}: centre {other:?}"),
        }
        assert!(
            (g.3 - w.3).abs() < 1e-6,
            "move {k}: feed {}, want {}",
            g.3,
            w.3
        );
    }
}

/// The contour both line and quarter-circle programs cut: approached at P4 (4, 4) along +X
/// under G42, left with G40 at (40, 40); entered again under G41 from (30, 20) to the
/// contour's end (4, 4), from which the WAB block retracts to P0 (0, -20).
const FILL_087: [&str; 6] = [
    "N10 T1 D1 G17",
    "N20 G0 X-40 Y-40 Z0",
    "N50 G40 G0 X40 Y40",
    "N100 G41 G1 X30 Y20",
    "N120 G40 G148 DISR=8 F700 X0 Y-20",
    "M30",
];

#[test]
fn f087_g147_comes_along_a_line_and_g148_leaves_along_one() {
    let text = filled("087", &FILL_087);
    let r = run_r5(&text).ok();
    let p4 = (4.0, 4.0);
    // Approach: along +X (N40's direction), on the right (G42); the line's length is
    // DISR + the cutter's radius, so the cutter's edge starts DISR before P4.
    let t = (1.0, 0.0);
    let n = right(t);
    let start = add(p4, t, -(8.0 + R));
    // Retraction: along N110's direction, on the left (G41), DISR + R long.
    let t2 = unit((30.0, 20.0), p4);
    let n2 = left(t2);
    let off = add(add(p4, t2, 8.0 + R), n2, R);
    assert_path(
        &path(&r),
        &[
            ('R', vec![-40.0, -40.0, 0.0], None, 0.0),
            // P0 → P1 at the speed before the block (G0), compensation coming on.
            ('R', p3(add(start, n, R), 0.0), None, 0.0),
            ('L', p3(add(p4, n, R), 0.0), None, 600.0),
            ('L', p3(add((40.0, 4.0), n, R), 0.0), None, 600.0),
            ('R', p3((40.0, 40.0), 0.0), None, 0.0),
            ('L', p3(add((30.0, 20.0), n2, R), 0.0), None, 600.0),
            ('L', p3(add(p4, n2, R), 0.0), None, 600.0),
            // The way off at the feed before the block, then to P0 at its F700 as
            // compensation goes.
            ('L', p3(off, 0.0), None, 600.0),
            ('L', p3((0.0, -20.0), 0.0), None, 700.0),
        ],
    );
}

#[test]
fn f088_g247_comes_on_a_quarter_circle_and_g248_leaves_on_one() {
    let fill = FILL_087.map(|l| l.replace("G148 DISR=8", "G248 DISR=20"));
    let fill: Vec<&str> = fill.iter().map(String::as_str).collect();
    let text = filled("088", &fill);
    let r = run_r5(&text).ok();
    let p4 = (4.0, 4.0);
    // The cutter centre's circle has the radius DISR = 20, tangent to the compensated
    // contour at P4: under G42 its centre lies on the right, and the cutter turns
    // clockwise onto the contour.
    let t = (1.0, 0.0);
    let n = right(t);
    let q4 = add(p4, n, R);
    let m = add(q4, n, 20.0);
    let s = add(m, t, -20.0);
    let t2 = unit((30.0, 20.0), p4);
    let n2 = left(t2);
    let q = add(p4, n2, R);
    let m2 = add(q, n2, 20.0);
    let e2 = add(m2, t2, 20.0);
    assert_path(
        &path(&r),
        &[
            ('R', vec![-40.0, -40.0, 0.0], None, 0.0),
            ('R', p3(s, 0.0), None, 0.0),
            ('C', p3(q4, 0.0), Some(p3(m, 0.0)), 600.0),
            ('L', p3(add((40.0, 4.0), n, R), 0.0), None, 600.0),
            ('R', p3((40.0, 40.0), 0.0), None, 0.0),
            ('L', p3(add((30.0, 20.0), n2, R), 0.0), None, 600.0),
            ('L', p3(q, 0.0), None, 600.0),
            // Off on the left, counter-clockwise, at the old feed.
            ('A', p3(e2, 0.0), Some(p3(m2, 0.0)), 600.0),
            ('L', p3((0.0, -20.0), 0.0), None, 700.0),
        ],
    );
    // The way on is a quarter: centre to start and centre to P4 at right angles.
    let (a, b) = (unit(m, s), unit(m, q4));
    assert!((a.0 * b.0 + a.1 * b.1).abs() < 1e-9);
}

/// Fixture 089 as printed, and the two forms the manual gives for N30/N40, each with the
/// contour going on along +X after P4 (the block the approach turns into).
#[test]
fn f089_g347_g340_comes_down_a_helix_on_a_semicircle_in_all_three_forms() {
    let printed = filled("089", &["N10 T1 D1 G17 G90 G94", "N50 X50 M30"]);
    let alone = printed.replace(
        "N30 G41 G347 G340 DISCL=3 DISR=13 Z=0 F500",
        "N30 G41 G347 G340 DISCL=3 DISR=13 X40 Y-10 Z0 F500",
    );
    let alone = alone.replace("N40 G1 X40 Y-10\n", "N40 G1\n");
    let split = printed
        .replace(
            "N30 G41 G347 G340 DISCL=3 DISR=13 Z=0 F500",
            "N30 G41 G347 G340 DISCL=3 DISR=13 F500",
        )
        .replace("N40 G1 X40 Y-10\n", "N40 G1 X40 Y-10 Z0\n");
    assert_ne!(alone, printed);
    assert_ne!(split, printed);
    // "以 G0 运行到平面中的点 P1 Z=30 (半圆起始点, 进行了刀具半径补偿), 然后运行至 Z=3 (DISCL)
    // 的深度 (P2, P3)。以 500 毫米/分钟的进给率沿螺旋曲线达到点 X40 Y-10, 深度 Z=0 (P4)."
    let p4 = (40.0, -10.0);
    let t = (1.0, 0.0);
    let n = left(t);
    let q4 = add(p4, n, R);
    let m = add(q4, n, 13.0);
    let s = add(m, n, 13.0);
    let want = [
        ('R', vec![0.0, 0.0, 30.0], None, 0.0),
        ('R', p3(s, 30.0), None, 0.0),
        ('R', p3(s, 3.0), None, 0.0),
        ('A', p3(q4, 0.0), Some(p3(m, 0.0)), 500.0),
        ('L', p3(add((50.0, -10.0), n, R), 0.0), None, 500.0),
    ];
    for text in [&printed, &alone, &split] {
        let r = run_r5(text).ok();
        assert_path(&path(&r), &want);
    }
}

#[test]
fn f090_g341_comes_down_beside_the_contour_at_fad_then_turns_on_at_f() {
    let text = filled(
        "090",
        &["N10 T1 D1 G17 G90 G94", "N50 G40 G0 X60 Y-30 Z30 M30"],
    );
    let r = run_r5(&text).ok();
    // "以 G0 运行到 P1 的 Z=30, 然后运行至 Z=5 (DISCL) (P2)。以 FAD=500 ... 至深度 Z=0 (P3)。
    // 接着以 F=800 ... 沿四分圆运行至轮廓上的点 P4" (the program's Y-10; the text's Y10 is
    // a misprint, D114).
    let p4 = (40.0, -10.0);
    let t = (1.0, 0.0);
    let n = left(t);
    let q4 = add(p4, n, R);
    let m = add(q4, n, 13.0);
    let s = add(m, t, -13.0);
    assert_path(
        &path(&r),
        &[
            ('R', vec![0.0, 0.0, 30.0], None, 0.0),
            ('R', p3(s, 30.0), None, 0.0),
            ('R', p3(s, 5.0), None, 0.0),
            ('L', p3(s, 0.0), None, 500.0),
            ('A', p3(q4, 0.0), Some(p3(m, 0.0)), 800.0),
            ('L', p3(add((50.0, -10.0), n, R), 0.0), None, 800.0),
            ('R', vec![60.0, -30.0, 30.0], None, 0.0),
        ],
    );
}

/// Commands of blocks between the WAB block and the contour come after the approach, in
/// program order; a retraction without plane axes ends at P2, with only Z at P1.
#[test]
fn blocks_between_wait_behind_the_approach_and_retraction_ends_as_programmed() {
    let text = "T1 D1 G17\nG0 X-30 Y0 Z10\nG41 G147 G341 DISCL=2 DISR=5 F300 X0 Y0 Z0\nM8\n\
                G1 X20\nG248 G341 DISR=4 DISCL=3 FAD=100 F900\nM30\n";
    let r = run_r5(text).ok();
    let m8 = r
        .out
        .iter()
        .position(|c| matches!(c, Command::Aux(cnc_interpreter::Aux::M(8))))
        .expect("M8");
    let first_feed = r
        .out
        .iter()
        .position(|c| matches!(c, Command::Linear { .. }))
        .expect("a line");
    assert!(m8 > first_feed, "M8 before the approach: {:#?}", r.out);
    // The retraction: quarter circle left of +X (G41), radius DISR 4 at the centre, then
    // up to DISCL at FAD; no axes in the block, so it ends at P2.
    let q = (20.0, R);
    let m = add(q, (0.0, 1.0), 4.0);
    let e = add(m, (1.0, 0.0), 4.0);
    let got = path(&r);
    let tail = &got[got.len() - 2..];
    assert_path(
        tail,
        &[
            ('A', p3(e, 0.0), Some(p3(m, 0.0)), 300.0),
            ('L', p3(e, 3.0), None, 100.0),
        ],
    );
    // The same with only Z: up to P2 at FAD, then at F900 to Z20 (P1).
    let up = text.replace("F900\n", "F900 Z20\n");
    let r = run_r5(&up).ok();
    let got = path(&r);
    assert_path(
        &got[got.len() - 3..],
        &[
            ('A', p3(e, 0.0), Some(p3(m, 0.0)), 300.0),
            ('L', p3(e, 3.0), None, 100.0),
            ('L', p3(e, 20.0), None, 900.0),
        ],
    );
}

#[test]
fn a_wab_that_cannot_be_made_is_an_alarm_with_its_number() {
    let cases: [(&str, u32); 8] = [
        // DISR missing.
        (
            "T1 D1\nG0 X-20 Y0\nG41 G147 X0 Y0 F100\nG1 X10\nM30\n",
            10742,
        ),
        // A circle without a side.
        (
            "T1 D1\nG0 X-20 Y0\nG247 DISR=5 X0 Y0 F100\nG1 X10\nM30\n",
            10744,
        ),
        // The contour after P4 goes only along Z.
        (
            "T1 D1\nG0 X-20 Y0\nG41 G147 DISR=5 X0 Y0 F100\nG1 Z-5\nM30\n",
            10744,
        ),
        // DISCL above P0: the infeed would turn back.
        (
            "T1 D1\nG0 X-20 Y0 Z2\nG41 G147 G341 DISR=5 DISCL=5 X0 Y0 Z0 F100\nG1 X10\nM30\n",
            10741,
        ),
        // Six blocks without a move.
        (
            "T1 D1\nG0 X-20 Y0\nG41 G147 DISR=5 X0 Y0 F100\nM8\nM9\nM8\nM9\nM8\nM9\nG1 X10\nM30\n",
            10740,
        ),
        // The program ends before the contour.
        (
            "T1 D1\nG0 X-20 Y0\nG41 G147 DISR=5 X0 Y0 F100\nM30\n",
            10745,
        ),
        // A second approach before the first ended.
        (
            "T1 D1\nG0 X-20 Y0\nG41 G147 DISR=5 X0 Y0 F100\nG247 DISR=5 X5\nM30\n",
            10743,
        ),
        // DISR without a WAB block.
        ("T1 D1\nG1 X10 DISR=5 F100\nM30\n", 12080),
    ];
    for (text, number) in cases {
        let r = run_r5(text);
        let e = r
            .error
            .as_ref()
            .unwrap_or_else(|| panic!("no alarm for {text}"));
        assert_eq!(e.number, number, "{text}: {e:?}");
        // Nothing of the approach was sent before the alarm.
        assert!(
            !r.out
                .iter()
                .any(|c| matches!(c, Command::Linear { feed, .. } if *feed == 100.0)),
            "{text}: {:#?}",
            r.out
        );
    }
}

#[test]
fn a_retraction_whose_discl_point_lies_above_p1_turns_back_and_is_refused() {
    // Off the contour at Z0 to Z5 (P1), but DISCL=20 puts P2 above P1.
    let text = "T1 D1\nG0 X-20 Y0\nG41 G1 X0 Y0 F100\nG1 X10\nG148 G341 DISR=5 DISCL=20 Z5\nM30\n";
    let r = run_r5(text);
    assert_eq!(r.alarm(), (10741, 5));
    // With DISCL=3 the same retraction runs: up to Z3, then to Z5.
    let r = run_r5(&text.replace("DISCL=20", "DISCL=3")).ok();
    let got = path(&r);
    assert!(near(&got[got.len() - 1].1[2..], &[5.0]), "{got:#?}");
    assert!(near(&got[got.len() - 2].1[2..], &[3.0]), "{got:#?}");
}
