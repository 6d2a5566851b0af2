//! Servo payloads between motion and io over iceoryx2: fixed size, `#[repr(C)]`, no heap.

#[cfg(feature = "shm")]
use iceoryx2::prelude::ZeroCopySend;

/// Most axes a channel can drive.
pub const MAX_AXES: usize = 8;

/// Position command for every axis, sent by motion every servo period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "shm",
    derive(ZeroCopySend),
    type_name("cnc_msgs::ServoSetpoint")
)]
#[repr(C)]
pub struct ServoSetpoint {
    /// Tick number, from 1; io echoes it in the feedback.
    pub seq: u64,
    /// Motion's monotonic clock when sent, ns; echoed to measure the round trip.
    pub sent_ns: u64,
    /// Commanded position per axis, mm (X in diameter on a lathe).
    pub position: [f64; MAX_AXES],
    pub axis_count: u32,
    /// 1 = drives enabled (servo on).
    pub enable: u32,
    /// The spindle drive's acceleration, percent of its rated (`ACC[S]`, 1–200; 100 when no
    /// program set it). The spindle is a drive on the same bus as the axes.
    pub spindle_acceleration_percent: f64,
    /// Per axis, the drive's torque limit in percent of its maximum (100: none; lower while
    /// the axis travels to a fixed stop or presses against it).
    pub torque_limit_percent: [f64; MAX_AXES],
    /// With the drives' setpoint queue (`servo.drive_queue_ms`): its index on the queued path,
    /// the drive tick it is for while nothing time-scales the path (0 in lock-step, where
    /// every setpoint is for the drives' next tick).
    pub tick: u64,
    /// The queue's episode: how many times motion has seen the queue run dry. The drives
    /// take only setpoints of their own episode, so nothing planned before a dry queue plays
    /// after the brake tail.
    pub episode: u32,
    /// With the setpoint queue: how the drives may time-scale this setpoint (one of
    /// `ServoSetpoint::SCALE_*`): feed hold and the overrides act at the drives, by playing the
    /// queued path slower (issue 48).
    pub scaling: u32,
    /// The feed override the setpoint was planned at (a `SCALE_FEED` setpoint): the drives
    /// play it at the operator's override over this one, at most 1.
    pub planned_override: f64,
    /// A `SCALE_GEARED` setpoint (rigid tapping): the drives set each axis from the
    /// spindle's encoder, from `gear_start` to `gear_end` (setpoint units) while the spindle
    /// turns `gear_degrees` (signed) from where it last stood: electronic gearing, whatever
    /// the queue (issue 48).
    pub gear_start: [f64; MAX_AXES],
    pub gear_end: [f64; MAX_AXES],
    pub gear_degrees: f64,
    /// A `SCALE_JOG` setpoint: the jog key that holds it, +(k + 1) for +J of the PLC's axis
    /// signal k (G100.k), −(k + 1) for −J (G102.k); its release stops the drives at once.
    pub jog_key: i32,
    /// A `SCALE_THREAD` setpoint: the spindle encoder's angle its position is for (degrees,
    /// as the feedback reports it) and the speed its axes' lead was computed at (rpm, signed):
    /// the drives play a thread by their own encoder, not by the clock (issue 48).
    pub thread_angle: f64,
    pub thread_rpm: f64,
    /// The program line (block) the setpoint belongs to, 0 outside a program: where it
    /// changes a block ends, and single block stops the drives there (issue 48).
    pub line: u32,
    /// Where between the previous setpoint and this one its block began, as a share of the
    /// way (1: at this setpoint): the drives stop a single block exactly there.
    pub block_start: f64,
    /// 1 while the turn-mill's C axis is in contour control (polar interpolation, D141): the
    /// main spindle, in position control, follows `c_position` (degrees, unwrapped as the
    /// spindle's turned angle) as an axis drive follows its setpoint.
    pub c_contour: u32,
    pub c_position: f64,
    /// The turn-mill's live tool (D142), a drive in position control on the same bus: the
    /// angle it is to stand at, degrees, unwrapped (it turns by following it).
    pub live_tool_position: f64,
}

