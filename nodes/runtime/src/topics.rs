//! Every DDS topic of one machine, in one table: its name under the machine's namespace, its
//! message type and what kind of delivery it needs. Nodes create their publishers and
//! subscriptions from these entries (so a name or type cannot drift between writer and reader),
//! and the recorder records exactly this table.

use ros2_client::QosProfile;

use crate::dds::qos;

/// How a topic is delivered (DESIGN.md "QoS says what a topic means").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delivery {
    /// Reliable, transient-local, depth 1: the current value.
    State,
    /// Reliable, volatile, keep the last `n`.
    Events(usize),
    /// Reliable, deep: command and block streams between nodes.
    Commands,
}

/// One topic: `/<namespace>/<path>` of type `type_name`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Topic {
    pub path: &'static str,
    /// `cnc_msgs/msg/SpindleState` style.
    pub type_name: &'static str,
    pub delivery: Delivery,
}

impl Topic {
    pub fn qos(&self) -> QosProfile {
        match self.delivery {
            Delivery::State => qos::state(),
            Delivery::Events(n) => qos::events(n),
            Delivery::Commands => qos::commands(),
        }
    }

    /// Internal topics (`_internal/…`) are the nodes' own plumbing; ROS 2 tools hide them.
    pub fn internal(&self) -> bool {
        self.path.starts_with("_internal/")
    }
}

const fn topic(path: &'static str, type_name: &'static str, delivery: Delivery) -> Topic {
    Topic {
        path,
        type_name,
        delivery,
    }
}

pub const MACHINE_STATE: Topic = topic(
    "machine_state",
    "cnc_msgs/msg/MachineState",
    Delivery::State,
);
pub const SPINDLE: Topic = topic("spindle", "cnc_msgs/msg/SpindleState", Delivery::State);
pub const AXES: Topic = topic("axes", "cnc_msgs/msg/AxisState", Delivery::State);
/// A turn-mill's live tool as a spindle: its speed in speed mode, its angle (D143).
pub const LIVE_TOOL: Topic = topic("live_tool", "cnc_msgs/msg/SpindleState", Delivery::State);
pub const PART_COUNT: Topic = topic("part_count", "cnc_msgs/msg/PartCount", Delivery::State);
pub const ALARMS: Topic = topic("alarms", "cnc_msgs/msg/ActiveAlarms", Delivery::State);
pub const ALARM_EVENTS: Topic = topic(
    "alarm_events",
    "cnc_msgs/msg/AlarmEvent",
    Delivery::Events(100),
);
pub const PLC_STATUS: Topic = topic("plc/status", "cnc_msgs/msg/PlcStatus", Delivery::State);
pub const SERVO_STATS: Topic = topic("servo_stats", "cnc_msgs/msg/ServoStats", Delivery::State);
/// The PLC's signal tables, five times a second.
pub const PLC_SIGNALS: Topic = topic("plc/signals", "cnc_msgs/msg/PlcSignals", Delivery::State);
/// The PLC program as rungs, latched: a late ladder monitor still gets it.
pub const PLC_PROGRAM: Topic = topic("plc/program", "cnc_msgs/msg/PlcProgram", Delivery::State);
pub const ROBOT_HANDSHAKE: Topic = topic(
    "robot_handshake",
    "cnc_msgs/msg/RobotHandshake",
    Delivery::State,
);
/// Robot signals set by hmi_bridge's robot service, for the io node's robot interface block
/// (X8): what a fieldbus robot interface would carry.
pub const ROBOT_SIGNALS: Topic = topic(
    "_internal/robot_signals",
    "cnc_msgs/msg/SimInput",
    Delivery::Events(32),
);
/// Override switch positions set by hmi_bridge's override service, for the io node's panel
/// block (X16–X18).
pub const PANEL_OVERRIDES: Topic = topic(
    "_internal/panel_overrides",
    "cnc_msgs/msg/Overrides",
    Delivery::Events(8),
);
pub const COMMAND_EVENTS: Topic = topic(
    "command_events",
    "cnc_msgs/msg/CommandEvent",
    Delivery::Events(100),
);
pub const PROGRAM_EVENTS: Topic = topic(
    "program_events",
    "cnc_msgs/msg/ProgramEvent",
    Delivery::Events(100),
);
/// Inputs to the simulated machine from clients (only when the machine is simulated); the
/// bridge checks who sent them and passes an allowed client's on [`SIM_INPUT_CHECKED`].
pub const SIM_INPUT: Topic = topic("sim/input", "cnc_msgs/msg/SimInput", Delivery::Events(10));
/// The simulated machine's inputs as the bridge passed them on, for the io node.
pub const SIM_INPUT_CHECKED: Topic = topic(
    "_internal/sim_input",
    "cnc_msgs/msg/SimInput",
    Delivery::Events(10),
);
/// The bridge's commands to the task (typed: `cnc_msgs::task::TaskRequest`), each answered on
/// [`COMMAND_RESULT`]; the task alone reads them.
pub const TASK_COMMAND: Topic = topic(
    "_internal/task_command",
    "cnc_msgs/msg/TaskCommand",
    Delivery::Commands,
);
/// What the task decided motion must do (feed hold, resume, cycle stop, reset, reference
/// return, jog, mode), each answered on [`MOTION_RESULT`]; motion takes commands from here
/// only (issue 47: one node judges a command).
pub const MOTION_COMMAND: Topic = topic(
    "_internal/motion_command",
    "cnc_msgs/msg/MotionCommand",
    Delivery::Commands,
);
/// Motion's answer to each [`MOTION_COMMAND`]: a refusal reaches the command's caller.
pub const MOTION_RESULT: Topic = topic(
    "_internal/motion_result",
    "cnc_msgs/msg/CommandResult",
    Delivery::Commands,
);
pub const COMMAND_RESULT: Topic = topic(
    "_internal/command_result",
    "cnc_msgs/msg/CommandResult",
    Delivery::Commands,
);
pub const MOTION_BLOCKS: Topic = topic(
    "_internal/motion_blocks",
    "cnc_msgs/msg/MotionBlock",
    Delivery::Commands,
);
pub const MOTION_STATUS: Topic = topic(
    "_internal/motion_status",
    "cnc_msgs/msg/MotionStatus",
    Delivery::State,
);

