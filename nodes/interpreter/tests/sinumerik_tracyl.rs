//! Cylinder surface milling, TRACYL/TRAFOOF (`001` §9.15, fixture 091, decisions D117), on
//! the machine of figure 9-70: X the radial infeed, Y a real slide through the centre of the
//! rotary axis C, Z along C's axis. The machine path is checked against the developed path
//! computed here: C = Y/r, the groove walls made by the Y slide.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Command, Library, Setup};
use cnc_interpreter_core::ToolOffset;
use support::*;

/// The fixture's cutter radius (its header: 10.123 mm) and a length of 40 along its axis.
const R: f64 = 10.123;
const LENGTH: f64 = 40.0;
/// The groove's half width, OFFN, and the machining radius.
const OFFN: f64 = 12.4;
const RADIUS: f64 = 17.5;

/// X, Y, Z and C, standing at X0 Y0 Z150 C0; T1 D1 the fixture's cutter; G54 and G55 zero.
fn machine() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z', 'C'], &[false; 4], &[0.0, 0.0, 150.0, 0.0]);
    s.offsets.tools.insert(
        11,
        ToolOffset {
            z: LENGTH,
            radius: R,
            ..ToolOffset::default()
        },
    );
    s
}

fn run4(text: &str) -> Run {
    run_with(text, machine(), Library::new())
}

/// The developed-surface position of a machine point: (Y on the surface, Z), the Y slide's
/// offset from C's centre (60, where N15 put it) added back.
fn developed(p: &[f64]) -> (f64, f64) {
    (p[3].to_radians() * RADIUS + (p[1] - 60.0), p[2])
}

#[test]
fn f091_cuts_the_hook_slot_with_the_walls_made_by_the_y_slide() {
    let r = run4(&fixture("091")).ok();
    let ends = r.ends();
    // Before TRACYL: N15 G153 Y60, N30 to X25 Z50 C120 (T1's length along Z in G17).
    assert!(
        ends.iter().any(|e| near(e, &[0.0, 60.0, 150.0, 0.0])),
        "{ends:?}"
    );
    assert!(ends
        .iter()
        .any(|e| near(e, &[25.0, 60.0, 50.0 + LENGTH, 120.0])));
    // N70 G0 Y70 Z10: C turns to 70/17.5 rad; the Y slide stays on C's centre.
    let c70 = (70.0 / RADIUS).to_degrees();
    let c20 = (20.0 / RADIUS).to_degrees();
    assert!(
        ends.iter().any(|e| near(e, &[25.0, 60.0, 10.0, c70])),
        "{ends:?}"
    );
    // Cutting at the groove's base: X17.5 plus the length, along X in G19.
    let x = RADIUS + LENGTH;
    let cutting: Vec<&Vec<f64>> = ends.iter().filter(|e| (e[0] - x).abs() < 1e-9).collect();
    assert!(!cutting.is_empty());
    let inside = OFFN - R;
    // N90–N100 along the cylinder's axis (centre line at Y70): the slide holds the cutter
    // OFFN − R to the right of the centre line (G42 going −Z is −Y); N140 back up on the
    // other wall.
    assert!(cutting
        .iter()
        .any(|e| near(e, &[x, 60.0 - inside, 1.0, c70])));
    assert!(cutting
        .iter()
        .any(|e| near(e, &[x, 60.0 + inside, 1.0, c70])));
    // N110/N130 round the circumference at Z−30: the walls in Z, C turning alone.
    assert!(cutting
        .iter()
        .any(|e| near(e, &[x, 60.0, -30.0 + inside, c20])));
    assert!(cutting
        .iter()
        .any(|e| near(e, &[x, 60.0, -30.0 - inside, c20])));
    // Every cutting point inside the groove's length keeps the cutter's centre within
    // OFFN − R of the centre line (Y70 from Z1 down to Z−30, then Y70…20 at Z−30): its edge
    // reaches the wall, OFFN from the centre line, and never beyond.
    let segment = |p: f64, lo: f64, hi: f64, across: f64| {
        let along = (lo - p).max(0.0).max(p - hi);
        along.hypot(across)
    };
    for e in cutting.iter().filter(|e| e[2] <= 1.0 + 1e-9) {
        let (y, z) = developed(e);
        let from_centre = segment(z, -30.0, 1.0, y - 70.0).min(segment(y, 20.0, 70.0, z + 30.0));
        assert!(
            from_centre <= inside + 1e-6,
            "{e:?}: {from_centre} from the centre line"
        );
    }
    // N200 G54 G17 G0 X25 Z50 C120: back where it began, T1's length along Z again.
    assert!(
        near(&r.end(), &[25.0, 60.0, 50.0 + LENGTH, 120.0]),
        "{:?}",
        r.end()
    );
}

