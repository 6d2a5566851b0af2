//! Tool-nose radius compensation on the manuals' examples (`000` §6, fixtures 053/054/058/059;
//! `002` fixture 021), checked geometrically: the nose circle, placed at the controlled point
//! minus the tip vector, never cuts into the programmed contour (no gouge) and touches every
//! cutting element of it (the contour is cut to size).

use cnc_interpreter::setup::ToolOffset;
use cnc_interpreter::{Canon, Command, Dialect, Setup};

mod support;
use support::contour_at;

const HOME: [f64; 2] = [200.0, 250.0];

fn fixture(dir: &str, name: &str) -> String {
    let path = format!(
        "{}/../../../shared/fixtures/{dir}/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    match text.split_once("(--- listing as printed ---)") {
        Some((_, listing)) => listing.to_string(),
        None => text,
    }
}

fn setup(radius: f64, tip: u8) -> Setup {
    setup_post(radius, tip, false)
}

/// `front`: the turret in front of the spindle axis, which swaps G41 and G42.
fn setup_post(radius: f64, tip: u8, front: bool) -> Setup {
    let mut s = Setup::lathe(HOME);
    s.front_tool_post = front;
    s.offsets.tools.insert(
        1,
        ToolOffset {
            radius,
            tip,
            ..ToolOffset::default()
        },
    );
    s
}

/// Plane elements (z, r) of a stream: lines and arcs with their centres, feeds only or all.
#[derive(Debug, Clone, Copy)]
enum El {
    Line([f64; 2], [f64; 2]),
    Arc([f64; 2], [f64; 2], [f64; 2], bool),
}

fn elements(cmds: &[Canon], start: [f64; 2]) -> Vec<(El, bool, u32)> {
    let mut at = [start[1], start[0] / 2.0];
    let mut out = Vec::new();
    for c in cmds {
        let (el, cut) = match &c.command {
            Command::Rapid { end } => (El::Line(at, [end[1], end[0] / 2.0]), false),
            Command::Linear { end, .. } => (El::Line(at, [end[1], end[0] / 2.0]), true),
            Command::Arc {
                end,
                center,
                clockwise,
                ..
            } => (
                El::Arc(
                    at,
                    [end[1], end[0] / 2.0],
                    [center[1], center[0] / 2.0],
                    *clockwise,
                ),
                true,
            ),
            _ => continue,
        };
        at = match el {
            El::Line(_, b) | El::Arc(_, b, _, _) => b,
        };
        out.push((el, cut, c.line));
    }
    out
}

/// Points along an element, every `step` mm or so.
fn samples(el: El, step: f64) -> Vec<[f64; 2]> {
    match el {
        El::Line(a, b) => {
            let l = (b[0] - a[0]).hypot(b[1] - a[1]);
            let n = ((l / step).ceil() as usize).max(1);
            (0..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
                })
                .collect()
        }
        El::Arc(a, b, c, cw) => {
            let r = (a[0] - c[0]).hypot(a[1] - c[1]);
            let a0 = (a[1] - c[1]).atan2(a[0] - c[0]);
            let a1 = (b[1] - c[1]).atan2(b[0] - c[0]);
            let mut sweep = a1 - a0;
            let tau = std::f64::consts::TAU;
            if cw {
                while sweep > 1e-12 {
                    sweep -= tau;
                }
            } else {
                while sweep < -1e-12 {
                    sweep += tau;
                }
            }
            let n = (((sweep.abs() * r) / step).ceil() as usize).max(1);
            (0..=n)
                .map(|i| {
                    let t = a0 + sweep * i as f64 / n as f64;
                    [c[0] + r * t.cos(), c[1] + r * t.sin()]
                })
                .collect()
        }
    }
}

