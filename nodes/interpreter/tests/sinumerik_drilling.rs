//! Issue 24: the 802D's drilling cycles CYCLE81–CYCLE89, CYCLE840 and the hole patterns
//! HOLES1/HOLES2 with MCALL, on the manual's fixtures 092–105 (`../shared/fixtures/001`).
//!
//! The checker here knows only the parameters and the manual's text, never the code that
//! makes the moves: it cuts the command stream into holes (the runs of moves at one position
//! of the plane), and for each asserts the position, the depth reached, the levels and feeds
//! of every move along the drilling axis, the dwells and the M functions, in order; that no
//! feed move crosses the plane (every cut is inside a hole), and that every hole is visited
//! once. Depth sequences and pattern positions are worked out in the test from the manual's
//! rules (§10.4–§10.5), by hand where the comment says so.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Aux, Command, Library, Setup};
use support::*;

/// What happens at one position of the plane, in order.
#[derive(Debug, Clone, PartialEq)]
enum Ev {
    /// Rapid or feed (mm/min) along the drilling axis to a level.
    Rapid(f64),
    Feed(f64, f64),
    Dwell(f64),
    M(i32),
    S(f64),
    /// The oriented stop: the spindle positioned at an angle.
    Orient(f64),
    /// Rigid tapping to a level: the lead (signed) and the spindle speed.
    Tap(f64, f64, f64),
}

#[derive(Debug)]
struct Hole {
    at: (f64, f64),
    events: Vec<Ev>,
}

impl Hole {
    fn feeds(&self) -> Vec<(f64, f64)> {
        self.events
            .iter()
            .filter_map(|e| match e {
                Ev::Feed(l, f) => Some((*l, *f)),
                // A tap's axis speed: the lead times the speed.
                Ev::Tap(l, lead, rpm) => Some((*l, lead.abs() * rpm)),
                _ => None,
            })
            .collect()
    }
}

/// The commands of the cycle blocks (program lines `cycle_lines`) as holes: `h`, `v` the
/// plane axes, `d` the drilling axis (indexes into the end vectors). A feed move that
/// changes the plane position fails the test.
fn holes(r: &Run, cycle_lines: &[u32], (h, v, d): (usize, usize, usize)) -> Vec<Hole> {
    let mut pos = vec![0.0; 3];
    let mut list: Vec<Hole> = Vec::new();
    let mut pending: Vec<Ev> = Vec::new();
    for (c, line) in r.out.iter().zip(&r.lines) {
        if !cycle_lines.contains(line) {
            if let Some(end) = c.end() {
                pos = end.to_vec();
            }
            list.push(Hole {
                at: (f64::NAN, f64::NAN),
                events: Vec::new(),
            });
            continue;
        }
        let ev = match c {
            Command::Rapid { end } | Command::Linear { end, .. } => {
                let across = (end[h] - pos[h]).abs() > 1e-6 || (end[v] - pos[v]).abs() > 1e-6;
                if across {
                    assert!(
                        matches!(c, Command::Rapid { .. }),
                        "a feed move across the plane: {c:?}"
                    );
                    pos = end.clone();
                    continue;
                }
                pos = end.clone();
                match c {
                    Command::Linear { feed, .. } => Ev::Feed(end[d], *feed),
                    _ => Ev::Rapid(end[d]),
                }
            }
            Command::Tap { end, lead, rpm } => {
                let across = (end[h] - pos[h]).abs() > 1e-6 || (end[v] - pos[v]).abs() > 1e-6;
                assert!(!across, "a tap across the plane: {c:?}");
                pos = end.clone();
                Ev::Tap(end[d], *lead, *rpm)
            }
            Command::Dwell { seconds } => Ev::Dwell(*seconds),
            Command::Aux(Aux::M(m)) => Ev::M(*m),
            Command::Aux(Aux::S(s)) => Ev::S(*s),
            Command::Aux(Aux::Orient { degrees, .. }) => Ev::Orient(*degrees),
            _ => continue,
        };
        let at = (pos[h], pos[v]);
        match list.last_mut() {
            Some(hole) if near(&[hole.at.0, hole.at.1], &[at.0, at.1]) => {
                hole.events.append(&mut pending);
                hole.events.push(ev);
            }
            _ => {
                // Events before the first move at a new position belong to it.
                pending.push(ev);
                if matches!(pending.last(), Some(Ev::Rapid(_) | Ev::Feed(..))) {
                    list.push(Hole {
                        at,
                        events: std::mem::take(&mut pending),
                    });
                }
            }
        }
    }
    // Only positions where something was cut are holes (the NaN entries part the holes of
    // different cycle blocks at one position).
    list.retain(|hl| {
        hl.events
            .iter()
            .any(|e| matches!(e, Ev::Feed(..) | Ev::Tap(..)))
    });
    list
}

