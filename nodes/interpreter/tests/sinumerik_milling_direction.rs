//! Issue 46 item 1 (D87 corrected): climb and conventional milling as the cutter defines them,
//! not as a table says. From each cycle's moves (the cutter centre's path in G17) and the
//! spindle's direction, the checker finds every place where the cutter's edge touches the
//! finished wall, takes the tooth's velocity there (the spindle's rotation: M3 clockwise seen
//! from above the part, M4 counter-clockwise) and compares it with the cutter's travel. In
//! climb milling the tooth leaves the wall it finishes (the chip goes from thick to thin): at
//! the wall it moves against the cutter's travel. In conventional milling it moves with it.
//!
//! Every cycle with a milling direction: POCKET3, POCKET4 (inside contours) and CYCLE76,
//! CYCLE77 (outside contours) with CDIR 0 climb and 1 conventional, under M3 and M4; SLOT1,
//! SLOT2 and CYCLE90 (internal and external), whose CDIR names G2 or G3, and CYCLE72, whose
//! side is G41/G42: each cuts the engagement its G2/G3 or side means, under M3 and M4.

#[path = "support/sinumerik.rs"]
mod support;

#[path = "support/stock.rs"]
mod stock;

use cnc_interpreter::{Command, Library};
use stock::*;
use support::*;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Engagement {
    Climb,
    Conventional,
}
use Engagement::*;

/// The engagement at every contact with the finished wall `wall` (signed distance: material
/// above 0) of a cutter of radius `r` following `out` from `start`, spindle `m3` (else M4).
fn contacts(
    out: &[Command],
    start: [f64; 3],
    r: f64,
    m3: bool,
    wall: &dyn Fn((f64, f64)) -> f64,
) -> Vec<Engagement> {
    const TOUCH: f64 = 0.02;
    let mut here = (start[0], start[1]);
    let mut found = Vec::new();
    let mut judge = |p: (f64, f64), t: (f64, f64)| {
        let n = t.0.hypot(t.1);
        if n < 1e-12 {
            return;
        }
        let t = (t.0 / n, t.1 / n);
        // The two sides of the travel; the edge touches the wall on one of them.
        let left = (-t.1, t.0);
        let sides = [left, (-left.0, -left.1)];
        let touching: Vec<(f64, f64)> = sides
            .into_iter()
            .filter(|s| wall((p.0 + r * s.0, p.1 + r * s.1)).abs() < TOUCH)
            .collect();
        let [side] = touching[..] else {
            return;
        };
        // The tooth at the contact: ω × (r·side), ω = −z under M3, +z under M4.
        let w = if m3 { -1.0 } else { 1.0 };
        let tooth = (-w * side.1, w * side.0);
        let along = tooth.0 * t.0 + tooth.1 * t.1;
        found.push(if along < 0.0 { Climb } else { Conventional });
    };
    for c in out {
        match c {
            Command::Linear { end, .. } => {
                let e = (end[0], end[1]);
                let t = (e.0 - here.0, e.1 - here.1);
                for k in 1..8 {
                    let f = f64::from(k) / 8.0;
                    judge((here.0 + f * t.0, here.1 + f * t.1), t);
                }
                here = e;
            }
            Command::Arc {
                end,
                center,
                clockwise,
                plane,
                ..
            } => {
                assert!(plane.is_none_or(|p| p == [0, 1]), "G17 only");
                let c = (center[0], center[1]);
                let e = (end[0], end[1]);
                let a0 = (here.1 - c.1).atan2(here.0 - c.0);
                let a1 = (e.1 - c.1).atan2(e.0 - c.0);
                let rad = (here.0 - c.0).hypot(here.1 - c.1);
                let tau = std::f64::consts::TAU;
                let mut sweep = if *clockwise { a0 - a1 } else { a1 - a0 };
                sweep = sweep.rem_euclid(tau);
                if sweep < 1e-9 {
                    sweep = tau;
                }
                let dir = if *clockwise { -1.0 } else { 1.0 };
                for k in 1..16 {
                    let a = a0 + dir * sweep * f64::from(k) / 16.0;
                    let p = (c.0 + rad * a.cos(), c.1 + rad * a.sin());
                    let t = (-dir * a.sin(), dir * a.cos());
                    judge(p, t);
                }
                here = e;
            }
            other => {
                if let Some(e) = other.end() {
                    here = (e[0], e[1]);
                }
            }
        }
    }
    found
}

