//! The turn-mill's live tool (飞刀盘) in motion.
//!
//! In position control (D142) its drive follows the planner's angle, so a tap with the live
//! tool (G14.n, M29 with G84/G88) is one move of the slides and the tool's angle, geared by
//! the interpolation itself. The program's angle starts at 0 with every run; `base` is where
//! the drive stood then.
//!
//! In speed mode (D143, the Huaxing M65 S…) motion turns the tool's angle on at its speed
//! every tick, as a control's pulse output turns a step-and-direction tool spindle: the
//! speed ramps at the tool's acceleration (its top speed in S#123's time constant) and the
//! path leaves the tool's axis alone. Out of speed mode (M66, M05, program end, reset,
//! emergency stop) it brakes the same way and stands in position control where it stopped,
//! the program's angle 0 there.

use super::*;

/// The live tool's state.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct LiveTool {
    /// The drive's setpoint, degrees since power-on.
    pub(super) at: f64,
    /// The setpoint before this tick, for the tool's speed.
    pub(super) last: f64,
    base: f64,
    /// The drive's actual angle, as its feedback says.
    actual: f64,
    /// The drive's actual speed, r/min, as its feedback says.
    actual_rpm: f64,
    /// How much longer the tool's drive lags than the slides', s (the config's lags).
    lead_time: f64,
    /// Speed mode: the speed asked for, degrees/s (0: stand).
    target: f64,
    /// Speed mode: the speed the tool's angle turns on at now, degrees/s.
    speed: f64,
    /// Speed mode: the angle the planner's points carry for the tool while it spins, so no
    /// path move turns it.
    hold: f64,
}

impl LiveTool {
    /// The live tool of `cfg`, standing at 0°.
    pub(super) fn of(cfg: &MotionConfig) -> LiveTool {
        let n = cfg.axes.len().max(1) as f64;
        let slides = cfg.axes.iter().map(|a| a.drive_lag).sum::<f64>() / n;
        LiveTool {
            lead_time: cfg.live_tool.as_ref().map_or(0.0, |t| t.drive_lag - slides),
            ..LiveTool::default()
        }
    }

    /// Whether the tool is in speed mode or still braking out of it.
    pub(super) fn spinning(&self) -> bool {
        self.target != 0.0 || self.speed != 0.0
    }
}

impl Motion {
    /// A block end's live tool angle in the planner's units.
    pub(super) fn live_tool_end(&self, p: &[f64], out: &mut Point) {
        if let Some(i) = self.cfg.live_tool_axis() {
            out[i] = match p.get(i) {
                _ if self.live.spinning() => self.live.hold,
                Some(v) => self.live.base + v,
                None => self.live.at,
            };
        }
    }

    /// A run starts: the program's live tool angle 0 is where the drive stands (where the
    /// path holds it, if it is still braking out of speed mode).
    pub(super) fn live_tool_run(&mut self) {
        self.live.base = match self.live.spinning() {
            true => self.live.hold,
            false => self.live.at,
        };
    }

    /// The planner's point with the live tool where it stands.
    pub(super) fn with_live_tool(&self, mut p: Point) -> Point {
        if let Some(i) = self.cfg.live_tool_axis() {
            p[i] = match self.live.spinning() {
                true => self.live.hold,
                false => self.live.at,
            };
        }
        p
    }

    /// This tick's live tool setpoint from the planner's point `out`.
    pub(super) fn live_tool_tick(&mut self, out: &Point) {
        if let Some(i) = self.cfg.live_tool_axis() {
            if self.locked == 0 && !self.live.spinning() {
                self.live.at = out[i];
            }
        }
    }

    /// The setpoint the live tool's drive gets: ahead of the path by the time its position
    /// loop lags the slides' more (its drive lag less theirs, the commissioning values in the
    /// config), so the tool's actual angle keeps to the slides' actual travel as a tap
    /// needs — what matched loop gains do on a control's rigid tapping.
    pub(super) fn live_tool_lead(&self) -> f64 {
        let speed = (self.live.at - self.live.last) / self.cfg.period;
        self.live.at + speed * self.live.lead_time
    }

    /// A line that turns the live tool (a tap, G14.n) is refused with the drives' setpoint
    /// queue, whose time-scaling does not turn the tool along (D142).
    pub(super) fn check_live_tool_move(
        &self,
        start: &Point,
        end: &Point,
    ) -> Result<(), (u32, String)> {
        match self.cfg.live_tool_axis() {
            Some(i) if self.cfg.time_scaling_at_drives && end[i] != start[i] => Err((
                alarm::BAD_BLOCK,
                "a live tool tap is not built for the drives' setpoint queue \
                 (servo.drive_queue_ms 0)"
                    .into(),
            )),
            _ => Ok(()),
        }
    }