/// Distance from `p` to an element.
fn distance(p: [f64; 2], el: El) -> f64 {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    match el {
        El::Line(a, b) => {
            let (u, w) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
            let l2 = u[0] * u[0] + u[1] * u[1];
            let t = if l2 > 0.0 {
                ((w[0] * u[0] + w[1] * u[1]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            d(p, [a[0] + u[0] * t, a[1] + u[1] * t])
        }
        El::Arc(a, b, c, cw) => {
            let r = d(a, c);
            let ang = |q: [f64; 2]| (q[1] - c[1]).atan2(q[0] - c[0]);
            let tau = std::f64::consts::TAU;
            // Counter-clockwise angle from a to x, and the arc's counter-clockwise span.
            let ccw_from = |from: f64, to: f64| (to - from).rem_euclid(tau);
            let (start, span) = if cw {
                (ang(b), ccw_from(ang(b), ang(a)))
            } else {
                (ang(a), ccw_from(ang(a), ang(b)))
            };
            if ccw_from(start, ang(p)) <= span + 1e-12 {
                (d(p, c) - r).abs()
            } else {
                d(p, a).min(d(p, b))
            }
        }
    }
}

fn tip_vector(tip: u8, r: f64) -> [f64; 2] {
    match tip {
        1 => [r, r],
        2 => [-r, r],
        3 => [-r, -r],
        4 => [r, -r],
        5 => [r, 0.0],
        6 => [0.0, r],
        7 => [-r, 0.0],
        8 => [0.0, -r],
        _ => [0.0, 0.0],
    }
}

/// Runs `text` compensated and uncompensated; checks gouging and contact on the cutting
/// elements from `first_line` to `last_line` of the programmed contour.
/// Which side of the contour the material is: an outside profile (material toward the axis)
/// or a bore (material outward).
#[derive(Clone, Copy, PartialEq)]
enum Work {
    Outside,
    Bore,
}

fn check(
    dialect: Dialect,
    text: &str,
    radius: f64,
    tip: u8,
    lines: (u32, u32),
    work: Work,
) -> Vec<Canon> {
    check_post(dialect, text, (radius, tip, false), lines, work)
}

fn check_post(
    dialect: Dialect,
    text: &str,
    (radius, tip, front): (f64, u8, bool),
    lines: (u32, u32),
    work: Work,
) -> Vec<Canon> {
    let (first_line, last_line) = lines;
    let comp = cnc_interpreter::check(dialect, text, setup_post(radius, tip, front))
        .unwrap_or_else(|e| panic!("{e}"));
    let plain_text = text
        .replace("G41", "")
        .replace("G42", "")
        .replace("G40", "");
    let plain = cnc_interpreter::check(dialect, &plain_text, setup(radius, tip))
        .unwrap_or_else(|e| panic!("{e}"));
    let inside = |cut: bool, line: u32| cut && line > first_line && line < last_line;
    let contour: Vec<El> = elements(&plain, HOME)
        .into_iter()
        .filter(|&(_, cut, line)| inside(cut, line))
        .map(|(e, _, _)| e)
        .collect();
    assert!(!contour.is_empty());
    let d = tip_vector(tip, radius);
    // The start-up and cancel moves are approach and retreat in the air; the rest cuts.
    let centre_path: Vec<[f64; 2]> = elements(&comp, HOME)
        .into_iter()
        .filter(|&(_, cut, line)| inside(cut, line))
        .flat_map(|(e, _, _)| samples(e, 0.05))
        .map(|p| [p[0] - d[0], p[1] - d[1]])
        .collect();
    // No gouge: the nose centre keeps at least R from every contour element.
    for p in &centre_path {
        for el in &contour {
            let dist = distance(*p, *el);
            assert!(
                dist > radius - 0.01,
                "nose centre {p:?} is {dist} from {el:?}"
            );
        }
    }
    // The nose stays out of the material: above an outside profile, below a bore, at every Z.
    let profile: Vec<[f64; 2]> = contour.iter().flat_map(|e| samples(*e, 0.05)).collect();
    for p in &centre_path {
        let near: Vec<f64> = profile
            .iter()
            .filter(|q| (q[0] - p[0]).abs() < 0.05)
            .map(|q| q[1])
            .collect();
        if near.is_empty() {
            continue;
        }
        match work {
            Work::Outside => {
                let top = near.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    p[1] > top - 0.01,
                    "nose centre {p:?} inside the part (profile r {top})"
                );
            }
            Work::Bore => {
                let bottom = near.iter().cloned().fold(f64::INFINITY, f64::min);
                assert!(
                    p[1] < bottom + 0.01,
                    "nose centre {p:?} in the wall (bore r {bottom})"
                );
            }
        }
    }
    // Contact: every contour element is touched by the nose somewhere.
    for el in &contour {
        let nearest = centre_path
            .iter()
            .map(|p| distance(*p, *el))
            .fold(f64::INFINITY, f64::min);
        assert!(
            (nearest - radius).abs() < 0.02,
            "{el:?} not touched: nearest centre {nearest}"
        );
    }
    comp
}

#[test]
fn fixture_053_outside_g42_tip_3() {
    let text = fixture("000", "053_tnrc_outer_G42.nc");
    // Listing lines: N0040 (start-up) is line 5, N0180 (cancel) line 19.
    check(Dialect::HuaxingLathe, &text, 1.0, 3, (5, 19), Work::Outside);
}

#[test]
fn fixture_058_outside_g42_tip_3_chapter_20() {
    let text = fixture("000", "058_ch20_ex4_tnrc_outer.nc");
    check(Dialect::HuaxingLathe, &text, 1.0, 3, (5, 19), Work::Outside);
}

#[test]
fn fixture_054_bore_g41_tip_2() {
    let text = fixture("000", "054_tnrc_inner_G41.nc");
    // N0040 (start-up) is line 5, N0140 (cancel) line 15.
    let cmds = check(Dialect::HuaxingLathe, &text, 2.0, 2, (5, 15), Work::Bore);
    // The bore diameter 50 is cut at the tip: with tip 2 the controlled point runs on the
    // programmed line of an axis-parallel bore.
    let on_bore = cmds.iter().any(|c| match &c.command {
        Command::Linear { end, .. } => (end[0] - 50.0).abs() < 1e-6 && c.line == 6,
        _ => false,
    });
    assert!(on_bore);
}

#[test]
fn fixture_059_same_bore_but_printed_without_a_program_end() {
    let text = fixture("000", "059_ch20_ex5_tnrc_inner.nc");
    // The Huaxing control ends a program at its last block; the cut is that of 054.
    check(Dialect::HuaxingLathe, &text, 2.0, 2, (5, 15), Work::Bore);
}

#[test]
fn fixture_002_021_gtc2e_g41_r3_centre_programmed() {
    let text = fixture("002", "021_g41_nose_radius_comp.nc");
    let n = |label: &str| text.lines().position(|l| l.starts_with(label)).unwrap() as u32 + 1;
    // G41 R3 on its own, the contour A-B-C-D-E, G40 on its own, then G0 U10 leaves it.
    let first = n("N0000");
    let last = n("N0060");
    // The GTC2E manual's machines have the turret in front.
    let comp =
        cnc_interpreter::check(Dialect::Gtc2eLathe, &text, setup_post(3.0, 0, true)).unwrap();
    // Convex arc B-C (G3 R15) runs at R18, concave C-D (G2 R30) at R27 (the manual's figures).
    let radii: Vec<f64> = elements(&comp, HOME)
        .iter()
        .filter_map(|(e, _, line)| match e {
            El::Arc(a, _, c, _) if *line > first && *line < last => {
                Some(((a[0] - c[0]).hypot(a[1] - c[1]) * 1000.0).round() / 1000.0)
            }
            _ => None,
        })
        .collect();
    assert!(radii.contains(&18.0) && radii.contains(&27.0), "{radii:?}");
    // Corner arcs of the nose radius at the outer corners B and E.
    assert!(
        radii.iter().filter(|r| **r == 3.0).count() >= 2,
        "{radii:?}"
    );
    // B-C, C-D and D-E are cut to size from outside (A-B shares its line with the move that
    // leaves the uncompensated start point A, so it is not in this check).
    check_post(
        Dialect::Gtc2eLathe,
        &text,
        (3.0, 0, true),
        (n("N0010"), last),
        Work::Outside,
    );
}

#[test]
fn compensation_errors_raise_the_manual_alarms() {
    let hx = |t: &str, r: f64| {
        cnc_interpreter::check(Dialect::HuaxingLathe, t, setup(r, 3)).unwrap_err()
    };
    // Start-up not on a G01 line (85), G00 while active (118), no radius (21), a concave
    // arc smaller than the nose (87), a cycle with compensation active (42).
    let e = hx("T1\nG0 X50 Z10\nG42 G00 X40 Z5\nM30\n", 1.0);
    assert_eq!((e.number, e.line), (85, 3), "{e}");
    let e = hx("T1\nG0 X50 Z10\nG42 G01 X40 Z5 F100\nG00 X60\nM30\n", 1.0);
    assert_eq!((e.number, e.line), (118, 4), "{e}");
    let e = hx("T1\nG0 X50 Z10\nG42 G01 X40 Z5 F100\nM30\n", 0.0);
    assert_eq!((e.number, e.line), (21, 3), "{e}");
    let e = hx(
        "T1\nG0 X50 Z10\nG42 G01 X40 Z5 F100\nG01 Z0\nG02 X40 Z-4 R2\nG01 Z-20\nG40 G01 X60\nM30\n",
        3.0,
    );
    assert_eq!(e.number, 87, "{e}");
    let e = hx(
        "T1\nG0 X50 Z10\nG42 G01 X40 Z5 F100\nG90 X30 Z-10 F100\nM30\n",
        1.0,
    );
    assert_eq!(e.number, 42, "{e}");
}

#[test]
fn fixture_032_g71_roughs_and_g70_finishes_the_compensated_contour() {
    let text = fixture("000", "032_g71_g70_tnrc_example4.nc");
    // Listing lines: N0030 (G71 P40 Q140) is line 4, N0040 (G41 start-up) 5, N0140 (G40) 15.
    // G41 on an outside contour: this example is drawn for a turret in front (§6.1: G41 is
    // left with the tool post in front, right with it behind), unlike §6.1.5's G42 examples.
    let comp = check_post(
        Dialect::HuaxingLathe,
        &text,
        (0.8, 3, true),
        (5, 15),
        Work::Outside,
    );
    // The roughing passes (on the G71 line) rough to the compensated contour plus the
    // allowance U0.2 W0.2, which shifts it +0.1 in radius and +0.2 in Z: on a wall facing −Z
    // (the groove's right side) that is 0.2 toward the wall (G71's rule, as for a sharp tool).
    let plain_text = text.replace("G41", "").replace("G40", "");
    let plain =
        cnc_interpreter::check(Dialect::HuaxingLathe, &plain_text, setup_post(0.8, 3, true))
            .unwrap();
    let contour: Vec<El> = elements(&plain, HOME)
        .into_iter()
        .filter(|&(_, cut, line)| cut && line > 5 && line < 15)
        .map(|(e, _, _)| e)
        .collect();
    let clearance = |cmds: &[Canon], d: [f64; 2]| {
        let mut closest = f64::INFINITY;
        for (e, cut, line) in elements(cmds, HOME) {
            if cut && line == 4 {
                for p in samples(e, 0.05) {
                    let c = [p[0] - d[0], p[1] - d[1]];
                    for el in &contour {
                        closest = closest.min(distance(c, *el));
                    }
                }
            }
        }
        closest
    };
    // So the nose keeps at least its radius less the W allowance from the contour.
    let nose = clearance(&comp, tip_vector(3, 0.8));
    assert!(
        nose > 0.8 - 0.2 - 0.01,
        "roughing nose comes within {nose} of the contour"
    );
}

/// The material of a turned part as its radius along Z (material inside), cut by a round
/// nose of radius `r` whose centre follows the path: each cut lowers the boundary to the
/// lower edge of the swept disc.
struct DiscStock {
    z0: f64,
    h: f64,
    v: Vec<f64>,
    r: f64,
}

impl DiscStock {
    fn new(z0: f64, z1: f64, radius: f64, nose: f64) -> DiscStock {
        let h = 0.005;
        DiscStock {
            z0,
            h,
            v: vec![radius; ((z1 - z0) / h).round() as usize + 1],
            r: nose,
        }
    }

    fn z(&self, i: usize) -> f64 {
        self.z0 + i as f64 * self.h
    }

    /// The lower edge of the disc centred at `c` (z, r) at each sample: (index, value).
    fn disc(&self, c: [f64; 2]) -> impl Iterator<Item = (usize, f64)> + '_ {
        let lo = (((c[0] - self.r - self.z0) / self.h).ceil().max(0.0)) as usize;
        let hi = ((c[0] + self.r - self.z0) / self.h).floor();
        let hi = if hi < 0.0 {
            0
        } else {
            (hi as usize + 1).min(self.v.len())
        };
        (lo..hi).map(move |i| {
            let dz = self.z(i) - c[0];
            (i, c[1] - (self.r * self.r - dz * dz).max(0.0).sqrt())
        })
    }

    /// The lower edge of the disc swept along `el`, exactly for lines (end discs and the
    /// offset line between them), every 1 µm of path for arcs.
    fn envelope(&self, el: El) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        match el {
            El::Line(a, b) => {
                out.extend(self.disc(a));
                out.extend(self.disc(b));
                let (dz, dr) = (b[0] - a[0], b[1] - a[1]);
                let l = dz.hypot(dr);
                if l > 1e-12 && dz.abs() > 1e-12 {
                    // The normal pointing toward the axis (its r part negative).
                    let mut n = [-dr / l, dz / l];
                    if n[1] > 0.0 {
                        n = [-n[0], -n[1]];
                    }
                    let (p, q) = (
                        [a[0] + self.r * n[0], a[1] + self.r * n[1]],
                        [b[0] + self.r * n[0], b[1] + self.r * n[1]],
                    );
                    let (lo, hi) = (p[0].min(q[0]), p[0].max(q[0]));
                    let i0 = ((lo - self.z0) / self.h).ceil().max(0.0) as usize;
                    let i1 = ((hi - self.z0) / self.h)
                        .floor()
                        .min(self.v.len() as f64 - 1.0);
                    let i1 = if i1 < 0.0 { 0 } else { i1 as usize + 1 };
                    for i in i0..i1 {
                        let z = self.z(i);
                        out.push((i, p[1] + (q[1] - p[1]) * (z - p[0]) / (q[0] - p[0])));
                    }
                }
            }
            El::Arc(..) => {
                for c in samples(el, 0.001) {
                    out.extend(self.disc(c));
                }
            }
        }
        out
    }

    /// Cuts along `el`; returns how deep it cut into the material.
    fn cut(&mut self, el: El) -> f64 {
        let mut deepest: f64 = 0.0;
        for (i, value) in self.envelope(el) {
            if value < self.v[i] {
                deepest = deepest.max(self.v[i] - value);
                self.v[i] = value;
            }
        }
        deepest
    }

    /// How deep a rapid along `el` would go into the material.
    fn intrusion(&self, el: El) -> f64 {
        self.envelope(el)
            .into_iter()
            .map(|(i, value)| self.v[i] - value)
            .fold(0.0, f64::max)
    }

    fn at(&self, z: f64) -> f64 {
        self.v[((z - self.z0) / self.h).round() as usize]
    }
}

