//! Feedforward of the drives (FFWON/FFWOF; decisions D106) and the program's acceleration
//! override (ACC; D108): the two settings a program makes on the axes' dynamics.
//!
//! Feedforward (D106). A drive trails a moving
//! setpoint by its lag (velocity × time constant): the following error. With feedforward the
//! setpoint each drive gets leads the commanded position by that much, so the slide stands on
//! the commanded path and the following error is (nearly) zero. The lead is the axis's
//! velocity over the last servo period, bounded by its rated speed, and is only added while a
//! block moves the axes along the program's path, so a jump of the position (a reset taking
//! the slides where they stand) never becomes a kick of the drive.

use super::*;

impl Motion {
    /// The setpoints of this tick as the drives get them: the drive position less the
    /// reference shift, plus the feedforward lead.
    pub(super) fn drive_output(&mut self) {
        let on = self.feedforward
            && !self.servo_off
            && matches!(
                self.active,
                Some((
                    _,
                    Active::Path | Active::Rapid { .. } | Active::Thread { .. } | Active::Tap(_)
                ))
            );
        let period = self.cfg.period.max(1e-6);
        for (i, a) in self.cfg.axes.iter().enumerate().take(self.drive.len()) {
            let lead = if on {
                let limit = a.max_velocity / 60.0;
                let v = (self.drive[i] - self.last_drive[i]) / period;
                v.clamp(-limit, limit) * a.drive_lag.max(0.0)
            } else {
                0.0
            };
            self.encoder_setpoint[i] = self.drive[i] + lead + self.press(i) - self.shift[i];
            self.last_drive[i] = self.drive[i];
        }
        let mut sent = [0.0; MAX_AXES];
        let n = self.drive.len().min(MAX_AXES);
        sent[..n].copy_from_slice(&self.drive[..n]);
        self.sent_drive.push_back(sent);
        while self.sent_drive.len() > self.cfg.feedback_delay_ticks.max(1) as usize {
            self.sent_drive.pop_front();
        }
    }

    /// The drive setpoints the latest feedback answers, per axis into `out`.
    pub fn answered_setpoint(&self, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate().take(self.drive.len()) {
            *o = self.answered_drive(i);
        }
    }

    /// The drive setpoint the latest feedback answers: the one sent `feedback_delay_ticks`
    /// ago (the current one before that many were sent).
    pub(super) fn answered_drive(&self, i: usize) -> f64 {
        match self.sent_drive.front() {
            Some(s) if self.sent_drive.len() >= self.cfg.feedback_delay_ticks.max(1) as usize => {
                s[i]
            }
            _ => self.drive[i],
        }
    }

    /// ACC: an axis at `share` of its rated acceleration from the next block on; the
    /// look-ahead stops at the change, so no segment planned at the old value runs after it.
    pub(super) fn set_acceleration_override(&mut self, axis: usize, share: f64) {
        if axis == usize::from(cnc_msgs::canon::SPINDLE_AXIS) {
            self.spindle_acceleration = share.clamp(0.01, 2.0);
            return;
        }
        let rated = self.cfg.planner().limits.acceleration;
        if let Some(a) = rated.get(axis).filter(|_| axis < self.cfg.axes.len()) {
            self.planner
                .set_acceleration(axis, a * share.clamp(0.01, 2.0));
        }
    }

    /// The spindle drive's acceleration, percent of its rated (`ACC[S]`): sent to the drives
    /// with every setpoint.
    /// What the drives get with this tick's positions: enable, the spindle's acceleration
    /// share and the axes' torque limits (the node and the test rig send the same).
    pub fn fill_setpoint(&self, sp: &mut cnc_msgs::servo::ServoSetpoint) {
        sp.enable = u32::from(self.servo_enabled());
        sp.spindle_acceleration_percent = self.spindle_acceleration_percent();
        sp.torque_limit_percent = self.torque_limits();
        self.fill_scaling(sp);
        self.fill_contour(sp);
    }

    pub fn spindle_acceleration_percent(&self) -> f64 {
        self.spindle_acceleration * 100.0
    }

    /// Every axis (and the spindle) at its rated acceleration (a run's start, reset).
    pub(super) fn rated_accelerations(&mut self) {
        self.spindle_acceleration = 1.0;
        let rated = self.cfg.planner().limits.acceleration;
        for (i, a) in rated.iter().enumerate().take(self.cfg.axes.len()) {
            self.planner.set_acceleration(i, *a);
        }
    }
}
