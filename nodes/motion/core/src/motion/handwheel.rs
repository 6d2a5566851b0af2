//! The handwheel (manual pulse generator; issue 28, decisions D72; Huaxing `000` §8.2 and
//! §19.4.2.4). The drives' bus reports the wheel's counter with every feedback, four counts a
//! detent; in HANDWHEEL mode each detent moves the axis the PLC selects (G18 HS1A–HS1C) by
//! 0.001 mm × 1, 10 or 100 (G19 MP1/MP2). The axis follows the wheel at up to
//! [`HANDWHEEL_MAX_FEED`]; what it cannot follow within [`MAX_LAG_S`] is dropped, so the axis
//! stands soon after the wheel does, however fast it was turned.
//!
//! In the handwheel trial run (`000` §13.3; D74) the wheel drives the program instead: in
//! AUTO with the trial switch on, the path moves as fast as the wheel turns clockwise (a
//! detent is 0.001 mm × the multiplier of path), never faster than programmed.

use cnc_msgs::msg::MachineState;
use cnc_msgs::signals::{f, g, GImage, SignalTable};

use super::Motion;

/// The handwheel's speed limit, mm/min (the manual's S#48 default).
pub const HANDWHEEL_MAX_FEED: f64 = 6000.0;
/// The handwheel's time constant over the axis's rapid one (S#47 default 150 %): its
/// acceleration is the axis's over this.
const ACCELERATION_DIVISOR: f64 = 1.5;
/// How far the axis may trail the wheel, in seconds at the speed limit.
pub const MAX_LAG_S: f64 = 0.1;
/// Counts a detent (4× quadrature).
const COUNTS_PER_DETENT: i32 = 4;
/// More counts than this in one servo period is not a hand (250 revolutions a second at
/// 4 ms): an encoder fault, and the jump is dropped.
const MAX_COUNTS_PER_PERIOD: i32 = 400;

/// Periods over which the trial run measures the wheel's speed (100 ms at 4 ms).
const TRIAL_WINDOW: usize = 25;

/// The handwheel trial run: the wheel's speed of the last [`TRIAL_WINDOW`] periods as the
/// path's speed limit.
#[derive(Debug, Clone, Default)]
pub(super) struct TrialRun {
    /// Clockwise detents of the last periods, a ring.
    detents: [i32; TRIAL_WINDOW],
    next: usize,
    /// In effect: the switch on in AUTO.
    on: bool,
    /// The wheel's speed, mm of path a second.
    speed: f64,
}

impl TrialRun {
    /// The path speed no block may exceed: the wheel's in a trial run, none otherwise.
    pub(super) fn speed_cap(&self) -> f64 {
        if self.on {
            self.speed
        } else {
            f64::INFINITY
        }
    }
}

/// The wheel's counter and the move it gives.
#[derive(Debug, Clone, Default)]
pub(super) struct Handwheel {
    /// The counter of the last feedback; `None` before the first.
    count: Option<i32>,
    /// Counts since the last servo period took them.
    counts: i32,
    moving: Option<HandwheelMove>,
}

/// The axis following the wheel.
#[derive(Debug, Clone)]
struct HandwheelMove {
    axis: usize,
    /// Where the wheel has sent it (slide, machine coordinates).
    target: f64,
    /// mm/s of slide.
    velocity: f64,
}

impl Handwheel {
    /// Drops the move (an alarm, a reset, an emergency stop: the setpoint stays where it is).
    pub(super) fn stop(&mut self) {
        self.moving = None;
    }

    pub(super) fn moving(&self) -> bool {
        self.moving.is_some()
    }
}

/// The G18 HS1 code: 1 X … 6 C, 0 none.
fn selected_code(plc: &GImage) -> u8 {
    u8::from(plc.get(g::HS1A)) | u8::from(plc.get(g::HS1B)) << 1 | u8::from(plc.get(g::HS1C)) << 2
}

/// The handwheel's multiplier from MP1/MP2: ×1, ×10 (MP1), ×100 (MP2 or both; the manual's
/// handwheel has no ×1000).
fn multiplier(plc: &GImage) -> f64 {
    match (plc.get(g::MP1), plc.get(g::MP2)) {
        (false, false) => 1.0,
        (true, false) => 10.0,
        (_, true) => 100.0,
    }
}

/// One period of an axis following `target` from `here` at `velocity` within `speed` and
/// `accel`: the next position and velocity. It brakes to stop on the target and turns back
/// when the target moved behind it.
fn follow(here: f64, velocity: f64, target: f64, speed: f64, accel: f64, dt: f64) -> (f64, f64) {
    let left = target - here;
    let step = accel * dt;
    // The speed from which braking a step per period, each period's speed moving the axis
    // for that period, stops it within `left`: v (v + step) / 2a = left.
    let brake = (-step + (step * step + 8.0 * accel * left.abs()).sqrt()) / 2.0;
    let want = left.signum() * brake.min(speed);
    let v = velocity + (want - velocity).clamp(-step, step);
    let next = here + v * dt;
    // On or past the target slowly enough to stop there within a period: stop on it.
    if (target - next) * left <= 0.0 && v.abs() <= 2.0 * step {
        return (target, 0.0);
    }
    (next, v)
}

impl Motion {
    /// The handwheel counter of the latest drive feedback (called every servo period before
    /// [`Motion::tick`]).
    pub fn handwheel_input(&mut self, count: i32) {
        let h = &mut self.handwheel;
        if let Some(last) = h.count {
            let d = count.wrapping_sub(last);
            if d.abs() <= MAX_COUNTS_PER_PERIOD {
                h.counts = h.counts.saturating_add(d);
            }
        }
        h.count = Some(count);
    }

