//! Single block at the drives (issue 48, D137): with the setpoint queue, motion computes a
//! queue's length ahead, so a single block decided there would stop a block or more later than
//! the one the operator saw running. The drives read the PLC's SBK themselves and stop at the
//! end of the block they play (where the setpoints' `line` changes), time-scaling the queued
//! path so that they arrive there at rest, within each axis's acceleration; a cycle start
//! (counted by motion) releases them into the next block. A block end too near to stop at is
//! passed, and the next one taken.

use std::collections::VecDeque;

use cnc_msgs::servo::{ServoSetpoint, MAX_AXES};

/// Share of an axis's acceleration the drives brake a block's end with: the rest is left to
/// the path's own acceleration (the realised change is checked besides, `time_scale::within`).
const BRAKE_SHARE: f64 = 0.5;

/// The drives' single block: the block end they head for, where they stand, what a cycle
/// start released.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct BlockStop {
    /// The block end the drives stop at (its index on the queued path: between the block's
    /// last setpoint and the next block's first, by `ServoSetpoint::block_start`), and the rate
    /// they may lose a tick on the way there.
    target: Option<(f64, f64)>,
    /// Standing at this block end, since motion's cycle starts counted so many.
    standing: Option<(f64, u32)>,
    /// The block end the last cycle start released the drives from.
    released: Option<f64>,
}

impl BlockStop {
    /// Standing at a block's end for single block.
    pub(crate) fn standing(&self) -> bool {
        self.standing.is_some()
    }

    /// Forgets everything (an episode ended: reset, emergency stop, a dry queue).
    pub(crate) fn clear(&mut self) {
        *self = BlockStop::default();
    }

    /// This tick's target from the PLC's single block and motion's cycle starts: standing, a
    /// cycle start releases; under single block the first block end the drives, at `index`
    /// going at `rate`, can still stop at.
    pub(crate) fn update(
        &mut self,
        single_block: bool,
        starts: u32,
        at: (f64, f64),
        queue: &VecDeque<ServoSetpoint>,
        limit: &[f64; MAX_AXES],
    ) {
        if let Some((end, since)) = self.standing {
            if starts != since {
                self.standing = None;
                self.released = Some(end);
            }
            return;
        }
        self.target = if single_block {
            self.first_reachable_end(at, queue, limit)
        } else {
            None
        };
    }

    fn first_reachable_end(
        &self,
        (index, rate): (f64, f64),
        queue: &VecDeque<ServoSetpoint>,
        limit: &[f64; MAX_AXES],
    ) -> Option<(f64, f64)> {
        let from = index.floor() as u64;
        let first = queue.iter().position(|s| s.tick >= from)?;
        let mut brake = 1.0f64;
        let mut scalable = true;
        for j in first..queue.len().saturating_sub(1) {
            let (a, b) = (&queue[j], &queue[j + 1]);
            brake = brake.min(BRAKE_SHARE * index_deceleration(a, b, limit));
            if a.tick > from {
                scalable &= is_scalable(a.scaling);
            }
            if a.line == 0 || b.line == 0 || a.line == b.line {
                continue;
            }
            // A share that is no number (motion sends 0–1) counts as the setpoint itself.
            let share = match b.block_start.is_finite() {
                true => b.block_start.clamp(0.0, 1.0),
                false => 1.0,
            };
            let end = a.tick as f64 + share;
            let released = self.released.is_some_and(|r| (r - end).abs() < 1e-9);
            if released || end < index - 1e-12 {
                continue;
            }
            let stops = index + travel((rate - brake).max(0.0), brake) <= end + 1e-9;
            // Spindle-locked and manual setpoints do not slow: only an end they reach at rest.
            if (scalable && stops) || at_rest(queue, a, b, limit) {
                return Some((end, brake));
            }
        }
        None
    }

    /// The rate for this tick: `proposed` (what feed hold and the overrides ask), unless the
    /// block end needs less; never more braking than `most` (the most that fits).
    pub(crate) fn rate(&self, index: f64, proposed: f64, most: impl FnOnce() -> f64) -> f64 {
        let Some((end, brake)) = self.target else {
            return proposed;
        };
        let allowed = approach(end - index, brake);
        if proposed <= allowed {
            proposed
        } else {
            allowed.max(most())
        }
    }

