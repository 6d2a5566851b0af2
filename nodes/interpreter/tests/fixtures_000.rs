//! The Huaxing manual's example programs (`../shared/fixtures/000/`), with what each header
//! says, checked on the canonical stream and, for cutting cycles, on the swept 2-D stock.

#[path = "support/huaxing.rs"]
mod huaxing;
use huaxing::fixture;

use cnc_interpreter::{Aux, Canon, Command, Dialect, Library, ProgramError, Setup};

mod support;
use support::contour_at;

const HOME: [f64; 2] = [200.0, 100.0];

/// The 1-based line of the listing that starts with `start`.
fn line_of(text: &str, start: &str) -> u32 {
    text.lines()
        .position(|l| l.trim_start().starts_with(start))
        .expect("line") as u32
        + 1
}

fn run(text: &str, start: [f64; 2]) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(Dialect::HuaxingLathe, text, Setup::lathe(start))
}

fn run_lib(text: &str, lib: Library) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check_with_library(Dialect::HuaxingLathe, text, Setup::lathe(HOME), lib)
}

fn end_of(c: &Command) -> Option<[f64; 2]> {
    c.end().map(|e| [e[0], e[1]])
}

fn ends(cmds: &[Canon]) -> Vec<[f64; 2]> {
    cmds.iter().filter_map(|c| end_of(&c.command)).collect()
}

fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
}

/// The material of a turned part as a boundary along one axis: for G71-style work the radius
/// of the material at each Z (material inside), for G72-style work the face Z at each radius
/// (material toward −Z). Sampled every `h` mm; feeds lower the boundary, rapids must not cut.
struct Stock {
    radial: bool,
    t0: f64,
    h: f64,
    v: Vec<f64>,
    max_cut: f64,
    rapid_through: Vec<String>,
}

impl Stock {
    fn new(radial: bool, t0: f64, t1: f64, value: f64) -> Stock {
        let h = 0.01;
        let n = ((t1 - t0) / h).round() as usize + 1;
        Stock {
            radial,
            t0,
            h,
            v: vec![value; n],
            max_cut: 0.0,
            rapid_through: vec![],
        }
    }
    /// Plane point of a machine end (X diameter, Z) as (t, value).
    fn tv(&self, p: [f64; 2]) -> (f64, f64) {
        let (r, z) = (p[0] / 2.0, p[1]);
        if self.radial {
            (z, r)
        } else {
            (r, z)
        }
    }
    fn segment(&mut self, a: [f64; 2], b: [f64; 2], rapid: bool, line: u32) {
        let ((ta, va), (tb, vb)) = (self.tv(a), self.tv(b));
        let (lo, hi) = (ta.min(tb), ta.max(tb));
        let i0 = ((lo - self.t0) / self.h).ceil().max(0.0) as usize;
        let i1 = (((hi - self.t0) / self.h).floor() as i64).min(self.v.len() as i64 - 1);
        if i1 < i0 as i64 {
            return;
        }
        for i in i0..=(i1 as usize) {
            let t = self.t0 + i as f64 * self.h;
            let path = if (tb - ta).abs() < 1e-12 {
                va.min(vb)
            } else {
                va + (vb - va) * (t - ta) / (tb - ta)
            };
            let cut = self.v[i] - path;
            if cut > 1e-6 {
                if rapid {
                    self.rapid_through.push(format!(
                        "line {line}: rapid {cut:.4} mm into stock at {t:.3}"
                    ));
                } else {
                    self.max_cut = self.max_cut.max(cut);
                    self.v[i] = path;
                }
            }
        }
    }
    fn apply(&mut self, cmds: &[Canon], start: [f64; 2]) {
        let mut cur = start;
        for c in cmds {
            match &c.command {
                Command::Rapid { end } => {
                    // Each axis runs at its own rate, so the path lies between the two
                    // axis-first paths: both must stay out of the stock.
                    let e = [end[0], end[1]];
                    for corner in [[e[0], cur[1]], [cur[0], e[1]]] {
                        self.segment(cur, corner, true, c.line);
                        self.segment(corner, e, true, c.line);
                    }
                    cur = e;
                }
                Command::Linear { end, .. } | Command::Thread { end, .. } => {
                    let e = [end[0], end[1]];
                    self.segment(cur, e, false, c.line);
                    cur = e;
                }
                Command::Arc {
                    end,
                    center,
                    clockwise,
                    ..
                } => {
                    let (cz, cr) = (center[1], center[0] / 2.0);
                    let (az, ar) = (cur[1], cur[0] / 2.0);
                    let (ez, er) = (end[1], end[0] / 2.0);
                    let rad = ((az - cz).powi(2) + (ar - cr).powi(2)).sqrt();
                    let a0 = (ar - cr).atan2(az - cz);
                    let a1 = (er - cr).atan2(ez - cz);
                    let mut sw = a1 - a0;
                    if *clockwise {
                        while sw >= 0.0 {
                            sw -= std::f64::consts::TAU;
                        }
                    } else {
                        while sw <= 0.0 {
                            sw += std::f64::consts::TAU;
                        }
                    }
                    let n = 20000;
                    let mut p = cur;
                    for k in 1..=n {
                        let ang = a0 + sw * k as f64 / n as f64;
                        let q = [2.0 * (cr + rad * ang.sin()), cz + rad * ang.cos()];
                        self.segment(p, q, false, c.line);
                        p = q;
                    }
                    cur = [end[0], end[1]];
                }
                _ => {}
            }
        }
    }
    fn at(&self, t: f64) -> f64 {
        self.v[((t - self.t0) / self.h).round() as usize]
    }
}

