//! Machine parameters motion needs, from the launch config.

use serde::Deserialize;

/// One axis. Positions in the units the operator sees (X in diameter when `diameter`).
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct AxisConfig {
    pub name: String,
    /// Programmed and displayed in diameter; the slide moves half of it.
    #[serde(default)]
    pub diameter: bool,
    /// Soft limits, in display units.
    pub min: f64,
    pub max: f64,
    /// Rapid rate, mm/min of slide travel.
    pub max_velocity: f64,
    /// mm/s² of slide travel.
    pub max_acceleration: f64,
    /// In-position window, mm of slide travel, checked before M/S/T codes and program end.
    #[serde(default = "default_in_position")]
    pub in_position: f64,
    /// Drive time constant of the simulated axis, s (io only).
    #[serde(default = "default_drive_lag")]
    pub drive_lag: f64,
}

fn default_in_position() -> f64 {
    0.0005
}
fn default_drive_lag() -> f64 {
    0.008
}

#[derive(Debug, Clone, PartialEq)]
pub struct MotionConfig {
    pub axes: Vec<AxisConfig>,
    /// Servo period, s.
    pub period: f64,
    /// Blocks the queue holds.
    pub queue_capacity: usize,
    /// Arc plane as (horizontal, vertical) axis indices: G02 turns clockwise seen this way.
    pub arc_plane: (usize, usize),
}

impl AxisConfig {
    /// Display units → slide travel.
    pub fn scale(&self) -> f64 {
        if self.diameter {
            0.5
        } else {
            1.0
        }
    }
}
