//! The robot handshake as a service: what a robot may ask, when the machine refuses and why,
//! which robot signal (X8, docs/plc.md) carries the request to the PLC, and when it is done.
//! Pure: the shell holds the signal, watches `/robot_handshake` and answers.
//!
//! The bridge refuses what the PLC's interlocks would refuse anyway (the PLC keeps them: a
//! robot wired to X8 directly meets the same rules), so the robot gets the reason at once
//! instead of a timeout.

use cnc_msgs::msg::{RobotHandshake, SimInput};
use cnc_msgs::srv::RobotRequestRequest as Rq;

/// Longest a door or chuck request may take before it is reported as failed, s.
pub const ACTUATION_TIMEOUT: f64 = 10.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    DoorOpen,
    DoorClose,
    ChuckUnclamp,
    ChuckClamp,
    /// The robot is clear of the work area (true) or entering it (false).
    Clear(bool),
    CycleStart,
}

impl Op {
    pub fn from_request(code: u8) -> Result<Op, String> {
        Ok(match code {
            Rq::DOOR_OPEN => Op::DoorOpen,
            Rq::DOOR_CLOSE => Op::DoorClose,
            Rq::CHUCK_UNCLAMP => Op::ChuckUnclamp,
            Rq::CHUCK_CLAMP => Op::ChuckClamp,
            Rq::CLEAR => Op::Clear(true),
            Rq::NOT_CLEAR => Op::Clear(false),
            Rq::CYCLE_START => Op::CycleStart,
            other => return Err(format!("unknown robot request {other}: 1..7")),
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Op::DoorOpen => "door open",
            Op::DoorClose => "door close",
            Op::ChuckUnclamp => "chuck unclamp",
            Op::ChuckClamp => "chuck clamp",
            Op::Clear(true) => "robot clear",
            Op::Clear(false) => "robot not clear",
            Op::CycleStart => "cycle start",
        }
    }

    /// Whether the request moves something (and so needs a client allowed to move the
    /// machine). Reporting clear or not clear moves nothing.
    pub fn moves(self) -> bool {
        !matches!(self, Op::Clear(_))
    }

    /// The robot signal that carries the request and whether it is held (a level the robot
    /// keeps, like clear) or dropped once the request is done.
    pub fn signal(self) -> Option<(u8, bool)> {
        match self {
            Op::DoorOpen => Some((SimInput::ROBOT_DOOR_OPEN, false)),
            Op::DoorClose => Some((SimInput::ROBOT_DOOR_CLOSE, false)),
            Op::ChuckUnclamp => Some((SimInput::ROBOT_CHUCK_OPEN, false)),
            Op::ChuckClamp => Some((SimInput::ROBOT_CHUCK_CLOSE, false)),
            Op::Clear(_) => Some((SimInput::ROBOT_CLEAR, true)),
            Op::CycleStart => None,
        }
    }

    /// Whether the machine shows the request done.
    pub fn done(self, h: &RobotHandshake) -> bool {
        match self {
            Op::DoorOpen => h.door_open,
            Op::DoorClose => h.door_closed,
            Op::ChuckUnclamp => h.chuck_unclamped,
            Op::ChuckClamp => h.chuck_clamped,
            Op::Clear(v) => h.robot_clear == v,
            Op::CycleStart => h.cycle_active,
        }
    }
}

/// Why the machine refuses `op` in state `h`, if it does.
pub fn refusal(op: Op, h: &RobotHandshake) -> Option<String> {
    if op.moves() && h.emergency_stop {
        return Some(format!("{} refused: emergency stop", op.name()));
    }
    let why = match op {
        Op::DoorOpen | Op::ChuckUnclamp | Op::ChuckClamp if h.cycle_active => "cycle active",
        Op::DoorOpen | Op::ChuckUnclamp if h.spindle_turning => "spindle turning",
        Op::DoorClose if !h.robot_clear => "robot not clear of the work area",
        Op::CycleStart if h.cycle_active => "cycle active",
        Op::CycleStart if !h.robot_clear => "robot not clear of the work area",
        Op::CycleStart if !h.door_closed => "door not closed",
        Op::CycleStart if !h.chuck_clamped => "chuck not clamped",
        _ => return None,
    };
    Some(format!("{} refused: {why}", op.name()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn idle() -> RobotHandshake {
        RobotHandshake {
            door_closed: true,
            chuck_clamped: true,
            robot_clear: true,
            ..RobotHandshake::default()
        }
    }

    #[test]
    fn every_request_code_and_only_those() {
        for code in 1..=7 {
            assert!(Op::from_request(code).is_ok());
        }
        assert!(Op::from_request(0).is_err());
        assert!(Op::from_request(8).unwrap_err().contains("unknown"));
    }

    #[test]
    fn refusals_name_the_reason() {
        let mut h = idle();
        assert_eq!(refusal(Op::CycleStart, &h), None);
        assert_eq!(refusal(Op::DoorOpen, &h), None);
        h.spindle_turning = true;
        assert!(refusal(Op::DoorOpen, &h)
            .unwrap()
            .contains("spindle turning"));
        assert!(refusal(Op::ChuckUnclamp, &h)
            .unwrap()
            .contains("spindle turning"));
        h.cycle_active = true;
        assert!(refusal(Op::DoorOpen, &h).unwrap().contains("cycle active"));
        assert!(refusal(Op::CycleStart, &h)
            .unwrap()
            .contains("cycle active"));
        let mut h = idle();
        h.robot_clear = false;
        assert!(refusal(Op::DoorClose, &h)
            .unwrap()
            .contains("robot not clear"));
        assert!(refusal(Op::CycleStart, &h)
            .unwrap()
            .contains("robot not clear"));
        let mut h = idle();
        h.door_closed = false;
        assert!(refusal(Op::CycleStart, &h)
            .unwrap()
            .contains("door not closed"));
        h.emergency_stop = true;
        assert!(refusal(Op::ChuckClamp, &h)
            .unwrap()
            .contains("emergency stop"));
        // Reporting clear is always taken.
        assert_eq!(refusal(Op::Clear(true), &h), None);
    }

    #[test]
    fn each_request_is_done_when_its_sensor_says_so() {
        let mut h = idle();
        assert!(!Op::DoorOpen.done(&h));
        h.door_open = true;
        assert!(Op::DoorOpen.done(&h));
        assert!(Op::Clear(true).done(&h) && !Op::Clear(false).done(&h));
        assert_eq!(
            Op::Clear(true).signal(),
            Some((SimInput::ROBOT_CLEAR, true))
        );
        assert_eq!(Op::CycleStart.signal(), None);
    }
}