    /// After the tick's advance: arriving at the block end, the drives stand on it (the
    /// setpoint's index exactly, rate 0) until a cycle start counted past `starts`.
    pub(crate) fn arrive(&mut self, index: &mut f64, rate: &mut f64, starts: u32) {
        let Some((end, _)) = self.target else {
            return;
        };
        if (*index - end).abs() <= 1e-9 {
            *index = end;
            *rate = 0.0;
            self.standing = Some((end, starts));
            self.target = None;
        }
    }

    /// The block end the drives stop at, if one is set: a move that steps by whole setpoints
    /// (spindle-locked, manual) stops on it.
    pub(crate) fn end(&self) -> Option<f64> {
        self.target.map(|(end, _)| end)
    }
}

fn is_scalable(kind: u32) -> bool {
    matches!(
        kind,
        ServoSetpoint::SCALE_FEED | ServoSetpoint::SCALE_RAPID | ServoSetpoint::SCALE_WAIT
    )
}

/// How much rate a tick may lose between setpoints `a` and `b` with every axis's change of
/// speed within its limit (mm a tick²): the limit over the step (1 where nothing moves).
fn index_deceleration(a: &ServoSetpoint, b: &ServoSetpoint, limit: &[f64; MAX_AXES]) -> f64 {
    let mut brake = 1.0f64;
    for (i, l) in limit.iter().enumerate() {
        let step = (b.position[i] - a.position[i]).abs();
        if step > 0.0 {
            brake = brake.min(l / step);
        }
    }
    brake
}

/// The path stands at the block end between `a` and `b` as planned: the steps into and out
/// of `a` are within a tick's acceleration, so the drives stop there without braking.
fn at_rest(
    queue: &VecDeque<ServoSetpoint>,
    a: &ServoSetpoint,
    b: &ServoSetpoint,
    limit: &[f64; MAX_AXES],
) -> bool {
    let Some(before) = a.tick.checked_sub(1).and_then(|t| {
        let i = queue.binary_search_by_key(&t, |s| s.tick).ok()?;
        queue.get(i)
    }) else {
        return false;
    };
    (0..MAX_AXES).all(|i| {
        (a.position[i] - before.position[i]).abs() <= limit[i]
            && (b.position[i] - a.position[i]).abs() <= limit[i]
    })
}

/// Index travelled from rate `v` braking by `brake` a tick to a stop: v + (v − b) + ….
fn travel(v: f64, brake: f64) -> f64 {
    if v <= 0.0 || brake <= 0.0 {
        return if v > 0.0 { f64::INFINITY } else { 0.0 };
    }
    let n = (v / brake).floor();
    (n + 1.0) * v - brake * n * (n + 1.0) / 2.0
}

