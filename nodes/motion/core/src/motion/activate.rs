//! What a block becomes: display units to slide travel, the soft limits and the checks a
//! block must pass before anything moves, and the path segment, rapid, dwell or thread piece
//! it is activated as.

use super::*;

/// Most spindle revolutions one thread block may take (a million: 2 h at 8000 rpm).
const MAX_THREAD_REVS: f64 = 1e6;

impl Motion {
    /// Slide positions of a display-unit point.
    pub(super) fn to_slide(&self, p: &[f64]) -> Point {
        let mut out = [0.0; MAX_AXES];
        for (i, a) in self.cfg.axes.iter().take(MAX_AXES).enumerate() {
            out[i] = p.get(i).copied().unwrap_or(0.0) * a.scale();
        }
        self.contour_end(p, &mut out);
        self.live_tool_end(p, &mut out);
        out
    }

    /// Display units of a slide point.
    fn to_display(&self, p: &Point) -> Vec<f64> {
        self.cfg
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| p[i] / a.scale())
            .collect()
    }

    /// Checks a display-unit point against the soft limits.
    pub(super) fn check_limits(&self, p: &[f64]) -> Result<(), (u32, String)> {
        for (i, a) in self.cfg.axes.iter().enumerate() {
            let v = p.get(i).copied().unwrap_or(0.0);
            if v < a.min - 1e-9 || v > a.max + 1e-9 {
                return Err((
                    alarm::SOFT_LIMIT,
                    format!(
                        "soft limit: {} {:.4} outside {:.3}..{:.3}",
                        a.name, v, a.min, a.max
                    ),
                ));
            }
        }
        self.check_live_tool_spin(p)
    }

    /// Turns a block into its active form; soft limits are checked here, before any motion.
    pub(super) fn activate(&mut self, block: &Block) -> Result<Active, (u32, String)> {
        let n = self.cfg.axes.len();
        let start = self.commanded_point();
        match &block.kind {
            Command::Rapid { end } => {
                self.check_block(&block.kind)?;
                self.check_limits(end)?;
                let end = self.to_slide(end);
                let mut axes = [RapidAxis {
                    length: 0.0,
                    travelled: 0.0,
                    mover: Mover::default(),
                }; MAX_AXES];
                for (i, ax) in axes.iter_mut().enumerate().take(n) {
                    ax.length = (end[i] - start[i]).abs();
                }
                Ok(Active::Rapid { start, end, axes })
            }
            Command::Linear { .. } | Command::Arc { .. } => {
                let (seg, feed) = self.segment_for(block, &start)?;
                self.approach_fixed_stops(block.seq);
                // COMPCAD: this line and the ones queued after it, as one arc if they fit.
                let fitted = match self.compressor && self.fixed_stops.iter().all(Option::is_none) {
                    true => self.compress(&start, Some(block)),
                    false => None,
                };
                if let Some((arc, feed, last, k)) = fitted {
                    self.planner.reset(start);
                    self.planner
                        .push(arc, feed, last, block.line, !self.exact_stop, 0.0);
                    for _ in 1..k {
                        self.queue.pop_front();
                    }
                    return Ok(Active::Path);
                }
                self.planner.reset(start);
                self.planner.push(
                    seg,
                    feed,
                    block.seq,
                    block.line,
                    !self.exact_stop,
                    self.contour_used(),
                );
                Ok(Active::Path)
            }
            Command::Probe { .. } => {
                // Cut on its own: nothing blends into or out of a measuring line.
                let (seg, feed) = self.segment_for(block, &start)?;
                self.start_probing(block)?;
                self.planner.reset(start);
                self.planner
                    .push(seg, feed, block.seq, block.line, false, 0.0);
                Ok(Active::Path)
            }
            Command::Thread { start_angle, .. } => {
                let piece = self.thread_piece(block, &start)?;
                self.thread.clear();
                self.thread.push(piece);
                Ok(Active::Thread {
                    shift: *start_angle,
                })
            }
            Command::Tap { .. } => Ok(Active::Tap(self.tap_for(block, &start)?)),
            Command::Rotary { .. } => Ok(Active::Tap(self.rotary_for(block, &start)?)),
            Command::Dwell { seconds } => Ok(Active::Dwell {
                remaining: *seconds,
            }),
            Command::FixedStop { .. } => {
                self.fixed_stop_block(block)?;
                Ok(Active::Dwell { remaining: 0.0 })
            }
            // Feed mode, path mode, profile and feedforward were taken over when the block
            // was popped.
            Command::FeedMode { .. }
            | Command::PathMode { .. }
            | Command::Profile { .. }
            | Command::Feedforward { .. }
            | Command::Compressor { .. }
            | Command::Fifo { .. }
            | Command::Acceleration { .. } => Ok(Active::Dwell { remaining: 0.0 }),
            // Every block before it has finished: the program may read the machine.
            Command::Sync => {
                self.sync_reached(block.seq);
                Ok(Active::Dwell { remaining: 0.0 })
            }
            Command::Contour { on } => {
                self.contour_block(*on)?;
                Ok(Active::Dwell { remaining: 0.0 })
            }
            Command::LiveTool { rpm } => {
                self.live_tool_block(*rpm)?;
                Ok(Active::LiveTool)
            }
            Command::Aux(code) => Ok(Active::Aux {
                code: *code,
                raised: false,
            }),
            Command::ProgramEnd => {
                // The end of a program also ends polar interpolation (§5.8: as reset does).
                self.contour.on = false;
                // And it stops the live tool: a robot reaches into the machine next.
                self.stop_live_tool();
                Ok(Active::End)
            }
        }
    }

    /// A block's end point and arc centre must name every axis with a finite value.
    pub(super) fn check_block(&self, kind: &Command) -> Result<(), (u32, String)> {
        let n = self.cfg.axes.len();
        // A turn-mill's blocks name C and the live tool after the machine's axes (D141, D142).
        let all = self.cfg.block_axes();
        let bad_len = |v: &[f64]| !(n..=all).contains(&v.len()) || v.iter().any(|x| !x.is_finite());
        if let Some(end) = kind.end() {
            if bad_len(end) {
                return Err((
                    alarm::BAD_BLOCK,
                    format!("block has {} axis values, machine has {n}", end.len()),
                ));
            }
        }
        if let Command::Arc { center, .. } = kind {
            if bad_len(center) {
                return Err((
                    alarm::BAD_BLOCK,
                    "arc centre has the wrong number of axes".into(),
                ));
            }
        }
        Ok(())
    }

    /// The path segment of a line, arc or thread starting at `start` (slide units), and its
    /// feed in mm/s. Soft limits are checked here, before the block joins the plan.
    pub(super) fn segment_for(
        &self,
        block: &Block,
        start: &Point,
    ) -> Result<(Segment, f64), (u32, String)> {
        self.check_block(&block.kind)?;
        match &block.kind {
            Command::Linear { end, feed } | Command::Probe { end, feed, .. } => {
                let feed = self.feed_mm_per_min(*feed)?;
                self.check_limits(end)?;
                let end = self.to_slide(end);
                self.check_live_tool_move(start, &end)?;
                Ok((Segment::Line { start: *start, end }, feed / 60.0))
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                plane,
            } => {
                let feed = self.feed_mm_per_min(*feed)?;
                self.check_limits(end)?;
                let (h, v) = match plane {
                    None => self.cfg.arc_plane,
                    Some([h, v]) => (usize::from(*h), usize::from(*v)),
                };
                if h >= self.cfg.axes.len() || v >= self.cfg.axes.len() {
                    return Err((
                        alarm::BAD_BLOCK,
                        format!(
                            "arc plane axes {h}, {v}: the machine has {} axes",
                            self.cfg.axes.len()
                        ),
                    ));
                }
                let end = self.to_slide(end);
                let c = self.to_slide(center);
                let seg = path::arc(start, &end, &c, (h, v), *clockwise)
                    .ok_or((alarm::BAD_BLOCK, "arc of zero radius".to_string()))?;
                let Segment::Arc {
                    radius, a0, sweep, ..
                } = seg
                else {
                    return Err((alarm::BAD_BLOCK, "not an arc".into()));
                };
                // Soft limits at the arc's extreme points (every quadrant crossing).
                let quarter = TAU / 4.0;
                let first = (a0 / quarter).floor() as i64;
                let mut k = first;
                loop {
                    let ang = if sweep > 0.0 {
                        (k + 1) as f64 * quarter
                    } else {
                        k as f64 * quarter
                    };
                    let passed = if sweep > 0.0 {
                        ang - a0 < sweep
                    } else {
                        ang - a0 > sweep && ang < a0
                    };
                    if !passed || (k - first).abs() > 5 {
                        break;
                    }
                    let mut p = self.to_display(start);
                    p[h] = (c[h] + radius * ang.cos()) / self.cfg.axes[h].scale();
                    p[v] = (c[v] + radius * ang.sin()) / self.cfg.axes[v].scale();
                    self.check_limits(&p)?;
                    k += if sweep > 0.0 { 1 } else { -1 };
                }
                Ok((seg, feed / 60.0))
            }
            _ => Err((alarm::BAD_BLOCK, "not a path block".into())),
        }
    }

    /// A thread block as a piece of a thread chain starting at `start` (slide units): the
    /// long axis (X as radius, `000` §5.23.1) advances one lead per spindle revolution.
    pub(super) fn thread_piece(
        &self,
        block: &Block,
        start: &Point,
    ) -> Result<Piece, (u32, String)> {
        self.check_block(&block.kind)?;
        let Command::Thread { end, lead, .. } = &block.kind else {
            return Err((alarm::BAD_BLOCK, "not a thread block".into()));
        };
        self.check_limits(end)?;
        let n = self.cfg.axes.len().min(MAX_AXES);
        let end = self.to_slide(end);
        let long = (0..n)
            .map(|i| (end[i] - start[i]).abs())
            .fold(0.0, f64::max);
        // Blocks come from anyone on the DDS domain: a lead so small that the thread would
        // take longer than any spindle could turn is refused, not waited for.
        let revs = long / lead;
        if !(revs.is_finite() && revs <= MAX_THREAD_REVS) {
            return Err((
                alarm::BAD_BLOCK,
                format!("thread of lead {lead} mm over {long:.4} mm: {revs:e} revolutions"),
            ));
        }
        Ok(Piece {
            start: *start,
            end,
            revs,
            seq: block.seq,
            line: block.line,
        })
    }

    fn spindle_rpm_for(&self, what: &str) -> Result<f64, (u32, String)> {
        if self.spindle_rpm > 0.0 {
            Ok(self.spindle_rpm)
        } else {
            Err((
                alarm::SPINDLE_NOT_TURNING,
                format!("{what} with no spindle speed commanded"),
            ))
        }
    }

    /// A programmed feed in mm/min, from mm/rev under G99; the dry-run feed under dry run.
    pub(super) fn feed_mm_per_min(&self, feed: f64) -> Result<f64, (u32, String)> {
        if self.panel.dry_run {
            Ok(self.cfg.dry_run_feed)
        } else if self.feed_per_rev {
            Ok(feed * self.spindle_rpm_for("feed per revolution")?)
        } else {
            Ok(feed)
        }
    }
}
