//! Polar interpolation on the Huaxing turn-mill (`000` §5.8, decision D141) on the canonical
//! stream: the manual's fixture 016, a hexagon and a slot near the pole mapped back from the
//! machine's X and C to the face, and the section's alarms 106, 107 and 108.

#[path = "support/huaxing.rs"]
mod huaxing;
use huaxing::{fixture, hx};

use cnc_interpreter::{Canon, Command, Setup};
use cnc_interpreter_core::setup::ToolOffset;

/// A turn-mill at X200 Z100, tool 1 an end mill of radius 3 (tip 0) with no length offset.
fn turn_mill() -> Setup {
    let mut s = Setup::lathe([200.0, 100.0]).with_spindle_c_axis();
    s.offsets.tools.insert(
        1,
        ToolOffset {
            radius: 3.0,
            tip: 0,
            ..ToolOffset::default()
        },
    );
    s
}

/// The face point (mm) of a machine point X (diameter), C (degrees).
fn face(end: &[f64]) -> (f64, f64) {
    let (r, c) = (end[0] / 2.0, end[2].to_radians());
    (r * c.cos(), r * c.sin())
}

fn distance_to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

fn distance_to_path(p: (f64, f64), path: &[(f64, f64)]) -> f64 {
    path.windows(2)
        .map(|w| distance_to_segment(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// The machine lines between C_CONTOUR_ON and C_CONTOUR_OFF: (start, end, feed).
fn contour_lines(cmds: &[Canon]) -> Vec<(Vec<f64>, Vec<f64>, f64)> {
    let mut lines = Vec::new();
    let mut on = false;
    let mut here: Option<Vec<f64>> = None;
    for c in cmds {
        match &c.command {
            Command::Contour { on: o } => on = *o,
            Command::Linear { end, feed } if on => {
                let start = here.clone().expect("a point before the contour");
                lines.push((start, end.clone(), *feed));
            }
            _ => {}
        }
        if let Some(end) = c.command.end() {
            here = Some(end.to_vec());
        }
        if let Command::Contour { on: true } = &c.command {
            // The contour starts at C 0 where the tool stands.
            let h = here.as_mut().expect("position");
            h[2] = 0.0;
        }
    }
    lines
}

/// Every machine line mapped back lies on `path` (the face's contour, the cutter's centre):
/// its ends within 1e-9 mm, its quarter points within the transformation's 0.25 µm; and it
/// takes the time its face length takes at `feed` (within 0.1 %: a line's bulge of up to
/// 0.25 µm makes a 20 µm piece near the pole 0.01 % longer than its stretch of contour).
fn assert_on_face_path(lines: &[(Vec<f64>, Vec<f64>, f64)], path: &[(f64, f64)], feed: f64) {
    let mut worst = 0.0f64;
    for (a, b, f) in lines {
        for s in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let p: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect();
            let d = distance_to_path(face(&p), path);
            let bound = if s == 0.0 || s == 1.0 { 1e-9 } else { 0.000_25 };
            assert!(d <= bound, "{p:?} is {d} mm off the face's path");
            worst = worst.max(d);
        }
        // The face's length of the piece: the machine line mapped back, finely sampled (it
        // lies on the face's line or circle).
        let at = |s: f64| {
            face(
                &a.iter()
                    .zip(b)
                    .map(|(x, y)| x + s * (y - x))
                    .collect::<Vec<_>>(),
            )
        };
        let face_len: f64 = (0..256)
            .map(|k| {
                let (p, q) = (at(f64::from(k) / 256.0), at(f64::from(k + 1) / 256.0));
                (q.0 - p.0).hypot(q.1 - p.1)
            })
            .sum();
        let slide = ((b[0] - a[0]) / 2.0).hypot(b[2] - a[2]);
        if face_len > 1e-9 {
            let minutes = slide / f;
            assert!(
                (minutes - face_len / feed).abs() <= 1e-3 * minutes,
                "{a:?} → {b:?} at F{f} takes {minutes} min, the face's {face_len} mm at F{feed} {}",
                face_len / feed
            );
        }
    }
    println!(
        "{} machine lines, worst {worst:.2e} mm off the face",
        lines.len()
    );
}

/// Fixture 016 after the tool's offset and a position at X40: C to 0 (G00 C0 at C's rapid),
/// G12.1, then the rectangle X10…−20 (diameter: u 5 … −10) by C −10 … 10 with G41 and an end
/// mill of radius 3: the cutter's centre runs the rectangle 3 mm inside, every machine line
/// mapped back onto it; G13.1 leaves X30 C0 and the Z-X plane.
#[test]
fn fixture_016_mills_the_rectangle_on_the_face() {
    let text = format!(
        "T0101\nG00 X40 Z0\nG98 F100\n{}G02 X40 Z-5 R5\nM30\n",
        fixture("016_g12_1_polar_interpolation.nc")
    );
    let cmds = hx(&text, turn_mill()).unwrap();
    let rotary = cmds
        .iter()
        .find_map(|c| match &c.command {
            Command::Rotary { degrees, rpm, .. } => Some((*degrees, *rpm)),
            _ => None,
        })
        .expect("G00 C0");
    assert_eq!(rotary, (0.0, 100.0), "C to 0 at its rapid, 100 r/min");
    let on = cmds
        .iter()
        .filter(|c| matches!(c.command, Command::Contour { .. }))
        .count();
    assert_eq!(on, 2, "G12.1 and G13.1");
    let lines = contour_lines(&cmds);
    // G01 X30, the start-up to the offset corner, the rectangle, the cancel back to X30.
    let r = 3.0;
    let path = [
        (20.0, 0.0),
        (15.0, 0.0),
        (5.0 - r, 0.0),
        (5.0 - r, 10.0 - r),
        (-10.0 + r, 10.0 - r),
        (-10.0 + r, -10.0 + r),
        (5.0 - r, -10.0 + r),
        (5.0 - r, 0.0),
        (15.0, 0.0),
    ];
    assert_on_face_path(&lines, &path, 100.0);
    // Every corner of the cutter's path is reached, in order.
    let mut next = 1;
    for (_, b, _) in &lines {
        let p = face(b);
        if next < path.len() && (p.0 - path[next].0).hypot(p.1 - path[next].1) < 1e-9 {
            next += 1;
        }
    }
    assert_eq!(next, path.len(), "corners reached in order");
    // After G13.1 the position is the machine's: X30 (diameter), C at 0°, and the Z-X plane's
    // arc runs.
    let arc = cmds
        .iter()
        .find_map(|c| match &c.command {
            Command::Arc { end, .. } => Some(end.clone()),
            _ => None,
        })
        .expect("G02 after G13.1");
    assert!(
        (arc[0] - 40.0).abs() < 1e-9 && (arc[1] + 5.0).abs() < 1e-9,
        "{arc:?}"
    );
    assert!(
        arc[2].abs() < 1e-9 || (arc[2] - 360.0).abs() < 1e-9,
        "C {}",
        arc[2]
    );
}

/// A hexagon of 30 mm across flats centred on the spindle, a slot that passes 1 mm from the
/// pole and a half circle about it (G03 by R in the X-C plane): each machine line within
/// 0.25 µm of the face's line or circle; near the pole C turns a quarter turn in 2 mm of
/// slot; on the circle X stands and C turns 180°.
#[test]
fn a_hexagon_and_a_slot_near_the_pole_stay_on_the_face() {
    let (a, h) = (15.0f64, 15.0 / 3f64.sqrt());
    // The hexagon's corners (flats at u = ±15), as X (diameter) and C.
    let corners = [
        (a, h),
        (0.0, 2.0 * h),
        (-a, h),
        (-a, -h),
        (0.0, -2.0 * h),
        (a, -h),
        (a, h),
    ];
    let mut text = String::from("T0101\nG00 X30 Z0\nG00 C0\nG12.1\nG98\n");
    for (u, v) in &corners {
        text.push_str(&format!("G01 X{:.6} C{:.6} F300\n", 2.0 * u, v));
    }
    text.push_str("G01 X40 C1\nG01 X-40 C1\nG01 X20 C0\nG03 X-20 C0 R10\nG13.1\nM30\n");
    let cmds = hx(&text, turn_mill()).unwrap();
    let lines = contour_lines(&cmds);
    let round = |x: f64| (x * 1e6).round() / 1e6;
    let mut path = vec![(15.0, 0.0)];
    path.extend(corners.iter().map(|&(u, v)| (round(u), round(v))));
    path.extend([(20.0, 1.0), (-20.0, 1.0), (10.0, 0.0)]);
    // The half circle of radius 10 about the pole, as fine a polygon as the tolerance.
    path.extend((0..=2_000).map(|k| {
        let a = std::f64::consts::PI * f64::from(k) / 2_000.0;
        (10.0 * a.cos(), 10.0 * a.sin())
    }));
    assert_on_face_path(&lines, &path, 300.0);
    let last = &lines.last().expect("lines").1;
    // C went once round with the hexagon, then half a turn on the circle: 540°.
    assert!(
        (last[0] - 20.0).abs() < 1e-9 && (last[2] - 540.0).abs() < 1e-9,
        "{last:?}"
    );
    let slot_cs: Vec<f64> = lines
        .iter()
        .filter(|(_, b, _)| (face(b).1 - 1.0).abs() < 1e-6 && face(b).0.abs() < 1.0)
        .map(|(_, b, _)| b[2])
        .collect();
    let turned = slot_cs.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - slot_cs.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(
        turned > 89.7,
        "C turns {turned}° within 1 mm either side of the pole"
    );
}

fn alarm(text: &str, setup: Setup) -> (u32, u32, String) {
    let e = hx(text, setup).expect_err("an alarm");
    (e.number, e.line, e.to_string())
}

/// §5.8's alarms: 107 without a C axis, 108 when the start is not X > 0 with C at 0, 106 for
/// what may not run inside (a tool change, G00, G99, a thread) or start it (no tool offset,
/// G99), and a move through the pole.
#[test]
fn polar_interpolation_alarms() {
    let start = "T0101\nG00 X30 Z0\nG00 C0\n";
    let plain = {
        let mut s = Setup::lathe([200.0, 100.0]);
        s.offsets.tools = turn_mill().offsets.tools;
        s
    };
    assert_eq!(alarm("T0101\nG00 X30 Z0\nG12.1\n", plain).0, 107);
    let cases = [
        ("T0101\nG00 X0 Z0\nG12.1\n", 108, 3),
        ("T0101\nG00 X30 Z0\nG00 C90\nG12.1\n", 108, 4),
        ("G00 X30 Z0\nG00 C0\nG12.1\n", 106, 3),
        ("T0101\nG99\nG00 X30 Z0\nG00 C0\nG12.1\n", 106, 5),
        ("G12.1\nT0202\n", 106, 5),
        ("G12.1\nG00 X20 C5\n", 106, 5),
        ("G12.1\nG99\n", 106, 5),
        ("G12.1\nG32 X20 C5 F1\n", 106, 5),
        ("G12.1\nG98 G01 X10 C0 F100\nG01 X-10 C0\n", 106, 6),
    ];
    for (tail, number, line) in cases {
        let text = if tail.starts_with("G12.1") {
            format!("{start}{tail}")
        } else {
            tail.to_string()
        };
        let (n, l, why) = alarm(&text, turn_mill());
        assert_eq!((n, l), (number, line), "{text:?}: {why}");
    }
}
