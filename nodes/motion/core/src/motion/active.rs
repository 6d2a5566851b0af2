//! The active block: what each kind of block does at every servo tick (path moves through the
//! look-ahead planner, threads locked to the spindle, dog-leg rapids, dwells, rigid taps, the
//! M/S/T handshake), until it is finished.

use super::*;

// The rapid's per-axis state is inline on purpose: boxing it would allocate on the servo
// thread for every rapid.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
pub(super) enum Active {
    /// Lines and arcs through the look-ahead planner; further path blocks join it as they
    /// arrive.
    Path,
    /// A thread chain, locked to the spindle encoder; `shift`: start angle after the index
    /// pulse, degrees.
    Thread {
        shift: f64,
    },
    /// Each axis on its own profile (dog-leg rapid).
    Rapid {
        start: Point,
        end: Point,
        axes: [RapidAxis; MAX_AXES],
    },
    Dwell {
        remaining: f64,
    },
    /// Rigid tapping: the axes follow the positioned spindle (D101).
    Tap(tapping::Tap),
    /// Waits until the live tool turns at its new speed or stands (D143).
    LiveTool,
    /// Waits for the axes to settle, then sends the strobe and waits for FIN.
    Aux {
        code: Aux,
        /// The strobe is up, waiting for FIN.
        raised: bool,
    },
    End,
}

/// One axis of a rapid: its travel and where it is on it.
#[derive(Debug, Clone, Copy)]
pub(super) struct RapidAxis {
    pub(super) length: f64,
    pub(super) travelled: f64,
    pub(super) mover: Mover,
}

impl Motion {
    /// Advances the active block by one tick; true when it is finished.
    pub(super) fn advance(&mut self, dt: f64, plc: &GImage) -> bool {
        let hold = self.planning_hold();
        let (feed_scale, rapid_scale) = (
            self.planning_feed_override(),
            self.planning_rapid_override(),
        );
        let in_pos = self.in_position();
        let n = self.commanded.len().min(MAX_AXES);
        // A rapid runs in the program's profile too (BRISK/SOFT act on every path move).
        let shape = self.planner.shape();
        let Some((_, active)) = self.active.as_mut() else {
            return false;
        };
        match active {
            Active::Thread { .. } => {
                // Feed hold and override do not apply: the thread is cut to its end
                // (`000` §5.23.1).
                let mut out = path::point_from(&self.commanded);
                self.finished.clear();
                let e = self.encoder;
                let end = self.thread.step(
                    e.revs,
                    e.omega(),
                    &self.thread_lead_time[..n],
                    &mut out,
                    &mut self.finished,
                );
                self.commanded[..n].copy_from_slice(&out[..n]);
                for &seq in &self.finished {
                    self.done_seq = self.done_seq.max(seq);
                }
                if let Some(line) = self.thread.line() {
                    self.line = line;
                }
                end
            }
            Active::Tap(tap) => {
                let mut t = *tap;
                let done = self.tap_tick(&mut t, plc, in_pos);
                if let Some((_, Active::Tap(tap))) = self.active.as_mut() {
                    *tap = t;
                }
                done
            }
            Active::Path => {
                let mut out = [0.0; MAX_AXES];
                self.finished.clear();
                let braking = self.probe_braking() || self.fixed_stop_braking();
                let end = self.planner.step(
                    hold || braking,
                    feed_scale,
                    self.trial.speed_cap(),
                    &mut self.finished,
                    &mut out,
                );
                self.commanded[..n].copy_from_slice(&out[..n]);
                self.contour_tick(&out);
                self.live_tool_tick(&out);
                for &seq in &self.finished {
                    self.done_seq = self.done_seq.max(seq);
                }
                if let Some((line, end)) = self.line_cut() {
                    self.line = line;
                    self.block_end = Some(end);
                }
                // A measuring block that braked at its edge ends at rest: the rest of its
                // line is dropped (delete distance to go).
                if braking && self.planner.velocity() == 0.0 {
                    let here = self.commanded_point();
                    self.planner.reset(here);
                    return true;
                }
                end
            }
            Active::Rapid { start, end, axes } => {
                let lim = self.planner.config().limits;
                let mut all = true;
                for (i, ax) in axes.iter_mut().enumerate().take(n) {
                    if ax.travelled < ax.length {
                        let limits = Limits {
                            velocity: (lim.velocity[i] * rapid_scale).min(self.trial.speed_cap()),
                            acceleration: lim.acceleration[i],
                            jerk: lim.jerk[i],
                        };
                        let ahead = [Ahead {
                            distance: ax.length - ax.travelled,
                            velocity: 0.0,
                            acceleration: lim.acceleration[i],
                        }];
                        ax.travelled += ax.mover.step(dt, shape, limits, hold, &ahead);
                        let rest = ax.mover.velocity < 1e-3 && ax.mover.acceleration <= 0.0;
                        if ax.travelled >= ax.length - 1e-9
                            || (rest && ax.length - ax.travelled < 1e-4)
                        {
                            ax.travelled = ax.length;
                            ax.mover = Mover::default();
                        }
                    }
                    let dir = (end[i] - start[i]).signum();
                    self.commanded[i] = if ax.travelled >= ax.length {
                        end[i]
                    } else {
                        start[i] + dir * ax.travelled
                    };
                    all &= ax.travelled >= ax.length;
                }
                all
            }
            Active::Dwell { remaining } => {
                if !hold {
                    *remaining -= dt;
                }
                *remaining <= 0.0
            }
            Active::Aux { code, raised } => {
                let (code, was_raised) = (*code, *raised);
                let (done, raised_now) = self.aux_tick(code, was_raised, plc, in_pos);
                if let Some((_, Active::Aux { raised, .. })) = self.active.as_mut() {
                    *raised = raised_now;
                }
                done
            }
            Active::LiveTool => self.live_tool_at_speed(),
            // The program's end waits for the live tool to stand too.
            Active::End => in_pos && self.live_tool_at_speed(),
        }
    }