/// Topics the machine reads from clients on DDS (checked by the bridge, never by a node
/// directly); the machine itself publishes nothing on them.
pub const INPUTS: &[Topic] = &[SIM_INPUT];

/// Every topic a machine's nodes may publish (on the machine bus, and the public ones on DDS);
/// [`published_by`] says which a given machine does, and the recorder records those.
pub const ALL: &[Topic] = &[
    MACHINE_STATE,
    SPINDLE,
    AXES,
    LIVE_TOOL,
    PART_COUNT,
    ALARMS,
    ALARM_EVENTS,
    PLC_STATUS,
    PLC_SIGNALS,
    PLC_PROGRAM,
    SERVO_STATS,
    COMMAND_EVENTS,
    PROGRAM_EVENTS,
    ROBOT_HANDSHAKE,
    SIM_INPUT_CHECKED,
    ROBOT_SIGNALS,
    TASK_COMMAND,
    MOTION_COMMAND,
    MOTION_RESULT,
    COMMAND_RESULT,
    MOTION_BLOCKS,
    MOTION_STATUS,
    PANEL_OVERRIDES,
];

/// The topics `cfg`'s machine publishes: [`ALL`] but those of parts it lacks (the live
/// tool's only on a machine with one).
pub fn published_by(cfg: &crate::LaunchConfig) -> Vec<Topic> {
    ALL.iter()
        .copied()
        .filter(|t| t.path != LIVE_TOOL.path || cfg.machine.live_tool.is_some())
        .collect()
}

/// Whether `path` matches `pattern`: `*` stands for any run of characters (also `/`).
pub fn matches(pattern: &str, path: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == path,
        Some((head, rest)) => {
            let Some(tail) = path.strip_prefix(head) else {
                return false;
            };
            (0..=tail.len())
                .filter(|&i| tail.is_char_boundary(i))
                .any(|i| matches(rest, &tail[i..]))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns() {
        assert!(matches("*", "plc/status"));
        assert!(matches("_internal/*", "_internal/motion_blocks"));
        assert!(!matches("_internal/*", "axes"));
        assert!(matches("*status", "plc/status"));
        assert!(matches("a*b*c", "axxbyyc"));
        assert!(!matches("a*b*c", "axxbyy"));
        assert!(matches("axes", "axes"));
        assert!(!matches("axes", "axes2"));
    }

    /// A topic left out of [`ALL`] would not be recorded: every `Topic` constant is in it.
    #[test]
    fn every_topic_constant_is_in_the_table() {
        let source = include_str!("topics.rs");
        let declared: Vec<&str> = source
            .lines()
            .filter_map(|l| l.strip_prefix("pub const "))
            .filter_map(|l| l.split_once(": Topic =").map(|(name, _)| name))
            .collect();
        assert_eq!(declared.len(), ALL.len() + INPUTS.len(), "{declared:?}");
    }

    #[test]
    fn names_are_unique() {
        for (i, a) in ALL.iter().enumerate() {
            assert!(ALL[i + 1..].iter().all(|b| b.path != a.path), "{}", a.path);
        }
    }
}
