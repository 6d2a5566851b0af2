//! The simulated lathe: axes that follow setpoints with a first-order drive lag (interpolating
//! linearly between setpoints, as drives do, so a slide at constant speed lags its setpoint by
//! exactly speed × time constant), a spindle that
//! ramps to its commanded speed with a brake, an emergency-stop input, and the [`devices`] the
//! PLC drives (turret, chuck, door, tailstock, coolant, air).
//!
//! Pure: [`SimLathe::step`] advances the machine by `dt` seconds.

pub mod devices;

use cnc_msgs::servo::{ServoFeedback, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{x, y, SignalTable, XImage, YImage};

pub use devices::{DeviceConfig, Devices};

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
}

#[derive(Debug, Clone)]
pub struct SimLathe {
    cfg: SimConfig,
    position: [f64; MAX_AXES],
    /// The setpoint of the previous step, where this step's interpolation starts.
    last_setpoint: [f64; MAX_AXES],
    spindle_rpm: f64,
    spindle_angle: f64,
    pub devices: Devices,
    emergency_stop: bool,
    x_seq: u64,
}

impl SimLathe {
    /// `start` is the slide position at power-on.
    pub fn new(cfg: SimConfig, start: &[f64]) -> Self {
        let mut position = [0.0; MAX_AXES];
        for (p, s) in position.iter_mut().zip(start) {
            *p = *s;
        }
        SimLathe {
            devices: Devices::new(cfg.devices.clone()),
            cfg,
            position,
            last_setpoint: position,
            spindle_rpm: 0.0,
            spindle_angle: 0.0,
            emergency_stop: false,
            x_seq: 0,
        }
    }

    pub fn set_emergency_stop(&mut self, pressed: bool) {
        self.emergency_stop = pressed;
    }

    pub fn position(&self) -> &[f64] {
        &self.position[..self.cfg.drive_lag.len()]
    }

    pub fn spindle_rpm(&self) -> f64 {
        self.spindle_rpm
    }

    /// Advances by `dt`: drives follow `setpoint` when enabled; devices follow `y`.
    pub fn step(&mut self, setpoint: &ServoSetpoint, y: &YImage, dt: f64) -> ServoFeedback {
        let n = self.cfg.drive_lag.len().min(MAX_AXES);
        if setpoint.enable != 0 && !self.emergency_stop {
            for i in 0..n {
                let target = setpoint.position[i];
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
        // A disabled drive starts interpolating from where its slide stands.
        let enabled = setpoint.enable != 0 && !self.emergency_stop;
        for i in 0..n {
            self.last_setpoint[i] = if enabled && setpoint.position[i].is_finite() {
                setpoint.position[i]
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
        let step = self.cfg.spindle_acceleration * brake * dt;
        self.spindle_rpm += (command - self.spindle_rpm).clamp(-step, step);
        self.spindle_angle =
            (self.spindle_angle + self.spindle_rpm / 60.0 * 360.0 * dt).rem_euclid(360.0);
        self.devices.step(y, dt);
        ServoFeedback {
            seq: setpoint.seq,
            setpoint_sent_ns: setpoint.sent_ns,
            position: self.position,
            axis_count: n as u32,
            drive_fault: 0,
            spindle_rpm: self.spindle_rpm,
            spindle_angle_deg: self.spindle_angle,
        }
    }

    /// The machine's inputs as the PLC reads them.
    pub fn x_image(&mut self, y: &YImage) -> XImage {
        self.x_seq += 1;
        let commanded = spindle_command(y);
        let tol = (commanded.abs() * self.cfg.at_speed_tolerance).max(1.0);
        let mut xi = XImage {
            seq: self.x_seq,
            spindle_actual_rpm: self.spindle_rpm,
            ..Default::default()
        };
        xi.set(x::ESP_N, !self.emergency_stop);
        xi.set(
            x::SPINDLE_AT_SPEED,
            (self.spindle_rpm - commanded).abs() <= tol,
        );
        self.devices.sensors(&mut xi);
        xi
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

    fn sim() -> SimLathe {
        SimLathe::new(
            SimConfig {
                drive_lag: vec![0.008, 0.008],
                spindle_acceleration: 2000.0,
                at_speed_tolerance: 0.02,
                devices: DeviceConfig::default(),
            },
            &[10.0, 20.0],
        )
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
}