#[test]
fn fixture_029_g71_type_one_leaves_contour_plus_allowance() {
    let cmds = run(&fixture("029_g71_type1_example1.nc"), HOME).unwrap();
    // Blank: bar dia 100 from Z140 to Z60 (the contour's span), start point X100 Z160.
    let mut stock = Stock::new(true, 40.0, 170.0, 50.0);
    stock.apply(&cmds, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    assert!(stock.max_cut <= 2.0 + 1e-6, "deepest cut {}", stock.max_cut);
    // Contour (Z, X) shifted by U2 (diameter) W2: material left = contour + allowance.
    let contour = [
        [140.0, 20.0],
        [100.0, 40.0],
        [100.0, 60.0],
        [80.0, 60.0],
        [60.0, 80.0],
        [60.0, 100.0],
    ];
    let shifted: Vec<[f64; 2]> = contour.iter().map(|p| [p[0] + 2.0, p[1] + 2.0]).collect();
    let mut z = 62.05;
    while z < 141.95 {
        let want = contour_at(&shifted, z).unwrap();
        assert!(
            (stock.at(z) - want).abs() < 1e-6,
            "at Z{z}: {} vs {want}",
            stock.at(z)
        );
        z += 0.5;
    }
    // The cycle ends at its start point, then M30.
    assert!(close(*ends(&cmds).last().unwrap(), [100.0, 160.0], 1e-9));
}

#[test]
fn fixture_030_g71_type_two_cuts_pockets() {
    let cmds = run(&fixture("030_g71_type2_example2.nc"), HOME).unwrap();
    let mut stock = Stock::new(true, 0.0, 130.0, 40.0);
    stock.apply(&cmds, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    assert!(stock.max_cut <= 2.0 + 1e-6, "deepest cut {}", stock.max_cut);
    // Straight pieces of the contour (+U3 diameter, W0): X25 Z110..100, X70 Z90..85, X60 at Z45.
    for (z, x) in [(105.0, 25.0), (87.5, 70.0), (45.0, 60.0)] {
        assert!(
            (stock.at(z) - (x + 3.0) / 2.0).abs() < 1e-6,
            "at Z{z}: {}",
            stock.at(z)
        );
    }
    assert!(close(*ends(&cmds).last().unwrap(), [80.0, 125.0], 1e-9));
}

#[test]
fn fixture_033_g72_faces_in_layers_and_g70_finishes() {
    let text = fixture("033_g72_radial_roughing_O0005.nc");
    let cmds = run(&text, HOME).unwrap();
    // Face model: material below Z10 for every radius up to 88 (X176).
    let mut stock = Stock::new(false, 0.0, 88.0, 10.0);
    // The roughing is what the G72 blocks produced; G70 later runs lines after them.
    let g72_line = line_of(&text, "G72 P10");
    let rough: Vec<Canon> = cmds
        .iter()
        .filter(|c| c.line <= g72_line)
        .cloned()
        .collect();
    stock.apply(&rough, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    assert!(stock.max_cut <= 2.0 + 1e-6, "deepest cut {}", stock.max_cut);
    // Contour X160 Z-55 → X80 Z-35 → Z-20 → X40 Z0, shifted U0.2 W0.1.
    let face = |r: f64| {
        let x = 2.0 * r;
        if x >= 80.2 {
            -55.0 + (160.2 - x) / 80.0 * 20.0 + 0.1
        } else if x >= 40.2 {
            -20.0 + (80.2 - x) / 40.0 * 20.0 + 0.1
        } else {
            f64::NAN
        }
    };
    let mut r = 20.2;
    while r < 80.0 {
        let want = face(r);
        assert!(
            (stock.at(r) - want).abs() < 1e-6,
            "at R{r}: {} vs {want}",
            stock.at(r)
        );
        r += 0.37;
    }
    // G70 runs the contour blocks themselves, then returns to the start; M30 after it.
    let g70: Vec<&Canon> = cmds.iter().filter(|c| c.line > g72_line).collect();
    assert!(g70.iter().any(|c| matches!(c.command, Command::Linear { ref end, .. } if close([end[0], end[1]], [40.0, 0.0], 1e-9))));
    let last_move = cmds.iter().rev().find_map(|c| end_of(&c.command)).unwrap();
    assert!(close(last_move, [176.0, 10.0], 1e-9));
    assert!(matches!(
        cmds[cmds.len() - 2].command,
        Command::Aux(Aux::M(30))
    ));
}

#[test]
fn fixture_034_g73_repeats_the_pattern_three_times() {
    let cmds = run(&fixture("034_g73_pattern_repeat_O0006.nc"), HOME).unwrap();
    // Feed per revolution for the roughing (G99), three passes approaching the contour.
    assert!(cmds
        .iter()
        .any(|c| c.command == Command::FeedMode { per_rev: true }));
    // Last rough pass: contour + (U0.5, W0.3): the final point X180 Z-80 lands at X180.5 Z-79.7.
    assert!(ends(&cmds).iter().any(|e| close(*e, [180.5, -79.7], 1e-9)));
    // First pass: + relief (U1.0 radius = 2 mm diameter, W1.0).
    assert!(ends(&cmds).iter().any(|e| close(*e, [182.5, -78.7], 1e-9)));
    let feed_moves = cmds
        .iter()
        .filter(|c| matches!(c.command, Command::Linear { feed, .. } if (feed - 0.3).abs() < 1e-12))
        .count();
    assert!(feed_moves >= 3 * 4, "{feed_moves}");
}

#[test]
fn fixture_027_g90_turns_dia_60_and_the_taper() {
    let cmds = run(&fixture("027_g90_axial_cycle_O0002.nc"), HOME).unwrap();
    // Blank dia 125 from the face Z0 back to Z-115.
    let mut stock = Stock::new(true, -115.0, 0.0, 62.5);
    stock.apply(&cmds, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    // The program's own steps: 5 mm (radius) per diameter pass, 7.5 mm per taper pass (R).
    assert!(stock.max_cut <= 7.5 + 1e-6, "deepest cut {}", stock.max_cut);
    assert!((stock.at(-100.0) - 60.0).abs() < 1e-6);
    assert!((stock.at(-15.0) - 30.0).abs() < 1e-6);
    // The taper's last pass: X60 at Z-30 to X120 at Z-80.
    assert!(
        (stock.at(-55.0) - (30.0 + 30.0 * 25.0 / 50.0)).abs() < 1e-6,
        "{}",
        stock.at(-55.0)
    );
}

#[test]
fn fixture_039_g92_threads_in_four_passes_with_lead_3() {
    let cmds = run(&fixture("039_g92_thread_cycle_O0012.nc"), HOME).unwrap();
    let threads: Vec<(f64, [f64; 2])> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Thread { end, lead, .. } = &c.command {
                Some((*lead, [end[0], end[1]]))
            } else {
                None
            }
        })
        .collect();
    // Each pass: thread to Z-27 (K1 run-out start) at lead 3, then run-out J3 (radius) to
    // Z-28. The run-out's long axis is X (3 mm against 1 mm), so its lead is stated along X
    // as 9: Z keeps advancing 3 mm per revolution (D36).
    for t in &threads {
        let want = if (t.1[1] + 28.0).abs() < 1e-9 {
            9.0
        } else {
            3.0
        };
        assert!((t.0 - want).abs() < 1e-12, "{t:?}");
    }
    let bottoms: Vec<f64> = threads
        .iter()
        .filter(|t| (t.1[1] + 27.0).abs() < 1e-9)
        .map(|t| t.1[0])
        .collect();
    assert_eq!(bottoms, [58.7, 57.7, 57.0, 56.9]);
    assert!(threads
        .iter()
        .filter(|t| (t.1[1] + 28.0).abs() < 1e-9)
        .all(|t| bottoms.iter().any(|b| (t.1[0] - b - 6.0).abs() < 1e-9)));
}

#[test]
fn fixture_040_g76_depths_follow_the_square_root_rule() {
    let cmds = run(&fixture("040_g76_multiple_thread_O0013.nc"), HOME).unwrap();
    // G50 shifts the work system, so compare depths, not absolute X.
    let threads: Vec<[f64; 2]> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Thread { end, lead, .. } = &c.command {
                assert_eq!(*lead, 6.0);
                Some([end[0], end[1]])
            } else {
                None
            }
        })
        .collect();
    // Pass bottoms (before the run-out) are where Z is 3 mm (0.5 × lead) short of the end.
    let zend = threads.iter().map(|t| t[1]).fold(f64::INFINITY, f64::min);
    let bottoms: Vec<f64> = threads
        .iter()
        .filter(|t| (t[1] - (zend + 3.0)).abs() < 1e-6)
        .map(|t| t[0])
        .collect();
    let root = bottoms.iter().copied().fold(f64::INFINITY, f64::min);
    let depths: Vec<f64> = bottoms.iter().map(|x| 3.68 - (x - root) / 2.0).collect();
    // 1.8 √n while below k − d = 3.58 (1.8 √4 = 3.6 is not), then the last rough pass at
    // 3.58, then 2 finishing passes at 3.68.
    let expect = [1.8, 1.8 * 2f64.sqrt(), 1.8 * 3f64.sqrt(), 3.58, 3.68, 3.68];
    assert_eq!(depths.len(), expect.len(), "{depths:?}");
    for (d, e) in depths.iter().zip(expect) {
        assert!((d - e).abs() < 1e-9, "{depths:?}");
    }
}