const XYZ: (usize, usize, usize) = (0, 1, 2);

/// The lines of `text` that call a cycle or a pattern (1-based, as the alarms count).
fn cycle_lines(text: &str) -> Vec<u32> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let code = l.split(';').next().unwrap_or("").to_uppercase();
            (code.contains("CYCLE") || code.contains("HOLES")) && !code.contains("MCALL")
        })
        .map(|(i, _)| i as u32 + 1)
        .collect()
}

fn run_fixture(number: &str) -> Run {
    let r = run(&fixture(number));
    assert!(r.error.is_none(), "{number}: {:?}", r.error);
    r
}

fn assert_levels(got: &[Ev], want: &[Ev]) {
    assert_eq!(got.len(), want.len(), "\n got {got:?}\nwant {want:?}");
    for (g, w) in got.iter().zip(want) {
        let same = match (g, w) {
            (Ev::Rapid(a), Ev::Rapid(b))
            | (Ev::Dwell(a), Ev::Dwell(b))
            | (Ev::S(a), Ev::S(b))
            | (Ev::Orient(a), Ev::Orient(b)) => (a - b).abs() < 1e-6,
            (Ev::Feed(a, f), Ev::Feed(b, g)) => (a - b).abs() < 1e-6 && (f - g).abs() < 1e-6,
            (Ev::Tap(a, l, s), Ev::Tap(b, m, t)) => {
                (a - b).abs() < 1e-6 && (l - m).abs() < 1e-9 && (s - t).abs() < 1e-9
            }
            (Ev::M(a), Ev::M(b)) => a == b,
            _ => false,
        };
        assert!(same, "{g:?} vs {w:?}\n got {got:?}\nwant {want:?}");
    }
}

#[test]
fn f092_cycle81_three_holes_to_z35_each_back_to_rtp() {
    let r = run_fixture("092");
    let hs = holes(&r, &cycle_lines(&fixture("092")), XYZ);
    let at: Vec<(f64, f64)> = hs.iter().map(|h| h.at).collect();
    assert_eq!(at, [(40.0, 120.0), (40.0, 30.0), (90.0, 30.0)]);
    use Ev::*;
    assert_levels(
        &hs[0].events,
        &[Rapid(102.0), Feed(35.0, 200.0), Rapid(110.0)],
    );
    // SDIS omitted: 0, the safety plane is RFP itself.
    assert_levels(
        &hs[1].events,
        &[Rapid(102.0), Feed(35.0, 200.0), Rapid(110.0)],
    );
    // DPR 65 from RFP 100: Z35, at N70's F180.
    assert_levels(
        &hs[2].events,
        &[Rapid(102.0), Feed(35.0, 180.0), Rapid(110.0)],
    );
    assert!(near(&r.end(), &[90.0, 30.0, 110.0]));
}

#[test]
fn f093_cycle82_dwells_two_seconds_at_z75() {
    let r = run_fixture("093");
    let hs = holes(&r, &cycle_lines(&fixture("093")), XYZ);
    assert_eq!(hs.len(), 1);
    assert_eq!(hs[0].at, (24.0, 15.0));
    use Ev::*;
    assert_levels(
        &hs[0].events,
        &[Rapid(106.0), Feed(75.0, 200.0), Dwell(2.0), Rapid(110.0)],
    );
}

