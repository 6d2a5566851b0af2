//! Time-scaling of the queued path at the drives (issue 48, D135): feed hold and the overrides
//! act where the setpoints are played, so their reaction is one tick whatever the queue's
//! length. The drives advance along the queued path at a rate s (1: a setpoint a tick; 0:
//! standing on the path) and change s no faster than each axis's acceleration allows.

use cnc_msgs::servo::{DriveControl, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{g, GImage, SignalTable};

/// What the drives are told beside the queue, each tick: the operator's feed hold and
/// overrides (from the PLC's G image and motion) and whether a reset stops them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    pub hold: bool,
    /// Feed override now, 0–1.5.
    pub feed_override: f64,
    /// Rapid override now, 0–1.
    pub rapid_override: f64,
    /// A reset: stop on the path whatever the setpoints are, then drop the queue.
    pub reset: bool,
    /// The PLC's jog keys, a bit per axis signal: +J (G100), −J (G102).
    pub jog_keys: (u32, u32),
    /// Single block (the PLC's SBK): the drives stop at the end of the block they play.
    pub single_block: bool,
    /// The cycle starts motion has taken: one releases the drives from a block's end.
    pub starts: u32,
}

impl Default for Scaling {
    fn default() -> Self {
        Scaling {
            hold: false,
            feed_override: 1.0,
            rapid_override: 1.0,
            reset: false,
            jog_keys: (0, 0),
            single_block: false,
            starts: 0,
        }
    }
}

impl Scaling {
    /// Whether the jog key a `SCALE_JOG` setpoint names (`ServoSetpoint::jog_key`) is held.
    pub fn jog_key_held(&self, key: i32) -> bool {
        let bit = |k: i32| {
            1u32.checked_shl((k.unsigned_abs()).saturating_sub(1))
                .unwrap_or(0)
        };
        match key {
            k if k > 0 => self.jog_keys.0 & bit(k) != 0,
            k if k < 0 => self.jog_keys.1 & bit(k) != 0,
            _ => false,
        }
    }

    /// The rate a setpoint of `scaling` (`ServoSetpoint::SCALE_*`) planned at feed override
    /// `planned` is to be played at. Rates above 1 would outrun the queue and the
    /// accelerations the path was planned with: an override above 100 % acts through
    /// planning instead (D135).
    pub fn target(&self, scaling: u32, planned: f64) -> f64 {
        if self.reset {
            return 0.0;
        }
        let clean = |v: f64| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                1.0
            }
        };
        match scaling {
            ServoSetpoint::SCALE_FIXED
            | ServoSetpoint::SCALE_GEARED
            | ServoSetpoint::SCALE_THREAD
            | ServoSetpoint::SCALE_JOG => 1.0,
            _ if self.hold => 0.0,
            ServoSetpoint::SCALE_FEED if planned > 0.0 => clean(self.feed_override / planned),
            ServoSetpoint::SCALE_RAPID => clean(self.rapid_override),
            _ => 1.0,
        }
    }
}

/// The drives' feed hold. The PLC's `*SP` (the panel's feed-hold key) reaches the drives
/// straight from its G image and holds them at once, motion or not; motion's own hold (a
/// request from the cell) comes with [`DriveControl`]. A hold taken from `*SP` lasts until
/// motion has taken a cycle start or reset after it (its counters move), as the NC's hold
/// lasts until cycle start (`000` §7.4).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HoldLatch {
    plc_hold: bool,
    control: Option<DriveControl>,
}

impl HoldLatch {
    /// This tick's scaling from the PLC's G image and motion's latest control.
    pub fn update(&mut self, plc: &GImage, control: Option<DriveControl>) -> Scaling {
        if let Some(c) = control {
            if let Some(old) = self.control {
                if c.starts != old.starts || c.resets != old.resets {
                    self.plc_hold = false;
                }
            }
            self.control = Some(c);
        }
        if !plc.get(g::SP_N) && plc.get(g::ESP_N) {
            self.plc_hold = true;
        }
        if !plc.get(g::ESP_N) {
            self.plc_hold = false;
        }
        let motion_hold = self.control.is_some_and(|c| c.hold != 0);
        let mut jog_keys = (0, 0);
        for k in 0..8 {
            jog_keys.0 |= u32::from(plc.get(g::jog_plus(k))) << k;
            jog_keys.1 |= u32::from(plc.get(g::jog_minus(k))) << k;
        }
        Scaling {
            hold: self.plc_hold || motion_hold,
            feed_override: plc.feed_override(),
            rapid_override: plc.rapid_override(),
            reset: false,
            jog_keys,
            single_block: plc.get(g::SBK),
            starts: self.control.map_or(0, |c| c.starts),
        }
    }

    /// The resets motion has taken (0 before it told any).
    pub fn resets(&self) -> u32 {
        self.control.map_or(0, |c| c.resets)
    }
}