#[test]
fn fixture_035_036_grooving_pecks_never_deeper_than_the_step() {
    let cmds = run(&fixture("036_g75_radial_grooving_O0008.nc"), HOME).unwrap();
    let mut stock = Stock::new(true, -60.0, 0.0, 62.5);
    stock.apply(&cmds, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    assert!(stock.max_cut <= 6.0 + 1e-6, "{}", stock.max_cut);
    // Groove floor X40 at every plunge from Z-24 in steps of 3 (Q30000) to Z-50 (the 4 mm
    // tool covers between them; the stock model follows the tool point).
    for z in [-24.0, -30.0, -42.0, -50.0] {
        assert!(
            (stock.at(z) - 20.0).abs() < 1e-6,
            "at Z{z}: {}",
            stock.at(z)
        );
    }
    let cmds = run(&fixture("035_g74_face_grooving_O0007.nc"), HOME).unwrap();
    let mut face = Stock::new(false, 0.0, 18.0, 0.0);
    face.apply(&cmds, HOME);
    assert!(face.max_cut <= 5.0 + 1e-6, "{}", face.max_cut);
    for r in [10.0, 12.0, 15.0, 18.0] {
        assert!((face.at(r) + 20.0).abs() < 1e-6, "at R{r}: {}", face.at(r));
    }
}

#[test]
fn fixture_037_g32_taper_thread_passes() {
    let cmds = run(&fixture("037_g32_taper_thread_O0009.nc"), HOME).unwrap();
    let t: Vec<[f64; 2]> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Thread { end, lead, .. } = &c.command {
                assert_eq!(*lead, 2.0);
                Some([end[0], end[1]])
            } else {
                None
            }
        })
        .collect();
    assert_eq!(t.len(), 2);
    assert!(close(t[0], [48.8571, -72.0], 1e-9) && close(t[1], [47.4286, -72.0], 1e-9));
}

#[test]
fn fixture_002_g96_speeds_at_the_end_points() {
    let cmds = run(&fixture("002_g96_constant_surface_speed.nc"), HOME).unwrap();
    let s: Vec<f64> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Aux(Aux::S(v)) = c.command {
                Some(v)
            } else {
                None
            }
        })
        .collect();
    // 300 m/min: X100 → 955, X50 → 1910, X80 → 1194 r/min (manual's figures, rounded).
    for want in [955.0, 1910.0, 1194.0] {
        assert!(
            s.iter().any(|v| (v - want).abs() < 0.5),
            "{want} not in {s:?}"
        );
    }
}