    /// The whole detents turned since the last period (a part detent waits for the rest).
    pub(super) fn take_detents(&mut self) -> i32 {
        let d = self.handwheel.counts / COUNTS_PER_DETENT;
        self.handwheel.counts -= d * COUNTS_PER_DETENT;
        d
    }

    /// The trial run's wheel speed from this period's `detents` (G19.6, AUTO mode; D74).
    pub(super) fn trial_run(&mut self, plc: &GImage, detents: i32, dt: f64) {
        let t = &mut self.trial;
        t.on = plc.get(g::HANDWHEEL_TRIAL) && self.mode == MachineState::MODE_AUTO;
        t.detents[t.next] = if t.on { detents.max(0) } else { 0 };
        t.next = (t.next + 1) % TRIAL_WINDOW;
        let turned: i32 = t.detents.iter().sum();
        t.speed = f64::from(turned) * 0.001 * multiplier(plc) / (TRIAL_WINDOW as f64 * dt);
    }

    /// The axis and multiplier the PLC selects, confirmed on F208/F209; in HANDWHEEL mode,
    /// with nothing else moving the axes, `detents` move the selected axis.
    pub(super) fn handwheel_detents(&mut self, plc: &GImage, detents: i32) {
        let code = selected_code(plc);
        let times = multiplier(plc);
        self.f.bytes[f::HANDWHEEL_AXIS] = code;
        self.f.set(f::HANDWHEEL_X1, times == 1.0);
        self.f.set(f::HANDWHEEL_X10, times == 10.0);
        self.f.set(f::HANDWHEEL_X100, times == 100.0);
        let axis = code.checked_sub(1).and_then(|k| {
            self.signal_axis
                .iter()
                .position(|s| *s == Some(usize::from(k)))
        });
        let busy = self.axes_driven() || self.alarm || self.servo_off;
        let Some(axis) = axis.filter(|_| detents != 0 && !busy) else {
            return;
        };
        if self.mode != MachineState::MODE_HANDWHEEL {
            return;
        }
        // Away from an overtravel switch only (D70).
        if self.on_overtravel_switch(axis, detents > 0) {
            return;
        }
        if self
            .handwheel
            .moving
            .as_ref()
            .is_some_and(|m| m.axis != axis)
        {
            return; // the other axis finishes first; these detents are not its
        }
        let a = &self.cfg.axes[axis];
        let scale = a.scale();
        let speed = self.handwheel_speed(axis);
        let here = self.commanded[axis];
        let m = self.handwheel.moving.get_or_insert(HandwheelMove {
            axis,
            target: here,
            velocity: 0.0,
        });
        let lag = speed * MAX_LAG_S;
        let mut target =
            (m.target + f64::from(detents) * 0.001 * times * scale).clamp(here - lag, here + lag);
        if self.referenced[axis] {
            let (lo, hi) = (a.min * scale, a.max * scale);
            target = target.clamp(lo.min(hi), lo.max(hi));
        }
        m.target = target;
    }

    /// The handwheel's speed limit on `axis`, mm/s of slide.
    fn handwheel_speed(&self, axis: usize) -> f64 {
        let a = &self.cfg.axes[axis];
        (HANDWHEEL_MAX_FEED * a.scale() / 60.0).min(a.max_velocity / 60.0)
    }

    /// Whether the handwheel trial run is in effect (its switch on, in AUTO).
    pub fn handwheel_trial(&self) -> bool {
        self.trial.on
    }

    /// Whether the handwheel moves an axis.
    pub fn handwheel_moving(&self) -> bool {
        self.handwheel.moving()
    }

    /// One servo period of the axis following the wheel. Outside HANDWHEEL mode it stops
    /// where it can.
    pub(super) fn handwheel_tick(&mut self, dt: f64) {
        let Some(mut m) = self.handwheel.moving.take() else {
            return;
        };
        let i = m.axis;
        let accel = self.cfg.axes[i].max_acceleration / ACCELERATION_DIVISOR;
        let here = self.commanded[i];
        if self.mode != MachineState::MODE_HANDWHEEL {
            m.target = here + m.velocity.signum() * m.velocity * m.velocity / (2.0 * accel);
        }
        let speed = self.handwheel_speed(i);
        let (next, v) = follow(here, m.velocity, m.target, speed, accel, dt);
        self.commanded[i] = next;
        m.velocity = v;
        if v == 0.0 && next == m.target {
            self.planner.reset(self.commanded_point());
            return;
        }
        self.handwheel.moving = Some(m);
    }
}

#[cfg(test)]
mod tests {
    use super::follow;

    #[test]
    fn the_follower_stops_on_the_target_and_turns_back_when_it_moves_behind() {
        let (dt, accel, speed) = (0.004, 1000.0, 100.0);
        let (mut x, mut v) = (0.0, 0.0);
        let mut ticks = 0;
        while !(x == 5.0 && v == 0.0) {
            (x, v) = follow(x, v, 5.0, speed, accel, dt);
            assert!(x <= 5.0 + 1e-9, "overshot to {x}");
            ticks += 1;
            assert!(ticks < 1000, "never arrived: {x} {v}");
        }
        // 5 mm at 100 mm/s with 0.1 s ramps: 0.15 s, a few periods more on the brake curve.
        assert!((35..60).contains(&ticks), "{ticks}");
        // Moving at speed, the target jumps behind: it brakes, turns back and arrives.
        let (mut x, mut v) = (0.0, 100.0);
        let mut furthest: f64 = 0.0;
        for _ in 0..1000 {
            (x, v) = follow(x, v, -1.0, speed, accel, dt);
            furthest = furthest.max(x);
        }
        assert_eq!((x, v), (-1.0, 0.0));
        // It went on for the braking distance v²/2a = 5 mm before turning back.
        assert!((4.5..5.5).contains(&furthest), "{furthest}");
    }
}
