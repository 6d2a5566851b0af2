//! With the drives' setpoint queue (issue 48, D135) feed hold and the overrides act at the
//! drives, which time-scale the queued path within a tick; the core plans as if they were off
//! and tells the drives, with every setpoint, how it may be scaled. Spindle-locked moves
//! cannot be scaled: a thread or tap starts only after a queue's length of unscaled waiting,
//! so the encoder reading its start is computed from was taken at the rate it plays at; a
//! rigid tap is geared to the spindle's encoder at the drives (its start, end and degrees go
//! with each setpoint), a thread is played by it (each setpoint says the encoder angle it is
//! for, D136).

use cnc_msgs::servo::{DriveControl, ServoSetpoint};

use super::*;

/// What the core leaves to the drives, and what it tells them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct AtDrives {
    /// Feed hold and the overrides act at the drives.
    pub on: bool,
    /// Ticks the active thread or tap has waited, its setpoints unscaled.
    pub locked_wait: u32,
    /// The drives stand at a block's end for single block (their feedback says so).
    pub block_stop: bool,
    /// The block the last setpoint was cut in, and where this one's began (D137).
    pub cut: block_ends::CutBlock,
    /// Cycle starts and resets taken (wrapping): they release the drives' hold.
    pub starts: u32,
    pub resets: u32,
}

impl Motion {
    /// Feed hold as the core's own path takes it: with the drives time-scaling, only a cycle
    /// stop (a planned end of the run) slows it.
    pub(super) fn planning_hold(&self) -> bool {
        self.feed_hold && (!self.at_drives.on || self.cycle_stop)
    }

    /// The feed override the path is planned at: with the drives time-scaling, at least
    /// 100 % (above it the override acts through planning, D135).
    pub(super) fn planning_feed_override(&self) -> f64 {
        match self.at_drives.on {
            true => self.panel.feed_override.max(1.0),
            false => self.panel.feed_override,
        }
    }

    /// The rapid override rapids are planned at (all of it at the drives when they scale).
    pub(super) fn planning_rapid_override(&self) -> f64 {
        match self.at_drives.on {
            true => 1.0,
            false => self.panel.rapid_override,
        }
    }

    /// Single block as the core takes it: with the drives time-scaling, the drives stop at a
    /// block's end (D137); the core only gives every block a tick of its own, so each ends
    /// where the setpoints' line changes.
    pub(super) fn planning_block_stop(&self) -> bool {
        !self.at_drives.on
    }

    /// The drives' feedback: they stand at a block's end for single block, until a cycle
    /// start (D137).
    pub fn drives_at_block_end(&mut self, standing: bool) {
        self.at_drives.block_stop = standing;
    }

    /// Counts the ticks a thread or tap has been active (its setpoints unscaled).
    pub(super) fn count_locked_wait(&mut self) {
        let locked = matches!(
            self.active,
            Some((_, Active::Thread { .. } | Active::Tap(_)))
        );
        self.at_drives.locked_wait = match locked {
            true => self.at_drives.locked_wait.saturating_add(1),
            false => 0,
        };
    }

    /// A thread or tap may start: the encoder reading it starts from is of a tick played at a
    /// setpoint a tick (always, without the drives' scaling).
    pub(super) fn locked_move_may_start(&self) -> bool {
        !self.at_drives.on || self.at_drives.locked_wait > self.cfg.feedback_delay_ticks
    }

    /// How the drives may scale this tick's setpoint, the feed override it was planned at,
    /// and for a tap what they gear to the spindle.
    pub fn fill_scaling(&self, sp: &mut ServoSetpoint) {
        (sp.scaling, sp.planned_override) = self.setpoint_scaling();
        if !self.at_drives.on {
            return;
        }
        sp.line = self.at_drives.cut.line();
        sp.block_start = self.at_drives.cut.began;
        if let Some(key) = self.held_jog_key() {
            sp.scaling = ServoSetpoint::SCALE_JOG;
            sp.jog_key = key;
        }
        if let Some((angle, rpm)) = self.thread_cam() {
            sp.scaling = ServoSetpoint::SCALE_THREAD;
            sp.thread_angle = angle;
            sp.thread_rpm = rpm;
        }
        if let Some((start, end, degrees)) = self.tap_gear() {
            sp.scaling = ServoSetpoint::SCALE_GEARED;
            sp.gear_start = start;
            sp.gear_end = end;
            sp.gear_degrees = degrees;
        }
    }

    /// The active thread as the drives play it by their encoder (D136): the angle the encoder
    /// is to show when this tick's setpoint plays (its reading a queue's length ago, at the
    /// speed then) and the speed its lead was computed at; none without a thread, or with an
    /// axis under machine lock.
    fn thread_cam(&self) -> Option<(f64, f64)> {
        if !matches!(self.active, Some((_, Active::Thread { .. }))) || self.locked != 0 {
            return None;
        }
        // The drives play tick j with the reading of tick j − 1; this one is of j − delay.
        let ticks = self.cfg.feedback_delay_ticks.max(1) - 1;
        let e = &self.encoder;
        Some((e.raw_ahead(f64::from(ticks) * self.cfg.period), e.rpm))
    }

    /// How the drives may scale this tick's setpoint, and the feed override it was planned at.
    pub fn setpoint_scaling(&self) -> (u32, f64) {
        let kind = match &self.active {
            Some((_, Active::Path)) => ServoSetpoint::SCALE_FEED,
            Some((_, Active::Rapid { .. })) => ServoSetpoint::SCALE_RAPID,
            Some((_, Active::Dwell { .. } | Active::Aux { .. })) => ServoSetpoint::SCALE_WAIT,
            _ => ServoSetpoint::SCALE_FIXED,
        };
        (kind, self.planning_feed_override())
    }

    /// What the drives are told beside the queue: feed hold (not a cycle stop's, which the
    /// core plans), the cycle starts and resets taken.
    pub fn drive_control(&self) -> DriveControl {
        DriveControl {
            hold: u32::from(self.feed_hold && !self.cycle_stop),
            starts: self.at_drives.starts,
            resets: self.at_drives.resets,
        }
    }

    /// After a reset or a jog key's release the drives stopped on the queued path at
    /// `setpoint` (encoder counts): the core stands there, its jog ended and its sent
    /// setpoints forgotten.
    pub fn stand_at(&mut self, setpoint: &[f64]) {
        self.jog = None;
        self.key_jog = false;
        for (i, s) in setpoint.iter().enumerate().take(self.commanded.len()) {
            if s.is_finite() {
                self.commanded[i] = s + self.shift[i];
                self.drive[i] = self.commanded[i];
                self.last_drive[i] = self.commanded[i];
            }
        }
        self.sent_drive.clear();
        let here = self.commanded_point();
        self.planner.reset(here);
    }
}
