//! The spindle as its encoder reports it: speed, angle after the index pulse and revolutions
//! turned, from the drive's raw readings (what threading locks to).

/// The spindle as its encoder reports it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Encoder {
    pub(crate) rpm: f64,
    /// Degrees after the index pulse, counted in the direction of rotation.
    pub(crate) angle: f64,
    /// Revolutions turned since start-up, in either direction.
    pub(crate) revs: f64,
    /// Degrees turned since start-up, signed (+ the way M3 turns): where rigid tapping
    /// reads the spindle.
    pub(crate) turned: f64,
    /// Last raw angle and direction (+1 CW, −1 CCW).
    raw: Option<f64>,
    direction: f64,
}

impl Encoder {
    /// Takes in one reading. Between two readings the spindle turns less than half a
    /// revolution (7500 rpm at 4 ms).
    pub(crate) fn read(&mut self, rpm: f64, raw_angle: f64) {
        if !rpm.is_finite() || !raw_angle.is_finite() {
            return;
        }
        if rpm != 0.0 {
            self.direction = rpm.signum();
        } else if self.direction == 0.0 {
            self.direction = 1.0;
        }
        if let Some(prev) = self.raw {
            let delta = (raw_angle - prev + 180.0).rem_euclid(360.0) - 180.0;
            self.revs += delta * self.direction / 360.0;
            self.turned += delta;
        }
        self.raw = Some(raw_angle);
        self.rpm = rpm;
        self.angle = (raw_angle * self.direction).rem_euclid(360.0);
    }

    /// The angle the encoder will report `seconds` after its last reading at the speed now
    /// (degrees, 0–360, as the drive reports it).
    pub(crate) fn raw_ahead(&self, seconds: f64) -> f64 {
        (self.raw.unwrap_or(0.0) + self.rpm * 6.0 * seconds).rem_euclid(360.0)
    }

    /// Revolutions per second, whatever the direction.
    pub(crate) fn omega(&self) -> f64 {
        self.rpm.abs() / 60.0
    }
}
