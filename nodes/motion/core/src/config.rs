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
    /// A turn-mill's C axis in contour control (polar interpolation, D141): planned as one
    /// more axis after the machine's, in degrees; `None` on a machine without it.
    pub c_axis: Option<cnc_machine::CAxisEntry>,
    /// A turn-mill's live tool (D142): planned as an axis after C, in degrees, its drive in
    /// position control following it.
    pub live_tool: Option<cnc_machine::LiveToolEntry>,
}

impl MotionConfig {
    /// The index the C axis has in blocks and the planner (after the machine's axes), if the
    /// machine has one and room for it.
    pub fn contour_axis(&self) -> Option<usize> {
        self.c_axis
            .and(Some(self.axes.len()))
            .filter(|&c| c < MAX_AXES)
    }

    /// The index the live tool has in blocks and the planner (after C), if the machine has
    /// one and room for it.
    pub fn live_tool_axis(&self) -> Option<usize> {
        let i = self.axes.len() + usize::from(self.c_axis.is_some());
        self.live_tool
            .as_ref()
            .and(Some(i))
            .filter(|&i| i < MAX_AXES)
    }

    /// How many values a block's end point carries: the machine's axes, then C and the live
    /// tool where the machine has them.
    pub fn block_axes(&self) -> usize {
        self.live_tool_axis()
            .or(self.contour_axis())
            .map_or(self.axes.len(), |i| i + 1)
    }

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
        if let Some(c) = self.contour_axis() {
            let a = self.c_axis.unwrap_or_default();
            limits.velocity[c] = a.max_velocity / 60.0;
            limits.acceleration[c] = a.max_acceleration;
            limits.jerk[c] = a.max_acceleration / cnc_machine::DEFAULT_JERK_TIME;
        }
        if let (Some(i), Some(t)) = (self.live_tool_axis(), &self.live_tool) {
            limits.velocity[i] = t.max_rpm * 6.0;
            limits.acceleration[i] = t.acceleration();
            limits.jerk[i] = t.acceleration() / cnc_machine::DEFAULT_JERK_TIME;
        }
        limits.axes = self.block_axes().min(MAX_AXES);
        PlannerConfig {
            limits,
            shape: self.shape,
            period: self.period,
            tolerance: self.tolerance,
            lookahead: self.lookahead.max(1),
        }
    }
}
