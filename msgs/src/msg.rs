//! Message types of `msg/`. Field order is wire order: keep it identical to the `.msg` files.

use crate::ros_message;

ros_message! {
    /// `builtin_interfaces/Time`.
    pub struct Time("builtin_interfaces/msg/Time") {
        consts {}
        sec: i32,
        nanosec: u32,
    }
}

impl Time {
    /// Time from nanoseconds since the epoch of the clock in use.
    pub fn from_nanos(ns: u64) -> Self {
        Time {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }
    pub fn as_secs_f64(&self) -> f64 {
        self.sec as f64 + self.nanosec as f64 * 1e-9
    }
}

ros_message! {
    /// One alarm, numbered as in the manual's alarm tables.
    pub struct Alarm("cnc_msgs/msg/Alarm") {
        consts {
            SEVERITY_INFO: u8 = 0,
            SEVERITY_WARNING: u8 = 1,
            SEVERITY_ERROR: u8 = 2,
            SEVERITY_FATAL: u8 = 3,
        }
        number: u32,
        severity: u8,
        text: String,
        source: String,
        program: String,
        line: u32,
        stamp: Time,
        acknowledged: bool,
    }
}

ros_message! {
    /// Every alarm that is active now.
    pub struct ActiveAlarms("cnc_msgs/msg/ActiveAlarms") {
        consts {}
        stamp: Time,
        alarms: Vec<Alarm>,
    }
}

ros_message! {
    /// An alarm was raised or cleared.
    pub struct AlarmEvent("cnc_msgs/msg/AlarmEvent") {
        consts { RAISED: u8 = 1, CLEARED: u8 = 2 }
        kind: u8,
        alarm: Alarm,
    }
}

ros_message! {
    /// One axis in machine coordinates.
    pub struct Axis("cnc_msgs/msg/Axis") {
        consts {}
        name: String,
        commanded_position: f64,
        actual_position: f64,
        following_error: f64,
        homed: bool,
        overtravel: i8,
        locked: bool,
    }
}

ros_message! {
    pub struct AxisState("cnc_msgs/msg/AxisState") {
        consts {}
        stamp: Time,
        axes: Vec<Axis>,
        machine_lock: bool,
    }
}

ros_message! {
    /// Mode and execution state of the machine.
    pub struct MachineState("cnc_msgs/msg/MachineState") {
        consts {
            MODE_AUTO: u8 = 0,
            MODE_MDI: u8 = 1,
            MODE_JOG: u8 = 2,
            MODE_HOME: u8 = 3,
            MODE_EDIT: u8 = 4,
            MODE_HANDWHEEL: u8 = 5,
            READY: u8 = 0,
            ACTIVE: u8 = 1,
            INTERRUPTED: u8 = 2,
            FEED_HOLD: u8 = 3,
            STOPPED: u8 = 4,
            PROGRAM_STOPPED: u8 = 5,
            PROGRAM_COMPLETED: u8 = 6,
            WAIT: u8 = 7,
        }
        stamp: Time,
        mode: u8,
        execution: u8,
        execution_name: String,
        program: String,
        line: u32,
        emergency_stop: bool,
        alarm_active: bool,
        message: String,
    }
}

impl MachineState {
    /// The mode's name as the panel's mode switch says it.
    pub fn mode_name_of(mode: u8) -> &'static str {
        match mode {
            Self::MODE_AUTO => "AUTO",
            Self::MODE_MDI => "MDI",
            Self::MODE_JOG => "JOG",
            Self::MODE_HOME => "HOME",
            Self::MODE_EDIT => "EDIT",
            Self::MODE_HANDWHEEL => "HANDWHEEL",
            _ => "UNKNOWN",
        }
    }

    /// MTConnect name of an execution state.
    pub fn execution_name_of(execution: u8) -> &'static str {
        match execution {
            Self::READY => "READY",
            Self::ACTIVE => "ACTIVE",
            Self::INTERRUPTED => "INTERRUPTED",
            Self::FEED_HOLD => "FEED_HOLD",
            Self::STOPPED => "STOPPED",
            Self::PROGRAM_STOPPED => "PROGRAM_STOPPED",
            Self::PROGRAM_COMPLETED => "PROGRAM_COMPLETED",
            Self::WAIT => "WAIT",
            _ => "UNAVAILABLE",
        }
    }
}

