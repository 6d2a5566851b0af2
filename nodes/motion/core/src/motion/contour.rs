//! The turn-mill's C axis in the path: the main spindle in contour control.
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
