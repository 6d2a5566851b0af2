//! Path geometry in slide coordinates: straight lines, arcs (with a helical part) and the
//! blend arcs the planner puts into corners.
//!
//! Points are fixed-size arrays so the servo thread allocates nothing while it interpolates.
//! Every segment is parameterised by its arc length `s`, from 0 to [`Segment::length`].

/// Most axes a machine may have: as many as a servo setpoint carries.
pub use cnc_msgs::servo::MAX_AXES;

pub type Point = [f64; MAX_AXES];

/// A piece of the tool path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    Line {
        start: Point,
        end: Point,
    },
    /// `point(θ) = center + radius·(cos(a0+θ)·e1 + sin(a0+θ)·e2) + θ/sweep·lift` for θ from 0
    /// to `sweep` (negative: turning from e2 towards e1). `lift` is the helical part.
    Arc {
        center: Point,
        e1: Point,
        e2: Point,
        radius: f64,
        a0: f64,
        sweep: f64,
        lift: Point,
    },
}

pub fn sub(a: &Point, b: &Point) -> Point {
    std::array::from_fn(|i| a[i] - b[i])
}

pub fn dot(a: &Point, b: &Point) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub fn norm(a: &Point) -> f64 {
    dot(a, a).sqrt()
}

fn scaled(a: &Point, k: f64) -> Point {
    a.map(|x| x * k)
}

fn add_scaled(a: &Point, b: &Point, k: f64) -> Point {
    std::array::from_fn(|i| a[i] + b[i] * k)
}

/// `a` as a unit vector (zero stays zero).
pub fn unit(a: &Point) -> Point {
    let n = norm(a);
    if n > 0.0 {
        scaled(a, 1.0 / n)
    } else {
        [0.0; MAX_AXES]
    }
}

impl Segment {
    pub fn length(&self) -> f64 {
        match self {
            Segment::Line { start, end } => norm(&sub(end, start)),
            Segment::Arc {
                radius,
                sweep,
                lift,
                ..
            } => (radius * sweep).hypot(norm(lift)),
        }
    }

    /// The point at arc length `s` (clamped to the segment).
    pub fn point(&self, s: f64) -> Point {
        let len = self.length();
        let f = if len > 0.0 {
            (s / len).clamp(0.0, 1.0)
        } else {
            1.0
        };
        match self {
            Segment::Line { start, end } => {
                if f >= 1.0 {
                    *end
                } else {
                    std::array::from_fn(|i| start[i] + (end[i] - start[i]) * f)
                }
            }
            Segment::Arc { sweep, .. } => self.arc_point(sweep * f),
        }
    }

    /// The arc's point `turned` radians (signed like the sweep) from its start.
    fn arc_point(&self, turned: f64) -> Point {
        let Segment::Arc {
            center,
            e1,
            e2,
            radius,
            a0,
            sweep,
            lift,
        } = self
        else {
            return self.end();
        };
        let f = if *sweep != 0.0 { turned / sweep } else { 1.0 };
        let (sin, cos) = (a0 + turned).sin_cos();
        std::array::from_fn(|i| center[i] + radius * (cos * e1[i] + sin * e2[i]) + f * lift[i])
    }

    pub fn start(&self) -> Point {
        self.point(0.0)
    }

    pub fn end(&self) -> Point {
        self.point(self.length())
    }

