//! The stock a milling cycle's cutter sweeps, for the tests of the 802D's milling cycles
//! (`sinumerik_milling.rs`, issue 24 must-show 2): a height map over a grid, the cutter a
//! flat-ended cylinder, and the walls to check against as signed distances worked out from
//! the parameters alone (circles, rounded rectangles, slots, polygons). It knows nothing of
//! the cycles.
#![allow(dead_code)]

use std::f64::consts::TAU;

use cnc_interpreter::Command;

/// The stock the cutter sweeps: a height map over a grid, starting flat at `top`; the cutter
/// a flat-ended cylinder of its radius. Following the stream, every move is sampled at most
/// 0.1 mm apart; what it removes lowers the map. It knows nothing of the cycle.
pub struct Stock {
    pub origin: (f64, f64),
    pub step: f64,
    pub n: usize,
    pub h: Vec<f64>,
    pub top: f64,
    pub radius: f64,
    /// Rapid moves that removed material.
    pub rapid_cuts: usize,
    /// The wall to check against: the signed distance of a point from it (outside positive).
    pub wall: Box<dyn Fn((f64, f64)) -> f64>,
    /// How far beyond the wall a cut reached (the largest signed distance of a cutting
    /// position plus the cutter's radius): 0 when the cut touches the wall and stops there.
    pub reach: f64,
    /// Levels of moves that cut at a constant level.
    pub levels: Vec<f64>,
}

impl Stock {
    pub fn new(
        centre: (f64, f64),
        half: f64,
        top: f64,
        radius: f64,
        wall: impl Fn((f64, f64)) -> f64 + 'static,
    ) -> Stock {
        let step = 0.5;
        let n = (2.0 * half / step) as usize + 1;
        Stock {
            origin: (centre.0 - half, centre.1 - half),
            step,
            n,
            h: vec![top; n * n],
            top,
            radius,
            rapid_cuts: 0,
            wall: Box::new(wall),
            reach: f64::NEG_INFINITY,
            levels: Vec::new(),
        }
    }

    pub fn at(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.origin.0 + i as f64 * self.step,
            self.origin.1 + j as f64 * self.step,
        )
    }

    /// The cutter's end at `p`: true when it removed material.
    pub fn stamp(&mut self, p: (f64, f64, f64)) -> bool {
        if p.2 >= self.top - 1e-9 {
            return false;
        }
        self.reach = self.reach.max((self.wall)((p.0, p.1)) + self.radius);
        let k = (self.radius / self.step).ceil() as i64 + 1;
        let ci = ((p.0 - self.origin.0) / self.step).round() as i64;
        let cj = ((p.1 - self.origin.1) / self.step).round() as i64;
        let mut removed = false;
        for i in (ci - k).max(0)..=(ci + k).min(self.n as i64 - 1) {
            for j in (cj - k).max(0)..=(cj + k).min(self.n as i64 - 1) {
                let q = self.at(i as usize, j as usize);
                if (q.0 - p.0).hypot(q.1 - p.1) <= self.radius {
                    let cell = &mut self.h[i as usize * self.n + j as usize];
                    if p.2 < *cell - 1e-6 {
                        *cell = p.2;
                        removed = true;
                    }
                }
            }
        }
        removed
    }

    pub fn follow(&mut self, out: &[Command], start: [f64; 3]) {
        self.follow_axes(out, start, (0, 1, 2));
    }

    /// As [`Stock::follow`], the plane's axes and the infeed axis given as indexes into the
    /// end points (G19: Y, Z, X); `start` in that order.
    pub fn follow_axes(
        &mut self,
        out: &[Command],
        start: [f64; 3],
        (h, v, d): (usize, usize, usize),
    ) {
        let mut here = start;
        for c in out {
            let Some(e) = c.end() else { continue };
            let end = [e[h], e[v], e[d]];
            let samples: Vec<(f64, f64, f64)> = match c {
                Command::Arc {
                    center, clockwise, ..
                } => {
                    let (cx, cy) = (center[h], center[v]);
                    let r = (here[0] - cx).hypot(here[1] - cy);
                    let a0 = (here[1] - cy).atan2(here[0] - cx);
                    let a1 = (end[1] - cy).atan2(end[0] - cx);
                    let mut sweep = if *clockwise { a0 - a1 } else { a1 - a0 };
                    sweep = sweep.rem_euclid(TAU);
                    if sweep < 1e-9 {
                        sweep = TAU;
                    }
                    let n = ((r * sweep) / 0.1).ceil().max(1.0) as usize;
                    let s = if *clockwise { -1.0 } else { 1.0 };
                    (0..=n)
                        .map(|k| {
                            let t = k as f64 / n as f64;
                            let a = a0 + s * sweep * t;
                            (
                                cx + r * a.cos(),
                                cy + r * a.sin(),
                                here[2] + (end[2] - here[2]) * t,
                            )
                        })
                        .collect()
                }
                _ => {
                    let l = (end[0] - here[0])
                        .hypot(end[1] - here[1])
                        .hypot(end[2] - here[2]);
                    let n = (l / 0.1).ceil().max(1.0) as usize;
                    (0..=n)
                        .map(|k| {
                            let t = k as f64 / n as f64;
                            (
                                here[0] + (end[0] - here[0]) * t,
                                here[1] + (end[1] - here[1]) * t,
                                here[2] + (end[2] - here[2]) * t,
                            )
                        })
                        .collect()
                }
            };
            let rapid = matches!(c, Command::Rapid { .. });
            let mut removed = false;
            for s in samples {
                removed |= self.stamp(s);
            }
            if rapid && removed {
                self.rapid_cuts += 1;
            }
            if !rapid && removed && (end[2] - here[2]).abs() < 1e-9 {
                self.levels.push(end[2]);
            }
            here = end;
        }
    }

    /// Lowest and highest floor of the cells `inset` inside the wall, and the lowest cell.
    pub fn floor_within(&self, inset: f64) -> (f64, f64, f64) {
        let (mut lo, mut hi, mut min) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
        for i in 0..self.n {
            for j in 0..self.n {
                let q = self.at(i, j);
                let z = self.h[i * self.n + j];
                min = min.min(z);
                if (self.wall)(q) <= -inset {
                    lo = lo.min(z);
                    hi = hi.max(z);
                }
            }
        }
        (lo, hi, min)
    }
}