#[test]
fn f094_cycle83_chip_breaking_and_chip_removal() {
    let r = run_fixture("094");
    let hs = holes(&r, &cycle_lines(&fixture("094")), XYZ);
    assert_eq!(hs.len(), 2);
    // By hand from §10.4.5: 145 mm from RFP 150, first depth 50 (Z100), DAM 20: then
    // 50−20 = 30, 30−20 = 10 < DAM so 20, 20; 25 left is less than two infeeds of 20:
    // split 12.5 + 12.5. Depths Z100, 70, 50, 30, 17.5, 5.
    let depths = [100.0, 70.0, 50.0, 30.0, 17.5, 5.0];
    use Ev::*;
    // Hole 1, chip breaking (VARI 0), FRF 1, no dwell: back 1 mm at F50 after each depth.
    let mut want = vec![Rapid(151.0)];
    for (k, z) in depths.iter().enumerate() {
        if k > 0 {
            want.push(Feed(depths[k - 1] + 1.0, 50.0));
        }
        want.push(Feed(*z, 50.0));
    }
    want.push(Rapid(155.0));
    assert_levels(&hs[0].events, &want);
    // Hole 2, chip removal (VARI 1), FRF 0.5 on the first depth, DTB 1 s at each depth,
    // DTS 1 s at the safety plane, back down at rapid to 145/50 = 2.9 mm above the last.
    let mut want = vec![Rapid(151.0)];
    for (k, z) in depths.iter().enumerate() {
        if k > 0 {
            want.extend([Rapid(151.0), Dwell(1.0), Rapid(depths[k - 1] + 2.9)]);
        }
        want.extend([Feed(*z, if k == 0 { 25.0 } else { 50.0 }), Dwell(1.0)]);
    }
    want.push(Rapid(155.0));
    assert_levels(&hs[1].events, &want);
}

#[test]
fn f095_cycle84_orients_taps_m5_at_200_and_out_at_500_then_m3() {
    let r = run_fixture("095");
    let hs = holes(&r, &cycle_lines(&fixture("095")), XYZ);
    assert_eq!(hs.len(), 1);
    use Ev::*;
    // MPIT 5: M5 coarse, pitch 0.8 (ISO 261); right hand: in the way M3 turns, out the other
    // way (D101). SDIS 2 over RFP 36; DPR 30: Z6. Spindle 200 rpm in, 500 out.
    assert_levels(
        &hs[0].events,
        &[
            Rapid(38.0),
            Orient(90.0),
            Tap(6.0, 0.8, 200.0),
            Tap(38.0, -0.8, 500.0),
            Rapid(40.0),
            S(0.0),
            M(3),
        ],
    );
}

#[test]
fn f096_f097_cycle840_without_and_with_encoder() {
    use Ev::*;
    let r = run_fixture("096");
    let hs = holes(&r, &cycle_lines(&fixture("096")), XYZ);
    // Without encoder (ENC 1): the feed before the call, F200; SDR 4 out, SDAC 3 after.
    assert_levels(
        &hs[0].events,
        &[
            Rapid(56.0),
            Feed(15.0, 200.0),
            Dwell(1.0),
            M(4),
            Feed(56.0, 200.0),
            Rapid(59.0),
            M(3),
        ],
    );
    // With encoder (ENC 0), PIT 3.5 at S500: 1750 mm/min; SDR 4 as the call gives it (the
    // text's "automatic reversal" would be SDR 0: the call wins).
    let r = run_fixture("097");
    let hs = holes(&r, &cycle_lines(&fixture("097")), XYZ);
    assert_levels(
        &hs[0].events,
        &[
            Rapid(56.0),
            Feed(15.0, 1750.0),
            M(4),
            Feed(56.0, 1750.0),
            Rapid(59.0),
            M(3),
        ],
    );
}

