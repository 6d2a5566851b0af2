//! Motion's shell: the servo loop on its own thread against the drives (iceoryx2), the machine
//! bus and DDS ([`node`]), and the loop's statistics ([`servo`]). Everything it runs is
//! `cnc_motion_core`'s, re-exported here.

pub mod loop_stats;
pub mod node;
mod queued;

pub use cnc_motion_core::*;

use cnc_runtime::LaunchConfig;

/// Motion's parameters from the launch config.
pub trait FromLaunch {
    fn from_launch(cfg: &LaunchConfig) -> Self;
}

impl FromLaunch for MotionConfig {
    fn from_launch(cfg: &LaunchConfig) -> Self {
        let idx = |n: &str| cfg.axis_index(n).unwrap_or(0);
        MotionConfig {
            axes: cfg.machine.axes.clone(),
            period: cfg.servo.period_ms / 1000.0,
            queue_capacity: cfg.servo.queue_capacity,
            arc_plane: (
                idx(&cfg.machine.arc_plane[0]),
                idx(&cfg.machine.arc_plane[1]),
            ),
            lookahead: cfg.servo.lookahead,
            tolerance: cfg.servo.tolerance,
            shape: cfg.servo.profile,
            feedback_lost_ticks: cfg.servo.feedback_lost_ticks,
            dry_run_feed: cfg.servo.dry_run_feed,
            reference_order: cfg.reference_order(),
            spindle_max_rpm: cfg.limits.spindle_max_rpm,
            feedback_delay_ticks: cfg.servo.drive_queue_ticks().max(1) as u32,
            time_scaling_at_drives: cfg.servo.drive_queue_ticks() > 0,
            c_axis: cfg.machine.spindle_c_axis.then_some(cfg.machine.c_axis),
            live_tool: cfg.machine.live_tool.clone(),
        }
    }
}
