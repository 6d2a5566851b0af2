//! Travel to a fixed stop (FXS, D118): an axis's drive runs with its torque limited through
//! the move that follows the `FixedStop` block; where the slide meets a stop it stays behind
//! its setpoint, and once it lags by [`THRESHOLD`] the stop is reached: the path brakes, the
//! rest of the move is dropped, the axis's setpoint is put where the slide stands, and the
//! drive presses against the stop with the clamping torque (its setpoint held [`PRESS`]
//! beyond it). From then on the slide must stay within the window, and its following error
//! is not a fault. A move that ends without meeting the stop is alarm 20091; a clamped axis
//! pushed out of its window is 20094 (the 802D manual's numbers, `001` §9.3.23).

use super::*;

/// How far the slide lags its setpoint when the stop is taken as reached, mm (the machine
/// data's fixed stop threshold).
pub const THRESHOLD: f64 = 2.0;

/// How far beyond the stop a clamped axis's setpoint is held, mm: the drive's position
/// controller then gives its (limited) torque against the stop.
pub const PRESS: f64 = 0.5;

/// One axis's fixed stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum FixedStop {
    /// Selected: the next move runs into the stop, torque limited.
    Selected { torque: f64, window: f64 },
    /// The move is under way (block `seq`).
    Approaching { seq: u64, torque: f64, window: f64 },
    /// Braking after the stop was met at slide position `at`, pressed in direction `dir`.
    Met {
        seq: u64,
        torque: f64,
        window: f64,
        at: f64,
        dir: f64,
    },
    /// Pressing against the stop at `at`.
    Clamped {
        torque: f64,
        window: f64,
        at: f64,
        dir: f64,
    },
}

impl Motion {
    /// A `FixedStop` block: on selects the axis for the next move; off lifts the torque limit
    /// (the move that follows leaves the stop).
    pub(super) fn fixed_stop_block(&mut self, block: &Block) -> Result<(), (u32, String)> {
        let Command::FixedStop {
            axis,
            on,
            torque,
            window,
        } = block.kind
        else {
            return Err((alarm::BAD_BLOCK, "not a fixed stop block".into()));
        };
        let i = usize::from(axis);
        let Some(slot) = self.fixed_stops.get_mut(i) else {
            return Err((
                alarm::BAD_BLOCK,
                format!(
                    "fixed stop on axis {i}: the machine has {}",
                    self.cfg.axes.len()
                ),
            ));
        };
        *slot = on.then_some(FixedStop::Selected { torque, window });
        if !on {
            // Off the stop: the axis follows its commanded position again from where it is.
            self.commanded[i] = self.actual[i];
            let here = self.commanded_point();
            self.planner.reset(here);
        }
        Ok(())
    }

    /// A move starts (block `seq`): a selected axis now approaches its stop.
    pub(super) fn approach_fixed_stops(&mut self, seq: u64) {
        for s in self.fixed_stops.iter_mut() {
            if let Some(FixedStop::Selected { torque, window }) = *s {
                *s = Some(FixedStop::Approaching {
                    seq,
                    torque,
                    window,
                });
            }
        }
    }

    /// Each period: an approaching axis lagging by the threshold has met its stop (the path
    /// brakes); a clamped axis out of its window is an alarm.
    pub(super) fn watch_fixed_stops(&mut self) {
        for i in 0..self.fixed_stops.len() {
            match self.fixed_stops[i] {
                Some(FixedStop::Approaching {
                    seq,
                    torque,
                    window,
                }) => {
                    let lag = self.drive[i] - self.actual[i];
                    if lag.abs() >= THRESHOLD {
                        self.fixed_stops[i] = Some(FixedStop::Met {
                            seq,
                            torque,
                            window,
                            at: self.actual[i],
                            dir: lag.signum(),
                        });
                    }
                }
                Some(FixedStop::Clamped { window, at, .. })
                    if (self.actual[i] - at).abs() > window =>
                {
                    self.fixed_stops[i] = None;
                    self.fixed_stop_alarm(
                        i,
                        alarm::FIXED_STOP_ABORTED,
                        &format!(
                            "fixed stop aborted: {{}} left its window of {window} at the stop"
                        ),
                    );
                }
                _ => {}
            }
        }
    }

    /// Whether the active move brakes because an axis met its stop.
    pub(super) fn fixed_stop_braking(&self) -> bool {
        self.fixed_stops
            .iter()
            .any(|s| matches!(s, Some(FixedStop::Met { .. })))
    }