#[test]
fn f098_cycle85_in_g18_bores_along_y() {
    let r = run_fixture("098");
    // G18: the plane is Z/X, the drilling axis Y.
    let hs = holes(&r, &cycle_lines(&fixture("098")), (2, 0, 1));
    assert_eq!(hs.len(), 1);
    assert_eq!(hs[0].at, (70.0, 50.0));
    use Ev::*;
    assert_levels(
        &hs[0].events,
        &[
            Rapid(104.0),
            Feed(77.0, 300.0),
            Feed(104.0, 450.0),
            Rapid(105.0),
        ],
    );
}

#[test]
fn f099_cycle86_orients_lifts_off_and_returns_over_the_hole() {
    let r = run_fixture("099");
    use Ev::*;
    // The lift-off X−1 Y−1 Z+1 moves across the plane: the checker sees the hole at X70
    // Y50 up to the oriented stop, then the retraction at X69 Y49, then X70 Y50 again.
    let hs = holes(&r, &cycle_lines(&fixture("099")), XYZ);
    assert_eq!(hs.len(), 1);
    assert_levels(
        &hs[0].events,
        &[
            M(3),
            Rapid(110.0),
            Feed(77.0, 200.0),
            Dwell(2.0),
            Orient(45.0),
        ],
    );
    let moves = r.moves();
    let n = moves.len();
    let ends: Vec<&[f64]> = moves[n - 4..].iter().map(|c| c.end().unwrap()).collect();
    assert!(near(ends[0], &[69.0, 49.0, 78.0]), "{ends:?}");
    assert!(near(ends[1], &[69.0, 49.0, 110.0]));
    assert!(near(ends[2], &[69.0, 49.0, 112.0]));
    assert!(near(ends[3], &[70.0, 50.0, 112.0]));
    assert!(moves[n - 4..]
        .iter()
        .all(|c| matches!(c, Command::Rapid { .. })));
    assert_eq!(r.out[r.out.len() - 3], Command::Aux(Aux::M(3)));
}

#[test]
fn f100_f101_cycle87_cycle88_stop_the_spindle_and_the_program_at_depth() {
    use Ev::*;
    let r = run_fixture("100");
    let hs = holes(&r, &cycle_lines(&fixture("100")), XYZ);
    assert_levels(
        &hs[0].events,
        &[
            M(3),
            Rapid(112.0),
            Feed(77.0, 200.0),
            M(5),
            M(0),
            Rapid(113.0),
        ],
    );
    let r = run_fixture("101");
    let hs = holes(&r, &cycle_lines(&fixture("101")), XYZ);
    // DPR 72 from RFP 102: Z30; SDIR 4; the tool is at RFP+SDIS = RTP = Z105 already.
    assert_levels(
        &hs[0].events,
        &[
            M(4),
            Feed(30.0, 100.0),
            Dwell(3.0),
            M(5),
            M(0),
            Rapid(105.0),
        ],
    );
}

#[test]
fn f102_cycle89_feeds_back_out_at_the_same_feed() {
    let r = run_fixture("102");
    let hs = holes(&r, &cycle_lines(&fixture("102")), XYZ);
    use Ev::*;
    // RFP+SDIS = 107 = RTP: the last rapid is no move.
    assert_levels(
        &hs[0].events,
        &[Feed(72.0, 100.0), Dwell(3.0), Feed(107.0, 100.0)],
    );
}

/// Positions on a line from (x0, y0) at `deg`, the first `first` away, then every `step`.
fn row(x0: f64, y0: f64, deg: f64, first: f64, step: f64, n: usize) -> Vec<(f64, f64)> {
    let (s, c) = deg.to_radians().sin_cos();
    (0..n)
        .map(|i| {
            let l = first + step * i as f64;
            (x0 + l * c, y0 + l * s)
        })
        .collect()
}

fn same_set(got: &[(f64, f64)], want: &[(f64, f64)]) {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for w in want {
        let k = got
            .iter()
            .filter(|g| near(&[g.0, g.1], &[w.0, w.1]))
            .count();
        assert_eq!(k, 1, "{w:?} once in {got:?}");
    }
}

