//! Every command the bridge takes from outside, whichever door it came through (a ROS 2
//! service, the `RunProgram` action, a robot request or a button of the web HMI), as one
//! value: so every door gets the same checks, the same refusals and the same event.

use cnc_msgs::msg::{MachineState, Overrides, ToolOffset, WorkOffset};
use cnc_msgs::srv::StopRequest;
use cnc_msgs::task::TaskRequest;

/// One command to the machine.
#[derive(Debug, Clone, PartialEq)]
pub enum Operation {
    Load {
        name: String,
        text: String,
    },
    /// Cycle start of a stored program; an empty name resumes after feed hold. `at` starts it
    /// in mid-program (block search, decisions D67): empty (the top), `line 12`, `N120`,
    /// `label NAME` or `interrupted`; the interpreter checks it.
    Start {
        name: String,
        at: String,
    },
    /// A jog of one axis (JOG and HANDWHEEL modes, D69); a continuous one is held by
    /// repeating it.
    Jog {
        axis: String,
        direction: i8,
        feed: f64,
        increment: f64,
    },
    /// `StopRequest::FEED_HOLD` or `CYCLE_STOP`.
    Stop {
        mode: u8,
    },
    Reset,
    List,
    Delete {
        name: String,
    },
    Overrides(Overrides),
    /// `MachineState::MODE_*`.
    Mode {
        mode: u8,
    },
    /// Blocks typed at the MDI line, run at once (MDI mode only).
    Mdi {
        text: String,
    },
    Read {
        name: String,
    },
    Offsets,
    SetToolOffset(ToolOffset),
    SetWorkOffset(WorkOffset),
    /// Parameters whose names start with `prefix`.
    Parameters {
        prefix: String,
    },
    SetParameter {
        name: String,
        value: String,
    },
    /// An empty source and number 0: every active alarm.
    Acknowledge {
        source: String,
        number: u32,
    },
}

impl Operation {
    /// The command's name in events (the service's name where there is one).
    pub fn command(&self) -> &'static str {
        match self {
            Operation::Load { .. } => "load_program",
            Operation::Start { .. } => "start_program",
            Operation::Jog { .. } => "jog",
            Operation::Stop { .. } => "stop",
            Operation::Reset => "reset",
            Operation::List => "list_programs",
            Operation::Delete { .. } => "delete_program",
            Operation::Overrides(_) => "set_overrides",
            Operation::Mode { .. } => "set_mode",
            Operation::Mdi { .. } => "mdi",
            Operation::Read { .. } => "read_program",
            Operation::Offsets => "get_offsets",
            Operation::SetToolOffset(_) => "set_tool_offset",
            Operation::SetWorkOffset(_) => "set_work_offset",
            Operation::Parameters { .. } => "get_parameters",
            Operation::SetParameter { .. } => "set_parameter",
            Operation::Acknowledge { .. } => "acknowledge_alarm",
        }
    }

    /// What the event says about it besides the command.
    pub fn detail(&self) -> String {
        match self {
            Operation::Start { name, at } if !at.is_empty() => format!("{name} at {at}"),
            Operation::Load { name, .. }
            | Operation::Start { name, .. }
            | Operation::Delete { name }
            | Operation::Read { name } => name.clone(),
            Operation::Stop { mode } => format!("mode {mode}"),
            Operation::Jog {
                axis,
                direction,
                feed,
                increment,
            } => format!("{axis} {direction:+} F{feed} step {increment}"),
            Operation::Overrides(o) => format!(
                "feed {} %, spindle {} %, rapid {} %",
                o.feed_percent, o.spindle_percent, o.rapid_percent
            ),
            Operation::Mode { mode } => MachineState::mode_name_of(*mode).into(),
            Operation::Mdi { text } => text.chars().take(200).collect(),
            Operation::SetToolOffset(t) => format!(
                "{}: {} {} {} {} {} {}",
                t.number, t.x, t.z, t.wear_x, t.wear_z, t.radius, t.tip
            ),
            Operation::SetWorkOffset(w) => {
                let values: Vec<String> = w
                    .axes
                    .iter()
                    .zip(&w.values)
                    .map(|(a, v)| format!("{a}={v}"))
                    .collect();
                format!("{}: {}", w.code, values.join(" "))
            }
            Operation::Parameters { prefix } => prefix.clone(),
            Operation::SetParameter { name, value } => format!("{name} = {value}"),
            Operation::Acknowledge { source, number } => format!("{source} {number}"),
            Operation::Reset | Operation::List | Operation::Offsets => String::new(),
        }
    }

    /// Whether only allowed clients may give it (`hmi.allowed_clients`): whatever starts
    /// motion or changes how the next cut comes out, loading and deleting programs included
    /// (a program overwritten is the next part cut wrong). Stopping is never refused; reading
    /// (the program list and texts too) is open to the cell.
    pub fn moves(&self) -> bool {
        matches!(
            self,
            Operation::Start { .. }
                | Operation::Jog { .. }
                | Operation::Load { .. }
                | Operation::Delete { .. }
                | Operation::Overrides(_)
                | Operation::Mode { .. }
                | Operation::Mdi { .. }
                | Operation::SetToolOffset(_)
                | Operation::SetWorkOffset(_)
                | Operation::SetParameter { .. }
        )
    }

    /// The task's request this operation is (`Ok(None)`: the bridge's own — overrides,
    /// parameters, the alarm list); values a request cannot carry are refused here.
    pub fn task_request(&self) -> Result<Option<TaskRequest>, String> {
        Ok(Some(match self {
            Operation::Load { name, text } => TaskRequest::Load {
                name: name.clone(),
                text: text.clone(),
            },
            Operation::Start { name, at } => TaskRequest::Start {
                name: name.clone(),
                at: at.clone(),
            },
            Operation::Jog {
                axis,
                direction,
                feed,
                increment,
            } => TaskRequest::Jog(cnc_msgs::jog::Jog::new(
                axis, *direction, *feed, *increment,
            )?),
            Operation::Stop { mode } => match *mode {
                StopRequest::FEED_HOLD => TaskRequest::FeedHold,
                StopRequest::CYCLE_STOP => TaskRequest::CycleStop,
                other => {
                    return Err(format!(
                        "unknown stop mode {other}: use 1 (FEED_HOLD) or 2 (CYCLE_STOP)"
                    ))
                }
            },
            Operation::Reset => TaskRequest::Reset,
            Operation::List => TaskRequest::List,
            Operation::Delete { name } => TaskRequest::Delete { name: name.clone() },
            Operation::Mode { mode } => TaskRequest::Mode(*mode),
            Operation::Mdi { text } => TaskRequest::Mdi { text: text.clone() },
            Operation::Read { name } => TaskRequest::Read { name: name.clone() },
            Operation::Offsets => TaskRequest::Offsets,
            Operation::SetToolOffset(t) => TaskRequest::SetToolOffset(t.clone()),
            Operation::SetWorkOffset(w) => TaskRequest::SetWorkOffset(w.clone()),
            Operation::Overrides(_)
            | Operation::Parameters { .. }
            | Operation::SetParameter { .. }
            | Operation::Acknowledge { .. } => return Ok(None),
        }))
    }

    /// Reading changes nothing: it is an event only when refused.
    pub fn reads(&self) -> bool {
        matches!(
            self,
            Operation::Read { .. } | Operation::Offsets | Operation::Parameters { .. }
        )
    }
}