ros_message! {
    pub struct PartCount("cnc_msgs/msg/PartCount") {
        consts {}
        stamp: Time,
        count: u32,
        target: u32,
        last_cycle_time: f64,
    }
}

ros_message! {
    pub struct SpindleState("cnc_msgs/msg/SpindleState") {
        consts { DIRECTION_STOP: u8 = 0, DIRECTION_CW: u8 = 1, DIRECTION_CCW: u8 = 2 }
        stamp: Time,
        commanded_rpm: f64,
        actual_rpm: f64,
        direction: u8,
        load: f32,
        override_percent: f32,
        at_speed: bool,
        positioned: bool,
        position_deg: f64,
    }
}

ros_message! {
    /// Servo loop statistics since start, in microseconds.
    pub struct ServoStats("cnc_msgs/msg/ServoStats") {
        consts {}
        stamp: Time,
        period_us: f64,
        ticks: u64,
        late_ticks: u64,
        interval_min_us: f64,
        interval_p50_us: f64,
        interval_p99_us: f64,
        interval_max_us: f64,
        round_trips: u64,
        round_trip_min_us: f64,
        round_trip_p50_us: f64,
        round_trip_p99_us: f64,
        round_trip_max_us: f64,
        realtime: bool,
        wake_late_max_us: f64,
        interpolation_max_us: f64,
        exchange_max_us: f64,
        worst_phase: String,
    }
}

ros_message! {
    /// The PLC's scan: which program runs, how long a scan takes, whether it stopped itself.
    pub struct PlcStatus("cnc_msgs/msg/PlcStatus") {
        consts {}
        stamp: Time,
        program: String,
        steps: u32,
        scans: u64,
        level2_divisions: u32,
        scan_time_last_us: f64,
        scan_time_p99_us: f64,
        scan_time_max_us: f64,
        fault: String,
    }
}

ros_message! {
    /// One canonical block from the interpreter to motion.
    pub struct MotionBlock("cnc_msgs/msg/MotionBlock") {
        consts {
            KIND_RAPID: u8 = 0,
            KIND_LINEAR: u8 = 1,
            KIND_ARC_CW: u8 = 2,
            KIND_ARC_CCW: u8 = 3,
            KIND_DWELL: u8 = 4,
            KIND_AUX: u8 = 5,
            KIND_PROGRAM_END: u8 = 6,
            KIND_THREAD: u8 = 7,
            KIND_FEED_MODE: u8 = 8,
            KIND_PATH_MODE: u8 = 9,
            KIND_PROFILE: u8 = 10,
            KIND_TAP: u8 = 11,
            KIND_FEEDFORWARD: u8 = 12,
            KIND_ACCELERATION: u8 = 13,
            KIND_PROBE: u8 = 14,
            KIND_FIXED_STOP: u8 = 15,
            KIND_COMPRESSOR: u8 = 16,
            KIND_FIFO: u8 = 17,
            KIND_SYNC: u8 = 18,
            KIND_ROTARY: u8 = 19,
            KIND_CONTOUR: u8 = 20,
            KIND_LIVE_TOOL: u8 = 21,
            AUX_M: u8 = 1,
            AUX_S: u8 = 2,
            AUX_T: u8 = 3,
            AUX_ORIENT: u8 = 4,
            AUX_H: u8 = 5,
        }
        run_id: u64,
        seq: u64,
        program: String,
        line: u32,
        kind: u8,
        end: Vec<f64>,
        center: Vec<f64>,
        plane: Vec<u8>,
        feed: f64,
        dwell_seconds: f64,
        lead: f64,
        start_angle: f64,
        flag: bool,
        aux_kind: u8,
        aux_code: i32,
        aux_value: f64,
        origin: Vec<f64>,
        work_frame: Vec<f64>,
    }
}