#[test]
fn fixture_032_roughing_leaves_the_contour_plus_allowance_under_the_nose() {
    let text = fixture("000", "032_g71_g70_tnrc_example4.nc");
    let nose = 0.8;
    let comp =
        cnc_interpreter::check(Dialect::HuaxingLathe, &text, setup_post(nose, 3, true)).unwrap();
    // Blank: bar dia 85 over the contour's span Z35–Z140. The nose centre is the controlled
    // point less the tip vector.
    let d = tip_vector(3, nose);
    let mut stock = DiscStock::new(30.0, 145.0, 42.5, nose);
    let mut deepest: f64 = 0.0;
    for (el, cut, line) in elements(&comp, HOME) {
        if line != 4 {
            continue;
        }
        let moved = match el {
            El::Line(a, b) => El::Line([a[0] - d[0], a[1] - d[1]], [b[0] - d[0], b[1] - d[1]]),
            El::Arc(a, b, c, cw) => El::Arc(
                [a[0] - d[0], a[1] - d[1]],
                [b[0] - d[0], b[1] - d[1]],
                [c[0] - d[0], c[1] - d[1]],
                cw,
            ),
        };
        if cut {
            deepest = deepest.max(stock.cut(moved));
        } else {
            let into = stock.intrusion(moved);
            assert!(into < 1e-6, "line {line}: rapid {into} mm into the stock");
        }
    }
    // U2: no pass cuts deeper than 2 mm (radius).
    assert!(deepest <= 2.0 + 1e-6, "deepest cut {deepest}");
    // Material left: the contour moved by the allowance (U0.2 diameter = 0.1 radius, W0.2),
    // wherever the nose can reach it: away from the corners, where it leaves its radius, and
    // off the first and last elements, where the start-up (N0040) and the cancel (G40 in
    // N0140) bring the offset on and off as §6 defines.
    let (du, dw) = (0.2, 0.2);
    let corners = [
        [140.0, 80.0],
        [130.0, 40.0],
        [120.0, 40.0],
        [110.0, 60.0],
        [100.0, 60.0],
        [90.0, 50.0],
        [80.0, 50.0],
    ];
    let tail = [[60.0, 50.0], [50.0, 50.0], [40.0, 70.0], [35.0, 80.0]];
    let moved = |pts: &[[f64; 2]]| -> Vec<[f64; 2]> {
        pts.iter().map(|p| [p[0] + dw, p[1] + du]).collect()
    };
    let (head, tail) = (moved(&corners), moved(&tail));
    let vertices: Vec<f64> = head.iter().chain(&tail).map(|p| p[0]).collect();
    let mut checked = 0;
    let mut z = 40.2;
    while z < 130.2 {
        if vertices.iter().all(|v| (z - v).abs() > nose + 0.3) {
            // The arc G02 X50 Z60 R10 (front tool post: a groove dipping to dia 30).
            let want = if (60.0 + dw..=80.0 + dw).contains(&z) {
                25.0 + du / 2.0 - (100.0 - (z - 70.0 - dw).powi(2)).max(0.0).sqrt()
            } else {
                contour_at(&head, z)
                    .or_else(|| contour_at(&tail, z))
                    .expect("contour")
            };
            assert!(
                (stock.at(z) - want).abs() < 1e-6,
                "at Z{z:.3}: {} vs {want}",
                stock.at(z)
            );
            checked += 1;
        }
        z += 0.05;
    }
    assert!(checked > 1000, "{checked}");
}
