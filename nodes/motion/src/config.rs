//! Machine parameters motion needs, taken from the launch config.

use cnc_runtime::LaunchConfig;

/// One axis, as the launch config describes it (limits in display units, X in diameter).
pub use cnc_runtime::config::AxisEntry as AxisConfig;

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

impl MotionConfig {
    pub fn from_launch(cfg: &LaunchConfig) -> Self {
        let idx = |n: &str| cfg.axis_index(n).unwrap_or(0);
        MotionConfig {
            axes: cfg.machine.axes.clone(),
            period: cfg.servo.period_ms / 1000.0,
            queue_capacity: cfg.servo.queue_capacity,
            arc_plane: (
                idx(&cfg.machine.arc_plane[0]),
                idx(&cfg.machine.arc_plane[1]),
            ),
        }
    }
}
