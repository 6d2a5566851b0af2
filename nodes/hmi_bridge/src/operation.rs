//! Every command the bridge takes from outside, whichever door it came through (a ROS 2
//! service, the `RunProgram` action, a robot request or a button of the web HMI), as one
//! value: so every door gets the same checks, the same refusals and the same event.

use cnc_msgs::msg::{MachineState, Overrides};

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
    SetToolOffset {
        number: String,
        values: String,
    },
    SetWorkOffset {
        code: String,
        values: String,
    },
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
            Operation::SetToolOffset { .. } => "set_tool_offset",
            Operation::SetWorkOffset { .. } => "set_work_offset",
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
            Operation::SetToolOffset { number, values } => format!("{number}: {values}"),
            Operation::SetWorkOffset { code, values } => format!("{code}: {values}"),
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
                | Operation::SetToolOffset { .. }
                | Operation::SetWorkOffset { .. }
                | Operation::SetParameter { .. }
        )
    }

    /// Reading changes nothing: it is an event only when refused.
    pub fn reads(&self) -> bool {
        matches!(
            self,
            Operation::Read { .. } | Operation::Offsets | Operation::Parameters { .. }
        )
    }
}

/// Parameter rows as one text (`name<TAB>value<TAB>pending` lines), as `List` answers.
pub fn parameter_text(rows: &[crate::parameters::Row]) -> String {
    rows.iter()
        .map(|(n, v, p)| format!("{n}\t{v}\t{p}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The rows of [`parameter_text`] again.
pub fn parameter_rows(text: &str) -> Vec<crate::parameters::Row> {
    text.lines()
        .filter_map(|line| {
            let mut f = line.splitn(3, '\t');
            Some((f.next()?.into(), f.next()?.into(), f.next()?.into()))
        })
        .collect()
}

/// The interpreter's program list (`name<TAB>size` lines) as names and sizes.
pub fn program_list(text: &str) -> Vec<(String, u64)> {
    text.lines()
        .filter_map(|line| line.rsplit_once('\t'))
        .map(|(name, size)| (name.to_string(), size.parse().unwrap_or(0)))
        .collect()
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
        let rows = vec![
            ("a.b".to_string(), "1.0".to_string(), String::new()),
            ("c".to_string(), "x y".to_string(), "z".to_string()),
        ];
        assert_eq!(parameter_rows(&parameter_text(&rows)), rows);
        assert_eq!(
            program_list("O0001\t95\nMDI\t12\nbroken line\n"),
            [("O0001".to_string(), 95), ("MDI".to_string(), 12)]
        );
    }
}
