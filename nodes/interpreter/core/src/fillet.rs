//! The corner element between two contour elements (lines or arcs) meeting at a point: a
//! chamfer with equal legs, a chamfer of a given length, or a rounding tangent to both.
//! Pure plane geometry for the corner filter (`corner.rs`); legs are straight distances
//! from the corner, on an arc too.

use std::f64::consts::PI;

use crate::geometry::{Elem, Pt};

/// What the corner gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A chamfer whose ends lie this far from the corner on both elements.
    Legs(f64),
    /// A chamfer this long.
    Length(f64),
    /// A rounding of this radius.
    Round(f64),
}

/// The first element cut back, the corner element, and where the second now starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    pub first: Elem,
    pub corner: Elem,
    pub second_start: Pt,
}

type V = (f64, f64);

fn unit(v: V) -> Option<V> {
    let l = v.0.hypot(v.1);
    (l > 1e-12).then(|| (v.0 / l, v.1 / l))
}

fn cross(a: V, b: V) -> f64 {
    a.0 * b.1 - a.1 * b.0
}

fn dot(a: V, b: V) -> f64 {
    a.0 * b.0 + a.1 * b.1
}

fn sub(a: Pt, b: Pt) -> V {
    (a.z - b.z, a.r - b.r)
}

/// The direction of travel at a point of the element's circle or line.
fn tangent_at(e: &Elem, p: Pt) -> Option<V> {
    match *e {
        Elem::Line { a, b } => unit(sub(b, a)),
        Elem::Arc { c, ccw, .. } => {
            let (dz, dr) = sub(p, c);
            let t = if ccw { (-dr, dz) } else { (dr, -dz) };
            unit(t)
        }
    }
}

/// How far the element reaches from one end in a straight line, at most.
fn reach(e: &Elem) -> f64 {
    match *e {
        Elem::Line { a, b } => a.dist(b),
        Elem::Arc { a, c, .. } => {
            let sweep = e.sweep().abs();
            2.0 * a.dist(c) * (sweep.min(PI) / 2.0).sin()
        }
    }
}

/// The parameter of the point `d` away in a straight line from the element's end (`from_end`)
/// or start.
fn at_chord(e: &Elem, d: f64, from_end: bool) -> Option<f64> {
    if d > reach(e) + 1e-9 {
        return None;
    }
    let s = match *e {
        Elem::Line { a, b } => d / a.dist(b),
        Elem::Arc { a, c, .. } => {
            let r = a.dist(c);
            2.0 * (d / (2.0 * r)).min(1.0).asin() / e.sweep().abs()
        }
    };
    let s = s.min(1.0);
    Some(if from_end { 1.0 - s } else { s })
}

/// The parameter of point `p` (on the element's line or circle) along the element, if it
/// lies on it.
fn param_of(e: &Elem, p: Pt) -> Option<f64> {
    let s = match *e {
        Elem::Line { a, b } => {
            let d = sub(b, a);
            dot(sub(p, a), d) / dot(d, d)
        }
        Elem::Arc { a, c, .. } => {
            let sweep = e.sweep();
            let a0 = (a.r - c.r).atan2(a.z - c.z);
            let a1 = (p.r - c.r).atan2(p.z - c.z);
            let mut d = a1 - a0;
            let tau = 2.0 * PI;
            d = if sweep >= 0.0 {
                d.rem_euclid(tau)
            } else {
                -(-d).rem_euclid(tau)
            };
            // A point just before the start counts as the start.
            if (d.abs() - tau).abs() < 1e-9 {
                d = 0.0;
            }
            d / sweep
        }
    };
    (-1e-9..=1.0 + 1e-9)
        .contains(&s)
        .then_some(s.clamp(0.0, 1.0))
}

/// An element moved `r` to the side `side` (+1 left of travel, −1 right): a line through a
/// point with its direction, or a circle.
enum Offset {
    Line(Pt, V),
    Circle(Pt, f64),
}

fn offset(e: &Elem, side: f64, r: f64) -> Option<Offset> {
    match *e {
        Elem::Line { a, b } => {
            let t = unit(sub(b, a))?;
            let n = (-t.1, t.0);
            Some(Offset::Line(
                Pt::new(a.z + side * r * n.0, a.r + side * r * n.1),
                t,
            ))
        }
        Elem::Arc { a, c, ccw, .. } => {
            // Left of travel points to the centre on a counter-clockwise arc.
            let toward_centre = if ccw { side } else { -side };
            let rad = a.dist(c) - toward_centre * r;
            (rad > 1e-9).then_some(Offset::Circle(c, rad))
        }
    }
}

