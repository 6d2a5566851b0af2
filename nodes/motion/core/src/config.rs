//! Machine parameters motion needs (the shell takes them from the launch config).

use crate::path::MAX_AXES;
use crate::planner::{AxisLimits, PlannerConfig};
use crate::profile::Shape;

/// One axis, as the launch config describes it (limits in display units, X in diameter).
pub use cnc_machine::AxisEntry as AxisConfig;

#[derive(Debug, Clone, PartialEq)]
pub struct MotionConfig {
    pub axes: Vec<AxisConfig>,
    /// Servo period, s.
    pub period: f64,
    /// Blocks the queue holds.
    pub queue_capacity: usize,
    /// Arc plane as (horizontal, vertical) axis indices: G02 turns clockwise seen this way.
    pub arc_plane: (usize, usize),
    /// Blocks the planner looks ahead.
    pub lookahead: usize,
    /// Path tolerance of blended corners, mm.
    pub tolerance: f64,
    pub shape: Shape,
    /// Ticks without drive feedback before the lost-feedback alarm.
    pub feedback_lost_ticks: u32,
    /// Feed under dry run, mm/min.
    pub dry_run_feed: f64,
    /// Axis indices in the order the reference return takes them.
    pub reference_order: Vec<usize>,
    /// The spindle's rating (`limits.spindle_max_rpm`): no tap turns it faster.
    pub spindle_max_rpm: f64,
    /// How many ticks old the drives' feedback is when a tick is computed: 1 in lock-step
    /// (it answers the last setpoint), the queue's length with the drives' setpoint queue
    /// (issue 48), where motion computes a tick that far ahead of the drives.
    pub feedback_delay_ticks: u32,
    /// With the drives' setpoint queue: feed hold and the overrides act at the drives, which
    /// time-scale the queued path (D135); the core plans as if they were off.
    pub time_scaling_at_drives: bool,
}

impl MotionConfig {
    /// The planner's view: limits per axis in slide travel, mm/s.
    pub fn planner(&self) -> PlannerConfig {
        let mut limits = AxisLimits {
            velocity: [0.0; MAX_AXES],
            acceleration: [0.0; MAX_AXES],
            jerk: [0.0; MAX_AXES],
            axes: self.axes.len().min(MAX_AXES),
        };
        for (i, a) in self.axes.iter().take(MAX_AXES).enumerate() {
            limits.velocity[i] = a.max_velocity / 60.0;
            limits.acceleration[i] = a.max_acceleration;
            limits.jerk[i] = a.jerk();
        }
        PlannerConfig {
            limits,
            shape: self.shape,
            period: self.period,
            tolerance: self.tolerance,
            lookahead: self.lookahead.max(1),
        }
    }
}
