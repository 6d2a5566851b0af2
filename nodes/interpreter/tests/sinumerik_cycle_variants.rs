//! Issue 24 must-show 3: the milling cycles' variants that no fixture of the manual prints,
//! each on the swept-stock checker (`support/stock.rs`, which knows only the parameters and
//! the cutter) and on what the manual says of the variant itself: POCKET3's reciprocating
//! insertion (§10.6.9: along the long axis, no steeper than RAD1, one pass more on the level),
//! finishing with no edge allowance (§10.6.9/10: "allowance zero → no finishing" of that
//! part), SLOT2 finished by a call of its own, CYCLE72 with G1 between levels and no
//! retraction (VARI 311), and CYCLE72's spatial approach and departure (AS tens 1, §10.6.3).

#[path = "support/sinumerik.rs"]
mod support;

#[path = "support/stock.rs"]
mod stock;

use cnc_interpreter::{Command, Library};
use stock::*;
use support::*;

/// One move of the stream with where it starts.
struct Step<'a> {
    from: [f64; 3],
    to: [f64; 3],
    command: &'a Command,
    line: u32,
}

impl Step<'_> {
    fn rapid(&self) -> bool {
        matches!(self.command, Command::Rapid { .. })
    }
    fn horizontal(&self) -> f64 {
        dist((self.from[0], self.from[1]), (self.to[0], self.to[1]))
    }
    /// How far the move goes down (negative: up).
    fn descent(&self) -> f64 {
        self.from[2] - self.to[2]
    }
}

fn steps(r: &Run, start: [f64; 3]) -> Vec<Step<'_>> {
    let mut here = start;
    let mut out = Vec::new();
    for (c, line) in r.out.iter().zip(&r.lines) {
        if let Some(e) = c.end() {
            let to = [e[0], e[1], e[2]];
            out.push(Step {
                from: here,
                to,
                command: c,
                line: *line,
            });
            here = to;
        }
    }
    out
}

const HEAD: &str = "G17 G90 T1 D1 S800 M3\nG0 X10 Y-5 Z10\n";

/// POCKET3 50 × 30 about X10 Y−5 turned 30°, corners R6, to Z−8 from RFP 0 within MID 3,
/// FAL 0.5, FALD 0.3, G3; VARI and RAD1 as given.
fn pocket3(vari: u32, rad1: f64) -> String {
    format!("POCKET3(10, 0, 1, -8, 50, 30, 6, 10, -5, 30, 3, 0.5, 0.3, 400, 150, 3, {vari}, 6, , , , {rad1})\n")
}

