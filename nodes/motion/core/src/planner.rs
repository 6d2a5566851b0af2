//! Look-ahead path planner: a window of path segments, the speed each may be entered at, and
//! the servo-tick step along them.
//!
//! Blocks are appended as they arrive. A corner between two lines is rounded by a blend arc
//! that stays within the path tolerance (G64) and takes at most half of either line, so chords
//! of a curve become that curve; G09/G61 corners and corners that cannot be blended are passed
//! at rest. A backward pass gives each segment the highest entry speed from which everything
//! after it can still be met, assuming the window ends at rest; the [`Mover`] then picks each
//! tick's speed online, so feed hold and newly arrived blocks need no re-planning.

use std::collections::VecDeque;

use crate::path::{deflection, fillet, Point, Segment};
use crate::profile::{stop_distance, Ahead, Limits, Mover, Shape};

/// Share of an axis's acceleration that turning (centripetal acceleration) may take on an arc;
/// the rest is left for speeding up and slowing down along it.
const CENTRIPETAL_SHARE: f64 = 0.8;
/// Deflection below which two segments are taken as tangent (rad).
const TANGENT: f64 = 1e-3;
/// Highest feed override (`000` §7.3: 150 %). Segments are planned for it, so turning the
/// override up needs no re-planning; each tick caps the speed at feed × override.
pub const MAX_FEED_OVERRIDE: f64 = 1.5;

