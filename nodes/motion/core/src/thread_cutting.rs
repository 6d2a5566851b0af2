//! Thread cutting locked to the spindle encoder (decision D36, `000` §5.23).
//!
//! A thread chain is a run of consecutive thread blocks, cut without waiting for the index
//! pulse between them (`000` §5.23.1, continuous threading). Its parameter is the spindle's
//! angle, not time: progress along it, the *phase*, is counted in spindle revolutions, and each
//! piece takes `length of its long axis / lead` of them. The setpoint is a pure function of the
//! encoder, so a pass lands on the same helix whatever the spindle speed was.
//!
//! The run-in and run-out ramps are shaped in the angle domain too: the phase rate (phase per
//! spindle revolution) rises from 0 to 1 along a smoothstep over `ramp` revolutions, which
//! always covers exactly `ramp / 2` of phase. Starting the run-in `ramp / 2` revolutions before
//! the sync angle (index pulse plus the programmed shift) therefore puts the slide on the helix
//! at any speed, where LinuxCNC's time-domain run-in leaves it a speed-dependent angle behind.
//! Each axis also reads the encoder ahead by one servo period and its drive lag, so the slide,
//! not only its setpoint, is on the helix.

use std::collections::VecDeque;

use crate::path::{Point, MAX_AXES};
use crate::planner::AxisLimits;

/// One thread block in slide coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    pub start: Point,
    pub end: Point,
    /// Spindle revolutions the piece takes: length of its long axis / lead.
    pub revs: f64,
    pub seq: u64,
    pub line: u32,
}

impl Piece {
    /// Travel of axis `i` per spindle revolution, mm.
    fn per_rev(&self, i: usize) -> f64 {
        self.velocity(i).abs()
    }

    /// Signed travel of axis `i` per spindle revolution, mm.
    fn velocity(&self, i: usize) -> f64 {
        if self.revs > 0.0 {
            (self.end[i] - self.start[i]) / self.revs
        } else {
            0.0
        }
    }
}

/// A piece in the chain, with the corner blend at its start.
#[derive(Debug, Clone, Copy)]
struct Link {
    piece: Piece,
    /// Half-width of the blend at the corner with the previous piece, spindle revolutions
    /// (0: no corner).
    blend: f64,
    /// The previous piece's travel per revolution, per axis.
    incoming: Point,
}

/// Share of an axis's acceleration the run-in and run-out may use, and the share a corner
/// blend may use: the two may overlap on a run-out.
const RAMP_SHARE: f64 = 0.5;
const BLEND_SHARE: f64 = 0.5;

/// Phase covered after `u` (0..1) of a smoothstep ramp, in ramp lengths: ∫ 3u² − 2u³.
fn ramp_phase(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * u - 0.5 * u * u * u * u
}

/// The pieces of one chain and where the spindle must be to cut them.
#[derive(Clone)]
pub struct ThreadChain {
    pieces: VecDeque<Link>,
    limits: AxisLimits,
    /// Spindle speed at synchronisation, rev/s: corners are blended for it.
    omega: f64,
    /// Phase at the start of the front piece.
    front_phase: f64,
    /// Phase at the end of the last piece.
    total: f64,
    /// Spindle revolutions of each ramp.
    ramp: f64,
    /// Spindle revolution count at which the run-in starts; `None` until synchronised.
    begin: Option<f64>,
    /// The run-out has started: no more pieces may join.
    closed: bool,
}

impl ThreadChain {
    pub fn new(capacity: usize, limits: AxisLimits) -> Self {
        ThreadChain {
            pieces: VecDeque::with_capacity(capacity),
            limits,
            omega: 0.0,
            front_phase: 0.0,
            total: 0.0,
            ramp: 0.0,
            begin: None,
            closed: false,
        }
    }

    pub fn clear(&mut self) {
        self.pieces.clear();
        self.front_phase = 0.0;
        self.total = 0.0;
        self.ramp = 0.0;
        self.omega = 0.0;
        self.begin = None;
        self.closed = false;
    }