#[test]
fn macros_fixtures_042_to_050() {
    let cmds = run(&fixture("042_macro_variables_intro.nc"), [0.0, 0.0]).unwrap();
    assert!(
        matches!(&cmds[0].command, Command::Linear { end, feed } if (end[0] - 34.202).abs() < 1e-3 && *feed == 500.0)
    );
    let cmds = run(
        &fixture("045_macro_expressions_in_blocks.nc")
            .lines()
            .nth(2)
            .unwrap()
            .replace("N0010", "#3=100\n"),
        [0.0, 0.0],
    )
    .unwrap();
    assert!(ends(&cmds).iter().any(|e| (e[0] - 84.2788).abs() < 1e-3));
    let xs: Vec<f64> = ends(&run(&fixture("048_macro_if_goto.nc"), [0.0, 0.0]).unwrap())
        .iter()
        .map(|e| e[0])
        .collect();
    assert_eq!(xs, [0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
    let xs: Vec<f64> = ends(&run(&fixture("049_macro_if_execute.nc"), [0.0, 0.0]).unwrap())
        .iter()
        .map(|e| e[0])
        .collect();
    assert_eq!(xs, [10.0]);
    // 050: 20 passes feeding to 80, 78, … 42, each followed by a rapid 4 mm out; the listing's
    // elision "N0090..." after the loop is a data format error on that line.
    let text = fixture("050_macro_loop_example.nc");
    let e = run(&text, [100.0, 20.0]).unwrap_err();
    assert_eq!((e.number, line_of(&text, "N0090...")), (13, e.line));
    let text: String = text
        .lines()
        .take_while(|l| !l.starts_with("N0090"))
        .collect::<Vec<_>>()
        .join("\n");
    let feeds: Vec<f64> = run(&text, [100.0, 20.0])
        .unwrap()
        .iter()
        .filter_map(|c| {
            if let Command::Linear { end, .. } = &c.command {
                Some(end[0])
            } else {
                None
            }
        })
        .collect();
    assert_eq!(feeds.len(), 21);
    assert!((feeds[20] - 42.0).abs() < 1e-9);
}

#[test]
fn fixture_051_sphere_calls_o0010_from_the_library() {
    let mut lib = Library::new();
    lib.insert(10, "O0010", &fixture("052_macro_sphere_sub_O0010.nc"));
    let cmds = run_lib(&fixture("051_macro_sphere_main.nc"), lib).unwrap();
    let radii: Vec<f64> = cmds
        .iter()
        .scan([200.0, 120.0], |cur, c| {
            let r = if let Command::Arc { center, .. } = &c.command {
                Some(
                    ((cur[0] / 2.0 - center[0] / 2.0).powi(2) + (cur[1] - center[1]).powi(2))
                        .sqrt(),
                )
            } else {
                None
            };
            if let Some(e) = end_of(&c.command) {
                *cur = e;
            }
            Some(r)
        })
        .flatten()
        .collect();
    let want: Vec<f64> = (1..=10).map(|k| 10.0 * k as f64).collect();
    assert_eq!(radii.len(), 10);
    for (r, w) in radii.iter().zip(want) {
        assert!((r - w).abs() < 1e-9, "{radii:?}");
    }
}

#[test]
fn block_range_fixtures_018_to_022_run_in_the_stated_order() {
    let order = |name: &str, inputs: &[(u32, u8)]| {
        let mut setup = Setup::lathe([0.0, 0.0]);
        setup.inputs = inputs.iter().copied().collect();
        let text = fixture(name);
        let cmds = cnc_interpreter::check(Dialect::HuaxingLathe, &text, setup).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        cmds.iter()
            .filter(|c| end_of(&c.command).is_some())
            .map(|c| {
                lines[c.line as usize - 1]
                    .split_whitespace()
                    .next()
                    .unwrap_or("")
                    .to_string()
            })
            .collect::<Vec<_>>()
            .join("-")
    };
    assert_eq!(
        order("020_g25_jump_machining.nc", &[]),
        "N0010-N0040-N0050-N0040-N0050"
    );
    assert_eq!(
        order("021_g26_transfer_machining.nc", &[]),
        "N0010-N0040-N0050-N0040-N0050-N0030-N0040-N0050"
    );
    // G21 runs the range when X2.7 has a signal, G23 when it has none (decision D21).
    assert_eq!(
        order("018_g21_jump_if_input_low.nc", &[(2, 7)]),
        "N0010-N0040-N0050-N0040-N0050"
    );
    assert_eq!(
        order("018_g21_jump_if_input_low.nc", &[]),
        "N0010-N0030-N0040-N0050"
    );
    assert_eq!(
        order("019_g23_jump_if_input_high.nc", &[]),
        "N0010-N0040-N0050-N0040-N0050"
    );
    assert_eq!(
        order("019_g23_jump_if_input_high.nc", &[(2, 7)]),
        "N0010-N0030-N0040-N0050"
    );
    // G27 without L loops forever; a check stops after the first pass.
    assert_eq!(
        order("022_g27_infinite_loop.nc", &[]),
        "N0010-N0020-N0030-N0040-N0030-N0040"
    );
}

#[test]
fn fixtures_with_the_alarm_the_manual_predicts() {
    // 041: after `G3 W-40 R20` the block `W-10` is still G03 by the modal rules and has no R:
    // alarm 11 (decision D26), after the arc of line 13 ran.
    let text = fixture("041_g98_feed_vector_example.nc");
    let e = run(&text, HOME).unwrap_err();
    assert_eq!((e.number, line_of(&text, "W-10;")), (11, e.line));
    // 057 writes `C01` (for G01): this lathe has no C axis, alarm 74 ("rotary axis not
    // defined", D138) on that line.
    let e = run(&fixture("057_ch20_ex3_aluminium_shaft.nc"), HOME).unwrap_err();
    assert_eq!(e.number, 74);
    assert!(e.text.contains('C'), "{e}");
}

/// Fixtures 005 and 006: the manual's built-in tool-change macros (`000` §4.3.3), called by a
/// T word when the machine names a tool-change macro program (S#170).
#[test]
fn fixtures_005_006_tool_change_macros_called_by_t() {
    let mut setup = Setup::lathe(HOME);
    setup.tool_change_macro = Some(9000);
    setup.offsets.tools.insert(
        3,
        cnc_interpreter::setup::ToolOffset {
            x: 4.0,
            z: -2.0,
            ..Default::default()
        },
    );
    // 006 (electric turret): M57 K[#3] sends the target tool, M53.1 K[#4] takes its offset,
    // M52 K8 reads the tool back and M99 returns because it is the target.
    let mut lib = Library::new();
    lib.insert(
        9000,
        "O9000",
        &fixture("006_toolchange_macro_electric_turret.nc"),
    );
    let main = "G00 X100 Z50\nT0203\nG00 X100 Z50\nM30\n";
    let cmds = cnc_interpreter::check_with_library(Dialect::HuaxingLathe, main, setup.clone(), lib)
        .unwrap();
    let t: Vec<&Command> = cmds
        .iter()
        .map(|c| &c.command)
        .filter(|c| matches!(c, Command::Aux(Aux::T(_))))
        .collect();
    assert_eq!(t, [&Command::Aux(Aux::T(2))]);
    // Offset 3 is active after the macro: the same work position is 4 (X) and −2 (Z) away.
    let at = ends(&cmds);
    assert!(
        close(at[1], [at[0][0] + 4.0, at[0][1] - 2.0], 1e-9),
        "{at:?}"
    );

    // 005 (gang tool post): no T to the PLC, the offset changes only.
    let mut lib = Library::new();
    lib.insert(9000, "O9000", &fixture("005_toolchange_macro_gang_tool.nc"));
    let cmds = cnc_interpreter::check_with_library(Dialect::HuaxingLathe, main, setup.clone(), lib)
        .unwrap();
    assert!(!cmds
        .iter()
        .any(|c| matches!(c.command, Command::Aux(Aux::T(_)))));
    let at = ends(&cmds);
    assert!(
        close(at[1], [at[0][0] + 4.0, at[0][1] - 2.0], 1e-9),
        "{at:?}"
    );

    // A macro whose M52 reads a tool other than the target raises the manual's alarm 6 by M58.
    let mut lib = Library::new();
    let wrong = fixture("006_toolchange_macro_electric_turret.nc").replace("M57 K[#3]", "M57 K9");
    lib.insert(9000, "O9000", &wrong);
    let e =
        cnc_interpreter::check_with_library(Dialect::HuaxingLathe, main, setup, lib).unwrap_err();
    assert_eq!(e.number, 6, "{e}");
}

/// The listing's lines, trimmed, without blank ones.
fn lines(text: &str) -> Vec<String> {
    text.lines()
        .map(|l| l.trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

fn speeds(cmds: &[Canon]) -> Vec<(u32, f64)> {
    cmds.iter()
        .filter_map(|c| match c.command {
            Command::Aux(Aux::S(v)) => Some((c.line, v)),
            _ => None,
        })
        .collect()
}

/// The radius (in the X-radius/Z plane) of an arc command that starts at `from`.
fn arc_radius(from: [f64; 2], c: &Command) -> Option<(f64, f64)> {
    if let Command::Arc { end, center, .. } = c {
        let r = |p: [f64; 2]| ((p[0] - center[0]) / 2.0).hypot(p[1] - center[1]);
        Some((r(from), r([end[0], end[1]])))
    } else {
        None
    }
}

#[test]
fn fixture_003_g96_surface_speed_is_kept_through_g97() {
    // Line 3 (G96 X3000) cuts at 50 m/min again: 50 000 / (π · X) r/min.
    let text = fixture("003_g96_s_value_retention_snippet.nc");
    let cmds = run(&text, HOME).unwrap();
    let s = speeds(&cmds);
    assert!(s.contains(&(line_of(&text, "G97"), 1000.0)), "{s:?}");
    // Speeds go out in 0.1 r/min steps, and not below 10 r/min (D17).
    let css = |x: f64| ((50_000.0 / (std::f64::consts::PI * x)).max(10.0) * 10.0).round() / 10.0;
    let third = line_of(&text, "G96 X3000");
    let on_third: Vec<f64> = s.iter().filter(|(l, _)| *l == third).map(|p| p.1).collect();
    // At the start point X200 as the block begins, then at the end point X3000.
    assert_eq!(on_third, [css(200.0), css(3000.0)], "{s:?}");
}

#[test]
fn fixtures_004_014_to_017_need_the_c_axis_or_live_tool_this_lathe_lacks() {
    // The plain lathe (`sim_lathe`) has X and Z only: its spindle is no C axis (M14.6, G08,
    // C words: alarm 74 "rotary axis not defined", D138) and it has no live tool (G14.4: 74,
    // D142); `sim_turnmill` runs them, see `c_axis_and_live_tool.rs` and `polar.rs`. G07.1's
    // oscillation is not defined by the manual: alarm 7 (D140). Every line of 004 is an
    // independent example.
    let text = fixture("004_spindle_c_axis_position_m14_g08.nc");
    for l in lines(&text) {
        let e = run(&l, HOME).unwrap_err();
        assert_eq!((e.number, e.line), (74, 1), "{l}: {e}");
    }
    for (name, first_bad, number) in [
        ("014_g07_1_thread_chip_break.nc", "N0020", 7),
        ("015_g08_rotary_axis_examples.nc", "M14.6", 74),
        ("016_g12_1_polar_interpolation.nc", "G00 C0", 74),
        ("017_g14_4_flying_cutter_tapping.nc", "N0020", 74),
    ] {
        let text = fixture(name);
        let e = run(&text, HOME).unwrap_err();
        assert_eq!(
            (e.number, e.line),
            (number, line_of(&text, first_bad)),
            "{name}: {e}"
        );
    }
}

#[test]
fn fixture_007_008_each_form_reaches_b() {
    for l in lines(&fixture("007_g00_rapid_forms.nc")) {
        let cmds = run(&l, [42.0, 43.0]).unwrap();
        assert!(
            matches!(&cmds[0].command, Command::Rapid { end } if close([end[0], end[1]], [20.0, 25.0], 1e-9)),
            "{l}"
        );
    }
    for l in lines(&fixture("008_g01_linear_forms.nc")) {
        // The F500 of the first form is modal for the other three.
        let cmds = run(&format!("F500\n{l}"), [40.0, 32.0]).unwrap();
        assert!(
            matches!(&cmds[0].command, Command::Linear { end, feed } if close([end[0], end[1]], [60.0, 7.0], 1e-9) && *feed == 500.0),
            "{l}: {cmds:?}"
        );
    }
}

#[test]
fn fixture_009_arc_forms_end_at_x63_060_on_radius_19_16() {
    // From X45.359 Z0. The I/K forms give the stated end point; I is the centre's offset
    // in radius (the printed text says diameter, the geometry says radius: decision D22's
    // reading for arcs as in fixture 010). The first form as printed has no X/U word: by
    // the modal rules it stays at X45.359 and ends at Z-24.071 on R19.16.
    let start = [45.359, 0.0];
    let forms = lines(&fixture("009_g02_arc_forms.nc"));
    for (l, want) in [
        (format!("G02\n{}", forms[0]), [45.359, -24.071]),
        (forms[1].clone(), [63.060, -24.071]),
        (forms[2].clone(), [63.060, -24.071]),
    ] {
        let cmds = run(&l, start).unwrap();
        let c = &cmds
            .iter()
            .find(|c| c.command.end().is_some())
            .unwrap()
            .command;
        assert!(close(end_of(c).unwrap(), want, 1e-9), "{l}: {c:?}");
        let (r0, r1) = arc_radius(start, c).unwrap();
        assert!(
            (r0 - 19.16).abs() < 3e-3 && (r1 - 19.16).abs() < 3e-3,
            "{l}: {r0} {r1}"
        );
    }
}

#[test]
fn fixtures_011_012_three_point_arcs() {
    // 012 (G05.1, absolute mid point X20 Z15) and 011 with the G05 its caption names (mid
    // point I5 radius, K-5 from the start) are the semicircle X10 Z20 → X20 Z15 → X10 Z10:
    // centre X10 Z15, radius 5.
    let semicircle = |text: &str| {
        let cmds = run(text, HOME).unwrap();
        let arc = cmds
            .iter()
            .find(|c| matches!(c.command, Command::Arc { .. }))
            .unwrap();
        let Command::Arc { end, center, .. } = &arc.command else {
            unreachable!()
        };
        (
            [end[0], end[1]],
            [center[0], center[1]],
            arc_radius([10.0, 20.0], &arc.command).unwrap(),
        )
    };
    let g05 = fixture("011_g05_three_point_arc_prog1.nc").replace("G5.1", "G05");
    for text in [g05, fixture("012_g05_1_three_point_arc_prog2.nc")] {
        let (end, center, (r0, r1)) = semicircle(&text);
        assert!(close(end, [10.0, 10.0], 1e-9) && close(center, [10.0, 15.0], 1e-9));
        assert!((r0 - 5.0).abs() < 1e-9 && (r1 - 5.0).abs() < 1e-9);
    }
    // As printed, 011's G5.1 takes I5 K-5 as the absolute mid point (D22): another circle,
    // through X5 Z-5.
    let (_, center, (r0, _)) = semicircle(&fixture("011_g05_three_point_arc_prog1.nc"));
    let mid = ((5.0 - center[0]) / 2.0).hypot(-5.0 - center[1]);
    assert!((mid - r0).abs() < 1e-9, "{center:?} {r0} {mid}");
}

#[test]
fn fixture_013_g07_pauses_1_s_every_5_mm() {
    // The listing's "....." elision is alarm 13 on its line; the blocks before it run.
    let text = fixture("013_g07_linear_chip_break.nc");
    let e = run(&text, HOME).unwrap_err();
    assert_eq!((e.number, e.line), (13, line_of(&text, ".....")));
    let head: String = text
        .lines()
        .take_while(|l| !l.starts_with("....."))
        .map(|l| format!("{l}\n"))
        .collect();
    let cmds = run(&(head + "N0100 G07\nG01 Z-40\nM30\n"), HOME).unwrap();
    let g01: Vec<&Canon> = cmds.iter().filter(|c| c.line == 4).collect();
    // Z0 → Z-30 at F300: six 5 mm pieces with a 1 s pause between them, none after the last.
    let mut z = 0.0;
    for (k, c) in g01.iter().enumerate() {
        if k % 2 == 0 {
            z -= 5.0;
            assert!(
                matches!(&c.command, Command::Linear { end, feed } if close([end[0], end[1]], [20.0, z], 1e-9) && *feed == 300.0),
                "{c:?}"
            );
        } else {
            assert_eq!(c.command, Command::Dwell { seconds: 1.0 });
        }
    }
    assert_eq!(g01.len(), 11);
    // After the cancel, the next G01 is one move.
    let after: Vec<&Canon> = cmds.iter().filter(|c| c.line == 6).collect();
    assert_eq!(after.len(), 1, "{after:?}");
    // Its errors (D45): K without L (23), L 0 or a negative pause (13), the thread form (7).
    for (bad, number) in [
        ("G07 K1", 23),
        ("G07 K1 L0", 13),
        ("G07 K-1 L5", 13),
        ("G07 P5 Q1 L15", 7),
    ] {
        let e = run(&format!("G00 X20 Z0\n{bad}\n"), HOME).unwrap_err();
        assert_eq!((e.number, e.line), (number, 2), "{bad}: {e}");
    }
}

/// Whether each motion of `cmds` runs in exact stop (`PathMode` before it), by line.
fn exact_stops(cmds: &[Canon]) -> Vec<(u32, bool)> {
    let mut exact = false;
    let mut out = Vec::new();
    for c in cmds {
        match c.command {
            Command::PathMode { exact_stop } => exact = exact_stop,
            _ if c.command.end().is_some() => out.push((c.line, exact)),
            _ => {}
        }
    }
    out
}

#[test]
fn fixtures_023_to_026_g09_g61_g64_exact_stop() {
    // 023/025: no G09/G61, every block blends.
    for name in ["023_g09_prog1_smooth_corner.nc", "025_g61_prog3_smooth.nc"] {
        let cmds = run(&fixture(name), HOME).unwrap();
        assert!(exact_stops(&cmds).iter().all(|&(_, e)| !e), "{name}");
    }
    // 024: G09 on N2 only.
    let text = fixture("024_g09_prog2_exact_stop.nc");
    let n = |k: u32| line_of(&text, &format!("N{k} "));
    let cmds = run(&text, HOME).unwrap();
    assert_eq!(
        exact_stops(&cmds),
        [(n(1), false), (n(2), true), (n(3), false), (n(4), false)]
    );
    // 026: G61 on N2 up to G64 on N7: N3–N6 stop exactly.
    let text = fixture("026_g61_g64_prog4_exact_stop_mode.nc");
    let n = |k: u32| line_of(&text, &format!("N{k} "));
    let cmds = run(&text, HOME).unwrap();
    assert_eq!(
        exact_stops(&cmds),
        [
            (n(1), false),
            (n(3), true),
            (n(4), true),
            (n(5), true),
            (n(6), true)
        ]
    );
    assert!(cmds
        .iter()
        .any(|c| c.line == n(7) && c.command == Command::PathMode { exact_stop: false }));
}

#[test]
fn fixture_028_g94_faces_the_end_and_the_taper_to_dia_60() {
    let cmds = run(&fixture("028_g94_radial_cycle_O0003.nc"), HOME).unwrap();
    // Face model: the blank's face at Z2 for every radius up to 62.5 (dia 125).
    let mut stock = Stock::new(false, 0.0, 62.5, 2.0);
    stock.apply(&cmds, HOME);
    assert!(stock.rapid_through.is_empty(), "{:?}", stock.rapid_through);
    // Faced to Z0 inside dia 60; from dia 60 at Z-30 the cone of the last pass (X60 R-50:
    // dia 120 at Z-80); outside dia 120 the first cycles' cut to Z-110.
    let face = |r: f64| {
        if r < 30.0 {
            0.0
        } else if r < 60.0 {
            -30.0 - (r - 30.0) * 50.0 / 30.0
        } else {
            -110.0
        }
    };
    let mut r: f64 = 0.5;
    while r < 62.4 {
        if (r - 30.0).abs() > 0.02 && (r - 60.0).abs() > 0.02 {
            assert!(
                (stock.at(r) - face(r)).abs() < 1e-6,
                "at R{r}: {} vs {}",
                stock.at(r),
                face(r)
            );
        }
        r += 0.25;
    }
    // Each cycle returns to its start point: the last one to X120 Z0.
    let last = cmds.iter().rev().find_map(|c| end_of(&c.command)).unwrap();
    assert!(close(last, [120.0, 0.0], 1e-9));
}

/// Stock after `cmds` cut a fresh blank (radius `blank` along Z from `z0` to `z1`).
fn swept(cmds: &[Canon], start: [f64; 2], z0: f64, z1: f64, blank: f64) -> Stock {
    let mut stock = Stock::new(true, z0, z1, blank);
    stock.apply(cmds, start);
    stock
}

/// `cmds` moved by `dx` (diameter) and `dz`.
fn translated(cmds: &[Canon], dx: f64, dz: f64) -> Vec<Canon> {
    let mut out = cmds.to_vec();
    for c in &mut out {
        match &mut c.command {
            Command::Rapid { end } | Command::Linear { end, .. } => {
                end[0] += dx;
                end[1] += dz;
            }
            Command::Arc { end, center, .. } => {
                end[0] += dx;
                end[1] += dz;
                center[0] += dx;
                center[1] += dz;
            }
            _ => {}
        }
    }
    out
}

#[test]
fn fixture_031_g71_type_two_leaves_the_mixed_contour_plus_u3() {
    let text = fixture("031_g71_mixed_example3.nc");
    let cmds = run(&text, HOME).unwrap();
    // Blank: bar dia 60 between the contour's ends (Z90 to Z10).
    let rough = swept(&cmds, HOME, 10.0, 90.0, 30.0);
    assert!(rough.rapid_through.is_empty(), "{:?}", rough.rapid_through);
    // U2 is the depth of cut (radius).
    assert!(rough.max_cut <= 2.0 + 1e-6, "deepest cut {}", rough.max_cut);
    // The finishing contour (its own blocks, run as a program from the start point), moved
    // by the allowance U3 W0, swept through the same blank: the material that must be left.
    let contour: String = text
        .lines()
        .skip_while(|l| !l.starts_with("N0040"))
        .take_while(|l| !l.starts_with("N0180"))
        .map(|l| format!("{l}\n"))
        .collect();
    let finish = run(&format!("G00 X60 Z90\n{contour}"), HOME).unwrap();
    let want = swept(
        &translated(&finish, 3.0, 0.0),
        [63.0, 90.0],
        10.0,
        90.0,
        30.0,
    );
    let mut z: f64 = 10.5;
    while z < 89.5 {
        // Away from the contour's vertical walls (Z85, Z60 and Z70's step).
        if [85.0, 70.0, 65.0, 60.0]
            .iter()
            .all(|w| (z - w).abs() > 0.02)
        {
            assert!(
                (rough.at(z) - want.at(z)).abs() < 1e-6,
                "at Z{z}: {} vs {}",
                rough.at(z),
                want.at(z)
            );
        }
        z += 0.1;
    }
    // The pockets are cut: at Z57.5 the material is the X30 floor + 1.5.
    assert!((rough.at(57.5) - 16.5).abs() < 1e-6, "{}", rough.at(57.5));
}

#[test]
fn fixture_038_g33_taps_to_z50_and_reverses_out() {
    let text = fixture("038_g33_tapping_O0011.nc");
    let cmds = run(&text, HOME).unwrap();
    let tap: Vec<&Command> = cmds
        .iter()
        .filter(|c| c.line == line_of(&text, "G33"))
        .map(|c| &c.command)
        .collect();
    // In at 1.5 mm/rev, spindle stop, reverse, out to the start at the same lead, stop.
    assert!(
        matches!(tap[0], Command::Thread { end, lead, .. } if close([end[0], end[1]], [0.0, 50.0], 1e-9) && *lead == 1.5)
    );
    assert_eq!(tap[1], &Command::Aux(Aux::M(5)));
    assert_eq!(tap[2], &Command::Aux(Aux::M(4)));
    assert!(
        matches!(tap[3], Command::Thread { end, lead, .. } if close([end[0], end[1]], [0.0, 90.0], 1e-9) && *lead == 1.5)
    );
    assert_eq!(tap[4], &Command::Aux(Aux::M(5)));
    assert_eq!(tap.len(), 5);
    // The spindle is started again by the program's own M03 on the next line.
    assert!(cmds
        .iter()
        .any(|c| c.line == line_of(&text, "M03;") && c.command == Command::Aux(Aux::M(3))));
}

#[test]
fn macro_fixtures_043_044_046_047() {
    // 043: the fragment is written for a mill (G90 = absolute); on this lathe G90 is the
    // turning cycle, which needs Z: alarm 23 on line 1.
    let text = fixture("043_macro_null_variable_snippets.nc");
    assert_eq!(run(&text, HOME).unwrap_err().number, 23);
    // A word with a null value is left out: `G00 X100 Y[#0]` is `G00 X100` (no Y axis here).
    let a = run("G00 X100 Z[#0]\n", HOME).unwrap();
    assert_eq!(ends(&a), [[100.0, 100.0]]);
    // #1 = null, #2 = #0 + 1 = 1, #3 = #0 * 3 = 0.
    let cmds = run("#1=#0\n#2=#0+1\n#3=#0*3\nG00 X[#2] Z[#3]\n", HOME).unwrap();
    assert_eq!(ends(&cmds), [[1.0, 0.0]]);
    for (cond, holds) in [
        ("#1==#0", true),
        ("#1==0", false),
        ("#1!=0", true),
        ("#1>=0", true),
    ] {
        let p = format!("#1=#0\nIF[{cond}]GOTO9\nG00 X1\nN9 G00 Z1\nM30\n");
        let first = ends(&run(&p, HOME).unwrap())[0];
        assert_eq!(first == [200.0, 1.0], holds, "{cond}");
    }
    // The comparisons as printed are not statements: alarm 20 on their line.
    let e = run("#1=#0\n#1==#0\n", HOME).unwrap_err();
    assert_eq!((e.number, e.line), (20, 2));

    // 044: G91 does not exist on this lathe (alarm 7); its incremental words are U and W.
    // With ROUND the third move returns exactly to the start.
    let text = fixture("044_macro_round_snippet.nc");
    let e = run(&text, HOME).unwrap_err();
    assert_eq!((e.number, e.line), (7, line_of(&text, "G00 G91")));
    let p = "#1=1.2345\n#2=2.3456\nG00 U[-ROUND[#1]]\nG01 U[-ROUND[#2]] F300\nG00 U[ROUND[#1]+ROUND[#2]]\n";
    let e = ends(&run(p, HOME).unwrap());
    assert!(close(e[0], [200.0 - 1.235, 100.0], 1e-9), "{e:?}");
    assert!(close(e[1], [200.0 - 1.235 - 2.346, 100.0], 1e-9), "{e:?}");
    assert!(close(e[2], HOME, 1e-9), "{e:?}");

    // 046: #1 = 60, #2 = COS[60] = 0.5, #3 = 87.5, #4 = 87.5.
    let text = fixture("046_macro_assignment.nc") + "G00 X[#4] Z[#2]\nG00 X[#3] Z[#1]\n";
    let e = ends(&run(&text, HOME).unwrap());
    assert!(close(e[0], [87.5, 0.5], 1e-9) && close(e[1], [87.5, 60.0], 1e-9));

    // 047: as printed there is no N200: alarm 24 on line 1. With one, each form gets there
    // (N200 and N0200 are the same number).
    let text = fixture("047_macro_goto_forms.nc");
    let e = run(&text, HOME).unwrap_err();
    assert_eq!((e.number, e.line), (24, line_of(&text, "N0010GOTO200")));
    for form in lines(&text) {
        for target in ["N200", "N0200"] {
            let p = format!("#1=100\n#2=200\n{form}\nG00 X1\n{target} G00 X2\nM30\n");
            assert_eq!(ends(&run(&p, HOME).unwrap())[0][0], 2.0, "{form} {target}");
        }
    }
}

/// Thread commands of `cmds` on `line`: (end, lead).
fn threads(cmds: &[Canon], line: u32) -> Vec<([f64; 2], f64)> {
    cmds.iter()
        .filter(|c| c.line == line)
        .filter_map(|c| match &c.command {
            Command::Thread { end, lead, .. } => Some(([end[0], end[1]], *lead)),
            _ => None,
        })
        .collect()
}

#[test]
fn fixtures_055_056_chapter_20_parts() {
    // 055: an internal M-thread of 1.5 mm lead in two passes (X37.5 then X38.5) to Z-16,
    // run out J3 (radius, toward the axis: inside a bore) over K1.
    let text = fixture("055_ch20_ex1_brass_bore_groove_thread.nc");
    let cmds = run(&text, [100.0, 50.0]).unwrap();
    for (line, x) in [
        (line_of(&text, "N0230"), 37.5),
        (line_of(&text, "N0240"), 38.5),
    ] {
        let t = threads(&cmds, line);
        assert_eq!(t.len(), 2, "{t:?}");
        assert!(close(t[0].0, [x, -15.0], 1e-9) && t[0].1 == 1.5, "{t:?}");
        assert!(close(t[1].0, [x - 6.0, -16.0], 1e-9), "{t:?}");
    }
    // The groove: T2 feeds out to dia 44 at Z-18.
    assert!(ends(&cmds).iter().any(|e| close(*e, [44.0, -18.0], 1e-9)));
    assert!(close(*ends(&cmds).last().unwrap(), [100.0, 250.0], 1e-9));
    assert!(matches!(
        cmds[cmds.len() - 2].command,
        Command::Aux(Aux::M(2))
    ));

    // 056: one pass of an inch taper thread, 14 threads per inch (lead 25.4/14), R-1.1: from
    // dia 17.8 at Z106 along the taper to Z84 at dia 20, run out J4 (radius) from Z88.
    let text = fixture("056_ch20_ex2_taper_inch_thread.nc");
    let cmds = run(&text, [100.0, 160.0]).unwrap();
    let t = threads(&cmds, line_of(&text, "N0300"));
    let lead = 25.4 / 14.0;
    assert_eq!(t.len(), 2, "{t:?}");
    assert!(close(t[0].0, [19.6, 88.0], 1e-9) && (t[0].1 - lead).abs() < 1e-12);
    assert!(close(t[1].0, [28.0, 84.0], 1e-9));
    let start = cmds
        .iter()
        .filter(|c| c.line == line_of(&text, "N0300"))
        .find_map(|c| end_of(&c.command))
        .unwrap();
    assert!(close(start, [17.8, 106.0], 1e-9));
    // Finished to dia 20 between Z84 and Z34 after roughing at 20.4.
    assert!(ends(&cmds).iter().any(|e| close(*e, [20.0, 34.0], 1e-9)));
    assert!(close(*ends(&cmds).last().unwrap(), [100.0, 160.0], 1e-9));
}

#[test]
fn fixture_060_single_block_examples() {
    let l = lines(&fixture("060_misc_single_block_examples.nc"));
    // N0010 G01 X1000 Z-23.7 F100 (its comment after ";").
    let cmds = run(&l[0], HOME).unwrap();
    assert!(
        matches!(&cmds[0].command, Command::Linear { end, feed } if close([end[0], end[1]], [1000.0, -23.7], 1e-9) && *feed == 100.0)
    );
    // M50 (bar feeder driving outputs itself) and G77 (absolute encoder zero) are refused with
    // alarm 7 and their reasons; M51 N0070 (auto-start block) is an MDI operation.
    for k in [1, 2, 3] {
        let e = run(&l[k], HOME).unwrap_err();
        assert_eq!((e.number, e.line), (7, 1), "{}: {e}", l[k]);
    }
    // G50 X100 Z150 makes the current point X100 Z150: G00 X0 Z0 then moves by (−100, −150).
    let cmds = run(&format!("{}\nG00 X0 Z0\n", l[5]), HOME).unwrap();
    assert_eq!(ends(&cmds), [[HOME[0] - 100.0, HOME[1] - 150.0]]);
}
