//! The turn-mill's spindle-driven axes in the path: C in contour control and the live tool.
//!
//! C (polar interpolation, D141): between the
//! interpreter's `Contour { on: true }` and `Contour { on: false }` the main spindle, standing
//! in position control at C 0, is one more path axis — planned after the machine's axes, in
//! degrees, at its own rate and acceleration — and follows each tick's C setpoint as an axis
//! drive follows its position (the spindle drive's cyclic position mode). Outside it C is not
//! planned: block ends take the C where it stands, so nothing moves it.

use super::*;

/// How far from the encoder's 0° the spindle may stand when polar interpolation starts,
/// degrees (its positioning's in-position band).
const START_BAND: f64 = 0.001;

/// How far a blended corner may leave the machine's path in contour control: mm of X's
/// slide, degrees of C (0.07 µm of face at 20 mm from the pole). The machine's tolerance is
/// mm of every axis; in X and C it would bend the face's contour by more than the
/// transformation's own 0.25 µm.
const CONTOUR_BLEND: f64 = 0.000_2;

/// The C axis's state in the path.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Contour {
    /// In contour control: the spindle follows `at`.
    pub(super) on: bool,
    /// The encoder's angle (signed, degrees) where the program's C is 0.
    base: f64,
    /// C's setpoint, degrees in the encoder's count (unwrapped): the planner's last point.
    pub(super) at: f64,
}

impl Motion {
    /// A block end's C in the planner's units: the program's C from the base while contour
    /// control is on, else where C stands (nothing moves it).
    pub(super) fn contour_end(&self, p: &[f64], out: &mut Point) {
        let Some(c) = self.cfg.contour_axis() else {
            return;
        };
        out[c] = match (self.contour.on, p.get(c)) {
            (true, Some(v)) => self.contour.base + v,
            _ => self.contour.at,
        };
    }

    /// The planner's point of the commanded position, C included.
    pub(super) fn with_contour(&self, mut p: Point) -> Point {
        if let Some(c) = self.cfg.contour_axis() {
            p[c] = self.contour.at;
        }
        p
    }

    /// `Contour { on }` taken at rest: on, the spindle must stand in position control at
    /// the encoder's 0° (§5.8, "极坐标插补的刀具位置必须从角度为 0 的位置开始"); off, the spindle
    /// holds where the path left it.
    pub(super) fn contour_block(&mut self, on: bool) -> Result<(), (u32, String)> {
        if !on {
            self.contour.on = false;
            return Ok(());
        }
        if self.cfg.contour_axis().is_none() {
            return Err((
                alarm::BAD_BLOCK,
                "polar interpolation: this machine has no C axis in contour control".into(),
            ));
        }
        if self.cfg.time_scaling_at_drives {
            return Err((
                alarm::BAD_BLOCK,
                "polar interpolation is not built for the drives' setpoint queue \
                 (servo.drive_queue_ms 0)"
                    .into(),
            ));
        }
        if self.encoder.rpm != 0.0 {
            return Err((
                alarm::SPINDLE_NOT_TURNING,
                format!(
                    "polar interpolation needs the spindle in position mode at C 0 (M14.6, \
                     G00 C0); it turns at {} rpm",
                    self.encoder.rpm
                ),
            ));
        }
        let raw = self.encoder.raw_ahead(0.0);
        let signed = (raw + 180.0).rem_euclid(360.0) - 180.0;
        if signed.abs() > START_BAND {
            return Err((
                alarm::BAD_BLOCK,
                format!("polar interpolation starts at C 0: the spindle stands at {raw:.4}°"),
            ));
        }
        self.contour = Contour {
            on: true,
            base: signed,
            at: signed,
        };
        Ok(())
    }

    /// The share of the path tolerance a block's corners may not use: all but
    /// [`CONTOUR_BLEND`] in contour control, none outside it.
    pub(super) fn contour_used(&self) -> f64 {
        match self.contour.on {
            true => (self.cfg.tolerance - CONTOUR_BLEND).max(0.0),
            false => 0.0,
        }
    }

    /// This tick's C setpoint from the planner's point `out`.
    pub(super) fn contour_tick(&mut self, out: &Point) {
        if let (true, Some(c)) = (self.contour.on, self.cfg.contour_axis()) {
            self.contour.at = out[c];
        }
    }

    /// What the drives get for C (whether the spindle follows, and where to) and the live
    /// tool.
    pub fn fill_contour(&self, sp: &mut cnc_msgs::servo::ServoSetpoint) {
        let follow = self.contour.on && self.locked == 0;
        sp.c_contour = u32::from(follow);
        sp.c_position = if follow { self.contour.at } else { 0.0 };
        sp.live_tool_position = self.live_tool_lead();
    }

    /// C's setpoint while contour control is on (degrees from where polar interpolation
    /// started), for the path view and the tests.
    pub fn contour_c(&self) -> Option<f64> {
        self.contour
            .on
            .then_some(self.contour.at - self.contour.base)
    }
}

/// The live tool in the path (D142): its drive in position control follows the planner's
/// angle, so a tap with the live tool (G14.n) is one move of the slides and the tool's angle,
/// geared by the interpolation itself. The program's angle starts at 0 with every run; `base`
/// is where the drive stood then.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct LiveTool {
    /// The drive's setpoint, degrees since power-on.
    pub(super) at: f64,
    /// The setpoint before this tick, for the tool's speed.
    pub(super) last: f64,
    base: f64,
    /// The drive's actual angle, as its feedback says.
    actual: f64,
    /// How much longer the tool's drive lags than the slides', s (the config's lags).
    lead_time: f64,
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
}

impl Motion {
    /// A block end's live tool angle in the planner's units.
    pub(super) fn live_tool_end(&self, p: &[f64], out: &mut Point) {
        if let Some(i) = self.cfg.live_tool_axis() {
            out[i] = match p.get(i) {
                Some(v) => self.live.base + v,
                None => self.live.at,
            };
        }
    }

    /// A run starts: the program's live tool angle 0 is where the drive stands.
    pub(super) fn live_tool_run(&mut self) {
        self.live.base = self.live.at;
    }

    /// The planner's point with the live tool where it stands.
    pub(super) fn with_live_tool(&self, mut p: Point) -> Point {
        if let Some(i) = self.cfg.live_tool_axis() {
            p[i] = self.live.at;
        }
        p
    }

    /// This tick's live tool setpoint from the planner's point `out`.
    pub(super) fn live_tool_tick(&mut self, out: &Point) {
        if let Some(i) = self.cfg.live_tool_axis() {
            if self.locked == 0 {
                self.live.at = out[i];
            }
        }
    }

    /// The setpoint the live tool's drive gets: ahead of the path by the time its position
    /// loop lags the slides' more (its drive lag less theirs, the commissioning values in the
    /// config), so the tool's actual angle keeps to the slides' actual travel as a tap
    /// needs — what matched loop gains do on a control's rigid tapping.
    fn live_tool_lead(&self) -> f64 {
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

    /// The live tool drive's reported angle.
    pub fn live_tool_feedback(&mut self, angle: f64) {
        if angle.is_finite() {
            self.live.actual = angle;
        }
    }

    /// The live tool's actual angle, degrees since power-on.
    pub fn live_tool_actual(&self) -> f64 {
        self.live.actual
    }

    /// The live tool's angle setpoint, degrees since power-on.
    pub fn live_tool_setpoint(&self) -> f64 {
        self.live.at
    }
}