#[test]
fn pocket3_reciprocating_insertion_slopes_along_the_long_axis_within_rad1() {
    let rad1: f64 = 2.0;
    let r = run_with(
        &format!("{HEAD}{}", pocket3(31, rad1)),
        with_edge(11, 5.0),
        Library::new(),
    )
    .ok();
    let stock = turned_pocket(&r.out, 0.5);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the wall 0.5 inside");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -7.7, "the floor 0.3 above DP");
    assert_within(hi, -7.7, "everywhere");
    assert_within(min, -7.7, "nothing deeper");
    stock.assert_infeeds_within(0.0, 3.0);
    // Every fed move that goes down below the safety plane: along the long axis (through
    // the centre at 30°), within the roughed half length 25 − 0.5 − 5, no steeper than RAD1.
    let (sin, cos) = 30f64.to_radians().sin_cos();
    let across = |p: [f64; 3]| (-(p[0] - 10.0) * sin + (p[1] + 5.0) * cos).abs();
    let along = |p: [f64; 3]| ((p[0] - 10.0) * cos + (p[1] + 5.0) * sin).abs();
    let mut ramps = 0;
    let all = steps(&r, [10.0, -5.0, 10.0]);
    for (k, s) in all.iter().enumerate() {
        if s.rapid() || s.descent() <= 1e-9 || s.to[2] >= 1.0 - 1e-9 {
            continue;
        }
        ramps += 1;
        assert!(
            s.descent() <= s.horizontal() * rad1.to_radians().tan() + 1e-9,
            "a plunge steeper than {rad1}°: {:?} → {:?}",
            s.from,
            s.to
        );
        for p in [s.from, s.to] {
            assert!(across(p) < 1e-6, "off the long axis: {p:?}");
            assert!(along(p) <= 19.5 + 1e-6, "beyond the roughed length: {p:?}");
        }
        // The pass that reaches a level is followed by one on the level, end to end.
        if [-7.7 / 3.0, -15.4 / 3.0, -7.7]
            .iter()
            .any(|l| (s.to[2] - l).abs() < 1e-9)
        {
            let next = &all[k + 1];
            assert!(next.descent().abs() < 1e-9 && !next.rapid());
            assert!(
                (next.horizontal() - 39.0).abs() < 1e-6,
                "{}",
                next.horizontal()
            );
            assert!(across(next.to) < 1e-6);
        }
    }
    // Three levels (from Z1 to −7.7 within 3), each reached in passes of at most 39 mm:
    // 3.567 mm and twice 2.567 mm at tan 2° need at least 3 + 2 + 2 sloping passes.
    assert!(ramps >= 7, "{ramps} sloping passes");
    // The insertion angle must be over 0 and at most 90°; POCKET4 has no reciprocation.
    let bad = run_with(
        &format!("{HEAD}{}", pocket3(31, 0.0)),
        with_edge(11, 5.0),
        Library::new(),
    );
    assert_eq!(bad.alarm().0, 61108);
    let p4 = run_with(
        "G17 G90 T1 D1 S650 M3\nG0 X50 Y60\nPOCKET4(3, 0, 1, -20, 25, 50, 60, 6, 0, 0.5, 200, 100, 1, 31, 0, 0, 0, 2)\n",
        with_edge(11, 5.0),
        Library::new(),
    );
    assert_eq!(p4.alarm().0, 61002);
}