impl ServoSetpoint {
    /// Played as queued, one a tick: spindle-locked moves (threads, taps), manual moves, an
    /// idle machine. Feed hold and overrides do not act on it at the drives.
    pub const SCALE_FIXED: u32 = 0;
    /// A program's wait (dwell, an M/S/T answer): feed hold stops it, no override slows it.
    pub const SCALE_WAIT: u32 = 1;
    /// A feed move: feed hold and the feed override act.
    pub const SCALE_FEED: u32 = 2;
    /// A rapid: feed hold and the rapid override act.
    pub const SCALE_RAPID: u32 = 3;
    /// Locked to the spindle at the drives (rigid tapping): played one a tick as a fixed
    /// setpoint, its position computed from the encoder (`gear_*`).
    pub const SCALE_GEARED: u32 = 4;
    /// A jog held by the operator's key (`jog_key`): played one a tick while the key is held;
    /// its release stops the drives on the jog's path and drops the rest of the queue.
    pub const SCALE_JOG: u32 = 5;
    /// A thread's setpoint, locked to the spindle at the drives: the thread's setpoints are a
    /// table of positions by spindle angle (`thread_angle`), which the drives look up with
    /// their own encoder every tick (electronic cam), whatever the spindle's speed did since
    /// motion computed them.
    pub const SCALE_THREAD: u32 = 6;
}

impl Default for ServoSetpoint {
    fn default() -> Self {
        ServoSetpoint {
            seq: 0,
            sent_ns: 0,
            position: [0.0; MAX_AXES],
            axis_count: 0,
            enable: 0,
            spindle_acceleration_percent: 100.0,
            torque_limit_percent: [100.0; MAX_AXES],
            tick: 0,
            episode: 0,
            scaling: ServoSetpoint::SCALE_FIXED,
            planned_override: 1.0,
            gear_start: [0.0; MAX_AXES],
            gear_end: [0.0; MAX_AXES],
            gear_degrees: 0.0,
            jog_key: 0,
            thread_angle: 0.0,
            thread_rpm: 0.0,
            line: 0,
            block_start: 1.0,
            c_contour: 0,
            c_position: 0.0,
            live_tool_position: 0.0,
        }
    }
}

/// Most ticks of a [`BrakeTail`]: 2 s at the 4 ms period.
pub const TAIL_TICKS: usize = 500;

/// What the drives play if their setpoint queue runs dry: the continuation that brings the
/// path from the last queued setpoint (tick `first_tick` − 1) to a stop at the machine's
/// limits, planned by motion with every batch (issue 48).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "shm",
    derive(ZeroCopySend),
    type_name("cnc_msgs::BrakeTail")
)]
#[repr(C)]
pub struct BrakeTail {
    /// The queue episode it belongs to (as [`ServoSetpoint::episode`]).
    pub episode: u32,
    /// Positions used, at most [`TAIL_TICKS`]; the last is held once played.
    pub len: u32,
    /// The drive tick of `position[0]`.
    pub first_tick: u64,
    pub position: [[f64; MAX_AXES]; TAIL_TICKS],
}

impl Default for BrakeTail {
    fn default() -> Self {
        BrakeTail {
            episode: 0,
            len: 0,
            first_tick: 0,
            position: [[0.0; MAX_AXES]; TAIL_TICKS],
        }
    }
}

