//! The typed command path (issue 47): what the one door for commands (hmi_bridge) asks of the
//! task, [`TaskRequest`], and what the task asks of motion, [`MotionRequest`], each with the one
//! conversion to and from its wire form (`TaskCommand`, `MotionCommand`), which checks every
//! value: a node reads typed fields, never text another node formatted.

use crate::jog::Jog;
use crate::msg::{MotionCommand, TaskCommand, ToolOffset, WorkOffset};

/// A command to the task.
#[derive(Debug, Clone, PartialEq)]
pub enum TaskRequest {
    Load {
        name: String,
        text: String,
    },
    /// Cycle start of a stored program (an empty name resumes after feed hold), at the top or
    /// where `at` says (block search, D67).
    Start {
        name: String,
        at: String,
    },
    FeedHold,
    CycleStop,
    Reset,
    List,
    Delete {
        name: String,
    },
    Read {
        name: String,
    },
    /// Blocks typed at the MDI line, run at once (MDI mode only).
    Mdi {
        text: String,
    },
    /// A `MachineState::MODE_*` number.
    Mode(u8),
    Offsets,
    SetToolOffset(ToolOffset),
    SetWorkOffset(WorkOffset),
    Jog(Jog),
}

impl TaskRequest {
    /// The wire form, as command `id`.
    pub fn to_command(&self, id: u64) -> TaskCommand {
        let mut c = TaskCommand {
            id,
            ..TaskCommand::default()
        };
        match self {
            TaskRequest::Load { name, text } => {
                c.kind = TaskCommand::LOAD;
                c.program.clone_from(name);
                c.text.clone_from(text);
            }
            TaskRequest::Start { name, at } => {
                c.kind = TaskCommand::START;
                c.program.clone_from(name);
                c.start_at.clone_from(at);
            }
            TaskRequest::FeedHold => c.kind = TaskCommand::FEED_HOLD,
            TaskRequest::CycleStop => c.kind = TaskCommand::CYCLE_STOP,
            TaskRequest::Reset => c.kind = TaskCommand::RESET,
            TaskRequest::List => c.kind = TaskCommand::LIST,
            TaskRequest::Delete { name } => {
                c.kind = TaskCommand::DELETE;
                c.program.clone_from(name);
            }
            TaskRequest::Read { name } => {
                c.kind = TaskCommand::READ;
                c.program.clone_from(name);
            }
            TaskRequest::Mdi { text } => {
                c.kind = TaskCommand::MDI;
                c.text.clone_from(text);
            }
            TaskRequest::Mode(m) => {
                c.kind = TaskCommand::MODE;
                c.mode = *m;
            }
            TaskRequest::Offsets => c.kind = TaskCommand::OFFSETS,
            TaskRequest::SetToolOffset(t) => {
                c.kind = TaskCommand::SET_TOOL_OFFSET;
                c.tool_offset = t.clone();
            }
            TaskRequest::SetWorkOffset(w) => {
                c.kind = TaskCommand::SET_WORK_OFFSET;
                c.work_offset = w.clone();
            }
            TaskRequest::Jog(j) => {
                c.kind = TaskCommand::JOG;
                c.axis.clone_from(&j.axis);
                c.direction = j.direction;
                c.feed = j.feed;
                c.increment = j.increment;
            }
        }
        c
    }

    /// The request a wire command carries, its values checked (anyone on the machine's bus
    /// could write one).
    pub fn from_command(c: &TaskCommand) -> Result<TaskRequest, String> {
        Ok(match c.kind {
            TaskCommand::LOAD => TaskRequest::Load {
                name: c.program.clone(),
                text: c.text.clone(),
            },
            TaskCommand::START => TaskRequest::Start {
                name: c.program.clone(),
                at: c.start_at.clone(),
            },
            TaskCommand::FEED_HOLD => TaskRequest::FeedHold,
            TaskCommand::CYCLE_STOP => TaskRequest::CycleStop,
            TaskCommand::RESET => TaskRequest::Reset,
            TaskCommand::LIST => TaskRequest::List,
            TaskCommand::DELETE => TaskRequest::Delete {
                name: c.program.clone(),
            },
            TaskCommand::READ => TaskRequest::Read {
                name: c.program.clone(),
            },
            TaskCommand::MDI => TaskRequest::Mdi {
                text: c.text.clone(),
            },
            TaskCommand::MODE => TaskRequest::Mode(c.mode),
            TaskCommand::OFFSETS => TaskRequest::Offsets,
            TaskCommand::SET_TOOL_OFFSET => TaskRequest::SetToolOffset(c.tool_offset.clone()),
            TaskCommand::SET_WORK_OFFSET => TaskRequest::SetWorkOffset(c.work_offset.clone()),
            TaskCommand::JOG => {
                TaskRequest::Jog(Jog::new(&c.axis, c.direction, c.feed, c.increment)?)
            }
            other => return Err(format!("unknown command kind {other}")),
        })
    }
}