#[test]
fn f103_holes1_rows_drilled_then_tapped_under_mcall() {
    let r = run(&fixture("103"));
    // As printed: the "..." line after the first MCALL cancel (line 12 of the file).
    assert_eq!(r.alarm(), (12080, 6));
    let text: String = fixture("103")
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("...") {
                ""
            } else {
                l
            }
        })
        .flat_map(|l| [l, "\n"])
        .collect();
    let r = run(&text).ok();
    let hs = holes(&r, &cycle_lines(&fixture("103")), XYZ);
    assert_eq!(hs.len(), 10);
    // HOLES1(20, 30, 0, 10, 20, 5): X30…X110 at Y30; CYCLE82 to DP 22, dwell 1.
    same_set(
        &hs[..5].iter().map(|h| h.at).collect::<Vec<_>>(),
        &row(20.0, 30.0, 0.0, 10.0, 20.0, 5),
    );
    use Ev::*;
    for h in &hs[..5] {
        assert_levels(
            &h.events,
            &[Rapid(104.0), Feed(22.0, 30.0), Dwell(1.0), Rapid(105.0)],
        );
    }
    // The row starts at the end nearer to the tool (X20 Y30 before N40): X30 first.
    assert_eq!(hs[0].at, (30.0, 30.0));
    // HOLES1(20, 0, 30, 20, 10, 5) at 30°, tapped with PIT 4.2 at SST 300: 1260 mm/min.
    let second = row(20.0, 0.0, 30.0, 20.0, 10.0, 5);
    same_set(&hs[5..].iter().map(|h| h.at).collect::<Vec<_>>(), &second);
    for h in &hs[5..] {
        assert_eq!(h.feeds(), [(22.0, 1260.0), (104.0, 1260.0)]);
        let taps = h.events.iter().filter(|e| matches!(e, Tap(..))).count();
        assert_eq!(taps, 2, "in and out by rigid tapping: {:?}", h.events);
        assert!(h.events.contains(&Orient(0.0)), "POSS omitted: 0°");
    }
    // From X30 Y105 the far end of the second row (the 5th hole) is nearer: it starts there.
    assert!(near(&[hs[5].at.0, hs[5].at.1], &[second[4].0, second[4].1]));
}

#[test]
fn f104_holes1_in_a_loop_drills_a_five_by_five_grid() {
    let r = run_fixture("104");
    let hs = holes(&r, &cycle_lines(&fixture("104")), XYZ);
    let mut want = Vec::new();
    for y in [20.0, 30.0, 40.0, 50.0, 60.0] {
        want.extend(row(30.0, y, 0.0, 10.0, 10.0, 5));
    }
    same_set(&hs.iter().map(|h| h.at).collect::<Vec<_>>(), &want);
    use Ev::*;
    for h in &hs {
        assert_levels(
            &h.events,
            &[Rapid(104.0), Feed(75.0, 300.0), Dwell(1.0), Rapid(105.0)],
        );
    }
    assert!(near(&r.end(), &[30.0, 20.0, 105.0]));
}

#[test]
fn f105_holes2_four_holes_on_a_circle_from_33_degrees() {
    let r = run_fixture("105");
    let hs = holes(&r, &cycle_lines(&fixture("105")), XYZ);
    let want: Vec<(f64, f64)> = (0..4)
        .map(|i| {
            let (s, c) = (33.0 + 90.0 * i as f64).to_radians().sin_cos();
            (70.0 + 42.0 * c, 60.0 + 42.0 * s)
        })
        .collect();
    same_set(&hs.iter().map(|h| h.at).collect::<Vec<_>>(), &want);
    // In the order of the angles.
    for (h, w) in hs.iter().zip(&want) {
        assert!(near(&[h.at.0, h.at.1], &[w.0, w.1]));
        assert_eq!(h.feeds(), [(-30.0, 140.0)]);
    }
}

fn alarm_of(text: &str) -> (u32, u32) {
    run(text).alarm()
}