/// Drive feedback, sent by io in answer to each setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "shm",
    derive(ZeroCopySend),
    type_name("cnc_msgs::ServoFeedback")
)]
#[repr(C)]
pub struct ServoFeedback {
    /// `seq` of the setpoint this answers.
    pub seq: u64,
    /// `sent_ns` of the setpoint this answers.
    pub setpoint_sent_ns: u64,
    /// Actual position per axis, mm.
    pub position: [f64; MAX_AXES],
    pub axis_count: u32,
    /// Bit per axis: drive fault.
    pub drive_fault: u32,
    /// Spindle encoder: speed in rpm and angle in degrees (0..360).
    pub spindle_rpm: f64,
    pub spindle_angle_deg: f64,
    /// Bit per axis: its reference deceleration dog is pressed (`*DEC`).
    pub reference_dog: u32,
    /// Bit per axis: the encoder passed its index mark in this period, at
    /// `marker_position` (the drive latches the count, so the position is exact).
    pub marker: u32,
    pub marker_position: [f64; MAX_AXES],
    /// Bit per axis: its + / − overtravel limit switch is pressed (the drive's limit inputs,
    /// as bus servo drives report them).
    pub overtravel_plus: u32,
    pub overtravel_minus: u32,
    /// The handwheel's (manual pulse generator's) counter: its A/B pulses counted four per
    /// detent (the encoder interface's 4× quadrature, `000` §1.3), wrapping.
    pub handwheel_count: i32,
    /// The touch probe (measuring input 1): 1 while it is deflected.
    pub probe: u32,
    /// The probe's rising and falling edges, counted (wrapping) so that none is missed
    /// between two periods, and every axis's position at the last of each: the drive latches
    /// the count at the edge, as it does at the index mark.
    pub probe_rising: u32,
    pub probe_falling: u32,
    pub probe_rising_position: [f64; MAX_AXES],
    pub probe_falling_position: [f64; MAX_AXES],
    /// Per axis, the torque the drive gives, percent of its maximum.
    pub torque_percent: [f64; MAX_AXES],
    /// With the setpoint queue: the index of the queued setpoint the drives are at (their
    /// own clock's tick while nothing time-scales the path, slower under feed hold or an
    /// override).
    pub tick: u64,
    /// Ticks of setpoints queued after this one.
    pub queue_depth: u32,
    /// 1 when this tick had no setpoint of its own (the brake tail or a hold played).
    pub underrun: u32,
    /// The queue's episode: times it ran dry since the drives started.
    pub episode: u32,
    /// The index at which the queue last ran dry (the brake tail's first).
    pub dry_tick: u64,
    /// Why the last episode ended: one of `ServoFeedback::ENDED_*`.
    pub episode_ended: u32,
    /// 1 while the emergency-stop input is pressed at the drives.
    pub emergency_stop: u32,
    /// 1 while the drives hold the queued path (feed hold reached them).
    pub held: u32,
    /// The rate the drives advance along the queued path, 0–1 (1: a setpoint a tick).
    pub scale: f64,
    /// With the setpoint queue: the setpoint the drives played this tick (interpolated on
    /// the queued path while it is time-scaled).
    pub setpoint: [f64; MAX_AXES],
    /// The resets the drives have stopped for ([`DriveControl::resets`] once done).
    pub resets_done: u32,
    /// 1 while the drives stand at a block's end for single block, until a cycle start.
    pub block_stop: u32,
    /// The live tool's drive (D142): degrees turned since power-on (its encoder, unwrapped)
    /// and its speed, rpm.
    pub live_tool_angle: f64,
    pub live_tool_rpm: f64,
}

impl ServoFeedback {
    /// The queue ran dry: the drives played the brake tail.
    pub const ENDED_DRY: u32 = 0;
    /// Emergency stop: the drives ramped to a stop on their own and removed power.
    pub const ENDED_EMERGENCY_STOP: u32 = 1;
    /// Reset: the drives stopped on the queued path and dropped the rest of it.
    pub const ENDED_RESET: u32 = 2;
    /// A jog key released: the drives stopped the jog and dropped the rest of the queue.
    pub const ENDED_JOG_RELEASE: u32 = 3;
}

impl Default for ServoFeedback {
    fn default() -> Self {
        ServoFeedback {
            seq: 0,
            setpoint_sent_ns: 0,
            position: [0.0; MAX_AXES],
            axis_count: 0,
            drive_fault: 0,
            spindle_rpm: 0.0,
            spindle_angle_deg: 0.0,
            reference_dog: 0,
            marker: 0,
            marker_position: [0.0; MAX_AXES],
            overtravel_plus: 0,
            overtravel_minus: 0,
            handwheel_count: 0,
            probe: 0,
            probe_rising: 0,
            probe_falling: 0,
            probe_rising_position: [0.0; MAX_AXES],
            probe_falling_position: [0.0; MAX_AXES],
            torque_percent: [0.0; MAX_AXES],
            tick: 0,
            queue_depth: 0,
            underrun: 0,
            episode: 0,
            dry_tick: 0,
            episode_ended: 0,
            emergency_stop: 0,
            live_tool_angle: 0.0,
            live_tool_rpm: 0.0,
            held: 0,
            scale: 1.0,
            setpoint: [0.0; MAX_AXES],
            resets_done: 0,
            block_stop: 0,
        }
    }
}

/// What motion tells the drives beside the queue, at once (issue 48): its feed hold, and
/// counters of the cycle starts and resets it took, so the drives release a hold they took
/// from the PLC's feed-hold signal, and stop for a reset until their
/// [`ServoFeedback::resets_done`] is the same count (counters, so a value read late or
/// missed loses nothing).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "shm",
    derive(ZeroCopySend),
    type_name("cnc_msgs::DriveControl")
)]
#[repr(C)]
pub struct DriveControl {
    /// 1 while motion is in feed hold.
    pub hold: u32,
    /// Cycle starts motion took (wrapping).
    pub starts: u32,
    /// Resets motion took (wrapping).
    pub resets: u32,
}