    /// One tick of the M/S/T handshake (`000` §4.2.1): code and strobe up, wait for FIN,
    /// strobe down; the next strobe waits until the PLC has dropped FIN again. Returns whether
    /// the block is finished and whether its strobe is up.
    fn aux_tick(&mut self, code: Aux, raised: bool, plc: &GImage, in_pos: bool) -> (bool, bool) {
        if raised {
            if !plc.get(g::FIN) {
                return (false, true);
            }
            self.clear_strobe();
            return (true, false);
        }
        if !in_pos || self.feed_hold || plc.get(g::FIN) {
            return (false, false);
        }
        // Auxiliary function lock: done without the PLC; the program stops stay. The
        // NC still knows the programmed speed (feed per revolution is computed from it).
        let program_stop = matches!(code, Aux::M(0 | 1 | 2 | 30));
        if self.panel.aux_lock && !program_stop {
            if let Aux::S(s) = code {
                self.spindle_rpm = s;
            }
            return (true, false);
        }
        let fi = &mut self.f;
        match code {
            // A spindle position is M19 with its stop position; M19 alone stops at
            // 0, the shortest way (D100).
            Aux::Orient { degrees, way } => {
                tapping::strobe_stop_position(fi, degrees, way, 0.0);
            }
            Aux::M(19) => tapping::strobe_stop_position(fi, 0.0, Turn::Shortest, 0.0),
            Aux::M(m) => {
                if matches!(m, 3..=5 | 19) {
                    self.spindle_quiet = 0;
                }
                fi.write_i32(f::ORIENT_ANGLE, 0);
                fi.bytes[f::ORIENT_WAY] = 0;
                fi.write_i32(f::ORIENT_SPEED, 0);
                fi.write_i32(f::M_CODE, m);
                fi.set(f::DM00, m == 0);
                fi.set(f::DM01, m == 1);
                fi.set(f::DM02, m == 2);
                fi.set(f::DM30, m == 30);
                fi.set(f::MF, true);
            }
            Aux::S(s) => {
                self.spindle_rpm = s;
                self.spindle_quiet = 0;
                fi.write_i32(f::S_CODE, s.round().clamp(0.0, i32::MAX as f64) as i32);
                fi.set(f::SF, true);
            }
            Aux::T(t) => {
                fi.write_i32(f::T_CODE, t);
                fi.set(f::TF, true);
            }
            // The second auxiliary function: address and value, HF (D107).
            Aux::H { address, value } => {
                fi.write_i32(f::H_ADDRESS, i32::from(address));
                fi.bytes[f::H_VALUE..f::H_VALUE + 8].copy_from_slice(&value.to_le_bytes());
                fi.set(f::HF, true);
            }
        }
        (false, true)
    }
}
