//! Cycle move sequences as pure functions of their parameters: no interpreter state, so each
//! can be tested alone and shared by the front ends whose cycles cut the same way.

/// Peck drilling down a hole: the depth of one peck, the back-off after each peck, and
/// whether each peck leaves the hole (deep-hole pecking) instead of backing off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pecking {
    /// Depth of one peck; 0 drills straight to the bottom.
    pub peck: f64,
    /// Back-off after each peck.
    pub retract: f64,
    /// Out of the hole after every peck, then rapid back to `retract` short of the depth.
    pub deep_hole: bool,
}

/// The moves down a hole from level `top` by `depth` (signed), as (level, is-feed). No peck,
/// or backing off nothing, drills straight to the bottom.
pub fn pecks(top: f64, depth: f64, w: Pecking) -> Vec<(f64, bool)> {
    let (total, dir) = (depth.abs(), if depth < 0.0 { -1.0 } else { 1.0 });
    let level = |d: f64| top + dir * d;
    if w.peck <= 0.0 || (!w.deep_hole && w.retract <= 0.0) {
        return vec![(level(total), true)];
    }
    let mut moves = Vec::new();
    let mut done = 0.0;
    loop {
        done = (done + w.peck).min(total);
        moves.push((level(done), true));
        if done >= total - 1e-9 {
            return moves;
        }
        let back = (done - w.retract).max(0.0);
        if w.deep_hole {
            // Out of the hole, then rapid back to `retract` short of the depth reached.
            moves.push((top, false));
            if back > 0.0 {
                moves.push((level(back), false));
            }
        } else {
            moves.push((level(back), false));
        }
    }
}

/// The infeed depths of a multiple-pass thread: the first pass `first` deep, the n-th
/// `first·√n`, each at least `min_step` deeper than the one before (the first at least
/// `min_step` deep), up to the height less the
/// finish allowance; then `finish_passes` passes at the full `height`.
pub fn thread_depths(
    first: f64,
    height: f64,
    min_step: f64,
    allowance: f64,
    finish_passes: u32,
) -> Vec<f64> {
    let mut depths = Vec::new();
    let mut n = 1.0f64;
    let mut prev = 0.0f64;
    loop {
        let d = (first * n.sqrt()).max(prev + min_step);
        if d >= height - allowance - 1e-9 || depths.len() > 10_000 {
            depths.push(height - allowance);
            break;
        }
        depths.push(d);
        prev = d;
        n += 1.0;
    }
    for _ in 0..finish_passes.max(1) {
        depths.push(height);
    }
    depths
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(peck: f64, retract: f64, deep_hole: bool) -> Pecking {
        Pecking {
            peck,
            retract,
            deep_hole,
        }
    }

    #[test]
    fn high_speed_pecks_back_off_r_and_feed_q_plus_r() {
        let m = pecks(0.0, -10.0, words(4.0, 1.0, false));
        assert_eq!(
            m,
            [
                (-4.0, true),
                (-3.0, false),
                (-8.0, true),
                (-7.0, false),
                (-10.0, true)
            ]
        );
    }

    #[test]
    fn deep_hole_pecks_leave_the_hole_each_time() {
        let m = pecks(5.0, -6.0, words(2.5, 0.5, true));
        assert_eq!(
            m,
            [
                (2.5, true),
                (5.0, false),
                (3.0, false),
                (0.0, true),
                (5.0, false),
                (0.5, false),
                (-1.0, true)
            ]
        );
    }

    #[test]
    fn no_peck_or_no_back_off_drills_straight() {
        assert_eq!(pecks(0.0, -10.0, words(0.0, 1.0, false)), [(-10.0, true)]);
        assert_eq!(pecks(0.0, -10.0, words(3.0, 0.0, false)), [(-10.0, true)]);
        // A back-off larger than the depth reached stops at the start level.
        assert_eq!(
            pecks(0.0, -3.0, words(1.0, 5.0, false)),
            [
                (-1.0, true),
                (0.0, false),
                (-2.0, true),
                (0.0, false),
                (-3.0, true)
            ]
        );
    }

    #[test]
    fn thread_depths_grow_with_the_square_root_then_finish() {
        let d = thread_depths(1.0, 3.0, 0.1, 0.1, 2);
        // 1, √2, √3, 2, √5 … up to 2.9, then twice the full height.
        assert_eq!(d.len(), 11);
        assert!((d[1] - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(&d[8..], [2.9, 3.0, 3.0]);
        // The minimum step wins where √n grows slower.
        let d = thread_depths(0.1, 0.5, 0.2, 0.0, 1);
        assert_eq!(d, [0.2, 0.4, 0.5, 0.5]);
    }
}
