//! Plane geometry of the lathe's ZX plane, shared by arcs, cycles and the stock model.
//!
//! Points are `(z, r)` with `r` the radius (half the programmed X diameter), seen with Z to the
//! right and X up (decision D3). Arcs turn counter-clockwise or clockwise in that view.

use std::f64::consts::TAU;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pt {
    pub z: f64,
    pub r: f64,
}

impl Pt {
    pub fn new(z: f64, r: f64) -> Pt {
        Pt { z, r }
    }
    pub fn dist(self, o: Pt) -> f64 {
        ((self.z - o.z).powi(2) + (self.r - o.r).powi(2)).sqrt()
    }
    pub fn lerp(self, o: Pt, s: f64) -> Pt {
        Pt::new(self.z + (o.z - self.z) * s, self.r + (o.r - self.r) * s)
    }
}

/// A contour element: a line, or an arc around `c` (`ccw` in the Z-right, X-up view).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Elem {
    Line { a: Pt, b: Pt },
    Arc { a: Pt, b: Pt, c: Pt, ccw: bool },
}

impl Elem {
    pub fn start(&self) -> Pt {
        match *self {
            Elem::Line { a, .. } | Elem::Arc { a, .. } => a,
        }
    }
    pub fn end(&self) -> Pt {
        match *self {
            Elem::Line { b, .. } | Elem::Arc { b, .. } => b,
        }
    }

    /// Signed sweep of an arc in radians (positive counter-clockwise); a full circle when the
    /// end equals the start.
    pub fn sweep(&self) -> f64 {
        match *self {
            Elem::Line { .. } => 0.0,
            Elem::Arc { a, b, c, ccw } => arc_sweep(a, b, c, ccw),
        }
    }

    /// The point at parameter `s` in `[0, 1]` along the element.
    pub fn at(&self, s: f64) -> Pt {
        match *self {
            Elem::Line { a, b } => a.lerp(b, s),
            Elem::Arc { a, c, .. } => {
                let r = a.dist(c);
                let a0 = (a.r - c.r).atan2(a.z - c.z);
                let ang = a0 + self.sweep() * s;
                Pt::new(c.z + r * ang.cos(), c.r + r * ang.sin())
            }
        }
    }

    /// The piece between parameters `s0` and `s1`.
    pub fn piece(&self, s0: f64, s1: f64) -> Elem {
        match *self {
            Elem::Line { .. } => Elem::Line {
                a: self.at(s0),
                b: self.at(s1),
            },
            Elem::Arc { c, ccw, .. } => Elem::Arc {
                a: self.at(s0),
                b: self.at(s1),
                c,
                ccw,
            },
        }
    }

    /// Parameters in `(0, 1)` where the element crosses `r == level` (or `z == level` when
    /// `along_z` is false).
    pub fn crossings(&self, level: f64, radial: bool) -> Vec<f64> {
        let coord = |p: Pt| if radial { p.r } else { p.z };
        let mut out = Vec::new();
        match *self {
            Elem::Line { a, b } => {
                let (da, db) = (coord(a) - level, coord(b) - level);
                if (da < 0.0) != (db < 0.0) && (da - db).abs() > 1e-12 {
                    out.push(da / (da - db));
                }
            }
            Elem::Arc { a, c, .. } => {
                let r = a.dist(c);
                let off = level - coord(c);
                if off.abs() < r {
                    let a0 = (a.r - c.r).atan2(a.z - c.z);
                    let sweep = self.sweep();
                    let base = if radial {
                        (off / r).asin()
                    } else {
                        (off / r).acos()
                    };
                    let sols = if radial {
                        [base, std::f64::consts::PI - base]
                    } else {
                        [base, -base]
                    };
                    for ang in sols {
                        let mut d = ang - a0;
                        if sweep >= 0.0 {
                            d = d.rem_euclid(TAU);
                        } else {
                            d = -(-d).rem_euclid(TAU);
                        }
                        let s = d / sweep;
                        if s > 1e-12 && s < 1.0 - 1e-12 {
                            out.push(s);
                        }
                    }
                }
            }
        }
        out.sort_by(f64::total_cmp);
        out.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
        out
    }

    /// Smallest and largest value of `r` (or `z`) on the element.
    pub fn extent(&self, radial: bool) -> (f64, f64) {
        let coord = |p: Pt| if radial { p.r } else { p.z };
        let (mut lo, mut hi) = (
            coord(self.start()).min(coord(self.end())),
            coord(self.start()).max(coord(self.end())),
        );
        if let Elem::Arc { a, c, .. } = *self {
            let r = a.dist(c);
            let a0 = (a.r - c.r).atan2(a.z - c.z);
            let sweep = self.sweep();
            for k in 0..4 {
                let ang = k as f64 * TAU / 4.0;
                let mut d = ang - a0;
                d = if sweep >= 0.0 {
                    d.rem_euclid(TAU)
                } else {
                    -(-d).rem_euclid(TAU)
                };
                if d / sweep > 0.0 && d / sweep < 1.0 {
                    let p = Pt::new(c.z + r * ang.cos(), c.r + r * ang.sin());
                    lo = lo.min(coord(p));
                    hi = hi.max(coord(p));
                }
            }
        }
        (lo, hi)
    }