    /// Whether another piece may join: room in the window and the run-out not begun.
    pub fn accepts(&self) -> bool {
        !self.closed && self.pieces.len() < self.pieces.capacity()
    }

    pub fn push(&mut self, piece: Piece) {
        self.total += piece.revs;
        let mut incoming = [0.0; MAX_AXES];
        if let Some(prev) = self.pieces.back() {
            for (i, v) in incoming.iter_mut().enumerate() {
                *v = prev.piece.velocity(i);
            }
        }
        self.pieces.push_back(Link {
            piece,
            blend: 0.0,
            incoming,
        });
        if self.omega > 0.0 {
            let k = self.pieces.len() - 1;
            self.blend_corner(k);
        }
    }

    /// Sizes the blend at the start of piece `k`: the change of speed at the corner is spread
    /// over ±h revolutions so that no axis accelerates beyond its share, at most half of
    /// either piece (a parabolic blend; the corner is cut by |Δv|·h/4).
    fn blend_corner(&mut self, k: usize) {
        if k == 0 || k >= self.pieces.len() {
            return;
        }
        let before = self.pieces[k - 1].piece.revs;
        let link = &mut self.pieces[k];
        let mut h: f64 = 0.0;
        for i in 0..self.limits.axes.min(MAX_AXES) {
            let dv = (link.piece.velocity(i) - link.incoming[i]).abs();
            let a = BLEND_SHARE * self.limits.acceleration[i];
            if dv > 0.0 && a > 0.0 {
                h = h.max(dv * self.omega * self.omega / (2.0 * a));
            }
        }
        link.blend = h.min(before / 2.0).min(link.piece.revs / 2.0);
    }

    pub fn synchronised(&self) -> bool {
        self.begin.is_some()
    }

    /// Ramp length in spindle revolutions at `omega` rev/s: the smoothstep's peak
    /// acceleration (1.5 × travel per rev × ω² / ramp) and initial jerk (6 × travel per rev ×
    /// ω³ / ramp²) stay within every axis's limits.
    pub fn ramp_for(&self, omega: f64) -> f64 {
        let limits = &self.limits;
        let mut ramp: f64 = 0.0;
        for p in self.pieces.iter().map(|l| &l.piece) {
            for i in 0..limits.axes.min(MAX_AXES) {
                let d = p.per_rev(i);
                if d == 0.0 {
                    continue;
                }
                let a = RAMP_SHARE * limits.acceleration[i];
                if a > 0.0 {
                    ramp = ramp.max(1.5 * d * omega * omega / a);
                }
                if limits.jerk[i] > 0.0 {
                    ramp = ramp.max((6.0 * d * omega.powi(3) / limits.jerk[i]).sqrt());
                }
            }
        }
        ramp
    }

    /// Fastest axis speed the chain asks for at `omega` rev/s, as (axis, mm/s), if any
    /// axis's share exceeds its velocity limit.
    pub fn too_fast(&self, omega: f64) -> Option<(usize, f64)> {
        let limits = &self.limits;
        self.pieces.iter().find_map(|l| {
            (0..limits.axes.min(MAX_AXES)).find_map(|i| {
                let v = l.piece.per_rev(i) * omega;
                (v > limits.velocity[i] * (1.0 + 1e-9)).then_some((i, v))
            })
        })
    }

    /// Phase length of the pieces known so far.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Synchronises the chain: the slide is to pass the chain's start at the next spindle
    /// angle `shift` (degrees after the index, in the direction of rotation) that leaves room
    /// for the run-in. `revs` counts spindle revolutions, `angle` is where the spindle is now
    /// (degrees after the index), `lead_time` the largest drive lag the setpoints lead by, s.
    pub fn synchronise(
        &mut self,
        revs: f64,
        angle: f64,
        shift: f64,
        omega: f64,
        ramp: f64,
        lead_time: f64,
    ) {
        self.ramp = ramp;
        self.omega = omega;
        for k in 1..self.pieces.len() {
            self.blend_corner(k);
        }
        let run_in = ramp / 2.0 + omega * lead_time;
        // The first sync angle ahead, then as many whole turns later as the run-in needs.
        let first = revs + ((shift - angle) / 360.0).rem_euclid(1.0);
        let sync = first + (revs + run_in - first).max(0.0).ceil();
        self.begin = Some(sync - ramp / 2.0);
    }