/// The next rate from `s` toward `target`: the one nearest `target` whose tick `fits` (keeps
/// every axis within its acceleration); keeping `s` always fits, as the path was planned
/// within the limits. Bisection on the share of the change: the realised positions are
/// checked, not an estimate of them.
pub fn next_rate(s: f64, target: f64, fits: impl Fn(f64) -> bool) -> f64 {
    let target = target.clamp(0.0, 1.0);
    if target == s || fits(target) {
        return target;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if fits(s + (target - s) * mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (s + (target - s) * lo).clamp(0.0, 1.0)
}

/// Whether a tick that moves the axes from `here` to `to` keeps each axis's change of step
/// against `step` (the last tick's) within `limit`, or no larger than `keeping` (the tick at
/// the unchanged rate) makes it.
pub fn within(
    limit: &[f64; MAX_AXES],
    here: &[f64; MAX_AXES],
    step: &[f64; MAX_AXES],
    keeping: &[f64; MAX_AXES],
    to: &[f64; MAX_AXES],
) -> bool {
    (0..MAX_AXES).all(|i| {
        let change = (to[i] - here[i] - step[i]).abs();
        let kept = (keeping[i] - here[i] - step[i]).abs();
        change <= limit[i].max(kept) * (1.0 + 1e-12)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rate goes to its target when that fits, else as near as fits.
    #[test]
    fn the_rate_goes_as_near_its_target_as_fits() {
        assert_eq!(next_rate(1.0, 0.0, |_| true), 0.0);
        let s = next_rate(1.0, 0.0, |r| r >= 0.75);
        assert!((s - 0.75).abs() < 1e-9, "{s}");
        assert_eq!(next_rate(0.5, 2.0, |_| true), 1.0, "never above 1");
        let mut p = [0.0; MAX_AXES];
        let limit = [0.024; MAX_AXES];
        p[0] = 0.4;
        let here = [0.0; MAX_AXES];
        let mut to = [0.0; MAX_AXES];
        to[0] = 0.38;
        assert!(within(&limit, &here, &p, &p, &to));
        to[0] = 0.37;
        assert!(!within(&limit, &here, &p, &p, &to));
    }

    /// Feed hold stops every setpoint but a fixed one; overrides scale feeds and rapids, and
    /// never above 1.
    #[test]
    fn the_target_rate_follows_hold_and_overrides() {
        let mut sc = Scaling {
            feed_override: 0.5,
            rapid_override: 0.25,
            ..Scaling::default()
        };
        assert_eq!(sc.target(ServoSetpoint::SCALE_FEED, 1.0), 0.5);
        assert_eq!(sc.target(ServoSetpoint::SCALE_FEED, 1.25), 0.4);
        assert_eq!(sc.target(ServoSetpoint::SCALE_RAPID, 1.0), 0.25);
        assert_eq!(sc.target(ServoSetpoint::SCALE_WAIT, 1.0), 1.0);
        sc.feed_override = 1.5;
        assert_eq!(sc.target(ServoSetpoint::SCALE_FEED, 1.0), 1.0);
        sc.hold = true;
        for k in [
            ServoSetpoint::SCALE_WAIT,
            ServoSetpoint::SCALE_FEED,
            ServoSetpoint::SCALE_RAPID,
        ] {
            assert_eq!(sc.target(k, 1.0), 0.0);
        }
        assert_eq!(sc.target(ServoSetpoint::SCALE_FIXED, 1.0), 1.0);
        sc.reset = true;
        assert_eq!(sc.target(ServoSetpoint::SCALE_FIXED, 1.0), 0.0);
    }

    /// `*SP` holds at once and until motion's next cycle start or reset; motion's hold holds
    /// while it lasts.
    #[test]
    fn the_hold_latch_takes_the_plcs_key_and_motions_hold() {
        let mut latch = HoldLatch::default();
        let mut plc = GImage::released();
        let c = |hold, starts, resets| {
            Some(DriveControl {
                hold,
                starts,
                resets,
            })
        };
        assert!(!latch.update(&plc, c(0, 0, 0)).hold);
        plc.set(g::SP_N, false);
        assert!(latch.update(&plc, None).hold, "the key holds at once");
        plc.set(g::SP_N, true);
        assert!(latch.update(&plc, c(1, 0, 0)).hold, "until cycle start");
        assert!(latch.update(&plc, c(1, 0, 0)).hold);
        assert!(!latch.update(&plc, c(0, 1, 0)).hold, "cycle start releases");
        assert!(latch.update(&plc, c(1, 1, 0)).hold, "motion's own hold");
        plc.set(g::SP_N, false);
        assert!(latch.update(&plc, c(0, 1, 0)).hold);
        plc.set(g::SP_N, true);
        assert!(!latch.update(&plc, c(0, 1, 1)).hold, "a reset releases");
        assert_eq!(latch.resets(), 1);
        plc.bytes[g::FEED_OVERRIDE as usize] = 50;
        assert_eq!(latch.update(&plc, None).feed_override, 0.5);
    }
}
