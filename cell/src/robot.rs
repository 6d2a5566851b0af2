//! A robot that tends machines (issue 29): it waits for a machine's cycle to end, opens its
//! door if the PLC has not, enters, unclamps the finished part, swaps it for a blank (the
//! move's time simulated), clamps, leaves, closes the door and starts the next cycle, through
//! each machine's public `robot_request` service and `robot_handshake` topic only.
//!
//! [`Robot`] is the pure core: what to ask which machine next, from the handshakes it sees and
//! the answers it got. It is one arm: inside one machine at a time. It never enters a machine
//! whose door is not open, whose spindle turns, whose cycle runs or that reports an emergency
//! stop, and it leaves at once when any of those appears while it is inside.

use cnc_msgs::msg::RobotHandshake;
use cnc_msgs::srv::RobotRequestRequest as Rq;

/// Where the robot is with one machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    /// Waits for the machine's cycle to end (M30/M02) with nothing running.
    WaitReady,
    /// Inside: unclamps the finished part.
    Unclamp,
    /// Inside: swaps the part until this time, s.
    Swap {
        until: f64,
    },
    /// Inside: clamps the blank.
    Clamp,
    /// Reports itself clear of the work area; `retreat`: it had to leave before the blank
    /// was clamped.
    Leave {
        retreat: bool,
    },
    CloseDoor,
    Start,
    /// The cycle it started: `seen` once the machine shows it running.
    Cycle {
        seen: bool,
    },
    /// It has loaded the parts it was asked for.
    Done,
    /// It had to leave the machine mid-swap (an emergency stop, a turning spindle, a closing
    /// door): the part may be loose, and an operator takes over.
    Retreated,
}

/// One tended machine.
#[derive(Debug, Clone)]
pub struct Tended {
    pub phase: Phase,
    /// Cycles this robot started that ended with the program's end.
    pub parts: u32,
    /// Refusals the machine answered, with the request.
    pub refusals: Vec<(u8, String)>,
}

/// The robot's arm over all its machines.
#[derive(Debug, Clone)]
pub struct Robot {
    pub machines: Vec<Tended>,
    /// The machine it is inside, if any.
    inside: Option<usize>,
    /// The machine it served last: the next is looked for after it, so no machine starves.
    last: usize,
    swap_seconds: f64,
    /// Parts to load into each machine.
    wanted: Vec<u32>,
    /// Machines the cell lets the robot serve now (its supervisor's word; all by default).
    allowed: Vec<bool>,
}

/// Whether a robot may enter the machine (or stay inside it).
pub fn safe_inside(h: &RobotHandshake) -> bool {
    h.door_open && !h.spindle_turning && !h.emergency_stop && !h.cycle_active
}

impl Robot {
    /// A robot for `machines` machines that swaps a part in `swap_seconds` and loads
    /// `parts_each` parts into each.
    pub fn new(machines: usize, swap_seconds: f64, parts_each: u32) -> Robot {
        Robot::with_parts(swap_seconds, &vec![parts_each; machines])
    }

    /// A robot that loads `parts[i]` parts into machine `i`.
    pub fn with_parts(swap_seconds: f64, parts: &[u32]) -> Robot {
        let machines = parts
            .iter()
            .map(|&p| Tended {
                phase: if p == 0 {
                    Phase::Done
                } else {
                    Phase::WaitReady
                },
                parts: 0,
                refusals: Vec::new(),
            })
            .collect();
        Robot {
            machines,
            inside: None,
            last: parts.len().saturating_sub(1),
            swap_seconds: swap_seconds.max(0.0),
            wanted: parts.to_vec(),
            allowed: vec![true; parts.len()],
        }
    }

    /// Lets the robot serve machine `i` or not (a supervisor's pause, an unreachable machine).
    /// A machine it is inside it finishes with: leaving a part loose would be worse.
    pub fn allow(&mut self, i: usize, allowed: bool) {
        if let Some(a) = self.allowed.get_mut(i) {
            *a = allowed;
        }
    }

    /// Every machine has its parts, or was left to an operator.
    pub fn finished(&self) -> bool {
        self.machines
            .iter()
            .all(|m| matches!(m.phase, Phase::Done | Phase::Retreated))
    }

    /// The machine it is inside.
    pub fn inside(&self) -> Option<usize> {
        self.inside
    }

