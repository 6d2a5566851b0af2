//! The look-ahead window: path blocks join the planner's window while it has room (short
//! lines merged into chords within the path tolerance), thread blocks the thread chain.

use super::*;

/// Most lines merged into one chord.
pub(super) const MAX_MERGE: usize = 32;
/// Share of the path tolerance merging may use; blends at the chord's ends use the rest.
pub(super) const MERGE_SHARE: f64 = 0.5;
/// Blocks the planner must hold before a merge waits for more lines from the interpreter.
const MERGE_WAIT_BLOCKS: usize = 8;

/// Lines merged into one chord.
struct Merged {
    end: Point,
    /// Block number of the last line merged.
    seq: u64,
    blocks: usize,
    /// Largest distance of a programmed point from the chord, mm.
    deviation: f64,
}

impl Motion {
    /// Path blocks waiting in the queue join the planner's window while it has room, so
    /// corners between them are blended and the speed carries over.
    pub(super) fn extend_chain(&mut self) -> Result<(), (u32, String, u32)> {
        // A measuring line, and a move into a fixed stop, are cut on their own.
        if !matches!(self.active, Some((_, Active::Path)))
            || self.probing.is_some()
            || self.fixed_stop_moving()
        {
            return Ok(());
        }
        while self.planner.has_room() {
            let Some(next) = self.queue.front() else {
                break;
            };
            let (seq, line) = (next.seq, next.line);
            if self.panel.single_block && line != self.line {
                break;
            }
            // COMPCAD: lines on a circle join as its arc (D119).
            let fitted = match (self.compressor, &next.kind) {
                (true, Command::Linear { .. }) => self.compress(&self.planner.end(), None),
                _ => None,
            };
            if let Some((arc, feed, last, k)) = fitted {
                let last_line = self.queue.get(k - 1).map_or(line, |b| b.line);
                self.planner
                    .push(arc, feed, last, last_line, !self.exact_stop, 0.0);
                for _ in 0..k {
                    self.queue.pop_front();
                }
                continue;
            }
            let Some(next) = self.queue.front() else {
                break;
            };
            match &next.kind {
                // Polar interpolation's lines are already within their tolerance of the face's
                // contour: merged in the machine's X and C they would leave it (D141).
                Command::Linear { .. } if !self.exact_stop && !self.contour.on => {
                    let start = self.planner.end();
                    let (seg, feed) = self
                        .segment_for(next, &start)
                        .map_err(|(n, t)| (n, t, line))?;
                    let Some(merged) = self.merge_lines(&start, seg.end()) else {
                        break; // wait for more blocks to merge with
                    };
                    let seg = Segment::Line {
                        start,
                        end: merged.end,
                    };
                    self.record_merge(&start, &merged.end, merged.seq, merged.blocks);
                    self.planner
                        .push(seg, feed, merged.seq, line, true, merged.deviation);
                    for _ in 0..merged.blocks {
                        self.queue.pop_front();
                    }
                    continue;
                }
                Command::Linear { .. } | Command::Arc { .. } => {
                    let (seg, feed) = self
                        .segment_for(next, &self.planner.end())
                        .map_err(|(n, t)| (n, t, line))?;
                    let blend = !self.exact_stop;
                    let used = self.contour_used();
                    self.planner.push(seg, feed, seq, line, blend, used);
                }
                Command::FeedMode { per_rev } => {
                    self.feed_per_rev = *per_rev;
                    self.planner.push_marker(seq, line);
                }
                Command::PathMode { exact_stop } => {
                    self.exact_stop = *exact_stop;
                    self.planner.push_marker(seq, line);
                }
                Command::Profile { jerk_limited } => {
                    self.planner.set_shape(super::profile_shape(*jerk_limited));
                    self.planner.push_marker(seq, line);
                }
                Command::Compressor { on } => {
                    self.compressor = *on;
                    self.planner.push_marker(seq, line);
                }
                _ => break,
            }
            self.queue.pop_front();
        }
        Ok(())
    }

