//! The simulated lathe: axes that follow setpoints with a first-order drive lag (interpolating
//! linearly between setpoints, as drives do, so a slide at constant speed lags its setpoint by
//! exactly speed × time constant), incremental encoders with a deceleration dog and index
//! marks where the config asks for them ([`Encoder`]), a spindle that
//! ramps to its commanded speed with a brake, an emergency-stop input, and the [`devices`] the
//! PLC drives (turret, chuck, door, tailstock, coolant, air).
//!
//! Pure: [`SimLathe::step`] advances the machine by `dt` seconds; the crate cannot reach a
//! thread, a clock, DDS or iceoryx2 (`tests/boundaries.rs`). The io node (`cnc_io`) is its shell.

pub mod devices;
pub mod drive_queue;
mod gearing;
pub mod probe;
mod single_block;
pub mod spindle_position;
pub mod time_scale;
pub mod trace;

use cnc_msgs::servo::{ServoFeedback, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{x, y, SignalTable, XImage, YImage};

pub use devices::{DeviceConfig, Devices};
use spindle_position::{ContourFollow, Positioning, StopCommand};

/// Simulation parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Drive time constant per axis, s.
    pub drive_lag: Vec<f64>,
    /// Spindle ramp, rpm/s.
    pub spindle_acceleration: f64,
    /// "At speed" window, fraction of the commanded speed.
    pub at_speed_tolerance: f64,
    pub devices: DeviceConfig,
    /// Per axis: an incremental encoder (`Some`), or an absolute one that reports the slide's
    /// machine position from power-on (`None`).
    pub encoders: Vec<Option<Encoder>>,
    /// Per axis: where the − and + overtravel switches are pressed (slide travel, machine
    /// coordinates); none given: no switches.
    pub overtravel: Vec<[f64; 2]>,
    /// Where the touch probe's stylus is deflected (slide travel, machine coordinates); none:
    /// it never switches.
    pub probe: Vec<probe::Target>,
    /// Per axis, a mechanical stop its slide cannot pass (slide travel, machine coordinates).
    pub fixed_stops: Vec<Option<f64>>,
    /// The live tool drive's time constant, s (D142).
    pub live_tool_lag: f64,
}

/// An incremental encoder and its reference dog, in slide travel (mm): the encoder counts
/// from 0 where the slide stood at power-on; index marks every `grid` mm, one of them at the
/// machine's `reference` point; the dog ends half a grid before the reference point on the
/// side the axis approaches from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Encoder {
    pub reference: f64,
    pub positive: bool,
    pub grid: f64,
    pub dog_length: f64,
}

impl Encoder {
    /// Whether the dog is pressed with the slide at `x` (machine position).
    fn dog(&self, x: f64) -> bool {
        let near = self.reference - self.grid / 2.0;
        let far = near - self.dog_length;
        if self.positive {
            (far..=near).contains(&x)
        } else {
            let (near, far) = (2.0 * self.reference - near, 2.0 * self.reference - far);
            (near..=far).contains(&x)
        }
    }

    /// The index mark the slide passed going from `a` to `b`, if any: a mark is passed when
    /// the slide reaches it (one that stops on a mark passes it once, going on or turning
    /// back). At one servo period a slide moves far less than a grid, so there is at most one.
    fn mark_between(&self, a: f64, b: f64) -> Option<f64> {
        let g = self.grid;
        let m = if a < b {
            self.reference + (((a - self.reference) / g).floor() + 1.0) * g
        } else if b < a {
            self.reference + (((a - self.reference) / g).ceil() - 1.0) * g
        } else {
            return None;
        };
        let passed = if a < b { m <= b } else { m >= b };
        passed.then_some(m)
    }
}