/// Where two offset curves meet.
fn meet(x: &Offset, y: &Offset) -> Vec<Pt> {
    match (x, y) {
        (Offset::Line(p, t), Offset::Line(q, u)) => {
            let det = cross(*t, *u);
            if det.abs() < 1e-12 {
                return Vec::new();
            }
            let k = cross(sub(*q, *p), *u) / det;
            vec![Pt::new(p.z + k * t.0, p.r + k * t.1)]
        }
        (Offset::Line(p, t), Offset::Circle(c, r)) | (Offset::Circle(c, r), Offset::Line(p, t)) => {
            // |p + k t − c|² = r²
            let w = sub(*p, *c);
            let b = dot(w, *t);
            let disc = b * b - (dot(w, w) - r * r);
            if disc < -1e-12 {
                return Vec::new();
            }
            let s = disc.max(0.0).sqrt();
            [-b - s, -b + s]
                .iter()
                .map(|k| Pt::new(p.z + k * t.0, p.r + k * t.1))
                .collect()
        }
        (Offset::Circle(c1, r1), Offset::Circle(c2, r2)) => {
            let d = c1.dist(*c2);
            if d < 1e-12 || d > r1 + r2 + 1e-9 || d < (r1 - r2).abs() - 1e-9 {
                return Vec::new();
            }
            let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
            let h = (r1 * r1 - a * a).max(0.0).sqrt();
            let (ez, er) = ((c2.z - c1.z) / d, (c2.r - c1.r) / d);
            let m = Pt::new(c1.z + a * ez, c1.r + a * er);
            vec![
                Pt::new(m.z - h * er, m.r + h * ez),
                Pt::new(m.z + h * er, m.r - h * ez),
            ]
        }
    }
}

/// The point of the element's line or circle nearest to `p`.
fn foot(e: &Elem, p: Pt) -> Pt {
    match *e {
        Elem::Line { a, b } => {
            let d = sub(b, a);
            let k = dot(sub(p, a), d) / dot(d, d);
            a.lerp(b, k)
        }
        Elem::Arc { a, c, .. } => {
            let r = a.dist(c);
            let (dz, dr) = sub(p, c);
            let l = dz.hypot(dr).max(1e-12);
            Pt::new(c.z + r * dz / l, c.r + r * dr / l)
        }
    }
}