    /// Lines at the front of the queue that lie within half the path tolerance of one chord
    /// from `start` are cut as that chord (decision D34: "collinear short segments merged"), so a
    /// curve given as short chords with rounded coordinates is not a string of kinks. The
    /// first line (ending at `first_end`) is always taken. `None`: the queue ran out while more
    /// lines might still merge and the planner has enough ahead to wait for them.
    fn merge_lines(&mut self, start: &Point, first_end: Point) -> Option<Merged> {
        let tolerance = self.cfg.tolerance * MERGE_SHARE;
        let first = self.queue.front()?;
        let (feed, line) = match &first.kind {
            Command::Linear { feed, .. } => (*feed, first.line),
            _ => return None,
        };
        let mut merged = Merged {
            end: first_end,
            seq: first.seq,
            blocks: 1,
            deviation: 0.0,
        };
        self.merge_points.clear();
        loop {
            if merged.blocks >= MAX_MERGE {
                return Some(merged);
            }
            let Some(b) = self.queue.get(merged.blocks) else {
                // More lines may come: wait for them while the window has plenty to cut (a
                // program's last line is followed by its end, which closes the merge).
                return (self.planner.blocks() < MERGE_WAIT_BLOCKS).then_some(merged);
            };
            let same = matches!(&b.kind, Command::Linear { feed: f, .. } if *f == feed)
                && !(self.panel.single_block && b.line != line);
            if !same || self.check_block(&b.kind).is_err() {
                return Some(merged);
            }
            let Some(end) = b.kind.end().filter(|e| self.check_limits(e).is_ok()) else {
                return Some(merged);
            };
            let candidate = self.to_slide(end);
            self.merge_points.push(merged.end);
            match path::chord_deviation(start, &candidate, &self.merge_points) {
                Some(d) if d <= tolerance => {
                    merged.end = candidate;
                    merged.seq = b.seq;
                    merged.blocks += 1;
                    merged.deviation = d;
                }
                _ => return Some(merged),
            }
        }
    }

    /// Thread blocks that follow the one being cut join its chain (continuous threading,
    /// `000` §5.23.1); once the chain is complete enough, it is synchronised to the spindle.
    pub(super) fn extend_thread(&mut self) -> Result<(), (u32, String, u32)> {
        let Some((first, Active::Thread { shift })) = &self.active else {
            return Ok(());
        };
        let (shift, line) = (*shift, first.line);
        while self.thread.accepts() {
            let Some(next) = self.queue.front() else {
                break;
            };
            if !matches!(next.kind, Command::Thread { .. }) {
                break;
            }
            let start = self.thread_end();
            let piece = self
                .thread_piece(next, &start)
                .map_err(|(n, t)| (n, t, next.line))?;
            self.thread.push(piece);
            self.queue.pop_front();
        }
        // Under feed hold the thread does not start; once started, it is cut to its end.
        if self.thread.synchronised() || self.feed_hold || !self.locked_move_may_start() {
            return Ok(());
        }
        // With the drives' queue the encoder reading is a queue's length old and the thread's
        // start is extrapolated over it: the reading must show the spindle settled since the
        // last command that changed it (D133).
        let delay = self.cfg.feedback_delay_ticks;
        if delay > 1 && (self.spindle_quiet < delay + 2 || self.spindle_steady < 5) {
            return Ok(());
        }
        // `000` §5.23: the thread starts only with the spindle turning (alarm 36).
        let omega = self.encoder.omega();
        if omega * 60.0 < 1.0 {
            return Err((
                alarm::SPINDLE_NOT_TURNING,
                "thread cutting with the spindle stopped".into(),
                line,
            ));
        }
        if let Some((axis, v)) = self.thread.too_fast(omega) {
            return Err((
                alarm::THREAD_RUN_IN,
                format!(
                    "thread feed {:.0} mm/min on {} at {:.0} rpm exceeds the axis's rapid rate",
                    v * 60.0,
                    self.cfg.axes.get(axis).map_or("?", |a| a.name.as_str()),
                    self.encoder.rpm.abs()
                ),
                line,
            ));
        }
        let ramp = self.thread.ramp_for(omega);
        if self.thread.total() < ramp {
            return Err((
                alarm::THREAD_RUN_IN,
                format!(
                    "thread of {:.2} revolutions too short: run-in and run-out need {ramp:.2} at {:.0} rpm",
                    self.thread.total(),
                    self.encoder.rpm.abs()
                ),
                line,
            ));
        }
        let lead_time = self.thread_lead_time.iter().copied().fold(0.0, f64::max);
        let e = self.encoder;
        self.thread
            .synchronise(e.revs, e.angle, shift, omega, ramp, lead_time);
        Ok(())
    }

    /// Where the last piece of the thread chain ends (slide coordinates).
    fn thread_end(&self) -> Point {
        self.thread
            .last_end()
            .unwrap_or_else(|| self.commanded_point())
    }
}
