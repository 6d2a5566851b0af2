//! Rigid tapping (G331/G332 and CYCLE84; decisions D101): the spindle, in position control,
//! turns through the tap's revolutions at the programmed speed, and the axes follow its
//! angle. The setpoint is a pure function of the encoder, so the tap stays in its thread
//! whatever the spindle's acceleration and stops where the spindle stops: the drive's
//! positioning ends the block.

use super::*;

/// Most degrees one tap may turn the spindle: what F30–F33 carry (0.001°, 4 bytes).
const MAX_TAP_DEGREES: f64 = 2_000_000.0;

/// A tap in progress: the axes from `start` to `end` (slide units) while the spindle turns
/// `degrees` (signed, + the way M3 turns) at `rpm`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Tap {
    start: Point,
    end: Point,
    degrees: f64,
    rpm: f64,
    /// The spindle's unwrapped angle when the positioning was sent; `None` before.
    from: Option<f64>,
}

/// Puts a stop position in F30–F39 and raises M19: the PLC passes it to the drive (D100).
pub(super) fn strobe_stop_position(fi: &mut FImage, degrees: f64, way: Turn, rpm: f64) {
    fi.write_i32(f::ORIENT_ANGLE, (degrees * 1000.0).round() as i32);
    fi.bytes[f::ORIENT_WAY] = way as u8;
    fi.bytes[f::ORIENT_COUNT] = fi.bytes[f::ORIENT_COUNT].wrapping_add(1);
    fi.write_i32(f::ORIENT_SPEED, rpm.round() as i32);
    fi.write_i32(f::M_CODE, 19);
    for b in [f::DM00, f::DM01, f::DM02, f::DM30] {
        fi.set(b, false);
    }
    fi.set(f::MF, true);
}

impl Motion {
    /// A tap block as the axes' travel and the spindle's: refused when the spindle could not
    /// turn it (auxiliary function lock, above the spindle's rating) or an axis could not
    /// follow (faster than it may move).
    pub(super) fn tap_for(&self, block: &Block, start: &Point) -> Result<Tap, (u32, String)> {
        self.check_block(&block.kind)?;
        let Command::Tap { end, lead, rpm } = &block.kind else {
            return Err((alarm::BAD_BLOCK, "not a tap block".into()));
        };
        self.check_limits(end)?;
        let n = self.cfg.axes.len().min(MAX_AXES);
        let end = self.to_slide(end);
        let long = (0..n)
            .map(|i| (end[i] - start[i]).abs())
            .fold(0.0, f64::max);
        let degrees = 360.0 * long / lead;
        self.geared_move(start, end, degrees, *rpm)
    }

    /// A rotary block (the turn-mill's C axis, D138) as a geared move: the spindle, standing
    /// in position control, turns from its angle now to the block's the way it says, and the
    /// axes follow its angle.
    pub(super) fn rotary_for(&self, block: &Block, start: &Point) -> Result<Tap, (u32, String)> {
        self.check_block(&block.kind)?;
        let Command::Rotary {
            end,
            degrees,
            way,
            rpm,
        } = &block.kind
        else {
            return Err((alarm::BAD_BLOCK, "not a rotary block".into()));
        };
        self.check_limits(end)?;
        if self.encoder.rpm != 0.0 {
            return Err((
                alarm::SPINDLE_NOT_TURNING,
                format!(
                    "the C axis needs the spindle in position mode (M14.6), it turns at {} rpm",
                    self.encoder.rpm
                ),
            ));
        }
        let now = self.encoder.raw_ahead(0.0);
        let travel = match way {
            Turn::Plus => (degrees - now).rem_euclid(360.0),
            Turn::Minus => -(now - degrees).rem_euclid(360.0),
            Turn::Shortest => (degrees - now + 180.0).rem_euclid(360.0) - 180.0,
            Turn::Incremental => *degrees,
        };
        let end = self.to_slide(end);
        let moves = (0..self.cfg.axes.len().min(MAX_AXES)).any(|i| end[i] != start[i]);
        if moves && travel == 0.0 {
            return Err((
                alarm::BAD_BLOCK,
                format!("the axes cannot follow C: it is at {degrees}° already"),
            ));
        }
        // The rotary axis leads (§5.7): it turns slower where an axis could not follow, as a
        // feed is clamped to an axis's rapid rate (D138).
        let revs = travel.abs() / 360.0;
        let mut rpm = *rpm;
        for (i, a) in self.cfg.axes.iter().enumerate().take(MAX_AXES) {
            let per_rev = (end[i] - start[i]).abs() / revs.max(f64::MIN_POSITIVE);
            if per_rev > 0.0 {
                rpm = rpm.min(a.max_velocity / per_rev);
            }
        }
        self.geared_move(start, end, travel, rpm)
    }