#[derive(Debug, Clone)]
pub struct SimLathe {
    cfg: SimConfig,
    /// Slide positions in machine coordinates.
    position: [f64; MAX_AXES],
    /// Machine position less what the encoder reports: where an incremental encoder's count
    /// began; 0 for an absolute encoder.
    encoder_offset: [f64; MAX_AXES],
    /// The setpoint of the previous step (machine coordinates), where this step's
    /// interpolation starts.
    last_setpoint: [f64; MAX_AXES],
    spindle_rpm: f64,
    /// Degrees the spindle has turned since power-on (unwrapped: a positioning's goal can
    /// lie turns away); the encoder's angle is this modulo 360.
    spindle_turned: f64,
    /// The drive in position control: its stop position and goal.
    positioning: Option<Positioning>,
    /// The drive following C's setpoints (polar interpolation, D141), and its speed then.
    contour: ContourFollow,
    contour_rpm: f64,
    /// The live tool's drive (D142): degrees turned, following its setpoint.
    live_tool: f64,
    live_tool_follow: ContourFollow,
    pub devices: Devices,
    /// The emergency-stop input (the PLC's X image, the spindle's stop).
    emergency_stop: bool,
    /// The axes' drives without power (they hold nothing, follow no setpoint).
    powered_off: bool,
    x_seq: u64,
    /// Overtravel switches pressed at the last step (bits per axis), for the PLC's inputs.
    overtravel: (u32, u32),
    /// The handwheel's counter, four counts a detent (the encoder interface's 4× quadrature).
    handwheel_count: i32,
    probe: probe::Probe,
    /// Per axis, the side of its fixed stop the slide is on (+1 above, −1 below).
    stop_side: [f64; MAX_AXES],
}

impl SimLathe {
    /// `start` is the slide position at power-on.
    pub fn new(cfg: SimConfig, start: &[f64]) -> Self {
        let mut position = [0.0; MAX_AXES];
        for (p, s) in position.iter_mut().zip(start) {
            *p = *s;
        }
        let mut encoder_offset = [0.0; MAX_AXES];
        for (i, e) in cfg.encoders.iter().enumerate().take(MAX_AXES) {
            if e.is_some() {
                encoder_offset[i] = position[i];
            }
        }
        let mut stop_side = [1.0; MAX_AXES];
        for (i, at) in cfg.fixed_stops.iter().enumerate().take(MAX_AXES) {
            if let Some(at) = at {
                stop_side[i] = if position[i] < *at { -1.0 } else { 1.0 };
            }
        }
        SimLathe {
            stop_side,
            probe: probe::Probe::new(cfg.probe.clone()),
            devices: Devices::new(cfg.devices.clone()),
            cfg,
            encoder_offset,
            position,
            last_setpoint: position,
            spindle_rpm: 0.0,
            spindle_turned: 0.0,
            positioning: None,
            contour: ContourFollow::default(),
            contour_rpm: 0.0,
            live_tool: 0.0,
            live_tool_follow: ContourFollow::default(),
            emergency_stop: false,
            powered_off: false,
            x_seq: 0,
            overtravel: (0, 0),
            handwheel_count: 0,
        }
    }

    /// Turns the handwheel by `detents` (clockwise positive): its counter, as the next
    /// feedback reports it, moves four counts a detent.
    pub fn turn_handwheel(&mut self, detents: i32) {
        self.handwheel_count = self.handwheel_count.wrapping_add(detents.wrapping_mul(4));
    }

    /// Emergency stop that removes the drives' power at once (the lock-step machine).
    pub fn set_emergency_stop(&mut self, pressed: bool) {
        self.emergency_stop = pressed;
        self.powered_off = pressed;
    }

    /// Whether the emergency-stop input is pressed.
    pub fn emergency_stop_pressed(&self) -> bool {
        self.emergency_stop
    }

    /// Power to the axes' drives. With the setpoint queue the io node gives it back after an
    /// emergency stop until the drives have ramped to a stop (a stop of category 1, D134).
    pub fn power_drives(&mut self, on: bool) {
        self.powered_off = !on;
    }

    /// Slide positions in machine coordinates (what an absolute encoder would report).
    pub fn position(&self) -> &[f64] {
        &self.position[..self.cfg.drive_lag.len()]
    }