    /// While the tool turns in speed mode no block may ask for another angle of it: a tap
    /// geared to it needs position control (M66 first).
    pub(super) fn check_live_tool_spin(&self, p: &[f64]) -> Result<(), (u32, String)> {
        let asked = self.cfg.live_tool_axis().and_then(|i| p.get(i));
        match asked {
            Some(v)
                if self.live.spinning() && (self.live.base + v - self.live.hold).abs() > 1e-9 =>
            {
                Err((
                    alarm::BAD_BLOCK,
                    "the live tool turns in speed mode: a block that turns it needs position \
                     control (M66) first"
                        .into(),
                ))
            }
            _ => Ok(()),
        }
    }

    /// A `LiveTool` block: speed mode at `rpm`, or out of it at 0 (D143). Refused where the
    /// machine has no live tool, above its top speed, or with the drives' setpoint queue
    /// (whose time-scaling would slow the tool with the path).
    pub(super) fn live_tool_block(&mut self, rpm: f64) -> Result<(), (u32, String)> {
        let Some(tool) = self.cfg.live_tool.as_ref() else {
            return Err((alarm::BAD_BLOCK, "this machine has no live tool".into()));
        };
        if !(0.0..=tool.max_rpm).contains(&rpm) {
            return Err((
                alarm::BAD_BLOCK,
                format!("live tool speed {rpm} r/min: 0…{} r/min", tool.max_rpm),
            ));
        }
        if rpm > 0.0 && self.cfg.time_scaling_at_drives {
            return Err((
                alarm::BAD_BLOCK,
                "a turning live tool is not built for the drives' setpoint queue \
                 (servo.drive_queue_ms 0)"
                    .into(),
            ));
        }
        if rpm > 0.0 && !self.live.spinning() {
            self.live.hold = self.live.at;
        }
        self.live.target = rpm * 6.0;
        Ok(())
    }

    /// Whether the live tool turns at the speed its last block asked for (stands, for 0).
    pub(super) fn live_tool_at_speed(&self) -> bool {
        self.live.speed == self.live.target
    }

    /// The live tool brakes out of speed mode (program end, reset, emergency stop).
    pub(super) fn stop_live_tool(&mut self) {
        self.live.target = 0.0;
    }

    /// One tick of speed mode: the speed ramps toward the target at the tool's acceleration
    /// and the angle turns on; once it stands again the program's angle 0 is there. While the
    /// PLC's `*SSTP` is low (`allowed` false) the target is 0 and a block waiting for the
    /// speed waits; when it rises the tool runs up to the programmed speed again.
    pub(super) fn spin_live_tool(&mut self, allowed: bool) {
        let Some(tool) = self.cfg.live_tool.as_ref() else {
            return;
        };
        if !self.live.spinning() {
            return;
        }
        let dt = self.cfg.period;
        let step = tool.acceleration() * dt;
        let to = if allowed { self.live.target } else { 0.0 };
        let from = self.live.speed;
        let speed = match to - from {
            d if d.abs() <= step => to,
            d => from + step * d.signum(),
        };
        // The angle turns on at the tick's mean speed (a trapezoid's exact area).
        self.live.at += (from + speed) / 2.0 * dt;
        self.live.speed = speed;
        if !self.live.spinning() {
            self.live.base = self.live.at;
        }
    }

    /// The live tool drive's reported angle (degrees turned) and speed (r/min).
    pub fn live_tool_feedback(&mut self, angle: f64, rpm: f64) {
        if angle.is_finite() {
            self.live.actual = angle;
        }
        if rpm.is_finite() {
            self.live.actual_rpm = rpm;
        }
    }

    /// The live tool drive's reported speed, r/min.
    pub fn live_tool_actual_rpm(&self) -> f64 {
        self.live.actual_rpm
    }

    /// The live tool's speed mode: the speed its last block asked for, r/min (0: position
    /// control), and whether it turns at it (stands, for 0).
    pub fn live_tool_mode(&self) -> (f64, bool) {
        (self.live.target / 6.0, self.live_tool_at_speed())
    }

    /// The live tool's actual angle, degrees since power-on.
    pub fn live_tool_actual(&self) -> f64 {
        self.live.actual
    }

    /// The live tool's angle setpoint, degrees since power-on.
    pub fn live_tool_setpoint(&self) -> f64 {
        self.live.at
    }

    /// The live tool's speed in speed mode, r/min (0 in position control).
    pub fn live_tool_rpm(&self) -> f64 {
        self.live.speed / 6.0
    }
}