    /// The axes from `start` to `end` (slide units) geared to the spindle turning `degrees`
    /// at `rpm`: refused when the spindle could not turn it (auxiliary function lock, above
    /// its rating) or an axis could not follow (faster than it may move).
    fn geared_move(
        &self,
        start: &Point,
        end: Point,
        degrees: f64,
        rpm: f64,
    ) -> Result<Tap, (u32, String)> {
        if self.panel.aux_lock {
            return Err((
                alarm::SPINDLE_NOT_TURNING,
                "a tap or C-axis move needs the spindle: auxiliary function lock is on".into(),
            ));
        }
        if rpm > self.cfg.spindle_max_rpm {
            return Err((
                alarm::BAD_BLOCK,
                format!(
                    "turning the spindle at {rpm} rpm: it is rated {} rpm",
                    self.cfg.spindle_max_rpm
                ),
            ));
        }
        let n = self.cfg.axes.len().min(MAX_AXES);
        if !(degrees.is_finite() && degrees.abs() <= MAX_TAP_DEGREES) {
            return Err((
                alarm::BAD_BLOCK,
                format!("{degrees:e}° of the spindle in one block"),
            ));
        }
        let revs = degrees.abs() / 360.0;
        for (i, a) in self.cfg.axes.iter().enumerate().take(n) {
            let speed = if revs > 0.0 {
                (end[i] - start[i]).abs() / revs * rpm
            } else {
                0.0
            };
            if speed > a.max_velocity + 1e-9 {
                return Err((
                    alarm::THREAD_RUN_IN,
                    format!(
                        "tap at {rpm} rpm moves {} at {speed:.1} mm/min, above its {:.1}",
                        a.name, a.max_velocity
                    ),
                ));
            }
        }
        Ok(Tap {
            start: *start,
            end,
            degrees,
            rpm,
            from: None,
        })
    }

    /// The active tap as the drives gear it (issue 48): start and end in setpoint units and
    /// the spindle's degrees; none without a tap, or with an axis under machine lock.
    pub(super) fn tap_gear(&self) -> Option<([f64; MAX_AXES], [f64; MAX_AXES], f64)> {
        let Some((_, Active::Tap(tap))) = &self.active else {
            return None;
        };
        if self.locked != 0 {
            return None;
        }
        let (mut start, mut end) = ([0.0; MAX_AXES], [0.0; MAX_AXES]);
        for i in 0..self.commanded.len().min(MAX_AXES) {
            start[i] = tap.start[i] - self.shift[i];
            end[i] = tap.end[i] - self.shift[i];
        }
        Some((start, end, tap.degrees))
    }

    /// One tick of a tap: sends the positioning once the axes stand, then sets each axis by
    /// the spindle's angle read ahead by its lead time; true when the PLC's FIN says the
    /// spindle stands at the end, the axes then exactly on it. Feed hold does not stop it.
    pub(super) fn tap_tick(&mut self, tap: &mut Tap, plc: &GImage, in_pos: bool) -> bool {
        let e = self.encoder;
        let Some(from) = tap.from else {
            if in_pos && !plc.get(g::FIN) && self.locked_move_may_start() {
                tap.from = Some(e.turned);
                strobe_stop_position(&mut self.f, tap.degrees, Turn::Incremental, tap.rpm);
            }
            return false;
        };
        let n = self.commanded.len().min(MAX_AXES);
        if plc.get(g::FIN) {
            self.commanded[..n].copy_from_slice(&tap.end[..n]);
            self.clear_strobe();
            return true;
        }
        for i in 0..n {
            let ahead = e.turned + e.rpm / 60.0 * 360.0 * self.thread_lead_time[i];
            let share = if tap.degrees != 0.0 {
                ((ahead - from) / tap.degrees).clamp(0.0, 1.0)
            } else {
                1.0
            };
            self.commanded[i] = tap.start[i] + (tap.end[i] - tap.start[i]) * share;
        }
        false
    }
}