    pub fn spindle_rpm(&self) -> f64 {
        self.spindle_rpm
    }

    /// The spindle's angle as its encoder shows it, 0 ≤ angle < 360°.
    pub fn spindle_angle(&self) -> f64 {
        self.spindle_turned.rem_euclid(360.0)
    }

    /// Advances by `dt`: drives follow `setpoint` when enabled; devices follow `y`.
    pub fn step(&mut self, setpoint: &ServoSetpoint, y: &YImage, dt: f64) -> ServoFeedback {
        let n = self.cfg.drive_lag.len().min(MAX_AXES);
        let before = self.position;
        if setpoint.enable != 0 && !self.powered_off {
            for i in 0..n {
                let target = setpoint.position[i] + self.encoder_offset[i];
                if !target.is_finite() {
                    continue;
                }
                let tau = self.cfg.drive_lag[i];
                // Exact response of the lag to a ramp from the last setpoint to this one.
                self.position[i] = if tau > 0.0 && dt > 0.0 {
                    let v = (target - self.last_setpoint[i]) / dt;
                    let settled = target - v * tau;
                    let off = self.position[i] - (self.last_setpoint[i] - v * tau);
                    settled + off * (-dt / tau).exp()
                } else {
                    target
                };
            }
        }
        let torque = self.fixed_stops(setpoint, &before, n);
        // A disabled drive starts interpolating from where its slide stands.
        let enabled = setpoint.enable != 0 && !self.powered_off;
        for i in 0..n {
            self.last_setpoint[i] = if enabled && setpoint.position[i].is_finite() {
                setpoint.position[i] + self.encoder_offset[i]
            } else {
                self.position[i]
            };
        }
        // Spindle: ramp toward the signed command, three times as fast with the brake on;
        // stops on emergency stop.
        let command = if self.emergency_stop {
            0.0
        } else {
            spindle_command(y)
        };
        let brake = if y.get(y::SPINDLE_BRAKE) { 3.0 } else { 1.0 };
        // The drive's rated acceleration under the program's override (ACC[S], D108).
        let share = setpoint.spindle_acceleration_percent / 100.0;
        let share = if share.is_finite() {
            share.clamp(0.01, 2.0)
        } else {
            1.0
        };
        let acceleration = self.cfg.spindle_acceleration * share;
        let step = acceleration * brake * dt;
        // Position control (M19, SPOS): a new stop position (or a new count) starts a
        // positioning from where the spindle is and how it turns.
        self.positioning = if self.orienting(y) {
            let command = StopCommand::of(y);
            match self.positioning {
                Some(p) if p.command == command => Some(p),
                _ => Some(Positioning::start(
                    command,
                    self.spindle_turned,
                    self.spindle_rpm,
                    acceleration,
                )),
            }
        } else {
            None
        };
        let command = match self.positioning {
            Some(p) => p.speed(self.spindle_turned, acceleration),
            None => command,
        };
        self.spindle_rpm += (command - self.spindle_rpm).clamp(-step, step);
        self.spindle_turned += self.spindle_rpm / 60.0 * 360.0 * dt;
        if let Some(p) = self.positioning {
            if p.reached(self.spindle_turned, self.spindle_rpm) {
                // In position: the drive holds it there.
                self.spindle_turned = p.goal;
                self.spindle_rpm = 0.0;
            }
        }
        self.follow_contour(setpoint, dt);
        let live_tool_was = self.live_tool;
        self.follow_live_tool(setpoint, dt);
        self.devices.step(y, dt);
        let mut fb = ServoFeedback {
            seq: setpoint.seq,
            setpoint_sent_ns: setpoint.sent_ns,
            axis_count: n as u32,
            spindle_rpm: self.spindle_rpm + self.contour_rpm,
            spindle_angle_deg: self.spindle_angle(),
            handwheel_count: self.handwheel_count,
            torque_percent: torque,
            live_tool_angle: self.live_tool,
            live_tool_rpm: if dt > 0.0 {
                (self.live_tool - live_tool_was) / dt / 6.0
            } else {
                0.0
            },
            ..ServoFeedback::default()
        };
        for (i, was) in before.iter().enumerate().take(n) {
            let (now, offset) = (self.position[i], self.encoder_offset[i]);
            fb.position[i] = now - offset;
            if let Some([minus, plus]) = self.cfg.overtravel.get(i) {
                if now <= *minus {
                    fb.overtravel_minus |= 1 << i;
                }
                if now >= *plus {
                    fb.overtravel_plus |= 1 << i;
                }
            }
            let Some(e) = self.cfg.encoders.get(i).copied().flatten() else {
                continue;
            };
            if e.dog(now) {
                fb.reference_dog |= 1 << i;
            }
            if let Some(m) = e.mark_between(*was, now) {
                fb.marker |= 1 << i;
                fb.marker_position[i] = m - offset;
            }
        }
        self.overtravel = (fb.overtravel_minus, fb.overtravel_plus);
        self.probe.step(
            &before[..n],
            &self.position[..n],
            &self.encoder_offset[..n],
            &mut fb,
        );
        fb
    }