/// The highest rate (≤ 1) from which the drives, braking by `brake` a tick, stop within
/// `distance` of index, this tick's step included: on the stretch where the braking takes
/// n more ticks, travel is (n + 1) v − brake n (n + 1) / 2, solved for v.
fn approach(distance: f64, brake: f64) -> f64 {
    if distance <= 0.0 || brake <= 0.0 {
        return 0.0;
    }
    if travel(1.0, brake) <= distance {
        return 1.0;
    }
    let guess = ((2.0 * distance / brake).sqrt()).floor();
    for k in 0..5 {
        let n = (guess - 2.0).max(0.0) + f64::from(k);
        let v = (distance + brake * n * (n + 1.0) / 2.0) / (n + 1.0);
        if v >= n * brake - 1e-12 && v <= (n + 1.0) * brake + 1e-12 {
            return v.min(1.0);
        }
    }
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive_queue::SetpointQueue;
    use crate::time_scale::Scaling;
    use cnc_msgs::servo::BrakeTail;

    const LIMIT: f64 = 1500.0 * 0.004 * 0.004 * (1.0 + 1e-9);

    /// X at 0.4 mm a tick (100 mm/s, planned through every block end), a block every 40
    /// setpoints, each ending a quarter of the way to the next block's first setpoint: at
    /// indices 40.25, 80.25, 120.25, ….
    fn blocks(kind: u32) -> SetpointQueue {
        let mut q = SetpointQueue::new();
        q.set_limits(&[1500.0], 0.004);
        for t in 1..=400u64 {
            let mut s = ServoSetpoint {
                tick: t,
                axis_count: 1,
                enable: 1,
                scaling: kind,
                line: 1 + ((t - 1) / 40) as u32,
                block_start: 0.25,
                ..ServoSetpoint::default()
            };
            s.position[0] = 0.4 * (t - 1) as f64;
            q.push(s);
        }
        let mut tail = BrakeTail {
            first_tick: 401,
            len: 1,
            ..BrakeTail::default()
        };
        tail.position[0][0] = 0.4 * 400.0;
        q.set_tail(&tail);
        q
    }

    /// Plays until the drives stand at a block end (at most `ticks`); asserts no step in
    /// velocity; returns where they stand and the index.
    fn until_standing(q: &mut SetpointQueue, sc: &Scaling, xs: &mut Vec<f64>) -> (f64, f64) {
        for _ in 0..200 {
            let p = q.play(sc);
            let x = p.setpoint.position[0];
            if let [.., a, b] = xs[..] {
                let dv = (x - b) - (b - a);
                assert!(dv.abs() <= LIMIT, "a step in velocity: {dv}");
            }
            xs.push(x);
            if q.standing_at_block_end() {
                return (x, p.index);
            }
        }
        panic!("never stood at a block end");
    }

    /// Single block switched on in the middle of a block planned through: the drives stop
    /// at its end exactly, within the acceleration; a cycle start takes them through the next
    /// block to its end. Switched on too near an end to stop there, they stop at the next.
    #[test]
    fn the_drives_stop_at_the_end_of_the_block_they_play() {
        let mut q = blocks(ServoSetpoint::SCALE_FEED);
        let mut sc = Scaling::default();
        let mut xs = Vec::new();
        for _ in 0..12 {
            xs.push(q.play(&sc).setpoint.position[0]);
        }
        sc.single_block = true;
        let (x, index) = until_standing(&mut q, &sc, &mut xs);
        assert_eq!(index, 40.25, "the first block's end");
        assert!((x - 0.4 * 39.25).abs() < 1e-12, "{x}");
        for _ in 0..20 {
            let p = q.play(&sc);
            assert_eq!(p.setpoint.position[0], x, "stands until cycle start");
        }
        sc.starts = 1;
        let (x, index) = until_standing(&mut q, &sc, &mut xs);
        assert_eq!(index, 80.25, "the next block's end");
        assert!((x - 0.4 * 79.25).abs() < 1e-12, "{x}");
        // Too near: 3 setpoints before the end at 120, at full speed.
        let mut q = blocks(ServoSetpoint::SCALE_FEED);
        let mut sc = Scaling::default();
        let mut xs = Vec::new();
        for _ in 0..117 {
            xs.push(q.play(&sc).setpoint.position[0]);
        }
        sc.single_block = true;
        let (_, index) = until_standing(&mut q, &sc, &mut xs);
        assert_eq!(index, 160.25, "the block end after");
    }

    /// Spindle-locked setpoints are not slowed: the drives stop only where the path stands.
    #[test]
    fn fixed_setpoints_stop_only_where_the_path_stands() {
        let mut q = blocks(ServoSetpoint::SCALE_FIXED);
        let sc = Scaling {
            single_block: true,
            ..Scaling::default()
        };
        for _ in 0..200 {
            q.play(&sc);
            assert!(!q.standing_at_block_end(), "never in full motion");
        }
    }

    #[test]
    fn the_approach_arrives_exactly_by_whole_braking_steps() {
        assert!((travel(0.3, 0.1) - (0.3 + 0.2 + 0.1)).abs() < 1e-12);
        assert_eq!(
            approach(0.05, 0.1),
            0.05,
            "the last step is the rest of the way"
        );
        let v = approach(0.6, 0.1);
        assert!((travel(v, 0.1) - 0.6).abs() < 1e-12, "{v}");
        assert_eq!(approach(100.0, 0.1), 1.0);
        assert_eq!(approach(0.0, 0.1), 0.0);
        // Braking from 1 by 0.1 a tick, re-aimed every tick, lands on the end exactly.
        let (mut index, mut rate) = (0.0f64, 1.0f64);
        let end = 7.3;
        for _ in 0..100 {
            let v = approach(end - index, 0.1).min(rate + 0.1);
            assert!(
                rate - v <= 0.1 + 1e-9,
                "braking within the limit: {rate} → {v}"
            );
            rate = v;
            index += rate;
        }
        assert!((index - end).abs() < 1e-9, "{index}");
    }
}
