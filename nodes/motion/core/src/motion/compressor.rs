//! The compressor (COMPCAD, D119): while it is on, a run of short G1 lines whose end points
//! lie on one circle of a coordinate plane, within the compressor's tolerance, is cut as that
//! circle's arc: one smooth segment in place of a string of chords with a kink at every
//! point, as a CAD system's polyline of a curved surface asks for. The run stops at a corner
//! sharper than [`CORNER_LIMIT`] (the corner is kept), at a change of feed, at anything that
//! is not a line, and at the first point off the circle; a run that fits no arc is left to
//! the line merging of the look-ahead window.

use super::*;

/// A turn between two lines sharper than this stays a corner, degrees (the setting data's
/// limit angle, SD42470's default).
pub const CORNER_LIMIT: f64 = 36.0;

/// Fewest lines an arc is fitted to (three end points and the start make it certain).
const MIN_LINES: usize = 3;

/// The largest radius taken as an arc, mm: flatter runs are left to the line merging.
const MAX_RADIUS: f64 = 10_000.0;

impl Motion {
    /// The arc that the run of lines from `start` fits, with the feed (mm/s), the last block
    /// number and how many blocks it takes: `first` (a block already taken from the queue)
    /// and the lines at the queue's front after it.
    pub(super) fn compress(
        &self,
        start: &Point,
        first: Option<&Block>,
    ) -> Option<(Segment, f64, u64, usize)> {
        let n = self.cfg.axes.len().min(MAX_AXES);
        let feed_of = |b: &Block| match b.kind {
            Command::Linear { feed, .. } => Some(feed),
            _ => None,
        };
        let head = first.or_else(|| self.queue.front())?;
        let feed = feed_of(head)?;
        // On the stack: the servo thread allocates nothing per block.
        let mut points = [([0.0; MAX_AXES], 0u64); window::MAX_MERGE];
        let mut count = 0;
        let blocks = first.into_iter().chain(self.queue.iter());
        for b in blocks.take(window::MAX_MERGE) {
            if feed_of(b) != Some(feed) || self.check_block(&b.kind).is_err() {
                break;
            }
            let Some(end) = b.kind.end().filter(|e| self.check_limits(e).is_ok()) else {
                break;
            };
            if self.panel.single_block && b.line != head.line {
                break;
            }
            points[count] = (self.to_slide(end), b.seq);
            count += 1;
        }
        let tolerance = self.cfg.tolerance * window::MERGE_SHARE;
        let mut best = None;
        for k in MIN_LINES..=count {
            match fit(start, &points[..k], n, tolerance) {
                Some(seg) => best = Some((seg, k)),
                None => break,
            }
        }
        let (seg, k) = best?;
        let feed = self.feed_mm_per_min(feed).ok()? / 60.0;
        Some((seg, feed, points[k - 1].1, k))
    }
}

