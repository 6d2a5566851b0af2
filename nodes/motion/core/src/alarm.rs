//! Alarm numbers raised by motion (`000` Appendix 1, inventory §11.2): one table, so a number
//! is chosen once and the shell and the core raise the same.

pub const SOFT_LIMIT: u32 = 38;
/// The block stream from the interpreter is out of step: queue overflow, a block with the
/// wrong number of axes, or one that could not run (`000` alarm 111, pre-read/execution sync).
pub const BAD_BLOCK: u32 = 111;
/// Feed per revolution or threading with the spindle stopped (`000` alarm 36).
pub const SPINDLE_NOT_TURNING: u32 = 36;
/// A slide lags its setpoint by more than its following-error limit: the servo alarm of
/// that axis (`000` alarm 69, "bus servo alarm on physical axis #", inventory §11.3).
pub const FOLLOWING_ERROR: u32 = 69;
/// No feedback from the drives for `servo.feedback_lost_ticks` ticks: the drive link
/// is down (`000` alarm 68, "bus communication line error", inventory §11.3).
pub const FEEDBACK_LOST: u32 = 68;
/// A thread the axes cannot follow at the spindle's speed: too short for the run-in and
/// run-out, or faster than an axis may move (`000` alarm 52, "thread acceleration length
/// insufficient").
pub const THREAD_RUN_IN: u32 = 52;
/// The PLC stopped sending its G image (the PLC's own alarms are 1000–1091).
pub const PLC_SILENT: u32 = 1092;
/// The servo loop missed its period again and again (`servo.late_alarm_ticks` late ticks
/// within a second): the drive bus's cycle is not kept (`000` alarm 54, "bus
/// communication … timeout", inventory §11.3; decisions D57). The machine stops.
pub const SERVO_OVERRUN: u32 = 54;
/// One servo tick later than `servo.late_warning_ms`: a warning (not in the manual: D57).
pub const SERVO_LATE: u32 = 1093;
/// A program started before every axis with an incremental encoder has returned to its
/// reference point. The Huaxing tables have none (its bus axes have absolute encoders); the
/// FANUC family's number for "return to reference point not done" (decisions D68).
pub const REFERENCE_NOT_DONE: u32 = 224;
/// A reference return that found no dog or index mark within the axis's travel (not in the
/// manuals: D68).
pub const REFERENCE_FAILED: u32 = 1094;
/// A reference return motion could not start (axes moving, alarm, emergency stop, servo
/// off): a warning with the reason, so a cycle start that moved nothing says why (D68).
pub const REFERENCE_REFUSED: u32 = 1095;
/// An axis on its + overtravel switch (`000` alarm 40, "+ hardware limit").
pub const OVERTRAVEL_PLUS: u32 = 40;
/// An axis on its − overtravel switch (`000` alarm 66, "limit alarm": its tables have no
/// number of their own for the − switch; decisions D70).
pub const OVERTRAVEL_MINUS: u32 = 66;
/// A measuring block asks for the probe's rising edge while the probe is already deflected
/// (the SINUMERIK family's 21700 "probe already deflected, edge cannot be detected"; the
/// other manuals have none: decisions D116).
pub const PROBE_DEFLECTED: u32 = 21700;
/// A travel to a fixed stop whose move ended without meeting it (`001` §9.3.23, "未到达固定
/// 挡块", D118).
pub const FIXED_STOP_NOT_REACHED: u32 = 20091;
/// An axis clamped at its fixed stop left the monitoring window (`001` §9.3.23, "固定挡块
/// 损坏", D118).
pub const FIXED_STOP_ABORTED: u32 = 20094;