/// The signed distance from a circle's wall.
pub fn circle(c: (f64, f64), r: f64) -> impl Fn((f64, f64)) -> f64 {
    move |p| (p.0 - c.0).hypot(p.1 - c.1) - r
}

/// The signed distance from the wall of a rectangle about `c`, `a` × `b` from its centre,
/// corners rounded by `r`, its long side at `deg` to the 1st axis.
pub fn rounded_rect(c: (f64, f64), a: f64, b: f64, r: f64, deg: f64) -> impl Fn((f64, f64)) -> f64 {
    let (s, co) = deg.to_radians().sin_cos();
    move |p| {
        let (dx, dy) = (p.0 - c.0, p.1 - c.1);
        let (x, y) = (dx * co + dy * s, -dx * s + dy * co);
        let (qx, qy) = (x.abs() - (a - r), y.abs() - (b - r));
        qx.max(0.0).hypot(qy.max(0.0)) + qx.max(qy).min(0.0) - r
    }
}

impl Stock {
    /// The levels the cutter cut at, from `top` down, each at most `mid` below the one
    /// before: every infeed within MID.
    pub fn assert_infeeds_within(&self, top: f64, mid: f64) -> Vec<f64> {
        let mut levels = self.levels.clone();
        levels.sort_by(|a, b| b.total_cmp(a));
        levels.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let mut last = top;
        for l in &levels {
            assert!(
                last - l <= mid + 1e-9,
                "infeed {} > MID {mid}: {levels:?}",
                last - l
            );
            last = *l;
        }
        levels
    }
}

pub fn assert_within(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() <= 0.01, "{what}: {a} vs {b}");
}

impl Stock {
    /// Lowest and highest level of the cells where `pred` holds.
    pub fn floor_where(&self, pred: impl Fn((f64, f64)) -> bool) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..self.n {
            for j in 0..self.n {
                let q = self.at(i, j);
                if pred(q) {
                    let z = self.h[i * self.n + j];
                    lo = lo.min(z);
                    hi = hi.max(z);
                }
            }
        }
        (lo, hi)
    }
}