    /// Alarm `number` for axis `i`, its name put in `text` where `{}` stands, on the line
    /// being run.
    fn fixed_stop_alarm(&mut self, i: usize, number: u32, text: &str) {
        let name = self.cfg.axes.get(i).map_or("?", |a| a.name.as_str());
        let text = text.replacen("{}", name, 1);
        let line = self.line;
        self.raise(number, text, line);
    }

    /// Whether a move into a fixed stop is under way (nothing joins it).
    pub(super) fn fixed_stop_moving(&self) -> bool {
        self.fixed_stops.iter().any(|s| {
            matches!(
                s,
                Some(FixedStop::Approaching { .. } | FixedStop::Met { .. })
            )
        })
    }

    /// Whether axis `i`'s lag is the fixed stop's, not a fault.
    pub(super) fn lag_allowed(&self, i: usize) -> bool {
        matches!(
            self.fixed_stops.get(i),
            Some(Some(
                FixedStop::Approaching { .. } | FixedStop::Met { .. } | FixedStop::Clamped { .. }
            ))
        )
    }

    /// Once block `done` is done: a met stop clamps (the block's result says where the axes
    /// rest); an approach whose move ended without meeting its stop is alarm 20091.
    pub(super) fn finish_fixed_stops(&mut self) {
        let mut result = None;
        for i in 0..self.fixed_stops.len() {
            match self.fixed_stops[i] {
                Some(FixedStop::Met {
                    seq,
                    torque,
                    window,
                    at,
                    dir,
                }) if self.done_seq >= seq => {
                    self.commanded[i] = self.actual[i];
                    self.fixed_stops[i] = Some(FixedStop::Clamped {
                        torque,
                        window,
                        at,
                        dir,
                    });
                    result = Some((seq, true));
                }
                Some(FixedStop::Approaching { seq, .. }) if self.done_seq >= seq => {
                    self.fixed_stops[i] = None;
                    self.fixed_stop_alarm(
                        i,
                        alarm::FIXED_STOP_NOT_REACHED,
                        "fixed stop not reached: {} ended its move without meeting it",
                    );
                    return;
                }
                _ => {}
            }
        }
        if let Some((seq, triggered)) = result {
            let here = self.commanded_point();
            self.planner.reset(here);
            let rest = self.display_point(&self.commanded);
            self.block_result = Some(BlockResult {
                seq,
                triggered,
                position: rest,
                rest,
            });
        }
    }

    /// Per axis, the drive's torque limit, percent (100 without a fixed stop).
    pub fn torque_limits(&self) -> [f64; MAX_AXES] {
        let mut out = [100.0; MAX_AXES];
        for (o, s) in out.iter_mut().zip(&self.fixed_stops) {
            *o = match s {
                Some(
                    FixedStop::Selected { torque, .. }
                    | FixedStop::Approaching { torque, .. }
                    | FixedStop::Met { torque, .. }
                    | FixedStop::Clamped { torque, .. },
                ) => *torque,
                None => 100.0,
            };
        }
        out
    }

    /// How far beyond the commanded position axis `i`'s drive is set: a clamped axis presses
    /// against its stop.
    pub(super) fn press(&self, i: usize) -> f64 {
        match self.fixed_stops.get(i) {
            Some(Some(FixedStop::Clamped { dir, .. })) => dir * PRESS,
            _ => 0.0,
        }
    }

    /// Every fixed stop lifted (a new run, reset, emergency stop): the axes follow their
    /// commanded positions again from where they stand.
    pub(super) fn release_fixed_stops(&mut self) {
        for i in 0..self.fixed_stops.len() {
            if self.fixed_stops[i].take().is_some() {
                self.commanded[i] = self.actual[i];
            }
        }
    }

    /// An alarm stops a travel to a stop not yet met; a clamped axis stays clamped.
    pub(super) fn drop_fixed_stop_approaches(&mut self) {
        for i in 0..self.fixed_stops.len() {
            if !matches!(self.fixed_stops[i], None | Some(FixedStop::Clamped { .. })) {
                self.fixed_stops[i] = None;
                self.commanded[i] = self.actual[i];
            }
        }
    }

    /// Whether an axis presses against a fixed stop (or is on its way to one).
    pub fn fixed_stop_active(&self, i: usize) -> bool {
        self.fixed_stops.get(i).is_some_and(Option::is_some)
    }
}