    /// Unit direction of travel at arc length `s`.
    pub fn tangent(&self, s: f64) -> Point {
        match self {
            Segment::Line { start, end } => unit(&sub(end, start)),
            Segment::Arc {
                e1,
                e2,
                radius,
                a0,
                sweep,
                lift,
                ..
            } => {
                let len = self.length();
                let f = if len > 0.0 {
                    (s / len).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let ang = a0 + sweep * f;
                let (sin, cos) = ang.sin_cos();
                // d/dθ of the point, times the sign of the sweep so it points along travel.
                let d: Point = std::array::from_fn(|i| {
                    radius * sweep * (-sin * e1[i] + cos * e2[i]) + lift[i]
                });
                unit(&d)
            }
        }
    }

    /// Radius of curvature in the arc's plane (infinite for a line).
    pub fn radius(&self) -> f64 {
        match self {
            Segment::Line { .. } => f64::INFINITY,
            Segment::Arc { radius, .. } => *radius,
        }
    }

    /// The part of the speed along the path that turns in the arc's plane (1 for a flat arc).
    pub fn planar_fraction(&self) -> f64 {
        match self {
            Segment::Line { .. } => 0.0,
            Segment::Arc { radius, sweep, .. } => {
                let len = self.length();
                if len > 0.0 {
                    (radius * sweep).abs() / len
                } else {
                    1.0
                }
            }
        }
    }

    /// How much each axis takes part: |direction component| for a line, and for an arc the
    /// largest share the axis can have anywhere on it (its plane span, or its helical part).
    pub fn axis_share(&self) -> Point {
        match self {
            Segment::Line { start, end } => unit(&sub(end, start)).map(f64::abs),
            Segment::Arc { e1, e2, lift, .. } => {
                let len = self.length();
                let k = self.planar_fraction();
                std::array::from_fn(|i| {
                    let plane = e1[i].hypot(e2[i]) * k;
                    let helix = if len > 0.0 { lift[i].abs() / len } else { 0.0 };
                    plane.max(helix).min(1.0)
                })
            }
        }
    }

    /// The line shortened at its start by `cut0` and at its end by `cut1` (lines only).
    pub fn trimmed(&self, cut0: f64, cut1: f64) -> Segment {
        match self {
            Segment::Line { start, end } => {
                let u = unit(&sub(end, start));
                Segment::Line {
                    start: add_scaled(start, &u, cut0),
                    end: add_scaled(end, &u, -cut1),
                }
            }
            arc => *arc,
        }
    }
}

/// The circular arc (helical if other axes move) from `start` to `end` around `center`,
/// turning in the plane of axes `(h, v)`: clockwise seen with h to the right and v up.
/// `end == start` in the plane is a full circle. None for a zero radius.
pub fn arc(
    start: &Point,
    end: &Point,
    center: &Point,
    (h, v): (usize, usize),
    clockwise: bool,
) -> Option<Segment> {
    use std::f64::consts::TAU;
    let radius = (start[h] - center[h]).hypot(start[v] - center[v]);
    if radius.is_nan() || radius <= 1e-9 {
        return None;
    }
    let a0 = (start[v] - center[v]).atan2(start[h] - center[h]);
    let a1 = (end[v] - center[v]).atan2(end[h] - center[h]);
    let moves = (end[h] - start[h]).abs() > 1e-9 || (end[v] - start[v]).abs() > 1e-9;
    let mut sweep = a1 - a0;
    if clockwise {
        while sweep >= -1e-12 {
            sweep -= TAU;
        }
        if sweep < -TAU + 1e-9 && moves {
            sweep += TAU;
        }
    } else {
        while sweep <= 1e-12 {
            sweep += TAU;
        }
        if sweep > TAU - 1e-9 && moves {
            sweep -= TAU;
        }
    }
    let mut e1 = [0.0; MAX_AXES];
    let mut e2 = [0.0; MAX_AXES];
    e1[h] = 1.0;
    e2[v] = 1.0;
    let mut c = *start;
    c[h] = center[h];
    c[v] = center[v];
    let mut lift = sub(end, start);
    lift[h] = 0.0;
    lift[v] = 0.0;
    Some(Segment::Arc {
        center: c,
        e1,
        e2,
        radius,
        a0,
        sweep,
        lift,
    })
}

/// Deflection angle between two unit directions (0 = straight on, π = reversal).
pub fn deflection(u1: &Point, u2: &Point) -> f64 {
    dot(u1, u2).clamp(-1.0, 1.0).acos()
}

/// The blend arc that rounds the corner at `vertex` between incoming direction `u1` and
/// outgoing `u2`, tangent to both lines at distance `tangent` from the vertex.
pub fn fillet(vertex: &Point, u1: &Point, u2: &Point, tangent: f64) -> Option<Segment> {
    let phi = deflection(u1, u2);
    if !(1e-12..std::f64::consts::PI - 1e-6).contains(&phi) || tangent <= 0.0 {
        return None;
    }
    let radius = tangent / (phi / 2.0).tan();
    // Normal in the corner's plane, pointing to the inside of the turn.
    let n = unit(&add_scaled(u2, u1, -dot(u1, u2)));
    let start = add_scaled(vertex, u1, -tangent);
    let center = add_scaled(&start, &n, radius);
    Some(Segment::Arc {
        center,
        e1: scaled(&n, -1.0),
        e2: *u1,
        radius,
        a0: 0.0,
        sweep: phi,
        lift: [0.0; MAX_AXES],
    })
}

/// A point from the first axes of a position (the rest zero).
pub fn point_from(p: &[f64]) -> Point {
    let mut out = [0.0; MAX_AXES];
    for (dst, src) in out.iter_mut().zip(p) {
        *dst = *src;
    }
    out
}

/// Distance from `p` to the segment (used to measure path deviation).
pub fn distance_to(seg: &Segment, p: &Point) -> f64 {
    match seg {
        Segment::Line { start, end } => {
            let d = sub(end, start);
            let len2 = dot(&d, &d);
            let t = if len2 > 0.0 {
                (dot(&sub(p, start), &d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            norm(&sub(p, &add_scaled(start, &d, t)))
        }
        Segment::Arc {
            center,
            e1,
            e2,
            a0,
            sweep,
            ..
        } => {
            // Angle of p in the plane, then the nearest point of the swept range (the
            // helical part follows the angle).
            let q = sub(p, center);
            let ang = dot(&q, e2).atan2(dot(&q, e1));
            let mut rel = ang - a0;
            let tau = std::f64::consts::TAU;
            if *sweep >= 0.0 {
                rel = rel.rem_euclid(tau);
                if rel > *sweep {
                    rel = if rel - sweep < tau - rel { *sweep } else { 0.0 };
                }
            } else {
                rel = -(-rel).rem_euclid(tau);
                if rel < *sweep {
                    rel = if sweep - rel < tau + rel { *sweep } else { 0.0 };
                }
            }
            norm(&sub(p, &seg.arc_point(rel)))
        }
    }
}

/// Largest distance of `points` from the chord `start`–`end`, if they lie along it in order
/// (each projects further along than the one before, inside the chord): how far replacing
/// the polyline through them by the chord moves the path.
pub fn chord_deviation(start: &Point, end: &Point, points: &[Point]) -> Option<f64> {
    let chord = sub(end, start);
    let len2 = dot(&chord, &chord);
    if len2 <= 1e-24 {
        return None;
    }
    let mut last = 0.0;
    let mut worst: f64 = 0.0;
    for p in points {
        let t = dot(&sub(p, start), &chord) / len2;
        if t <= last || t >= 1.0 {
            return None;
        }
        last = t;
        worst = worst.max(norm(&sub(p, &add_scaled(start, &chord, t))));
    }
    Some(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64) -> Point {
        let mut q = [0.0; MAX_AXES];
        q[0] = x;
        q[1] = y;
        q
    }

    #[test]
    fn fillet_is_tangent_to_both_lines_and_within_its_tolerance() {
        let v = p(100.0, 0.0);
        let (u1, u2) = (p(1.0, 0.0), p(0.0, 1.0));
        let f = fillet(&v, &u1, &u2, 0.5).unwrap();
        let (a, b) = (f.start(), f.end());
        assert!(norm(&sub(&a, &p(99.5, 0.0))) < 1e-12);
        assert!(norm(&sub(&b, &p(100.0, 0.5))) < 1e-12, "{b:?}");
        assert!(norm(&sub(&f.tangent(0.0), &u1)) < 1e-12);
        assert!(norm(&sub(&f.tangent(f.length()), &u2)) < 1e-9);
        // The arc passes the vertex at R(1/cos(φ/2) − 1).
        let mid = f.point(f.length() / 2.0);
        let r = 0.5;
        assert!((norm(&sub(&mid, &v)) - r * (2f64.sqrt() - 1.0)).abs() < 1e-12);
    }

    #[test]
    fn distance_to_an_arc_and_a_line() {
        let arc = Segment::Arc {
            center: p(0.0, 0.0),
            e1: p(1.0, 0.0),
            e2: p(0.0, 1.0),
            radius: 10.0,
            a0: 0.0,
            sweep: -std::f64::consts::FRAC_PI_2,
            lift: [0.0; MAX_AXES],
        };
        assert!((distance_to(&arc, &p(0.0, -11.0)) - 1.0).abs() < 1e-12);
        // Outside the swept quarter: the nearer end point.
        assert!((distance_to(&arc, &p(0.0, 12.0)) - (100.0f64 + 144.0).sqrt()).abs() < 1e-9);
        let line = Segment::Line {
            start: p(0.0, 0.0),
            end: p(10.0, 0.0),
        };
        assert!((distance_to(&line, &p(5.0, 2.0)) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn chord_deviation_measures_points_in_order_along_the_chord() {
        let p = |x: f64, y: f64| point_from(&[x, y]);
        let (a, b) = (p(0.0, 0.0), p(4.0, 0.0));
        assert_eq!(
            chord_deviation(&a, &b, &[p(1.0, 0.1), p(3.0, -0.2)]),
            Some(0.2)
        );
        // Out of order or beyond the end: not a chord of them.
        assert_eq!(chord_deviation(&a, &b, &[p(3.0, 0.0), p(1.0, 0.0)]), None);
        assert_eq!(chord_deviation(&a, &b, &[p(5.0, 0.0)]), None);
    }
}