/// An operation's answer: accepted or refused with why, and the rows a reading brings, typed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Answer {
    pub accepted: bool,
    pub message: String,
    /// `List`: the stored programs and their sizes, bytes.
    pub programs: Vec<(String, u64)>,
    /// `Offsets`: the offset pages.
    pub tools: Vec<ToolOffset>,
    pub work: Vec<WorkOffset>,
    /// `Parameters`: name, value, pending value.
    pub parameters: Vec<crate::parameters::Row>,
}

impl Answer {
    pub fn said(accepted: bool, message: impl Into<String>) -> Answer {
        Answer {
            accepted,
            message: message.into(),
            ..Answer::default()
        }
    }

    pub fn refused(why: impl Into<String>) -> Answer {
        Answer::said(false, why)
    }

    /// The task's answer.
    pub fn of_task(r: cnc_msgs::msg::CommandResult) -> Answer {
        Answer {
            accepted: r.accepted,
            message: r.message,
            programs: r.programs.into_iter().zip(r.program_sizes).collect(),
            tools: r.tool_offsets,
            work: r.work_offsets,
            parameters: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stopping_and_reading_are_open_to_everyone_moving_is_not() {
        assert!(!Operation::Stop { mode: 1 }.moves());
        assert!(!Operation::Reset.moves());
        assert!(!Operation::Offsets.moves());
        assert!(Operation::Start {
            name: "O1".into(),
            at: String::new()
        }
        .moves());
        // Program memory is guarded: a program overwritten is the next part cut wrong.
        assert!(Operation::Load {
            name: "O1".into(),
            text: String::new()
        }
        .moves());
        assert!(Operation::Delete { name: "O1".into() }.moves());
        assert!(!Operation::List.moves());
        assert!(!Operation::Read { name: "O1".into() }.moves());
        assert!(Operation::Mdi {
            text: "G0X1".into()
        }
        .moves());
        assert_eq!(Operation::Mode { mode: 1 }.detail(), "MDI");
        assert!(Operation::SetParameter {
            name: "servo.lookahead".into(),
            value: "8".into()
        }
        .moves());
        assert!(!Operation::Acknowledge {
            source: String::new(),
            number: 0
        }
        .moves());
        assert_eq!(
            Operation::Stop { mode: 1 }.task_request(),
            Ok(Some(TaskRequest::FeedHold))
        );
        assert!(Operation::Stop { mode: 7 }.task_request().is_err());
        assert_eq!(
            Operation::Parameters {
                prefix: String::new()
            }
            .task_request(),
            Ok(None)
        );
    }
}