    /// The machine's inputs as the PLC reads them.
    pub fn x_image(&mut self, y: &YImage) -> XImage {
        self.x_seq += 1;
        let commanded = spindle_command(y);
        let tol = (commanded.abs() * self.cfg.at_speed_tolerance).max(1.0);
        let mut xi = XImage {
            seq: self.x_seq,
            spindle_actual_rpm: self.spindle_rpm,
            spindle_angle_deg: self.spindle_angle(),
            ..Default::default()
        };
        xi.set(x::ESP_N, !self.emergency_stop);
        xi.set(x::LIMIT_MINUS, self.overtravel.0 != 0);
        xi.set(x::LIMIT_PLUS, self.overtravel.1 != 0);
        xi.set(
            x::SPINDLE_AT_SPEED,
            (self.spindle_rpm - commanded).abs() <= tol,
        );
        xi.set(
            x::SPINDLE_ORIENTED,
            self.orienting(y)
                && self.spindle_rpm == 0.0
                && self.positioning.is_some_and(|p| {
                    p.command == StopCommand::of(y) && p.goal == self.spindle_turned
                }),
        );
        self.devices.sensors(&mut xi);
        xi
    }
}

impl SimLathe {
    /// The fixed stops: a slide that would pass its stop stands at it, and its drive, set
    /// beyond, gives its torque limit against it; elsewhere the simulated drives carry no
    /// load (torque 0). Returns each axis's torque, percent.
    fn fixed_stops(
        &mut self,
        setpoint: &ServoSetpoint,
        before: &[f64; MAX_AXES],
        n: usize,
    ) -> [f64; MAX_AXES] {
        let mut torque = [0.0; MAX_AXES];
        for (i, stop) in self.cfg.fixed_stops.iter().enumerate().take(n) {
            let Some(at) = *stop else { continue };
            let side = self.stop_side[i];
            if (self.position[i] - at) * side < 0.0 || (before[i] - at) * side < 0.0 {
                self.position[i] = at;
            }
            if self.position[i] != at {
                self.stop_side[i] = (self.position[i] - at).signum();
            }
            let target = setpoint.position[i] + self.encoder_offset[i];
            let pressing = self.position[i] == at && (target - at) * side < 0.0;
            if pressing && setpoint.enable != 0 && !self.powered_off {
                let limit = setpoint.torque_limit_percent[i];
                torque[i] = if limit.is_finite() {
                    limit.clamp(0.0, 100.0)
                } else {
                    100.0
                };
            }
        }
        torque
    }