/// Asserts that every contact is `expected`, and that there are enough to tell.
fn assert_all(what: &str, found: &[Engagement], expected: Engagement) {
    assert!(found.len() >= 8, "{what}: only {} contacts", found.len());
    let wrong = found.iter().filter(|e| **e != expected).count();
    assert_eq!(
        wrong,
        0,
        "{what}: {wrong} of {} contacts not {expected:?}",
        found.len()
    );
}

/// A program that turns the spindle `m3` (else M4) with a 10 mm cutter (T1 D1) and calls.
fn program(m3: bool, call: &str) -> String {
    let spindle = if m3 { "M3" } else { "M4" };
    format!("G17 G90 T1 D1 S1000 {spindle}\nG0 X0 Y0 Z20\n{call}\nM30\n")
}

fn run(m3: bool, call: &str) -> Vec<Command> {
    run_with(&program(m3, call), with_edge(11, 5.0), Library::new())
        .ok()
        .out
}

fn spindles() -> [(bool, &'static str); 2] {
    [(true, "M3"), (false, "M4")]
}

/// POCKET4 and POCKET3, roughed to the wall with no allowance and finished: the wall is
/// outside the path, inside contours.
#[test]
fn pockets_climb_and_conventional_under_m3_and_m4() {
    for (m3, m) in spindles() {
        for (cdir, expected) in [(0, Climb), (1, Conventional)] {
            // Roughed to the wall, or finished to it from an allowance (finishing without one
            // leaves the wall alone).
            for (vari, fal) in [(11, 0.0), (12, 0.5)] {
                let call = format!(
                    "POCKET4(10, 0, 1, -6, 30, 50, 40, 6, {fal}, 0, 300, 100, {cdir}, {vari}, 5)"
                );
                let found = contacts(
                    &run(m3, &call),
                    [0.0, 0.0, 20.0],
                    5.0,
                    m3,
                    &circle((50.0, 40.0), 30.0),
                );
                assert_all(
                    &format!("POCKET4 CDIR {cdir} VARI {vari} {m}"),
                    &found,
                    expected,
                );
                let call = format!(
                    "POCKET3(10, 0, 1, -6, 60, 40, 8, 50, 40, 15, 6, {fal}, 0, 300, 100, {cdir}, {vari}, 5)"
                );
                let wall = rounded_rect((50.0, 40.0), 30.0, 20.0, 8.0, 15.0);
                let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &wall);
                assert_all(
                    &format!("POCKET3 CDIR {cdir} VARI {vari} {m}"),
                    &found,
                    expected,
                );
            }
        }
    }
}

/// CYCLE77 and CYCLE76 round a spigot: the wall is inside the path, outside contours.
#[test]
fn spigots_climb_and_conventional_under_m3_and_m4() {
    for (m3, m) in spindles() {
        for (cdir, expected) in [(0, Climb), (1, Conventional)] {
            for vari in [1, 2] {
                let call = format!(
                    "CYCLE77(10, 0, 2, -6, , 40, 50, 40, 6, 0, 0, 300, 100, {cdir}, {vari}, 56)"
                );
                let spigot = circle((50.0, 40.0), 20.0);
                let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &|p| -spigot(p));
                assert_all(
                    &format!("CYCLE77 CDIR {cdir} VARI {vari} {m}"),
                    &found,
                    expected,
                );
                let call = format!(
                    "CYCLE76(10, 0, 2, -6, , 40, 30, 6, 50, 40, 20, 6, 0, 0, 300, 100, {cdir}, {vari}, 60, 50)"
                );
                let spigot = rounded_rect((50.0, 40.0), 20.0, 15.0, 6.0, 20.0);
                let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &|p| -spigot(p));
                assert_all(
                    &format!("CYCLE76 CDIR {cdir} VARI {vari} {m}"),
                    &found,
                    expected,
                );
            }
        }
    }
}

