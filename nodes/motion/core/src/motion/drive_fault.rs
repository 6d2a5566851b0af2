//! Drive faults: a slide lagging its setpoint beyond its limit, the servo loop overrunning
//! its period; either switches the servo off with the run dropped.

use super::*;

impl Motion {
    /// Compares each slide with the setpoint it was given (the one sent last tick).
    pub(super) fn check_following_error(&mut self) {
        // A position that is no number (a drive that reports NaN, a setpoint gone infinite)
        // is the axis's servo alarm too, whether or not the servo is on: every comparison
        // with it is false, so without this the machine would run on blind (issue 45).
        let lost = (0..self.cfg.axes.len())
            .find(|&i| !(self.actual[i].is_finite() && self.drive[i].is_finite()));
        if let Some(i) = lost {
            if !self.servo_off || self.state() != RunState::Alarm {
                let text = format!(
                    "{}: no valid position (drive {}, setpoint {})",
                    self.cfg.axes[i].name, self.actual[i], self.drive[i]
                );
                self.drive_fault(alarm::FOLLOWING_ERROR, text);
            }
            return;
        }
        if self.servo_off {
            return;
        }
        let lagging = self.cfg.axes.iter().enumerate().find_map(|(i, a)| {
            // At (or on its way to) a fixed stop the lag is the stop's doing.
            if self.lag_allowed(i) {
                return None;
            }
            let lag = (self.answered_drive(i) - self.actual[i]).abs();
            let limit = a.following_error_limit();
            (lag > limit).then(|| {
                format!(
                    "following error: {} lags its setpoint by {lag:.3} mm (limit {limit:.3})",
                    a.name
                )
            })
        });
        if let Some(text) = lagging {
            self.drive_fault(alarm::FOLLOWING_ERROR, text);
        }
    }

    /// The servo loop cannot keep its period: the servo alarm, the axes stop where they are
    /// and the servo is switched off, as for a drive fault (D57).
    pub fn servo_overrun(&mut self, text: String) {
        self.drive_fault(alarm::SERVO_OVERRUN, text);
    }

    /// The setpoints put where the slides are, so nothing jumps when the servo comes back; an
    /// axis with no valid position keeps its last setpoint.
    pub(super) fn hold_where_slides_are(&mut self) {
        for (c, a) in self.commanded.iter_mut().zip(&self.actual) {
            if a.is_finite() {
                *c = *a;
            }
        }
    }

    /// A drive fault: servo off, the run dropped, the setpoints held where the slides are
    /// (`000` §11.2: servo alarms switch the servo off).
    pub(super) fn drive_fault(&mut self, number: u32, text: String) {
        let line = self.line;
        self.raise(number, text, line);
        self.queue.clear();
        self.servo_off = true;
        self.hold_where_slides_are();
        let here = self.commanded_point();
        self.planner.reset(here);
    }
}