/// Each machine line of the transformed path takes the time its developed length takes at
/// the programmed feed, and C turns by exactly the developed travel over the radius.
#[test]
fn a_line_on_the_surface_is_one_machine_line_at_the_developed_feed() {
    let text = "G17 G0 X30 Y60 Z20 C0\nTRACYL(40)\nG19 G1 Y31.4159265 Z-10 F500\nTRAFOOF\nM30\n";
    let r = run_with(
        text,
        Setup::new(&['X', 'Y', 'Z', 'C'], &[false; 4], &[0.0; 4]),
        Library::new(),
    )
    .ok();
    let line = r
        .out
        .iter()
        .find_map(|c| match c {
            Command::Linear { end, feed } => Some((end.clone(), *feed)),
            _ => None,
        })
        .expect("the line");
    // 31.4159265 mm round a radius of 20 is 90°.
    assert!(near(&line.0, &[30.0, 60.0, -10.0, 90.0]), "{:?}", line.0);
    let developed = 31.4159265f64.hypot(30.0);
    let machine = line.0[3].hypot(30.0);
    assert!(
        (line.1 - 500.0 * machine / developed).abs() < 1e-6,
        "{}",
        line.1
    );
}

/// A circle on the developed surface is cut as chords within the tolerance, each on the
/// circle, C following the developed Y; TRAFOOF gives the machine's coordinates back.
#[test]
fn a_circle_on_the_surface_is_cut_as_chords_on_it() {
    let text = "G0 X30 Y0 Z0 C0\nTRACYL(40)\nG19 G1 Y10 Z0 F300\nG2 Y20 Z0 CR=5\n\
                TRAFOOF\nG0 C0\nM30\n";
    let r = run_with(
        text,
        Setup::new(&['X', 'Y', 'Z', 'C'], &[false; 4], &[0.0; 4]),
        Library::new(),
    )
    .ok();
    let chords: Vec<(f64, f64)> = r
        .ends()
        .iter()
        .filter(|e| e[3] > (10.0 / 20.0f64).to_degrees() + 1e-6 && e[3] < 57.2957795 + 1e-6)
        .map(|e| ((e[3]).to_radians() * 20.0, e[2]))
        .collect();
    assert!(chords.len() > 20, "{} chords", chords.len());
    for (y, z) in &chords {
        let d = (y - 15.0).hypot(*z);
        assert!((d - 5.0).abs() < 1e-6, "({y}, {z}) is {d} from the centre");
        // G2 in G19 (Y right, Z up) runs through Z > 0.
        assert!(*z >= -1e-9);
    }
    assert!(near(&r.end(), &[30.0, 0.0, 0.0, 0.0]));
}

#[test]
fn what_tracyl_cannot_do_is_an_alarm_with_its_number() {
    for (text, alarm, line) in [
        // The machine has C.
        ("TRACYL(35) G1 X10\n", 12080, 1),
        ("TRACYL(0.5)\n", 17020, 1),
        ("TRACYL(35, 2)\n", 17020, 1),
        ("TRACYL()\n", 14051, 1),
        // C is the transformation's.
        ("TRACYL(35)\nG1 C10 F100\n", 14092, 2),
        ("TRACYL(35)\nG153 Y0\n", 12140, 2),
        // Compensation must end before TRAFOOF.
        (
            "T1 D1\nTRACYL(35)\nG19 G1 G41 Y10 Z0 F100\nY20\nTRAFOOF\n",
            10753,
            5,
        ),
        ("TRACYL(35)\nTRAILON(Y, Z)\n", 12140, 2),
        ("TRACYL(35)\nS100 M3\nG33 Z10 K2\n", 12140, 3),
    ] {
        let r = run4(&format!("{text}M30\n"));
        assert_eq!(r.alarm(), (alarm, line), "{text}: {:?}", r.error);
    }
    // A machine without C.
    let r = run("TRACYL(35)\nM30\n");
    assert_eq!(r.alarm(), (14092, 1), "{:?}", r.error);
    // TRAFOFF, the table's spelling, switches it off as TRAFOOF does.
    let r = run4("G0 C90\nTRACYL(20)\nTRAFOFF\nG0 C0\nM30\n").ok();
    assert!(near(&r.end(), &[0.0, 0.0, 150.0, 0.0]));
}