    /// The drive orients: asked to, with no direction commanded and no emergency stop.
    /// In contour control the spindle, holding a position, follows C's setpoint (with the
    /// X drive's lag); the position it holds moves along, so it stays where the path left it.
    fn follow_contour(&mut self, setpoint: &ServoSetpoint, dt: f64) {
        let holding = self.spindle_rpm == 0.0
            && self
                .positioning
                .is_some_and(|p| p.goal == self.spindle_turned);
        let follow = setpoint.c_contour != 0
            && setpoint.enable != 0
            && holding
            && !self.powered_off
            && !self.emergency_stop;
        let tau = self.cfg.drive_lag.first().copied().unwrap_or(0.0);
        let before = self.spindle_turned;
        match self
            .contour
            .step(follow, setpoint.c_position, before, tau, dt)
        {
            Some(turned) => {
                self.spindle_turned = turned;
                if let Some(p) = self.positioning.as_mut() {
                    p.goal = turned;
                }
                self.contour_rpm = if dt > 0.0 {
                    (turned - before) / dt / 6.0
                } else {
                    0.0
                };
            }
            None => self.contour_rpm = 0.0,
        }
    }

    /// The live tool's drive in position control follows its setpoint (with the X drive's
    /// lag), whole turns included; without power it stands.
    fn follow_live_tool(&mut self, setpoint: &ServoSetpoint, dt: f64) {
        let on = setpoint.enable != 0 && !self.powered_off && !self.emergency_stop;
        let tau = self.cfg.live_tool_lag;
        if let Some(a) = self.live_tool_follow.step_unwrapped(
            on,
            setpoint.live_tool_position,
            self.live_tool,
            tau,
            dt,
        ) {
            self.live_tool = a;
        }
    }

    fn orienting(&self, yi: &YImage) -> bool {
        yi.get(y::SPINDLE_ORIENT)
            && !yi.get(y::SPINDLE_CW)
            && !yi.get(y::SPINDLE_CCW)
            && !self.emergency_stop
    }
}