/// Per-axis limits of slide travel, mm/s, mm/s², mm/s³.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLimits {
    pub velocity: Point,
    pub acceleration: Point,
    pub jerk: Point,
    pub axes: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerConfig {
    pub limits: AxisLimits,
    pub shape: Shape,
    pub period: f64,
    /// Largest distance a blended corner may leave the programmed path, mm.
    pub tolerance: f64,
    /// Blocks the planner looks ahead.
    pub lookahead: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Planned {
    seg: Segment,
    length: f64,
    seq: u64,
    line: u32,
    /// Programmed feed, mm/s.
    feed: f64,
    /// Speed limit from the axes and the curvature, and the feed at the highest override.
    vmax: f64,
    accel: f64,
    jerk: f64,
    /// Corner limit at the start, and the entry speed after the backward pass.
    entry_limit: f64,
    entry: f64,
    /// A line as programmed (before blending), for the half-length rule; 0 for others.
    programmed_length: f64,
    /// Blend corners at this segment's end (G64); false under G09/G61.
    blend_end: bool,
    /// How far the segment already leaves the programmed path (merged lines), mm: a blend at
    /// its ends may use only the rest of the tolerance.
    deviation: f64,
    /// The segment that stands for its block in the look-ahead count (not a blend or mode).
    counts: bool,
    /// The acceleration profile it is cut with.
    shape: Shape,
}

/// The sequence number of a finished block, reported by [`Planner::step`].
pub type Done = u64;

#[derive(Clone)]
pub struct Planner {
    cfg: PlannerConfig,
    segs: VecDeque<Planned>,
    /// Distance travelled into the front segment.
    s: f64,
    mover: Mover,
    /// End point of the last segment appended.
    end: Point,
    blocks: usize,
    ahead: Vec<Ahead>,
    /// The profile of segments appended from now on ([`Planner::set_shape`]).
    shape: Shape,
}

impl Planner {
    /// An empty window starting at `start` (slide coordinates).
    pub fn new(cfg: PlannerConfig, start: Point) -> Self {
        let cap = cfg.lookahead * 2 + 8;
        Planner {
            cfg,
            segs: VecDeque::with_capacity(cap),
            s: 0.0,
            mover: Mover::default(),
            end: start,
            blocks: 0,
            ahead: Vec::with_capacity(cap),
            shape: cfg.shape,
        }
    }

    /// Empties the window; the tool stands at `start`.
    pub fn reset(&mut self, start: Point) {
        self.segs.clear();
        self.s = 0.0;
        self.mover = Mover::default();
        self.end = start;
        self.blocks = 0;
    }

    /// The acceleration profile of the segments appended from now on (a program's switch,
    /// decision D99). Where it changes the tool comes to rest between the two segments, so
    /// no tick runs half in one profile and half in the other.
    pub fn set_shape(&mut self, shape: Shape) {
        self.shape = shape;
    }

    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// An axis's acceleration limit (slide travel, mm/s²) for the segments appended from now
    /// on and for rapids (a program's acceleration override, decision D108).
    pub fn set_acceleration(&mut self, axis: usize, acceleration: f64) {
        if let Some(a) = self.cfg.limits.acceleration.get_mut(axis) {
            *a = acceleration;
        }
    }

    pub fn config(&self) -> &PlannerConfig {
        &self.cfg
    }

    pub fn end(&self) -> Point {
        self.end
    }

    /// Whether the window has room for another block.
    pub fn has_room(&self) -> bool {
        self.blocks < self.cfg.lookahead
    }

    pub fn is_empty(&self) -> bool {
        self.segs.is_empty()
    }

    pub fn velocity(&self) -> f64 {
        self.mover.velocity
    }

    /// The line of the segment being cut.
    pub fn line(&self) -> Option<u32> {
        self.segs.front().map(|p| p.line)
    }

    /// The segment being cut: its block number, line and end.
    pub fn front(&self) -> Option<(u64, u32, Point)> {
        self.segs.front().map(|p| (p.seq, p.line, p.seg.end()))
    }

    /// Where the tool is now.
    pub fn position(&self) -> Point {
        self.segs.front().map_or(self.end, |p| p.seg.point(self.s))
    }

    /// Appends a block that does not move (a mode change): it is done when the tool gets there.
    pub fn push_marker(&mut self, seq: u64, line: u32) {
        let here = self.end;
        self.push_segment(
            Segment::Line {
                start: here,
                end: here,
            },
            f64::INFINITY,
            seq,
            line,
            f64::INFINITY,
            true,
            0.0,
        );
        if let Some(p) = self.segs.back_mut() {
            p.counts = false;
        }
    }

    /// Appends a line or arc starting at [`Planner::end`] at up to `feed` mm/s. `blend`: the
    /// corner before it may be rounded (G64) rather than passed at rest. `deviation`: how far
    /// the segment leaves the programmed path (a chord standing for merged lines), mm.
    pub fn push(
        &mut self,
        seg: Segment,
        feed: f64,
        seq: u64,
        line: u32,
        blend: bool,
        deviation: f64,
    ) {
        let len = seg.length();
        let (mut seg, mut entry_limit) = (seg, 0.0);
        self.blocks += 1;
        if len <= 1e-12 {
            self.push_segment(seg, feed, seq, line, f64::INFINITY, blend, deviation);
            return;
        }
        if let Some(k) = self.last_moving() {
            let prev = self.segs[k];
            let u1 = prev.seg.tangent(prev.length);
            let u2 = seg.tangent(0.0);
            let phi = deflection(&u1, &u2);
            if prev.shape != self.shape {
                // A profile change is passed at rest.
            } else if phi < TANGENT {
                entry_limit = f64::INFINITY;
            } else if blend && prev.blend_end {
                if let Some(new_seg) = self.try_blend(k, &seg, feed, deviation) {
                    seg = new_seg;
                    entry_limit = f64::INFINITY;
                }
            }
        }
        self.push_segment(seg, feed, seq, line, entry_limit, blend, deviation);
    }

    /// Blocks in the window (lines and arcs as programmed, not blends or mode changes).
    pub fn blocks(&self) -> usize {
        self.blocks
    }

    /// Index of the last segment that moves (the one a new block's corner joins).
    fn last_moving(&self) -> Option<usize> {
        self.segs.iter().rposition(|p| p.length > 1e-12)
    }

    /// Rounds the corner between line `k` and the new line `next`: trims both, inserts the blend
    /// arc. Returns the trimmed new line, or None when the corner must be passed at rest.
    fn try_blend(
        &mut self,
        k: usize,
        next: &Segment,
        feed: f64,
        next_deviation: f64,
    ) -> Option<Segment> {
        let prev = self.segs[k];
        let (Segment::Line { end: vertex, .. }, Segment::Line { .. }) = (prev.seg, next) else {
            return None;
        };
        let (u1, u2) = (prev.seg.tangent(0.0), next.tangent(0.0));
        let phi = deflection(&u1, &u2);
        let half = (phi / 2.0).tan();
        // Tangent length from the tolerance: the arc passes the vertex at R·(1/cos(φ/2) − 1).
        let tolerance = self.cfg.tolerance - prev.deviation.max(next_deviation);
        if tolerance <= 0.0 {
            return None;
        }
        let from_tol = tolerance / (1.0 / (phi / 2.0).cos() - 1.0) * half;
        // What is left of the previous line, and not behind the tool if it is being cut.
        let mut room = prev.length - if k == 0 { self.s } else { 0.0 };
        room = room.min(prev.programmed_length / 2.0);
        let t = from_tol.min(room).min(next.length() / 2.0);
        if t.is_nan() || t <= 1e-9 {
            return None;
        }
        let arc = fillet(&vertex, &u1, &u2, t)?;
        let trimmed_prev = prev.seg.trimmed(0.0, t);
        let trimmed_next = next.trimmed(t, 0.0);
        // The blend's speed limit must still be reachable from where the tool is now.
        let (vmax, accel, jerk) = self.segment_limits(&arc, feed * MAX_FEED_OVERRIDE);
        let next_len = trimmed_next.length();
        let (_, next_accel, _) = self.segment_limits(&trimmed_next, feed);
        let next_entry = (2.0 * next_accel * next_len).sqrt();
        let arc_entry = vmax.min((next_entry.powi(2) + 2.0 * accel * arc.length()).sqrt());
        let mut dist = -self.s;
        let mut amin = f64::INFINITY;
        for p in self.segs.iter().take(k) {
            dist += p.length;
            amin = amin.min(p.accel);
        }
        dist += trimmed_prev.length();
        amin = amin.min(prev.accel);
        let need = stop_distance(
            self.mover.velocity,
            self.mover.acceleration,
            arc_entry,
            amin,
            self.path_jerk(),
        );
        if need > dist + 1e-9 {
            return None;
        }
        let p = &mut self.segs[k];
        p.seg = trimmed_prev;
        p.length = trimmed_prev.length();
        self.segs.push_back(Planned {
            seg: arc,
            length: arc.length(),
            seq: prev.seq,
            line: prev.line,
            feed,
            vmax,
            accel,
            jerk,
            entry_limit: f64::INFINITY,
            entry: 0.0,
            programmed_length: 0.0,
            blend_end: true,
            deviation: 0.0,
            counts: false,
            shape: prev.shape,
        });
        Some(trimmed_next)
    }

    fn path_jerk(&self) -> f64 {
        match self.segs.front() {
            Some(p) if p.shape == Shape::SCurve => p.jerk,
            _ => f64::INFINITY,
        }
    }

    // The block's identity and its corner attributes travel together only here.
    #[allow(clippy::too_many_arguments)]
    fn push_segment(
        &mut self,
        seg: Segment,
        feed: f64,
        seq: u64,
        line: u32,
        entry_limit: f64,
        blend_end: bool,
        deviation: f64,
    ) {
        let (vmax, accel, jerk) = self.segment_limits(&seg, feed * MAX_FEED_OVERRIDE);
        let length = seg.length();
        let programmed_length = match seg {
            Segment::Line { .. } => length,
            Segment::Arc { .. } => 0.0,
        };
        self.end = seg.end();
        self.segs.push_back(Planned {
            seg,
            length,
            seq,
            line,
            feed,
            vmax,
            accel,
            jerk,
            entry_limit,
            entry: 0.0,
            programmed_length,
            blend_end,
            deviation,
            counts: true,
            shape: self.shape,
        });
        self.backward_pass();
    }

    /// Speed, acceleration and jerk limits along a segment from the axes' limits.
    fn segment_limits(&self, seg: &Segment, feed: f64) -> (f64, f64, f64) {
        let lim = &self.cfg.limits;
        let share = seg.axis_share();
        let (mut v, mut a, mut j) = (feed, f64::INFINITY, f64::INFINITY);
        for (i, &share) in share.iter().enumerate().take(lim.axes) {
            if share > 1e-12 {
                v = v.min(lim.velocity[i] / share);
                a = a.min(lim.acceleration[i] / share);
                j = j.min(lim.jerk[i] / share);
            }
        }
        if let Segment::Arc { e1, e2, .. } = seg {
            // Turning takes up to CENTRIPETAL_SHARE of the plane axes' acceleration:
            // (k·v)²/R ≤ share·A, with k the part of the speed that turns.
            let plane_acc = (0..lim.axes)
                .filter(|&i| e1[i].hypot(e2[i]) > 1e-12)
                .map(|i| lim.acceleration[i])
                .fold(f64::INFINITY, f64::min);
            let k = seg.planar_fraction().max(1e-12);
            let r = seg.radius();
            v = v.min((CENTRIPETAL_SHARE * plane_acc * r).sqrt() / k);
            let normal = (k * v).powi(2) / r;
            a = a.min((plane_acc.powi(2) - normal.powi(2)).max(0.0).sqrt());
        }
        if !a.is_finite() {
            a = 1.0;
        }
        (v.max(0.0), a.max(1e-6), j)
    }

    /// Entry speeds from the end of the window backwards: each segment must be able to slow
    /// to the next one's entry, and the last to rest.
    fn backward_pass(&mut self) {
        let n = self.segs.len();
        let mut exit = 0.0;
        for k in (0..n).rev() {
            let prev_vmax = if k > 0 {
                self.segs[k - 1].vmax
            } else {
                f64::INFINITY
            };
            let p = &mut self.segs[k];
            let reach = (exit * exit + 2.0 * p.accel * p.length).sqrt();
            let entry = p.entry_limit.min(p.vmax).min(prev_vmax).min(reach);
            // Appending only raises entries; once one is unchanged, all before it are too.
            let unchanged = entry == p.entry && k + 2 < n;
            p.entry = entry;
            exit = entry;
            if unchanged {
                break;
            }
        }
    }

    /// One servo tick: moves along the path and writes the new position into `out`. Finished
    /// blocks go to `done`. Returns true when the window is empty and the tool at rest.
    /// `feed_scale` is the feed override; `speed_cap` a path speed no block exceeds (the
    /// handwheel trial run's; infinite otherwise).
    pub fn step(
        &mut self,
        hold: bool,
        feed_scale: f64,
        speed_cap: f64,
        done: &mut Vec<Done>,
        out: &mut Point,
    ) -> bool {
        let dt = self.cfg.period;
        let Some(front) = self.segs.front().copied() else {
            *out = self.end;
            return true;
        };
        let jerk = match front.shape {
            Shape::Trapezoidal => f64::INFINITY,
            Shape::SCurve => front.jerk,
        };
        // The speed limits ahead, as far as braking from the next tick's speed could reach.
        let v_next = self.mover.velocity + front.accel * dt;
        let horizon = stop_distance(
            v_next,
            self.mover.acceleration.max(0.0) + jerk.min(1e12) * dt,
            0.0,
            front.accel,
            jerk,
        ) + 2.0 * v_next * dt
            + 1e-6;
        self.ahead.clear();
        let mut dist = front.length - self.s;
        let mut amin = front.accel;
        let mut lowest = f64::INFINITY;
        let mut k = 1;
        while k < self.segs.len() && dist <= horizon {
            let p = &self.segs[k];
            let entry = p.entry.min(p.feed * feed_scale).min(speed_cap);
            if entry < lowest {
                lowest = entry;
                self.ahead.push(Ahead {
                    distance: dist,
                    velocity: entry,
                    acceleration: amin,
                });
            }
            amin = amin.min(p.accel);
            dist += p.length;
            k += 1;
        }
        if k == self.segs.len() {
            self.ahead.push(Ahead {
                distance: dist,
                velocity: 0.0,
                acceleration: amin,
            });
        }
        let lim = Limits {
            velocity: front.vmax.min(front.feed * feed_scale).min(speed_cap),
            acceleration: front.accel,
            jerk,
        };
        let ds = self.mover.step(dt, front.shape, lim, hold, &self.ahead);
        self.s += ds;
        while let Some(p) = self.segs.front().copied() {
            // The tool comes to rest at the end of this segment: the window ends there, or a
            // corner that cannot be blended follows. It must not turn through the stop within
            // a tick, so the next segment starts on the next tick.
            let stop_after = self.segs.get(1).is_none_or(|q| q.entry == 0.0);
            if stop_after {
                // A jerk-limited stop may come to rest a hair short of the point.
                let at_rest = self.mover.velocity < 1e-3 && self.mover.acceleration <= 0.0;
                if self.s < p.length - 1e-9 && !(at_rest && p.length - self.s < 1e-4) {
                    break;
                }
            } else if self.s < p.length - 1e-12 {
                break;
            }
            done.push(p.seq);
            if p.counts {
                self.blocks = self.blocks.saturating_sub(1);
            }
            self.segs.pop_front();
            if stop_after {
                self.s = 0.0;
                self.mover = Mover::default();
                if self.segs.is_empty() {
                    self.blocks = 0;
                    *out = self.end;
                    return true;
                }
                break;
            }
            self.s -= p.length;
        }
        *out = self.position();
        false
    }
}