/// The corner between `first` (ending at the corner) and `second` (starting there);
/// `Ok(None)` when they meet tangentially and there is no corner; an error says why the
/// shape does not fit.
pub fn corner(first: Elem, second: Elem, shape: Shape) -> Result<Option<Cut>, String> {
    let p = first.end();
    let (Some(t1), Some(t2)) = (tangent_at(&first, p), tangent_at(&second, p)) else {
        return Ok(None);
    };
    let turn = cross(t1, t2);
    if turn.abs() < 1e-9 && dot(t1, t2) > 0.0 {
        return Ok(None);
    }
    let legs = |d: f64| -> Option<(f64, f64)> {
        Some((at_chord(&first, d, true)?, at_chord(&second, d, false)?))
    };
    let chamfer = |s1: f64, s2: f64| Cut {
        first: first.piece(0.0, s1),
        corner: Elem::Line {
            a: first.at(s1),
            b: second.at(s2),
        },
        second_start: second.at(s2),
    };
    match shape {
        Shape::Legs(d) => {
            let (s1, s2) = legs(d).ok_or_else(|| {
                format!("the chamfer's legs of {d} mm are longer than the elements")
            })?;
            Ok(Some(chamfer(s1, s2)))
        }
        Shape::Length(len) => {
            // The chamfer grows with its legs: find the legs that make it `len` long.
            let most = reach(&first).min(reach(&second));
            let length = |d: f64| legs(d).map(|(s1, s2)| first.at(s1).dist(second.at(s2)));
            if length(most).is_none_or(|l| l < len - 1e-9) {
                return Err(format!("a chamfer {len} mm long does not fit the elements"));
            }
            let (mut lo, mut hi) = (0.0, most);
            for _ in 0..100 {
                let mid = (lo + hi) / 2.0;
                if length(mid).is_some_and(|l| l < len) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let (s1, s2) = legs(hi).ok_or("chamfer legs")?;
            Ok(Some(chamfer(s1, s2)))
        }
        Shape::Round(r) => {
            if turn.abs() < 1e-9 {
                return Err("the path reverses at the corner: no rounding fits".into());
            }
            let side = turn.signum();
            let (Some(o1), Some(o2)) = (offset(&first, side, r), offset(&second, side, r)) else {
                return Err(format!(
                    "a rounding of R{r} is larger than the arc it meets"
                ));
            };
            let centre = meet(&o1, &o2)
                .into_iter()
                .min_by(|x, y| x.dist(p).total_cmp(&y.dist(p)))
                .ok_or_else(|| format!("no rounding of R{r} touches both elements"))?;
            let (f1, f2) = (foot(&first, centre), foot(&second, centre));
            let (Some(s1), Some(s2)) = (param_of(&first, f1), param_of(&second, f2)) else {
                return Err(format!("a rounding of R{r} does not fit the elements"));
            };
            Ok(Some(Cut {
                first: first.piece(0.0, s1),
                corner: Elem::Arc {
                    a: f1,
                    b: f2,
                    c: centre,
                    ccw: side > 0.0,
                },
                second_start: second.at(s2),
            }))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn near(a: Pt, b: Pt) -> bool {
        a.dist(b) < 1e-7
    }

    fn line(a: (f64, f64), b: (f64, f64)) -> Elem {
        Elem::Line {
            a: Pt::new(a.0, a.1),
            b: Pt::new(b.0, b.1),
        }
    }

    #[test]
    fn lines_at_a_right_angle() {
        let (e1, e2) = (
            line((0.0, 0.0), (10.0, 0.0)),
            line((10.0, 0.0), (10.0, 10.0)),
        );
        let c = corner(e1, e2, Shape::Legs(2.0)).unwrap().unwrap();
        assert!(near(c.first.end(), Pt::new(8.0, 0.0)));
        assert!(near(c.second_start, Pt::new(10.0, 2.0)));
        let c = corner(e1, e2, Shape::Length(2.0 * 2f64.sqrt()))
            .unwrap()
            .unwrap();
        assert!(near(c.second_start, Pt::new(10.0, 2.0)));
        let c = corner(e1, e2, Shape::Round(3.0)).unwrap().unwrap();
        assert_eq!(
            c.corner,
            Elem::Arc {
                a: Pt::new(7.0, 0.0),
                b: Pt::new(10.0, 3.0),
                c: Pt::new(7.0, 3.0),
                ccw: true
            }
        );
        assert!(corner(e1, e2, Shape::Round(11.0)).is_err());
        // Straight on: no corner.
        let e3 = line((10.0, 0.0), (20.0, 0.0));
        assert_eq!(corner(e1, e3, Shape::Round(1.0)).unwrap(), None);
    }

    #[test]
    fn a_line_into_an_arc_and_an_arc_into_a_line() {
        // Along +X to (10, 0), then a counter-clockwise half circle about (10, 10), radius 10,
        // bulging to the right: a right turn at the corner.
        let e1 = line((0.0, 0.0), (10.0, 0.0));
        let e2 = Elem::Arc {
            a: Pt::new(10.0, 0.0),
            b: Pt::new(10.0, 20.0),
            c: Pt::new(10.0, 10.0),
            ccw: true,
        };
        // Tangent: the arc starts along +X.
        assert_eq!(corner(e1, e2, Shape::Round(2.0)).unwrap(), None);
        // A clockwise arc about (10, -10) turns right: the rounding's centre is 2 mm right of
        // the line and 12 mm from (10, −10).
        let e2 = Elem::Arc {
            a: Pt::new(10.0, 0.0),
            b: Pt::new(20.0, -10.0),
            c: Pt::new(10.0, -10.0),
            ccw: false,
        };
        let c = corner(e1, e2, Shape::Round(2.0)).unwrap();
        assert_eq!(
            c, None,
            "tangent again: the clockwise arc also starts along +X"
        );
        let e2 = Elem::Arc {
            a: Pt::new(10.0, 0.0),
            b: Pt::new(30.0, 0.0),
            c: Pt::new(20.0, 0.0),
            ccw: false,
        };
        // Into a clockwise half circle about (20, 0) starting upwards: a left turn of 90°.
        let c = corner(e1, e2, Shape::Round(2.0)).unwrap().unwrap();
        let Elem::Arc { c: m, ccw, a, b } = c.corner else {
            panic!()
        };
        assert!(ccw);
        assert!((m.r - 2.0).abs() < 1e-9, "2 mm left of the line");
        // Left of the arc's upward start is outside its circle: 10 + 2 from its centre.
        assert!((m.dist(Pt::new(20.0, 0.0)) - 12.0).abs() < 1e-9);
        assert!(near(a, Pt::new(m.z, 0.0)));
        assert!((b.dist(Pt::new(20.0, 0.0)) - 10.0).abs() < 1e-9);
        // And on: the arc ends going down at (30, 0), the line leaves along +X.
        let e3 = line((30.0, 0.0), (40.0, 0.0));
        let c = corner(e2, e3, Shape::Legs(3.0)).unwrap().unwrap();
        assert!(near(c.second_start, Pt::new(33.0, 0.0)));
        assert!((c.first.end().dist(Pt::new(30.0, 0.0)) - 3.0).abs() < 1e-9);
        assert!((c.first.end().dist(Pt::new(20.0, 0.0)) - 10.0).abs() < 1e-9);
    }
}