    /// The next request (machine, `RobotRequest` code) from the machines' handshakes at time
    /// `now` (s), or `None` to wait.
    pub fn next(&mut self, handshakes: &[Option<RobotHandshake>], now: f64) -> Option<(usize, u8)> {
        if let Some(i) = self.inside {
            let h = handshakes.get(i)?.as_ref()?;
            let m = &mut self.machines[i];
            if !safe_inside(h) && !matches!(m.phase, Phase::Leave { .. }) {
                m.phase = Phase::Leave { retreat: true };
                m.refusals
                    .push((Rq::CLEAR, "left the machine: no longer safe inside".into()));
            }
            return match m.phase {
                Phase::Unclamp => Some((i, Rq::CHUCK_UNCLAMP)),
                Phase::Swap { until } if now >= until => {
                    m.phase = Phase::Clamp;
                    Some((i, Rq::CHUCK_CLAMP))
                }
                Phase::Clamp => Some((i, Rq::CHUCK_CLAMP)),
                Phase::Leave { .. } => Some((i, Rq::CLEAR)),
                _ => None,
            };
        }
        let n = self.machines.len();
        for k in 1..=n {
            let i = (self.last + k) % n;
            let Some(h) = handshakes.get(i).and_then(|h| h.as_ref()) else {
                continue;
            };
            let m = &mut self.machines[i];
            let ask = match m.phase {
                Phase::WaitReady if h.cycle_complete && !h.cycle_active => {
                    if safe_inside(h) {
                        Some(Rq::NOT_CLEAR)
                    } else if !h.door_open && !h.spindle_turning && !h.emergency_stop {
                        Some(Rq::DOOR_OPEN)
                    } else {
                        None
                    }
                }
                Phase::CloseDoor => Some(Rq::DOOR_CLOSE),
                Phase::Start => Some(Rq::CYCLE_START),
                Phase::Cycle { seen } => {
                    if h.cycle_active {
                        m.phase = Phase::Cycle { seen: true };
                    } else if seen && h.cycle_complete {
                        // Ended with the program's end: a part. A cycle stopped by an alarm
                        // or a reset is not; the robot waits for whoever clears the machine
                        // and runs it to its end, and serves the others meanwhile.
                        m.parts += 1;
                        m.phase = if m.parts >= self.wanted.get(i).copied().unwrap_or(0) {
                            Phase::Done
                        } else {
                            Phase::WaitReady
                        };
                    }
                    None
                }
                _ => None,
            };
            let allowed = self.allowed.get(i).copied().unwrap_or(false);
            if let (Some(code), true) = (ask, allowed) {
                self.last = i;
                return Some((i, code));
            }
        }
        None
    }