/// The signed speed the PLC commands: the analog value with the direction of the CW/CCW
/// contactors (none or both: stop).
fn spindle_command(yi: &YImage) -> f64 {
    match (yi.get(y::SPINDLE_CW), yi.get(y::SPINDLE_CCW)) {
        (true, false) => yi.spindle_rpm.max(0.0),
        (false, true) => -yi.spindle_rpm.max(0.0),
        _ => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two axes with an 8 ms lag and absolute encoders, nothing else.
    fn config() -> SimConfig {
        SimConfig {
            drive_lag: vec![0.008, 0.008],
            spindle_acceleration: 2000.0,
            at_speed_tolerance: 0.02,
            devices: DeviceConfig::default(),
            encoders: vec![None, None],
            overtravel: Vec::new(),
            probe: Vec::new(),
            fixed_stops: Vec::new(),
            live_tool_lag: 0.0,
        }
    }

    fn sim() -> SimLathe {
        SimLathe::new(config(), &[10.0, 20.0])
    }

    #[test]
    fn axes_follow_with_first_order_lag() {
        let mut m = sim();
        let mut sp = ServoSetpoint {
            enable: 1,
            axis_count: 2,
            ..Default::default()
        };
        sp.position[0] = 11.0;
        sp.position[1] = 20.0;
        let fb = m.step(&sp, &YImage::default(), 0.008);
        // A ramp of 1 mm over one time constant: 1 − τ(1 − e⁻¹)/τ of it.
        assert!((fb.position[0] - (10.0 + (-1.0f64).exp())).abs() < 1e-12);
        // A steady ramp: the slide lags by exactly speed × time constant.
        for k in 1..=200 {
            sp.position[0] = 11.0 + 0.1 * k as f64;
            m.step(&sp, &YImage::default(), 0.004);
        }
        let lag = sp.position[0] - m.position()[0];
        assert!((lag - 0.1 / 0.004 * 0.008).abs() < 1e-9, "{lag}");
        sp.position[0] = 11.0;
        for _ in 0..200 {
            m.step(&sp, &YImage::default(), 0.004);
        }
        assert!((m.position()[0] - 11.0).abs() < 1e-9);
        // Servo off: the axes stay.
        sp.enable = 0;
        sp.position[0] = 50.0;
        m.step(&sp, &YImage::default(), 0.004);
        assert!((m.position()[0] - 11.0).abs() < 1e-9);
    }

    #[test]
    fn spindle_ramps_and_reports_at_speed() {
        let mut m = sim();
        let mut y = YImage {
            spindle_rpm: 1000.0,
            ..Default::default()
        };
        y.set(y::SPINDLE_CW, true);
        let sp = ServoSetpoint::default();
        for _ in 0..100 {
            m.step(&sp, &y, 0.004); // 0.4 s at 2000 rpm/s = 800 rpm
        }
        assert!((m.spindle_rpm() - 800.0).abs() < 1e-6);
        assert!(!m.x_image(&y).get(x::SPINDLE_AT_SPEED));
        for _ in 0..100 {
            m.step(&sp, &y, 0.004);
        }
        assert!(m.x_image(&y).get(x::SPINDLE_AT_SPEED));
        m.set_emergency_stop(true);
        for _ in 0..300 {
            m.step(&sp, &y, 0.004);
        }
        assert_eq!(m.spindle_rpm(), 0.0);
        assert!(!m.x_image(&y).get(x::ESP_N));
    }

    /// ACC[S] (D108): the setpoint's share of the drive's rated acceleration; a value that is
    /// no number leaves it rated.
    #[test]
    fn the_spindle_ramps_at_the_programmed_share_of_its_acceleration() {
        let mut y = YImage {
            spindle_rpm: 1000.0,
            ..Default::default()
        };
        y.set(y::SPINDLE_CW, true);
        for (percent, rpm) in [(50.0, 400.0), (150.0, 1000.0), (f64::NAN, 800.0)] {
            let mut m = sim();
            let sp = ServoSetpoint {
                spindle_acceleration_percent: percent,
                ..Default::default()
            };
            for _ in 0..100 {
                m.step(&sp, &y, 0.004); // 0.4 s at 2000 rpm/s × share
            }
            assert!(
                (m.spindle_rpm() - rpm).abs() < 1e-6,
                "{percent} %: {}",
                m.spindle_rpm()
            );
        }
    }

    /// The simulated spindle at 600 rpm M3, with the image that keeps it there.
    fn turning_at_600() -> (SimLathe, YImage) {
        let mut m = sim();
        let mut y = YImage {
            spindle_rpm: 600.0,
            ..Default::default()
        };
        y.set(y::SPINDLE_CW, true);
        for _ in 0..200 {
            m.step(&ServoSetpoint::default(), &y, 0.004);
        }
        (m, y)
    }

    #[test]
    fn orientation_stops_the_spindle_at_its_angle_and_holds_it() {
        let (mut m, mut y) = turning_at_600();
        let sp = ServoSetpoint::default();
        // Orientation asked with the spindle still commanded: it goes on turning.
        y.set(y::SPINDLE_ORIENT, true);
        m.step(&sp, &y, 0.004);
        assert!(m.spindle_rpm() > 500.0);
        assert!(!m.x_image(&y).get(x::SPINDLE_ORIENTED));
        y.set(y::SPINDLE_CW, false);
        let mut ticks = 0;
        while !m.x_image(&y).get(x::SPINDLE_ORIENTED) {
            m.step(&sp, &y, 0.004);
            ticks += 1;
            assert!(ticks < 2000, "oriented within 8 s");
            assert!(m.spindle_rpm().abs() <= 600.0 + 1e-9);
        }
        let fb = m.step(&sp, &y, 0.004);
        assert_eq!((fb.spindle_rpm, fb.spindle_angle_deg), (0.0, 0.0));
        // Released: no longer oriented.
        y.set(y::SPINDLE_ORIENT, false);
        assert!(!m.x_image(&y).get(x::SPINDLE_ORIENTED));
    }

    /// Drives the spindle to the stop position in `y` (SPINDLE_ORIENT on): the angles it
    /// passed, one per tick, until the PLC's input says oriented.
    fn position(m: &mut SimLathe, y: &YImage) -> Vec<f64> {
        let sp = ServoSetpoint::default();
        let mut turned = vec![m.spindle_turned];
        m.step(&sp, y, 0.004);
        assert!(
            !m.x_image(y).get(x::SPINDLE_ORIENTED),
            "a new stop position is not reached at once"
        );
        while !m.x_image(y).get(x::SPINDLE_ORIENTED) {
            turned.push(m.spindle_turned);
            assert!(turned.len() < 20_000, "positioned within 80 s");
            m.step(&sp, y, 0.004);
        }
        turned.push(m.spindle_turned);
        turned
    }

    #[test]
    fn spindle_positioning_takes_the_way_it_is_given() {
        use cnc_msgs::canon::Turn;
        let mut m = sim();
        let mut y = YImage::default();
        y.set(y::SPINDLE_ORIENT, true);
        let stop = |y: &mut YImage, degrees: f64, way: Turn| {
            y.write_i32(y::ORIENT_ANGLE, (degrees * 1000.0).round() as i32);
            y.bytes[y::ORIENT_WAY] = way as u8;
            y.bytes[y::ORIENT_COUNT] = y.bytes[y::ORIENT_COUNT].wrapping_add(1);
        };
        let rising = |t: &[f64]| t.windows(2).all(|w| w[1] >= w[0] - 1e-9);
        let falling = |t: &[f64]| t.windows(2).all(|w| w[1] <= w[0] + 1e-9);
        // SPOS=14.3 from 0: the short way forward, and no overshoot.
        stop(&mut y, 14.3, Turn::Shortest);
        let t = position(&mut m, &y);
        assert!(rising(&t), "{t:?}");
        assert_eq!(m.spindle_angle(), 14.3);
        // SPOS=ACN(300): backwards 74.3°.
        stop(&mut y, 300.0, Turn::Minus);
        let t = position(&mut m, &y);
        assert!(falling(&t) && (t[0] - t[t.len() - 1] - 74.3).abs() < 1e-9);
        assert!((m.spindle_angle() - 300.0).abs() < 1e-9);
        // SPOS=ACP(290): forward 350° though 10° back is nearer.
        stop(&mut y, 290.0, Turn::Plus);
        let t = position(&mut m, &y);
        assert!(rising(&t) && (t[t.len() - 1] - t[0] - 350.0).abs() < 1e-9);
        // SPOS=IC(-720.5), twice: two turns back and a half degree, each time.
        for _ in 0..2 {
            let before = m.spindle_angle();
            stop(&mut y, -720.5, Turn::Incremental);
            let t = position(&mut m, &y);
            assert!(falling(&t) && (t[0] - t[t.len() - 1] - 720.5).abs() < 1e-9);
            assert!((m.spindle_angle() - (before - 0.5).rem_euclid(360.0)).abs() < 1e-9);
        }
        // Held: the drive stays on it.
        let at = m.spindle_angle();
        for _ in 0..100 {
            m.step(&ServoSetpoint::default(), &y, 0.004);
        }
        assert_eq!(m.spindle_angle(), at);
        assert!(m.x_image(&y).get(x::SPINDLE_ORIENTED));
    }

    #[test]
    fn positioned_from_m3_the_spindle_keeps_its_direction() {
        let (mut m, mut y) = turning_at_600();
        y.set(y::SPINDLE_CW, false);
        y.set(y::SPINDLE_ORIENT, true);
        y.write_i32(y::ORIENT_ANGLE, 25_600);
        y.bytes[y::ORIENT_COUNT] = 1;
        let t = position(&mut m, &y);
        assert!(
            t.windows(2).all(|w| w[1] >= w[0] - 1e-9),
            "never turned back"
        );
        assert!((m.spindle_angle() - 25.6).abs() < 1e-9);
    }

    #[test]
    fn an_incremental_encoder_counts_from_power_on_and_shows_its_dog_and_index_marks() {
        let e = Encoder {
            reference: 100.0,
            positive: true,
            grid: 5.0,
            dog_length: 20.0,
        };
        let mut m = SimLathe::new(
            SimConfig {
                drive_lag: vec![0.0],
                spindle_acceleration: 2000.0,
                at_speed_tolerance: 0.02,
                devices: DeviceConfig::default(),
                encoders: vec![Some(e)],
                overtravel: Vec::new(),
                probe: Vec::new(),
                fixed_stops: Vec::new(),
                live_tool_lag: 0.0,
            },
            &[60.0],
        );
        let mut sp = ServoSetpoint {
            enable: 1,
            axis_count: 1,
            ..Default::default()
        };
        // Walk the slide from 60 to 110 (machine) in 0.5 mm steps; the encoder starts at 0.
        let (mut dog_on, mut marks) = (Vec::new(), Vec::new());
        for k in 0..=100 {
            sp.position[0] = 0.5 * f64::from(k);
            let fb = m.step(&sp, &YImage::default(), 0.004);
            assert_eq!(fb.position[0], 0.5 * f64::from(k));
            if fb.reference_dog & 1 != 0 {
                dog_on.push(m.position()[0]);
            }
            if fb.marker & 1 != 0 {
                marks.push(fb.marker_position[0] + 60.0);
            }
        }
        // The dog: 77.5..=97.5, ending half a grid before the reference point.
        assert_eq!(dog_on.first(), Some(&77.5));
        assert_eq!(dog_on.last(), Some(&97.5));
        assert_eq!(
            marks,
            [65.0, 70.0, 75.0, 80.0, 85.0, 90.0, 95.0, 100.0, 105.0, 110.0]
        );
        // Back down: the mark at 110, where the slide stands, is not passed again.
        sp.position[0] = 49.0;
        let fb = m.step(&sp, &YImage::default(), 0.004);
        assert_eq!(fb.marker, 0);
        sp.position[0] = 45.0;
        let fb = m.step(&sp, &YImage::default(), 0.004);
        assert_eq!((fb.marker, fb.marker_position[0] + 60.0), (1, 105.0));
    }

    /// A fixed stop (D118): the slide stands at it however far beyond the setpoint goes, its
    /// drive gives the torque limit while set beyond it, and it leaves the stop the other way.
    #[test]
    fn a_slide_stands_at_its_fixed_stop_and_presses_with_the_torque_limit() {
        let mut m = SimLathe::new(
            SimConfig {
                fixed_stops: vec![None, Some(15.0)],
                live_tool_lag: 0.0,
                ..config()
            },
            &[10.0, 20.0],
        );
        let mut sp = ServoSetpoint {
            enable: 1,
            axis_count: 2,
            ..Default::default()
        };
        sp.position[0] = 10.0;
        sp.torque_limit_percent[1] = 12.3;
        let mut fb = ServoFeedback::default();
        for k in 1..=100 {
            sp.position[1] = 20.0 - 0.1 * k as f64;
            fb = m.step(&sp, &YImage::default(), 0.004);
        }
        assert_eq!(fb.position[1], 15.0, "stands at the stop");
        assert_eq!(fb.torque_percent[1], 12.3);
        assert_eq!(fb.torque_percent[0], 0.0);
        // Set back above the stop: it leaves, and no torque is given.
        sp.position[1] = 18.0;
        for _ in 0..100 {
            fb = m.step(&sp, &YImage::default(), 0.004);
        }
        assert!((fb.position[1] - 18.0).abs() < 1e-6);
        assert_eq!(fb.torque_percent[1], 0.0);
        // Without a torque limit (no FXS) the drive pushes with all it has.
        sp.torque_limit_percent[1] = 100.0;
        sp.position[1] = 10.0;
        for _ in 0..100 {
            fb = m.step(&sp, &YImage::default(), 0.004);
        }
        assert_eq!((fb.position[1], fb.torque_percent[1]), (15.0, 100.0));
    }
}