#[test]
fn cycle_alarms_as_the_manual_lists_them() {
    let head = "G17 G90 G0 X0 Y0 Z110 F100 S300 M3\n";
    // Too many parameters: 12340.
    assert_eq!(
        alarm_of(&format!("{head}CYCLE81(110, 100, 2, 35, , 1)\n")),
        (12340, 2)
    );
    // RFP = RTP with a relative depth; RTP on the drilling side of RFP: 61101.
    assert_eq!(
        alarm_of(&format!("{head}CYCLE81(100, 100, 2, , 20)\n")),
        (61101, 2)
    );
    assert_eq!(
        alarm_of(&format!("{head}CYCLE81(90, 100, 2, 35)\n")),
        (61101, 2)
    );
    // A first depth above the reference plane: 61107.
    assert_eq!(
        alarm_of(&format!(
            "{head}CYCLE83(110, 100, 2, 35, , 105, , 5, 0, 0, 1, 0)\n"
        )),
        (61107, 2)
    );
    // Pitch as size and value contradicting: 61001.
    assert_eq!(
        alarm_of(&format!(
            "{head}CYCLE84(110, 100, 2, 35, , , 3, 5, 1.0, 0, 200, 500)\n"
        )),
        (61001, 2)
    );
    // No spindle direction: 61102.
    assert_eq!(
        alarm_of(&format!("{head}CYCLE87(110, 100, 2, 35, , 0)\n")),
        (61102, 2)
    );
    assert_eq!(
        alarm_of(&format!(
            "{head}CYCLE86(110, 100, 2, 35, , 0, 5, 0, 0, 0, 0)\n"
        )),
        (61102, 2)
    );
    // A pattern without a modal drilling cycle: 62100; no holes: 61103.
    assert_eq!(
        alarm_of(&format!("{head}HOLES1(0, 0, 0, 10, 10, 3)\n")),
        (62100, 2)
    );
    assert_eq!(
        alarm_of(&format!(
            "{head}MCALL CYCLE81(110, 100, 2, 35)\nHOLES1(0, 0, 0, 10, 10, 0)\n"
        )),
        (61103, 3)
    );
    // Holes overrunning the full circle: 61106.
    assert_eq!(
        alarm_of(&format!(
            "{head}MCALL CYCLE81(110, 100, 2, 35)\nHOLES2(0, 0, 10, 0, 100, 5)\n"
        )),
        (61106, 3)
    );
    // A cycle the manual does not have: no such name.
    let r = run(&format!("{head}CYCLE99(10, 0, 2, -5)\n"));
    assert_eq!(r.alarm(), (12550, 2));
    // CYCLE72 with a contour program that is not there: 14011.
    let r = run(&format!(
        "{head}T1 D1\nCYCLE72(\"KONTUR\", 10, 0, 2, -5, 2, 0.5, 0.2, 300, 100, 11, 41, 2, 5, 300, 2, 5)\n"
    ));
    assert_eq!(r.alarm(), (14011, 3));
}

#[test]
fn mcall_runs_after_every_block_that_moves_until_cancelled_and_keeps_g_codes() {
    let text = "G17 G90 G1 F100 S300 M3\nG0 X0 Y0 Z110\nMCALL CYCLE81(110, 100, 2, 35)\n\
        X10 Y10\nX20\nF50\nY20\nMCALL\nX30\nG1 Z120\n";
    let r = run(text).ok();
    let hs = holes(&r, &[4, 5, 7, 9], XYZ);
    // The MCALL block and the F block move nothing: holes at the three positions after.
    let at: Vec<(f64, f64)> = hs.iter().map(|h| h.at).collect();
    assert_eq!(at, [(10.0, 10.0), (20.0, 10.0), (20.0, 20.0)]);
    assert_eq!(hs[2].feeds(), [(35.0, 50.0)]);
    // After MCALL alone, X30 (line 9) is one rapid and nothing more; G0 is still the motion
    // of the blocks without a G, and G1 comes back with its feed.
    let at9: Vec<&Command> = r
        .out
        .iter()
        .zip(&r.lines)
        .filter(|(_, l)| **l == 9)
        .map(|(c, _)| c)
        .collect();
    assert!(matches!(at9[..], [Command::Rapid { .. }]), "{at9:?}");
    let m = r.moves();
    let n = m.len();
    assert!(matches!(m[n - 2], Command::Rapid { end } if near(end, &[30.0, 20.0, 110.0])));
    assert!(matches!(m[n - 1], Command::Linear { feed, .. } if *feed == 50.0));
}