ros_message! {
    /// Motion's report to the interpreter: queue credit and execution progress.
    pub struct MotionStatus("cnc_msgs/msg/MotionStatus") {
        consts { STATE_IDLE: u8 = 0, STATE_RUNNING: u8 = 1, STATE_HOLD: u8 = 2, STATE_ALARM: u8 = 3 }
        run_id: u64,
        accepted_seq: u64,
        done_seq: u64,
        capacity: u32,
        line: u32,
        state: u8,
        result_seq: u64,
        result_triggered: bool,
        result_position: Vec<f64>,
        result_rest: Vec<f64>,
        cutting_time: f64,
        cycle_time: f64,
        operating_time: f64,
        power_on_time: f64,
    }
}

ros_message! {
    /// A command to the task from hmi_bridge (typed; `task::TaskRequest` converts it).
    pub struct TaskCommand("cnc_msgs/msg/TaskCommand") {
        consts {
            LOAD: u8 = 1,
            START: u8 = 2,
            FEED_HOLD: u8 = 3,
            CYCLE_STOP: u8 = 4,
            RESET: u8 = 5,
            LIST: u8 = 6,
            DELETE: u8 = 7,
            READ: u8 = 8,
            MDI: u8 = 9,
            MODE: u8 = 10,
            OFFSETS: u8 = 11,
            SET_TOOL_OFFSET: u8 = 12,
            SET_WORK_OFFSET: u8 = 13,
            JOG: u8 = 14,
        }
        id: u64,
        kind: u8,
        program: String,
        text: String,
        start_at: String,
        mode: u8,
        axis: String,
        direction: i8,
        feed: f64,
        increment: f64,
        tool_offset: ToolOffset,
        work_offset: WorkOffset,
    }
}

ros_message! {
    /// What the task decided motion must do (typed; `task::MotionRequest` converts it).
    pub struct MotionCommand("cnc_msgs/msg/MotionCommand") {
        consts {
            FEED_HOLD: u8 = 1,
            RESUME: u8 = 2,
            CYCLE_STOP: u8 = 3,
            RESET: u8 = 4,
            REFERENCE_RETURN: u8 = 5,
            JOG: u8 = 6,
            MODE: u8 = 7,
        }
        id: u64,
        kind: u8,
        axis: u8,
        direction: i8,
        feed: f64,
        increment: f64,
        mode: u8,
    }
}

ros_message! {
    /// The answer to a `TaskCommand` (or a `MotionCommand`), with the same id; a LIST or
    /// OFFSETS answer brings its rows typed.
    pub struct CommandResult("cnc_msgs/msg/CommandResult") {
        consts {}
        id: u64,
        accepted: bool,
        message: String,
        programs: Vec<String>,
        program_sizes: Vec<u64>,
        tool_offsets: Vec<ToolOffset>,
        work_offsets: Vec<WorkOffset>,
    }
}

ros_message! {
    /// Operator or test input to the simulated machine.
    pub struct SimInput("cnc_msgs/msg/SimInput") {
        consts {
            EMERGENCY_STOP: u8 = 1,
            TURRET_STUCK: u8 = 2,
            AIR_LOST: u8 = 3,
            DOOR_FORCED_OPEN: u8 = 4,
            ROBOT_CLEAR: u8 = 5,
            ROBOT_CHUCK_OPEN: u8 = 6,
            ROBOT_CHUCK_CLOSE: u8 = 7,
            ROBOT_DOOR_OPEN: u8 = 8,
            ROBOT_DOOR_CLOSE: u8 = 9,
            ROBOT_CYCLE_START: u8 = 10,
            CYCLE_START_KEY: u8 = 11,
            RESET_KEY: u8 = 12,
            MACHINE_LOCK_KEY: u8 = 13,
            AUX_LOCK_KEY: u8 = 14,
            DRY_RUN_KEY: u8 = 15,
            BLOCK_SKIP_KEY: u8 = 16,
            HANDWHEEL_SELECT_X: u8 = 17,
            HANDWHEEL_SELECT_Z: u8 = 18,
            HANDWHEEL_X10: u8 = 19,
            HANDWHEEL_X100: u8 = 20,
            Z_AXIS_LOCK_KEY: u8 = 21,
            HANDWHEEL_DETENT: u8 = 22,
            HANDWHEEL_TRIAL_KEY: u8 = 23,
            FEED_HOLD_KEY: u8 = 24,
            JOG_PLUS_X_KEY: u8 = 25,
            JOG_MINUS_X_KEY: u8 = 26,
            JOG_PLUS_Z_KEY: u8 = 27,
            JOG_MINUS_Z_KEY: u8 = 28,
            SINGLE_BLOCK_KEY: u8 = 29
        }
        input: u8,
        value: bool,
    }
}