#[test]
fn pocket_finishing_without_an_edge_allowance_takes_only_the_floor() {
    // POCKET4 R25 about X50 Y60 to Z−20: roughed with FAL 0 and FALD 0.5 (VARI 11), then
    // finished (VARI 12): the finishing call never leaves the floor.
    let call = |vari: u32, fald: f64| {
        format!("POCKET4(3, 0, 1, -20, 25, 50, 60, 6, 0, {fald}, 200, 100, 1, {vari})\n")
    };
    let head = "G17 G90 T1 D1 S650 M3\nG0 X50 Y60 Z5\n";
    let text = format!("{head}{}{}", call(11, 0.5), call(12, 0.5));
    let r = run_with(&text, with_edge(11, 5.0), Library::new()).ok();
    let mut stock = Stock::new((50.0, 60.0), 30.0, 0.0, 5.0, circle((50.0, 60.0), 25.0));
    stock.follow(&r.out, [50.0, 60.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall on size from roughing");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -20.0, "the floor finished");
    assert_within(hi, -20.0, "everywhere");
    assert_within(min, -20.0, "nothing deeper");
    let finishing: Vec<Step> = steps(&r, [50.0, 60.0, 5.0])
        .into_iter()
        .filter(|s| s.line == 4 && !s.rapid())
        .collect();
    assert!(!finishing.is_empty());
    for s in &finishing {
        assert!(
            (s.to[2] + 20.0).abs() < 1e-9,
            "finishing off the floor: {:?}",
            s.to
        );
    }
    // No allowance at all: finishing has nothing to cut.
    let text = format!("{head}{}", call(12, 0.0));
    let r = run_with(&text, with_edge(11, 5.0), Library::new()).ok();
    assert!(steps(&r, [50.0, 60.0, 5.0])
        .iter()
        .filter(|s| s.line == 3)
        .all(|s| s.rapid() && s.to[2] >= 0.0));
    // POCKET3 the same: FAL 0, roughed then finished, the finishing on the floor alone.
    let p3 = |vari: u32| {
        format!("POCKET3(10, 0, 1, -8, 50, 30, 6, 10, -5, 30, 3, 0, 0.3, 400, 150, 3, {vari}, 6)\n")
    };
    let text = format!("{HEAD}{}{}", p3(11), p3(12));
    let r = run_with(&text, with_edge(11, 5.0), Library::new()).ok();
    let stock = turned_pocket(&r.out, 0.0);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the wall on size");
    let (lo, hi, _) = stock.floor_within(0.01);
    assert_within(lo, -8.0, "floor");
    assert_within(hi, -8.0, "floor");
    for s in steps(&r, [10.0, -5.0, 10.0])
        .iter()
        .filter(|s| s.line == 4 && !s.rapid())
    {
        assert!((s.to[2] + 8.0).abs() < 1e-9, "{:?}", s.to);
    }
}

#[test]
fn slot2_roughed_then_finished_by_a_call_of_its_own() {
    // Fixture 113's three slots, VARI 1 then VARI 2 in two calls: the walls on size.
    let rough = fixture("113").replace(", 0.5, 0, , 0, )", ", 0.5, 1, , 0, )");
    let finish = fixture("113").replace(", 0.5, 0, , 0, )", ", 0.5, 2, , 0, )");
    let call = |t: &str| {
        t.lines()
            .find(|l| l.contains("SLOT2"))
            .map(|l| format!("{l}\n"))
            .unwrap()
    };
    let text = format!(
        "N10 G17 G90 T1 D1 S600 M3\nN20 G0 X60 Y60 Z5\n{}{}N40 M02\n",
        call(&rough),
        call(&finish).replace("N30", "N35")
    );
    let r = run_with(&text, with_edge(11, 5.0), Library::new()).ok();
    let wall = arc_slots_wall((60.0, 60.0), 42.0, vec![0.0, 120.0, 240.0], 70.0, 7.5);
    let mut stock = Stock::new((60.0, 60.0), 55.0, 0.0, 5.0, wall);
    stock.follow(&r.out, [60.0, 60.0, 5.0]);
    assert_eq!(stock.rapid_cuts, 0);
    assert_within(stock.reach, 0.0, "the slots' walls on size");
    let (lo, hi, min) = stock.floor_within(0.01);
    assert_within(lo, -23.0, "floor");
    assert_within(hi, -23.0, "every slot");
    assert_within(min, -23.0, "nothing deeper");
    // The finishing call alone cuts no deeper than the roughing left and only the 0.5 mm
    // ring at the walls: its cutter keeps within the slots.
    let wall = arc_slots_wall((60.0, 60.0), 42.0, vec![0.0, 120.0, 240.0], 70.0, 7.5);
    for s in steps(&r, [60.0, 60.0, 5.0])
        .iter()
        .filter(|s| s.line == 4 && !s.rapid())
    {
        assert!(wall((s.to[0], s.to[1])) <= -5.0 + 1e-6, "{:?}", s.to);
    }
}

/// Fixture 108 with CYCLE72's VARI, AS1 and AS2 replaced.
fn f108(vari: u32, as1: u32, as2: u32) -> String {
    fixture("108").replace(
        ", 11, 41, 2, 20, 1000, 2, 20)",
        &format!(", {vari}, 41, {as1}, 20, 1000, {as2}, 20)"),
    )
}

/// The stock of fixture 108's contour roughed 1 mm out to Z176.5 in 3 levels.
fn assert_roughed(r: &Run) {
    let out = outside_of(contour_107());
    let mut stock = Stock::new((180.0, 120.0), 90.0, 200.0, 7.0, move |p| 1.0 - out(p));
    stock.follow(&r.out, [100.0, 200.0, 250.0]);
    assert_eq!(stock.rapid_cuts, 0, "no rapid into material");
    assert_within(stock.reach, 0.0, "the contour 1 mm out");
    let out = outside_of(contour_107());
    let (lo, hi) = stock.floor_where(|q| (1.01..=8.0).contains(&out(q)));
    assert_within(lo, 176.5, "down to Z175 + 1.5");
    assert_within(hi, 176.5, "all round");
}

#[test]
fn cycle72_vari_311_stays_down_between_levels_on_g1() {
    let r = run_with(&f108(311, 2, 2), with_edge(31, 7.0), Library::new()).ok();
    assert_roughed(&r);
    // From the first level (200 − 23.5/3) to the end of the last: nothing rises above the
    // level just cut, and nothing is rapid (tens 1: G1 at FF3 between levels).
    let first = 200.0 - 23.5 / 3.0;
    let all: Vec<Step> = steps(&r, [100.0, 200.0, 250.0])
        .into_iter()
        .filter(|s| s.line == 4)
        .collect();
    let start = all
        .iter()
        .position(|s| (s.to[2] - first).abs() < 1e-6)
        .expect("the first level");
    let last = all.len() - 1;
    let mut floor = first;
    for s in &all[start..last] {
        assert!(!s.rapid(), "a rapid between levels: {:?}", s.to);
        assert!(s.to[2] <= floor + 1e-6, "rose to {} above {floor}", s.to[2]);
        floor = floor.min(s.to[2]);
    }
    // Only the cycle's end goes back to RTP.
    assert!(all[last].rapid() && (all[last].to[2] - 250.0).abs() < 1e-9);
}

#[test]
fn cycle72_spatial_approach_and_departure_take_sdis_along_their_path() {
    // AS1 = AS2 = 12: quarter circles R20 in space: helices from 3 mm (SDIS) above each
    // level down to it, and back up by 3 mm on the way out.
    let r = run_with(&f108(11, 12, 12), with_edge(31, 7.0), Library::new()).ok();
    assert_roughed(&r);
    let levels = [200.0 - 23.5 / 3.0, 200.0 - 47.0 / 3.0, 176.5];
    let all = steps(&r, [100.0, 200.0, 250.0]);
    let helices: Vec<&Step> = all
        .iter()
        .filter(|s| matches!(s.command, Command::Arc { .. }) && s.descent().abs() > 1e-9)
        .collect();
    assert_eq!(helices.len(), 6, "one helix in and one out per level");
    for (k, level) in levels.iter().enumerate() {
        let (down, up) = (helices[2 * k], helices[2 * k + 1]);
        assert!(
            (down.from[2] - (level + 3.0)).abs() < 1e-6,
            "{:?}",
            down.from
        );
        assert!((down.to[2] - level).abs() < 1e-6, "{:?}", down.to);
        assert!((up.from[2] - level).abs() < 1e-6);
        assert!((up.to[2] - (level + 3.0)).abs() < 1e-6);
    }
    // The infeed beside the contour stops SDIS above each level: no vertical feed reaches
    // a level.
    for s in &all {
        if !s.rapid() && s.horizontal() < 1e-9 && s.descent() > 0.0 {
            assert!(
                levels.iter().all(|l| (s.to[2] - l).abs() > 1.0),
                "a vertical feed to the level at {:?}",
                s.to
            );
        }
    }
    // AS1 = AS2 = 11: straight lines in space, LP1 = 20 long in the plane, 3 mm deep.
    let r = run_with(&f108(11, 11, 11), with_edge(31, 7.0), Library::new()).ok();
    assert_roughed(&r);
    let slopes: Vec<Step> = steps(&r, [100.0, 200.0, 250.0])
        .into_iter()
        .filter(|s| !s.rapid() && s.horizontal() > 1e-6 && s.descent().abs() > 1e-9)
        .collect();
    assert_eq!(slopes.len(), 6, "one line in and one out per level");
    for s in &slopes {
        assert!(
            (s.descent().abs() - 3.0).abs() < 1e-6,
            "{:?} → {:?}",
            s.from,
            s.to
        );
        assert!((s.horizontal() - 20.0).abs() < 1e-6, "{}", s.horizontal());
    }
}