#[test]
fn cycles_keep_the_frame_and_the_tool_length() {
    // Under TRANS X100 and AROT 90 the hole at program X10 Y0 is at machine X100 Y10;
    // T1 D1's 50 mm length lifts every Z.
    let mut s: Setup = mill();
    s.active_tool = 1;
    let text = "G17 G90 T1 D1 F100\nTRANS X100\nAROT RPL=90\nG0 X10 Y0 Z20\nCYCLE82(20, 10, 1, 0, , 0.5)\n";
    let r = run_with(text, s, Library::new()).ok();
    let hs = holes(&r, &cycle_lines(text), XYZ);
    assert_eq!(hs.len(), 1);
    assert!(
        near(&[hs[0].at.0, hs[0].at.1], &[100.0, 10.0]),
        "{:?}",
        hs[0].at
    );
    use Ev::*;
    assert_levels(
        &hs[0].events,
        &[Rapid(61.0), Feed(50.0, 100.0), Dwell(0.5), Rapid(70.0)],
    );
}

#[test]
fn f076_mcall_cycle82_with_holes1_drills_a_row() {
    // As printed its parameters are placeholders (12080 at N10). Filled: CYCLE82 from RFP 100
    // to Z50 with a 1 s dwell at four holes 20 apart from X10 along X.
    assert_eq!(run(&fixture("076")).alarm().0, 12080);
    let text = "G17 G90 F120 S500 M3\nG0 X0 Y0 Z110\n\
        N10 MCALL CYCLE82(110, 100, 2, 50, , 1)\nN20 HOLES1(0, 0, 0, 10, 20, 4)\nN30 MCALL\nG0 X0\n";
    let r = run(text).ok();
    let hs = holes(&r, &[4], XYZ);
    same_set(
        &hs.iter().map(|h| h.at).collect::<Vec<_>>(),
        &row(0.0, 0.0, 0.0, 10.0, 20.0, 4),
    );
    use Ev::*;
    for h in &hs {
        assert_levels(
            &h.events,
            &[Rapid(102.0), Feed(50.0, 120.0), Dwell(1.0), Rapid(110.0)],
        );
    }
    // After MCALL alone the last move drills nothing.
    assert!(matches!(r.moves().last(), Some(Command::Rapid { end }) if end[0] == 0.0));
}

#[test]
fn cycle840_sdr0_reverses_the_spindle_turning_and_cycle83_takes_fdpr() {
    use Ev::*;
    // SDR 0: the spindle turning M3 goes out M4; SDAC 5 stops it after.
    let text = "G17 G90 F100 S400 M3\nG0 X10 Y10 Z20\nCYCLE840(20, 10, 1, 0, , 0, 0, 5, 1)\n";
    let r = run(text).ok();
    let hs = holes(&r, &[3], XYZ);
    assert_levels(
        &hs[0].events,
        &[
            Rapid(11.0),
            Feed(0.0, 100.0),
            M(4),
            Feed(11.0, 100.0),
            Rapid(20.0),
            M(5),
        ],
    );
    // CYCLE83 with the first depth relative (FDPR 4 from RFP 10: Z6), DAM 0: the next infeed
    // 4 again; the 6 left are more than one infeed and no more than two: 3 and 3 (D84).
    // Chip breaking: back 1 mm after each.
    let text =
        "G17 G90 F100 S400 M3\nG0 X10 Y10 Z20\nCYCLE83(20, 10, 1, 0, , , 4, 0, 0, 0, 1, 0)\n";
    let r = run(text).ok();
    let hs = holes(&r, &[3], XYZ);
    let feeds: Vec<f64> = hs[0]
        .feeds()
        .iter()
        .filter(|(_, f)| *f == 100.0)
        .map(|(l, _)| *l)
        .collect();
    assert_eq!(feeds, [6.0, 7.0, 3.0, 4.0, 0.0], "{feeds:?}");
}