ros_message! {
    /// A command from outside the machine, accepted or refused, with who sent it.
    pub struct CommandEvent("cnc_msgs/msg/CommandEvent") {
        consts {}
        stamp: Time,
        command: String,
        detail: String,
        client: String,
        accepted: bool,
        message: String,
    }
}

ros_message! {
    /// One row of the tool offset page.
    pub struct ToolOffset("cnc_msgs/msg/ToolOffset") {
        consts {}
        number: u32,
        x: f64,
        z: f64,
        wear_x: f64,
        wear_z: f64,
        radius: f64,
        tip: u8,
    }
}

ros_message! {
    /// One work offset (G54–G59): the named axes' values.
    pub struct WorkOffset("cnc_msgs/msg/WorkOffset") {
        consts {}
        code: String,
        axes: Vec<String>,
        values: Vec<f64>,
    }
}

ros_message! {
    /// What happened to a program run: started, each block, paused, resumed, completed, aborted.
    pub struct ProgramEvent("cnc_msgs/msg/ProgramEvent") {
        consts {
            STARTED: u8 = 1,
            BLOCK: u8 = 2,
            PAUSED: u8 = 3,
            RESUMED: u8 = 4,
            COMPLETED: u8 = 5,
            ABORTED: u8 = 6,
        }
        stamp: Time,
        kind: u8,
        kind_name: String,
        program: String,
        line: u32,
        blocks: u32,
        elapsed: f64,
        reason: String,
    }
}

ros_message! {
    /// One machine of the cell as the cell supervisor sees it.
    pub struct CellMachine("cnc_msgs/msg/CellMachine") {
        consts {
            WAITING: u8 = 0,
            PRODUCING: u8 = 1,
            PAUSED: u8 = 2,
            UNREACHABLE: u8 = 3,
            DONE: u8 = 4,
        }
        name: String,
        status: u8,
        reason: String,
        program: String,
        target: u32,
        count: u32,
        counter_at_start: u32,
        cycle_times: Vec<f64>,
        silent_seconds: f64,
    }
}

ros_message! {
    /// The cell supervisor's view of its work order.
    pub struct CellState("cnc_msgs/msg/CellState") {
        consts {}
        stamp: Time,
        order: String,
        complete: bool,
        machines: Vec<CellMachine>,
    }
}

ros_message! {
    /// The machine's side of the robot handshake.
    pub struct RobotHandshake("cnc_msgs/msg/RobotHandshake") {
        consts {}
        stamp: Time,
        ready_for_load: bool,
        cycle_complete: bool,
        door_open: bool,
        door_closed: bool,
        chuck_clamped: bool,
        chuck_unclamped: bool,
        robot_clear: bool,
        spindle_turning: bool,
        cycle_active: bool,
        emergency_stop: bool,
    }
}

ros_message! {
    /// The panel's override switches.
    pub struct Overrides("cnc_msgs/msg/Overrides") {
        consts {}
        feed_percent: u8,
        spindle_percent: u8,
        rapid_percent: u8,
    }
}

ros_message! {
    /// A low-rate snapshot of the PLC's signal tables (ladder monitor, audits).
    pub struct PlcSignals("cnc_msgs/msg/PlcSignals") {
        consts {}
        stamp: Time,
        scan: u64,
        x: Vec<u8>,
        y: Vec<u8>,
        f: Vec<u8>,
        g: Vec<u8>,
        r: Vec<u8>,
        a: Vec<u8>,
        k: Vec<u8>,
    }
}

ros_message! {
    /// The running PLC program as rungs, sent when it is loaded.
    pub struct PlcProgram("cnc_msgs/msg/PlcProgram") {
        consts {}
        stamp: Time,
        source: String,
        rungs: Vec<String>,
        lines: Vec<u32>,
    }
}