impl Stock {
    /// Only where `region` holds is there material; elsewhere air.
    pub fn only(mut self, region: impl Fn((f64, f64)) -> bool) -> Stock {
        for i in 0..self.n {
            for j in 0..self.n {
                if !region(self.at(i, j)) {
                    self.h[i * self.n + j] = f64::NEG_INFINITY;
                }
            }
        }
        self
    }
}

/// The union of stadiums (slots) on a circle: the signed distance from the nearest one's wall.
pub fn slots_wall(
    centre: (f64, f64),
    rad: f64,
    angles: Vec<f64>,
    half_len: f64,
    half_wid: f64,
) -> impl Fn((f64, f64)) -> f64 {
    let shapes: Vec<_> = angles
        .into_iter()
        .map(|a| {
            let (s, c) = a.to_radians().sin_cos();
            rounded_rect(
                (centre.0 + rad * c, centre.1 + rad * s),
                half_len,
                half_wid,
                half_wid,
                a,
            )
        })
        .collect();
    move |p| shapes.iter().map(|f| f(p)).fold(f64::INFINITY, f64::min)
}

/// The signed distance from the walls of slots bent along the circle `rad` about `c`, each
/// from `a` over `len` degrees, `half` either side of its middle arc.
pub fn arc_slots_wall(
    c: (f64, f64),
    rad: f64,
    starts: Vec<f64>,
    len: f64,
    half: f64,
) -> impl Fn((f64, f64)) -> f64 {
    move |p| {
        let (dx, dy) = (p.0 - c.0, p.1 - c.1);
        let r = dx.hypot(dy);
        let phi = dy.atan2(dx).to_degrees();
        starts
            .iter()
            .map(|a| {
                let along = (phi - a).rem_euclid(360.0);
                if along <= len {
                    (r - rad).abs() - half
                } else {
                    let end = |ang: f64| {
                        let (s, co) = ang.to_radians().sin_cos();
                        (p.0 - c.0 - rad * co).hypot(p.1 - c.1 - rad * s)
                    };
                    end(*a).min(end(a + len)) - half
                }
            })
            .fold(f64::INFINITY, f64::min)
    }
}

pub fn point_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    dist(p, (a.0 + t * dx, a.1 + t * dy))
}

/// Signed distance from a closed polygon (positive outside).
pub fn outside_of(poly: Vec<(f64, f64)>) -> impl Fn((f64, f64)) -> f64 {
    move |p| {
        let mut d = f64::INFINITY;
        let mut inside = false;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            d = d.min(point_segment(p, a, b));
            if (a.1 > p.1) != (b.1 > p.1) && p.0 < a.0 + (p.1 - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                inside = !inside;
            }
        }
        if inside {
            -d
        } else {
            d
        }
    }
}

pub fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// The contour of fixtures 107 and 108, worked out here: X150 Y160 → X230 with a 10 mm
/// chamfer → Y80 with a 10 mm chamfer → X125 → Y135 → clockwise R25 about X150 Y135 back to
/// X150 Y160; its corners, the arc every degree (0.001 mm from the true arc).
pub fn contour_107() -> Vec<(f64, f64)> {
    let leg = 10.0 / 2f64.sqrt();
    let mut pts = vec![
        (150.0, 160.0),
        (230.0 - leg, 160.0),
        (230.0, 160.0 - leg),
        (230.0, 80.0 + leg),
        (230.0 - leg, 80.0),
        (125.0, 80.0),
    ];
    // From (125, 135) round by the top to (150, 160), clockwise about (150, 135).
    pts.extend((0..90).map(|k| {
        let a = (180.0 - k as f64).to_radians();
        (150.0 + 25.0 * a.cos(), 135.0 + 25.0 * a.sin())
    }));
    pts
}

/// The stock of the POCKET3 examples' pocket (50 × 30 about X10 Y−5, turned 30°, corners R6,
/// cut with a tool of radius 5 from Z10): its wall `allowance` inside the drawn one, after
/// the moves of `out`.
pub fn turned_pocket(out: &[Command], allowance: f64) -> Stock {
    let a = allowance;
    let mut stock = Stock::new(
        (10.0, -5.0),
        35.0,
        0.0,
        5.0,
        rounded_rect((10.0, -5.0), 25.0 - a, 15.0 - a, 6.0 - a, 30.0),
    );
    stock.follow(out, [10.0, -5.0, 10.0]);
    stock
}