/// The arc from `start` through the `points` (each a line's end), or `None` when they do not
/// lie on one circle of a coordinate plane within `tolerance`, turn both ways, turn sharper
/// than the corner limit anywhere, or go round more than once.
fn fit(start: &Point, points: &[(Point, u64)], n: usize, tolerance: f64) -> Option<Segment> {
    let end = points.last()?.0;
    // The plane: the two axes that move; every other stays put.
    let mut moving = (0..n).filter(|&i| points.iter().any(|(p, _)| (p[i] - start[i]).abs() > 1e-9));
    let (Some(h), Some(v), None) = (moving.next(), moving.next(), moving.next()) else {
        return None;
    };
    let mid = points[points.len() / 2].0;
    let (ax, ay) = (start[h], start[v]);
    let (bx, by) = (mid[h], mid[v]);
    let (cx, cy) = (end[h], end[v]);
    let d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
    if d.abs() < 1e-12 {
        return None;
    }
    let a2 = ax * ax + ay * ay;
    let b2 = bx * bx + by * by;
    let c2 = cx * cx + cy * cy;
    let ux = (a2 * (by - cy) + b2 * (cy - ay) + c2 * (ay - by)) / d;
    let uy = (a2 * (cx - bx) + b2 * (ax - cx) + c2 * (bx - ax)) / d;
    let radius = (ax - ux).hypot(ay - uy);
    if !(radius.is_finite() && radius <= MAX_RADIUS) {
        return None;
    }
    // Every point on the circle, the path turning one way, each corner under the limit.
    let mut prev = (ax, ay);
    let mut prev_dir: Option<(f64, f64)> = None;
    let mut turn_sign = 0.0f64;
    let mut swept = 0.0;
    let limit = CORNER_LIMIT.to_radians();
    for (p, _) in points {
        let (x, y) = (p[h], p[v]);
        if ((x - ux).hypot(y - uy) - radius).abs() > tolerance {
            return None;
        }
        let dir = (x - prev.0, y - prev.1);
        let len = dir.0.hypot(dir.1);
        if len < 1e-9 {
            return None;
        }
        let a_prev = (prev.1 - uy).atan2(prev.0 - ux);
        let a_now = (y - uy).atan2(x - ux);
        let mut step = a_now - a_prev;
        if step > std::f64::consts::PI {
            step -= std::f64::consts::TAU;
        } else if step < -std::f64::consts::PI {
            step += std::f64::consts::TAU;
        }
        if turn_sign == 0.0 {
            turn_sign = step.signum();
        } else if step.signum() != turn_sign {
            return None;
        }
        swept += step.abs();
        if let Some(pd) = prev_dir {
            let cross = pd.0 * dir.1 - pd.1 * dir.0;
            let dot = pd.0 * dir.0 + pd.1 * dir.1;
            if cross.atan2(dot).abs() > limit {
                return None;
            }
        }
        prev_dir = Some(dir);
        prev = (x, y);
    }
    if swept >= std::f64::consts::TAU - 1e-6 {
        return None;
    }
    let mut center = *start;
    center[h] = ux;
    center[v] = uy;
    path::arc(start, &end, &center, (h, v), turn_sign < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, z: f64) -> Point {
        let mut p = [0.0; MAX_AXES];
        p[0] = x;
        p[2] = z;
        p
    }

    #[test]
    fn points_on_a_circle_fit_its_arc_and_a_corner_or_a_wobble_does_not() {
        // Radius 50 about X0 Z0 in the X–Z plane, from 90° down to 30°, coordinates rounded
        // to a micrometre as a CAD system writes them.
        let on = |deg: f64| {
            let r = deg.to_radians();
            let q = |v: f64| (v * 1000.0).round() / 1000.0;
            pt(q(50.0 * r.cos()), q(50.0 * r.sin()))
        };
        let start = on(90.0);
        let pts: Vec<(Point, u64)> = (1..=12).map(|k| (on(90.0 - 5.0 * k as f64), k)).collect();
        let seg = fit(&start, &pts, 3, 0.005).expect("an arc");
        let Segment::Arc { radius, sweep, .. } = seg else {
            panic!("{seg:?}");
        };
        // Three of the rounded points make the circle: within the rounding's reach of 50.
        assert!((radius - 50.0).abs() < 0.01, "{radius}");
        // Clockwise in X–Z (from +Z towards +X): 60° the other way round.
        assert!(
            (sweep.to_degrees() + 60.0).abs() < 0.01,
            "{}",
            sweep.to_degrees()
        );
        // A point 0.02 mm off the circle breaks it.
        let mut off = pts.clone();
        off[5].0[0] += 0.02;
        assert!(fit(&start, &off, 3, 0.005).is_none());
        // A straight run is no arc.
        let line: Vec<(Point, u64)> = (1..=5).map(|k| (pt(k as f64, 0.0), k)).collect();
        assert!(fit(&pt(0.0, 0.0), &line, 3, 0.005).is_none());
        // Points on a circle with a 60° step between chords keep their corners.
        let coarse: Vec<(Point, u64)> = (1..=3).map(|k| (on(90.0 - 60.0 * k as f64), k)).collect();
        assert!(fit(&start, &coarse, 3, 0.005).is_none());
    }
}
