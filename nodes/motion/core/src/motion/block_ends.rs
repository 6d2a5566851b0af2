//! Where each programmed block ends on the path as cut (D137): the line being cut is the
//! programmed one also inside a chord of merged lines, and with the drives' setpoint queue each
//! setpoint says where between it and the one before its block began, so single block at the
//! drives stops exactly where one block ends (the operator sees the same line).

use super::*;

/// Chords of merged lines remembered: more than the planner's window holds.
const CHORDS_KEPT: usize = 64;

/// The lines merged into one chord: where along it each ends, and its line.
#[derive(Debug, Clone, Copy)]
pub(super) struct MergedLines {
    /// The chord's block number (its last line's).
    seq: u64,
    start: Point,
    /// Unit direction of the chord.
    direction: Point,
    /// Per line: its end's distance from the chord's start, and its line number.
    ends: [(f64, u32); window::MAX_MERGE],
    count: usize,
}

/// The block being cut as the setpoints tell the drives: its line, where it ends, and the
/// last setpoint's position.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct CutBlock {
    line: u32,
    end: Point,
    point: Point,
    /// Share of the way from the last setpoint to this one at which this one's block began.
    pub(super) began: f64,
}

impl CutBlock {
    /// The setpoint's program line (0 outside a program).
    pub(super) fn line(&self) -> u32 {
        self.line
    }
}

fn sub(a: &Point, b: &Point) -> Point {
    let mut d = [0.0; MAX_AXES];
    for (d, (a, b)) in d.iter_mut().zip(a.iter().zip(b)) {
        *d = a - b;
    }
    d
}

fn dot(a: &Point, b: &Point) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

impl Motion {
    /// Records the `blocks` lines merged into the chord from `start` to `end` (block number
    /// `seq`), before they leave the queue: `merge_points` holds their ends.
    pub(super) fn record_merge(&mut self, start: &Point, end: &Point, seq: u64, blocks: usize) {
        let along = sub(end, start);
        let length = dot(&along, &along).sqrt();
        if blocks < 2 || length <= 0.0 {
            return;
        }
        let mut m = MergedLines {
            seq,
            start: *start,
            direction: along.map(|v| v / length),
            ends: [(0.0, 0); window::MAX_MERGE],
            count: blocks.min(window::MAX_MERGE),
        };
        for k in 0..m.count {
            let at = match k + 1 == m.count {
                true => *end,
                false => self.merge_points.get(k).copied().unwrap_or(*end),
            };
            let line = self.queue.get(k).map_or(0, |b| b.line);
            m.ends[k] = (dot(&sub(&at, start), &m.direction), line);
        }
        if self.merged.len() == CHORDS_KEPT {
            self.merged.pop_front();
        }
        self.merged.push_back(m);
    }

    /// The programmed line the planner is cutting, and where that line ends: inside a chord
    /// of merged lines, the one whose stretch the tool is on.
    pub(super) fn line_cut(&mut self) -> Option<(u32, Point)> {
        let (seq, line, end) = self.planner.front()?;
        while self.merged.front().is_some_and(|m| m.seq < seq) {
            self.merged.pop_front();
        }
        let Some(m) = self.merged.front().filter(|m| m.seq == seq) else {
            return Some((line, end));
        };
        let d = dot(&sub(&self.planner.position(), &m.start), &m.direction);
        let ends = &m.ends[..m.count];
        let (e, line) = ends
            .iter()
            .copied()
            .find(|(e, _)| d < *e - 1e-9)
            .unwrap_or(ends[m.count - 1]);
        let mut at = m.start;
        for (p, u) in at.iter_mut().zip(&m.direction) {
            *p += u * e;
        }
        Some((line, at))
    }

    /// After a tick with the drives' queue: where between the last setpoint and this one the
    /// block of this one began (1: at this one), from where the last one's block ends.
    pub(super) fn mark_block_start(&mut self) {
        let line = if self.program_running { self.line } else { 0 };
        let here = self.commanded_point();
        let end = match &self.active {
            Some((_, Active::Path)) => self.block_end.unwrap_or(here),
            Some((_, Active::Rapid { end, .. })) => *end,
            _ => here,
        };
        let last = self.at_drives.cut;
        let mut began = 1.0;
        if line != last.line && line != 0 && last.line != 0 {
            let step = sub(&here, &last.point);
            let gone = sub(&last.end, &last.point);
            let step2 = dot(&step, &step);
            if step2 > 0.0 {
                began = (dot(&gone, &step) / step2).clamp(0.0, 1.0);
            }
        }
        self.at_drives.cut = CutBlock {
            line,
            end,
            point: here,
            began,
        };
    }
}