    /// Phase reached `x` spindle revolutions after the run-in began.
    fn phase(&self, x: f64) -> f64 {
        let (r, total) = (self.ramp, self.total);
        if x <= 0.0 {
            0.0
        } else if x >= total + r {
            total
        } else if x > total {
            let w = x - total;
            total - r / 2.0 + w - r * ramp_phase(w / r)
        } else if x < r {
            r * ramp_phase(x / r)
        } else {
            x - r / 2.0
        }
    }

    /// Coordinate `axis` of the point at `phase`.
    fn coordinate(&self, phase: f64, axis: usize) -> f64 {
        let mut start = self.front_phase;
        for (k, l) in self.pieces.iter().enumerate() {
            let p = &l.piece;
            let end = start + p.revs;
            if phase <= end {
                // In the blend of the corner at either end of the piece?
                if l.blend > 0.0 && phase < start + l.blend {
                    return corner(
                        p.start[axis],
                        start,
                        l.blend,
                        l.incoming[axis],
                        p.velocity(axis),
                        phase,
                    );
                }
                if let Some(next) = self.pieces.get(k + 1) {
                    if next.blend > 0.0 && phase > end - next.blend {
                        return corner(
                            p.end[axis],
                            end,
                            next.blend,
                            p.velocity(axis),
                            next.piece.velocity(axis),
                            phase,
                        );
                    }
                }
                let f = if p.revs > 0.0 {
                    ((phase - start) / p.revs).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                return p.start[axis] + (p.end[axis] - p.start[axis]) * f;
            }
            start = end;
        }
        self.pieces.back().map_or(0.0, |l| l.piece.end[axis])
    }

    /// One servo tick: the setpoint of every axis at spindle count `revs` and speed `omega`
    /// rev/s, each axis `lead_time[i]` seconds ahead. Pieces every axis has left are reported in
    /// `finished`. True when the chain is cut.
    pub fn step(
        &mut self,
        revs: f64,
        omega: f64,
        lead_time: &[f64],
        out: &mut Point,
        finished: &mut Vec<u64>,
    ) -> bool {
        let Some(begin) = self.begin else {
            if let Some(p) = self.pieces.front() {
                *out = p.piece.start;
            }
            return false;
        };
        let x = revs - begin;
        let lead = lead_time.iter().copied().fold(0.0, f64::max);
        if x + omega * lead > self.total - self.ramp / 2.0 {
            // The run-out is near for the leading axis: the chain is what it is.
            self.closed = true;
        }
        let mut slowest = f64::INFINITY;
        for (i, l) in lead_time.iter().enumerate().take(MAX_AXES) {
            let phase = self.phase(x + omega * l);
            out[i] = self.coordinate(phase, i);
            slowest = slowest.min(phase);
        }
        while let Some(p) = self.pieces.front().map(|l| l.piece) {
            let end = self.front_phase + p.revs;
            if slowest < end - 1e-12 && slowest < self.total {
                break;
            }
            if self.pieces.len() == 1 && slowest < self.total {
                break;
            }
            finished.push(p.seq);
            self.front_phase = end;
            if self.pieces.len() == 1 {
                *out = p.end;
                self.pieces.pop_front();
                return true;
            }
            self.pieces.pop_front();
        }
        false
    }

    /// End of the last piece, if any.
    pub fn last_end(&self) -> Option<Point> {
        self.pieces.back().map(|l| l.piece.end)
    }

    /// Line of the piece being cut.
    pub fn line(&self) -> Option<u32> {
        self.pieces.front().map(|l| l.piece.line)
    }
}

/// A parabolic blend through the corner at `at` (coordinate) and `phase0`: the travel per
/// revolution goes linearly from `v_in` to `v_out` over `phase0 ± h`.
fn corner(at: f64, phase0: f64, h: f64, v_in: f64, v_out: f64, phase: f64) -> f64 {
    let d = phase - phase0;
    at + v_in * d + (v_out - v_in) * (d + h).powi(2) / (4.0 * h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain() -> ThreadChain {
        ThreadChain::new(
            4,
            AxisLimits {
                velocity: [1e6; MAX_AXES],
                acceleration: [1e6; MAX_AXES],
                jerk: [1e9; MAX_AXES],
                axes: 2,
            },
        )
    }

    fn piece(z0: f64, z1: f64, lead: f64, seq: u64) -> Piece {
        let mut start = [0.0; MAX_AXES];
        let mut end = [0.0; MAX_AXES];
        start[1] = z0;
        end[1] = z1;
        Piece {
            start,
            end,
            revs: (z1 - z0).abs() / lead,
            seq,
            line: seq as u32,
        }
    }

    #[test]
    fn the_run_in_covers_half_its_length_at_any_speed() {
        let mut c = chain();
        c.push(piece(0.0, -30.0, 2.0, 1));
        c.ramp = 3.0;
        // Ramp up over 3 revs covers 1.5 revs of phase, then the phase runs 1:1.
        assert!((c.phase(3.0) - 1.5).abs() < 1e-12);
        assert!((c.phase(7.0) - 5.5).abs() < 1e-12);
        // Continuous phase rate through the ramps.
        for x in [0.5, 2.9, 3.1, 14.9, 15.2, 17.5] {
            let rate = (c.phase(x + 1e-6) - c.phase(x - 1e-6)) / 2e-6;
            assert!((0.0..=1.0 + 1e-6).contains(&rate), "rate {rate} at {x}");
        }
        // The run-out ends on the end with rate 0.
        assert_eq!(c.phase(18.0), 15.0);
        assert!((c.phase(18.0) - c.phase(17.999)).abs() < 1e-6);
    }

    #[test]
    fn the_slide_passes_the_start_at_the_sync_angle_whatever_the_speed() {
        for (omega, ramp) in [(5.0, 1.0), (20.0, 4.0)] {
            let mut c = chain();
            c.push(piece(0.0, -30.0, 2.0, 1));
            // Spindle at 100.25 revs (90° after index); sync 30° after index.
            c.synchronise(100.25, 90.0, 30.0, omega, ramp, 0.0);
            let mut out = [0.0; MAX_AXES];
            let mut done = Vec::new();
            // In the locked part, z = -2 × (revs − sync); sync ≡ 30° mod 360.
            let revs = 100.25 + ramp + 3.0;
            c.step(revs, omega, &[0.0, 0.0], &mut out, &mut done);
            let sync = revs + out[1] / 2.0;
            assert!(
                ((sync * 360.0).rem_euclid(360.0) - 30.0).abs() < 1e-9,
                "{sync}"
            );
            assert!(sync - ramp / 2.0 >= 100.25);
        }
    }

    #[test]
    fn pieces_finish_in_order_and_the_chain_ends_on_the_last_end() {
        let mut c = chain();
        c.push(piece(0.0, -10.0, 2.0, 1));
        c.push(piece(-10.0, -12.0, 1.0, 2));
        c.synchronise(0.0, 0.0, 0.0, 10.0, 1.0, 0.0);
        let mut out = [0.0; MAX_AXES];
        let mut done = Vec::new();
        let mut revs = 0.0;
        while !c.step(revs, 10.0, &[0.0, 0.0], &mut out, &mut done) {
            revs += 0.01;
            assert!(revs < 20.0);
        }
        assert_eq!(done, vec![1, 2]);
        assert_eq!(out[1], -12.0);
    }
}
