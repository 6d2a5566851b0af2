//! Drive faults: a slide lagging its setpoint beyond its limit, the servo loop overrunning
//! its period; either switches the servo off with the run dropped.

use super::*;

impl Motion {
    /// Compares each slide with the setpoint it was given (the one sent last tick).
    pub(super) fn check_following_error(&mut self) {
        if self.servo_off {
            return;
        }
        let lagging = self.cfg.axes.iter().enumerate().find_map(|(i, a)| {
            // At (or on its way to) a fixed stop the lag is the stop's doing.
            if self.lag_allowed(i) {
                return None;
            }
            let lag = (self.drive[i] - self.actual[i]).abs();
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

    /// A drive fault: servo off, the run dropped, the setpoints held where the slides are
    /// (`000` §11.2: servo alarms switch the servo off).
    pub(super) fn drive_fault(&mut self, number: u32, text: String) {
        let line = self.line;
        self.raise(number, text, line);
        self.queue.clear();
        self.servo_off = true;
        self.commanded.clone_from(&self.actual);
        let here = self.commanded_point();
        self.planner.reset(here);
    }
}