    /// The machine's answer to `code` at time `now`: accepted, the robot goes on; refused, it
    /// asks again later (the refusal is kept).
    pub fn answered(&mut self, machine: usize, code: u8, accepted: bool, message: &str, now: f64) {
        let Some(m) = self.machines.get_mut(machine) else {
            return;
        };
        if !accepted {
            m.refusals.push((code, message.to_string()));
            return;
        }
        match (code, m.phase) {
            (Rq::NOT_CLEAR, Phase::WaitReady) => {
                self.inside = Some(machine);
                m.phase = Phase::Unclamp;
            }
            (Rq::CHUCK_UNCLAMP, Phase::Unclamp) => {
                m.phase = Phase::Swap {
                    until: now + self.swap_seconds,
                }
            }
            (Rq::CHUCK_CLAMP, Phase::Clamp) => m.phase = Phase::Leave { retreat: false },
            (Rq::CLEAR, Phase::Leave { retreat }) => {
                self.inside = None;
                // A retreat before the blank was clamped leaves the machine to an operator.
                m.phase = if retreat {
                    Phase::Retreated
                } else {
                    Phase::CloseDoor
                };
            }
            (Rq::DOOR_CLOSE, Phase::CloseDoor) => m.phase = Phase::Start,
            (Rq::CYCLE_START, Phase::Start) => m.phase = Phase::Cycle { seen: false },
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A machine at the end of its cycle: the PLC has opened the door, nothing turns.
    fn finished() -> RobotHandshake {
        RobotHandshake {
            ready_for_load: true,
            cycle_complete: true,
            door_open: true,
            chuck_clamped: true,
            robot_clear: true,
            ..RobotHandshake::default()
        }
    }

    fn running() -> RobotHandshake {
        RobotHandshake {
            door_closed: true,
            chuck_clamped: true,
            robot_clear: true,
            spindle_turning: true,
            cycle_active: true,
            ..RobotHandshake::default()
        }
    }

    /// Answers every request as accepted; returns the requests made.
    fn drive(
        r: &mut Robot,
        hs: &[Option<RobotHandshake>],
        t: &mut f64,
        steps: usize,
    ) -> Vec<(usize, u8)> {
        let mut asked = Vec::new();
        for _ in 0..steps {
            if let Some((i, code)) = r.next(hs, *t) {
                asked.push((i, code));
                r.answered(i, code, true, "done", *t);
            }
            *t += 0.1;
        }
        asked
    }

    #[test]
    fn a_finished_machine_is_unloaded_and_loaded_and_started_in_order() {
        let mut r = Robot::new(1, 0.5, 1);
        let mut t = 0.0;
        let asked = drive(&mut r, &[Some(finished())], &mut t, 20);
        let codes: Vec<u8> = asked.iter().map(|a| a.1).collect();
        assert_eq!(
            codes,
            [
                Rq::NOT_CLEAR,
                Rq::CHUCK_UNCLAMP,
                Rq::CHUCK_CLAMP,
                Rq::CLEAR,
                Rq::DOOR_CLOSE,
                Rq::CYCLE_START
            ]
        );
        assert_eq!(r.machines[0].phase, Phase::Cycle { seen: false });
        // The cycle runs, then ends with M30: one part, and done.
        drive(&mut r, &[Some(running())], &mut t, 2);
        drive(&mut r, &[Some(finished())], &mut t, 1);
        assert_eq!(r.machines[0].parts, 1);
        assert!(r.finished());
    }

    #[test]
    fn it_never_enters_a_machine_that_is_not_safe_and_opens_a_closed_door_first() {
        for (unsafe_state, why) in [
            (
                RobotHandshake {
                    spindle_turning: true,
                    ..finished()
                },
                "spindle",
            ),
            (
                RobotHandshake {
                    emergency_stop: true,
                    ..finished()
                },
                "emergency stop",
            ),
            (running(), "cycle"),
            (
                RobotHandshake {
                    cycle_complete: false,
                    ..finished()
                },
                "no finished cycle",
            ),
        ] {
            let mut r = Robot::new(1, 0.5, 1);
            let mut t = 0.0;
            let asked = drive(&mut r, &[Some(unsafe_state)], &mut t, 20);
            assert!(
                asked.iter().all(|a| a.1 != Rq::NOT_CLEAR),
                "{why}: {asked:?}"
            );
        }
        // Door closed at the end of a cycle: it asks to open it, then enters once it is open.
        let closed = RobotHandshake {
            door_open: false,
            door_closed: true,
            ..finished()
        };
        let mut r = Robot::new(1, 0.5, 1);
        let mut t = 0.0;
        assert_eq!(
            drive(&mut r, &[Some(closed)], &mut t, 3)[0].1,
            Rq::DOOR_OPEN
        );
        assert_eq!(
            drive(&mut r, &[Some(finished())], &mut t, 1)[0].1,
            Rq::NOT_CLEAR
        );
    }

    #[test]
    fn it_leaves_at_once_when_the_machine_becomes_unsafe_and_leaves_it_to_an_operator() {
        let mut r = Robot::new(1, 5.0, 1);
        let mut t = 0.0;
        drive(&mut r, &[Some(finished())], &mut t, 3); // in, unclamped, swapping
        assert_eq!(r.inside(), Some(0));
        let estop = RobotHandshake {
            emergency_stop: true,
            ..finished()
        };
        let asked = drive(&mut r, &[Some(estop)], &mut t, 3);
        assert_eq!(asked[0].1, Rq::CLEAR, "{asked:?}");
        assert_eq!(r.inside(), None);
        assert_eq!(r.machines[0].phase, Phase::Retreated);
        assert!(r.finished());
    }

    #[test]
    fn one_arm_serves_two_machines_in_turn_and_is_inside_one_at_a_time() {
        let mut r = Robot::new(2, 0.3, 2);
        let mut t = 0.0;
        let both = [Some(finished()), Some(finished())];
        let mut entered = Vec::new();
        for _ in 0..40 {
            if let Some((i, code)) = r.next(&both, t) {
                if code == Rq::NOT_CLEAR {
                    assert_eq!(r.inside(), None, "entered {i} while inside another");
                    entered.push(i);
                }
                r.answered(i, code, true, "done", t);
            }
            t += 0.1;
        }
        assert_eq!(entered, [0, 1], "one swap each, in turn");
        // A refusal is kept and the request asked again.
        let mut r = Robot::new(1, 0.3, 1);
        let (i, code) = r.next(&[Some(finished())], 0.0).unwrap();
        r.answered(i, code, false, "robot not clear refused: test", 0.0);
        assert_eq!(r.machines[0].refusals.len(), 1);
        assert_eq!(r.next(&[Some(finished())], 0.1), Some((0, Rq::NOT_CLEAR)));
    }

    #[test]
    fn a_machine_the_cell_holds_back_is_not_entered_and_the_other_is_served() {
        let mut r = Robot::with_parts(0.3, &[1, 1]);
        r.allow(1, false);
        let both = [Some(finished()), Some(finished())];
        let mut t = 0.0;
        let asked = drive(&mut r, &both, &mut t, 40);
        assert!(asked.iter().all(|a| a.0 == 0), "{asked:?}");
        assert!(asked.contains(&(0, Rq::CYCLE_START)));
        // Allowed again, it is served.
        r.allow(1, true);
        assert_eq!(r.next(&both, t), Some((1, Rq::NOT_CLEAR)));
        // Each machine its own number of parts.
        let r = Robot::with_parts(0.3, &[0, 2]);
        assert_eq!(r.machines[0].phase, Phase::Done);
        assert_eq!(r.machines[1].phase, Phase::WaitReady);
    }
}