/// What the task asks of motion.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionRequest {
    FeedHold,
    Resume,
    CycleStop,
    Reset,
    ReferenceReturn,
    /// Axis index, +1/-1 (0 ends the jog), mm/min, mm (0: continuous).
    Jog {
        axis: u8,
        direction: i8,
        feed: f64,
        increment: f64,
    },
    /// A `MachineState::MODE_*` number.
    Mode(u8),
}

impl MotionRequest {
    pub fn to_command(&self, id: u64) -> MotionCommand {
        let mut c = MotionCommand {
            id,
            ..MotionCommand::default()
        };
        c.kind = match self {
            MotionRequest::FeedHold => MotionCommand::FEED_HOLD,
            MotionRequest::Resume => MotionCommand::RESUME,
            MotionRequest::CycleStop => MotionCommand::CYCLE_STOP,
            MotionRequest::Reset => MotionCommand::RESET,
            MotionRequest::ReferenceReturn => MotionCommand::REFERENCE_RETURN,
            MotionRequest::Jog {
                axis,
                direction,
                feed,
                increment,
            } => {
                c.axis = *axis;
                c.direction = *direction;
                c.feed = *feed;
                c.increment = *increment;
                MotionCommand::JOG
            }
            MotionRequest::Mode(m) => {
                c.mode = *m;
                MotionCommand::MODE
            }
        };
        c
    }

    /// The request a wire command carries, checked again by motion (`axes`: how many the
    /// machine has).
    pub fn from_command(c: &MotionCommand, axes: usize) -> Result<MotionRequest, String> {
        Ok(match c.kind {
            MotionCommand::FEED_HOLD => MotionRequest::FeedHold,
            MotionCommand::RESUME => MotionRequest::Resume,
            MotionCommand::CYCLE_STOP => MotionRequest::CycleStop,
            MotionCommand::RESET => MotionRequest::Reset,
            MotionCommand::REFERENCE_RETURN => MotionRequest::ReferenceReturn,
            MotionCommand::JOG => {
                if usize::from(c.axis) >= axes {
                    return Err(format!("jog: no axis {}", c.axis));
                }
                let j = Jog::new("X", c.direction, c.feed, c.increment)?;
                MotionRequest::Jog {
                    axis: c.axis,
                    direction: j.direction,
                    feed: j.feed,
                    increment: j.increment,
                }
            }
            MotionCommand::MODE => MotionRequest::Mode(c.mode),
            other => return Err(format!("unknown motion command kind {other}")),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_request_crosses_the_wire_and_comes_back_the_same() {
        let requests = [
            TaskRequest::Load {
                name: "O1".into(),
                text: "M30\n".into(),
            },
            TaskRequest::Start {
                name: "O1".into(),
                at: "line 3".into(),
            },
            TaskRequest::FeedHold,
            TaskRequest::CycleStop,
            TaskRequest::Reset,
            TaskRequest::List,
            TaskRequest::Delete { name: "O1".into() },
            TaskRequest::Read { name: "O1".into() },
            TaskRequest::Mdi {
                text: "G0 X1".into(),
            },
            TaskRequest::Mode(2),
            TaskRequest::Offsets,
            TaskRequest::SetToolOffset(ToolOffset {
                number: 3,
                x: 1.5,
                ..ToolOffset::default()
            }),
            TaskRequest::SetWorkOffset(WorkOffset {
                code: "G55".into(),
                axes: vec!["X".into()],
                values: vec![2.0],
            }),
            TaskRequest::Jog(Jog::new("z", -1, 600.0, 0.1).unwrap()),
        ];
        for (id, r) in requests.iter().enumerate() {
            let c = r.to_command(id as u64);
            assert_eq!(c.id, id as u64);
            assert_eq!(TaskRequest::from_command(&c).as_ref(), Ok(r));
        }
        let motion = [
            MotionRequest::FeedHold,
            MotionRequest::Resume,
            MotionRequest::CycleStop,
            MotionRequest::Reset,
            MotionRequest::ReferenceReturn,
            MotionRequest::Jog {
                axis: 1,
                direction: 1,
                feed: 500.0,
                increment: 0.0,
            },
            MotionRequest::Mode(5),
        ];
        for r in &motion {
            assert_eq!(
                MotionRequest::from_command(&r.to_command(1), 2).as_ref(),
                Ok(r)
            );
        }
    }

    #[test]
    fn bad_values_on_the_wire_are_refused() {
        let mut jog = TaskRequest::Jog(Jog::new("X", 1, 100.0, 0.0).unwrap()).to_command(1);
        jog.feed = f64::NAN;
        assert!(TaskRequest::from_command(&jog).is_err());
        let unknown = TaskCommand {
            kind: 99,
            ..TaskCommand::default()
        };
        assert!(TaskRequest::from_command(&unknown).is_err());
        let far = MotionRequest::Jog {
            axis: 4,
            direction: 1,
            feed: 100.0,
            increment: 0.0,
        }
        .to_command(1);
        assert!(MotionRequest::from_command(&far, 2).is_err());
    }
}