    /// The element shifted by `(dz, dr)`.
    pub fn shifted(&self, dz: f64, dr: f64) -> Elem {
        let s = |p: Pt| Pt::new(p.z + dz, p.r + dr);
        match *self {
            Elem::Line { a, b } => Elem::Line { a: s(a), b: s(b) },
            Elem::Arc { a, b, c, ccw } => Elem::Arc {
                a: s(a),
                b: s(b),
                c: s(c),
                ccw,
            },
        }
    }
}

pub fn arc_sweep(a: Pt, b: Pt, c: Pt, ccw: bool) -> f64 {
    let a0 = (a.r - c.r).atan2(a.z - c.z);
    let a1 = (b.r - c.r).atan2(b.z - c.z);
    let mut s = a1 - a0;
    let full = a.dist(b) < 1e-9;
    if ccw {
        while s <= 1e-12 {
            s += TAU;
        }
        if s > TAU - 1e-9 && !full {
            s -= TAU;
        }
    } else {
        while s >= -1e-12 {
            s -= TAU;
        }
        if s < -TAU + 1e-9 && !full {
            s += TAU;
        }
    }
    s
}

/// Why an arc cannot be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArcError {
    /// R smaller than half the chord, or a full circle with R.
    RadiusTooSmall,
    /// The end point is not on the circle given by I/K.
    EndNotOnCircle,
    /// Three points on a line.
    Collinear,
}

/// Tolerance for "the end point lies on the arc", mm.
pub const ARC_TOLERANCE: f64 = 0.005;

/// Centre of an arc from `a` to `b` with radius `r` (negative: more than 180°).
pub fn center_from_radius(a: Pt, b: Pt, r: f64, ccw: bool) -> Result<Pt, ArcError> {
    let chord = a.dist(b);
    if chord < 1e-9 {
        return Err(ArcError::RadiusTooSmall);
    }
    let half = chord / 2.0;
    if r.abs() + 1e-9 < half {
        return Err(ArcError::RadiusTooSmall);
    }
    let h = (r * r - half * half).max(0.0).sqrt();
    let (dz, dr) = (b.z - a.z, b.r - a.r);
    // Left of the chord direction.
    let (lz, lr) = (-dr / chord, dz / chord);
    // CCW minor arc: centre on the left; CW: right; R < 0 (more than 180°) flips it.
    let side = if ccw { 1.0 } else { -1.0 } * r.signum();
    Ok(Pt::new(
        a.z + dz / 2.0 + side * h * lz,
        a.r + dr / 2.0 + side * h * lr,
    ))
}

/// Checks an I/K centre: the end must lie on the circle within [`ARC_TOLERANCE`].
pub fn check_center(a: Pt, b: Pt, c: Pt) -> Result<Pt, ArcError> {
    let (ra, rb) = (a.dist(c), b.dist(c));
    if ra < ARC_TOLERANCE || (ra - rb).abs() > ARC_TOLERANCE {
        return Err(ArcError::EndNotOnCircle);
    }
    Ok(c)
}

/// Circle through three points and the turning sense from `a` via `m` to `b`.
pub fn three_point(a: Pt, m: Pt, b: Pt) -> Result<(Pt, bool), ArcError> {
    let d = 2.0 * (a.z * (m.r - b.r) + m.z * (b.r - a.r) + b.z * (a.r - m.r));
    if d.abs() < 1e-9 || a.dist(b) < 1e-9 {
        return Err(ArcError::Collinear);
    }
    let sq = |p: Pt| p.z * p.z + p.r * p.r;
    let cz = (sq(a) * (m.r - b.r) + sq(m) * (b.r - a.r) + sq(b) * (a.r - m.r)) / d;
    let cr = (sq(a) * (b.z - m.z) + sq(m) * (a.z - b.z) + sq(b) * (m.z - a.z)) / d;
    // Counter-clockwise when the turn a → m → b is to the left.
    let cross = (m.z - a.z) * (b.r - m.r) - (m.r - a.r) * (b.z - m.z);
    Ok((Pt::new(cz, cr), cross > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_crossings_and_extent() {
        // Upper half circle of radius 10 around (0,0), from (10,0) ccw to (-10,0).
        let e = Elem::Arc {
            a: Pt::new(10.0, 0.0),
            b: Pt::new(-10.0, 0.0),
            c: Pt::new(0.0, 0.0),
            ccw: true,
        };
        let s = e.crossings(5.0, true);
        assert_eq!(s.len(), 2);
        for s in s {
            assert!((e.at(s).r - 5.0).abs() < 1e-9);
        }
        let (lo, hi) = e.extent(true);
        assert!((lo - 0.0).abs() < 1e-9 && (hi - 10.0).abs() < 1e-9);
        let (c, ccw) =
            three_point(Pt::new(10.0, 0.0), Pt::new(0.0, 10.0), Pt::new(-10.0, 0.0)).unwrap();
        assert!(c.dist(Pt::new(0.0, 0.0)) < 1e-9 && ccw);
    }
}