/// Inside contours whose CDIR names the arc's sense: G3 under M3 is climb, G2 conventional;
/// M4 the other way round. SLOT1 and SLOT2 finish round each slot's wall; CYCLE90 internal
/// runs its helix inside the thread.
#[test]
fn slots_and_an_internal_thread_cut_what_their_g2_or_g3_means() {
    for (m3, m) in spindles() {
        for (cdir, g3) in [(2, false), (3, true)] {
            let expected = if g3 == m3 { Climb } else { Conventional };
            let call = format!(
                "SLOT1(5, 0, 1, -6, , 1, 30, 15, 40, 45, 20, 45, 90, 100, 320, 6, {cdir}, 0, 2, , 0, )"
            );
            let wall = slots_wall((40.0, 45.0), 20.0, vec![45.0], 15.0, 7.5);
            let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &|p| -wall(p));
            assert_all(&format!("SLOT1 CDIR {cdir} {m}"), &found, expected);
            let call = format!(
                "SLOT2(5, 0, 1, -6, , 1, 70, 15, 60, 60, 42, 0, 120, 100, 300, 6, {cdir}, 0, 2, , 0, )"
            );
            let wall = arc_slots_wall((60.0, 60.0), 42.0, vec![0.0], 70.0, 7.5);
            let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &|p| -wall(p));
            assert_all(&format!("SLOT2 CDIR {cdir} {m}"), &found, expected);
            // M20 × 2.5 internal: the cutter's edge on the thread's major diameter.
            let call = format!("CYCLE90(10, 0, 2, -10, , 20, 17.3, 2.5, 200, {cdir}, 0, 50, 40)");
            let thread = circle((50.0, 40.0), 10.0);
            let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &thread);
            assert_all(
                &format!("CYCLE90 internal CDIR {cdir} {m}"),
                &found,
                expected,
            );
        }
    }
}

/// Outside contours whose direction is given: CYCLE90 external (G2 under M3 is climb round
/// the bolt) and CYCLE72 round an outside contour (G41, the cutter left of the material, is
/// climb under M3).
#[test]
fn an_external_thread_and_a_contour_cut_what_their_direction_means() {
    for (m3, m) in spindles() {
        for (cdir, g3) in [(2, false), (3, true)] {
            let expected = if g3 != m3 { Climb } else { Conventional };
            let call = format!("CYCLE90(10, 0, 2, -10, , 20, 17.3, 2.5, 200, {cdir}, 1, 50, 40)");
            // The cutter's edge runs on the thread's outer diameter (the cycle's path).
            let bolt = circle((50.0, 40.0), 10.0);
            let found = contacts(&run(m3, &call), [0.0, 0.0, 20.0], 5.0, m3, &|p| -bolt(p));
            assert_all(
                &format!("CYCLE90 external CDIR {cdir} {m}"),
                &found,
                expected,
            );
        }
        // A 40 × 30 block about X50 Y40: G41 on its clockwise contour, G42 on its
        // counter-clockwise one, the cutter outside either way.
        for (side, contour, expected_m3) in [
            (41, "G1 X30 Y40\nY55\nX70\nY25\nX30\nY40\nM2\n", Climb),
            (
                42,
                "G1 X30 Y40\nY25\nX70\nY55\nX30\nY40\nM2\n",
                Conventional,
            ),
        ] {
            let expected = match (m3, expected_m3) {
                (true, e) => e,
                (false, Climb) => Conventional,
                (false, Conventional) => Climb,
            };
            let mut lib = Library::new();
            lib.insert_named("BLOCK", "BLOCK.SPF", contour);
            let call = format!(
                "CYCLE72(\"BLOCK\", 10, 0, 2, -6, 6, 0, 0, 300, 100, 11, {side}, 2, 12, 300, 2, 12)"
            );
            let r = run_with(&program(m3, &call), with_edge(11, 5.0), lib).ok();
            let block = rounded_rect((50.0, 40.0), 20.0, 15.0, 0.0, 0.0);
            let found = contacts(&r.out, [0.0, 0.0, 20.0], 5.0, m3, &|p| -block(p));
            assert_all(&format!("CYCLE72 G{side} {m}"), &found, expected);
        }
    }
}
