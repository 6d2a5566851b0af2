//! The cell supervisor (issue 29, decisions D76): it takes a work order (a program and a number
//! of parts per machine), loads each machine's program, starts its first cycle, counts the parts
//! and their cycle times as the machines report them, pauses a machine that alarms, marks one it
//! has not heard from within its liveliness lease unreachable, and says which machines the robot
//! may serve. It uses each machine's public interface only.
//!
//! [`Supervisor`] is the pure core: it is given what was heard from each machine and when, and
//! answers with the calls to make and the decisions taken, in words, for the audit bag.

use cnc_msgs::msg::{ActiveAlarms, CellMachine, CellState, MachineState, PartCount};
use serde::Deserialize;

/// One line of a work order: `parts` parts of `program` on `machine`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct OrderLine {
    /// The machine's namespace.
    pub machine: String,
    /// The program's name in the machine's memory.
    pub program: String,
    /// The program's text, loaded into the machine under `program`.
    pub text: String,
    pub parts: u32,
}

/// A work order.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Order {
    pub name: String,
    pub lines: Vec<OrderLine>,
}

/// What the supervisor has heard from one machine; `heard_at` is when it last heard anything
/// (s, the shell's clock).
#[derive(Debug, Clone, Default)]
pub struct Heard {
    pub state: Option<MachineState>,
    pub part_count: Option<PartCount>,
    pub alarms: Option<ActiveAlarms>,
    pub heard_at: Option<f64>,
}

/// A call the supervisor makes to a machine.
#[derive(Debug, Clone, PartialEq)]
pub enum Call {
    Load { name: String, text: String },
    Start { name: String },
}

impl Call {
    pub fn command(&self) -> &'static str {
        match self {
            Call::Load { .. } => "load_program",
            Call::Start { .. } => "start_program",
        }
    }
}

/// Where the supervisor is with one machine.
#[derive(Debug, Clone)]
struct Watched {
    status: u8,
    reason: String,
    /// The status before the machine became unreachable, taken up again when it is heard.
    before_silence: u8,
    loaded: bool,
    started: bool,
    /// A call made and not answered yet.
    waiting: bool,
    /// No call before this time (s): a refused call is asked again later.
    retry_at: f64,
    counter_at_start: Option<u32>,
    /// The machine's counter at the last part-count sample taken in.
    last_counter: Option<u32>,
    cycle_times: Vec<f64>,
    heard_at: Option<f64>,
}

/// Seconds between a refused call and its next try.
const RETRY_SECONDS: f64 = 2.0;

/// The supervisor of one work order.
#[derive(Debug, Clone)]
pub struct Supervisor {
    order: Order,
    machines: Vec<Watched>,
    /// Longest silence (s) before a machine is unreachable.
    lease: f64,
}

impl Supervisor {
    pub fn new(order: Order, lease_seconds: f64) -> Supervisor {
        let watched = Watched {
            status: CellMachine::WAITING,
            reason: "not heard from yet".into(),
            before_silence: CellMachine::WAITING,
            loaded: false,
            started: false,
            waiting: false,
            retry_at: 0.0,
            counter_at_start: None,
            last_counter: None,
            cycle_times: Vec::new(),
            heard_at: None,
        };
        Supervisor {
            machines: vec![watched; order.lines.len()],
            order,
            lease: lease_seconds.max(0.0),
        }
    }

    pub fn order(&self) -> &Order {
        &self.order
    }

    /// Every machine has its parts.
    pub fn complete(&self) -> bool {
        self.machines.iter().all(|m| m.status == CellMachine::DONE)
    }

    /// Whether the robot may serve machine `i`: it works on its order and is heard.
    pub fn may_serve(&self, i: usize) -> bool {
        self.machines
            .get(i)
            .is_some_and(|m| m.status == CellMachine::PRODUCING)
    }

    /// Takes in what was heard (one entry per order line) at time `now` (s): the calls to make
    /// (machine index, call) and the decisions taken, in words.
    pub fn step(&mut self, heard: &[Heard], now: f64) -> (Vec<(usize, Call)>, Vec<String>) {
        let mut calls = Vec::new();
        let mut notes = Vec::new();
        for (i, (m, line)) in self.machines.iter_mut().zip(&self.order.lines).enumerate() {
            let h = heard.get(i).cloned().unwrap_or_default();
            let mut note = |m: &mut Watched, status: u8, reason: String| {
                if m.status != status {
                    notes.push(format!(
                        "{}: {} ({reason})",
                        line.machine,
                        status_name(status)
                    ));
                }
                m.status = status;
                m.reason = reason;
            };
            if h.heard_at.is_some() {
                m.heard_at = h.heard_at;
            }
            // Liveliness first: nothing else is known of a machine that is not heard.
            let Some(heard_at) = m.heard_at else {
                continue;
            };
            let silent = now - heard_at;
            if silent > self.lease {
                if m.status != CellMachine::UNREACHABLE {
                    m.before_silence = m.status;
                    let why = format!("nothing heard for {silent:.2} s");
                    note(m, CellMachine::UNREACHABLE, why);
                }
                continue;
            }
            if m.status == CellMachine::UNREACHABLE {
                let back = m.before_silence;
                note(m, back, "heard again".into());
            }
            // The parts: the machine's own counter, from where it stood when the order began.
            if let Some(pc) = &h.part_count {
                let start = *m.counter_at_start.get_or_insert(pc.count);
                if m.last_counter.is_some_and(|c| pc.count > c) && pc.count > start {
                    m.cycle_times.push(pc.last_cycle_time);
                }
                m.last_counter = Some(pc.count);
            }
            let count = count(m);
            if m.status != CellMachine::DONE && count >= line.parts && m.started {
                note(m, CellMachine::DONE, format!("{count} parts"));
                continue;
            }
            let Some(state) = &h.state else {
                continue;
            };
            let alarmed = state.alarm_active || state.emergency_stop;
            match m.status {
                CellMachine::DONE => continue,
                CellMachine::PAUSED => {
                    // An operator cleared the machine and runs the cycle again.
                    if !alarmed && state.execution == MachineState::ACTIVE {
                        note(m, CellMachine::PRODUCING, "its cycle runs again".into());
                    }
                    continue;
                }
                _ if alarmed => {
                    let why = alarm_reason(state, h.alarms.as_ref());
                    note(m, CellMachine::PAUSED, why);
                    continue;
                }
                _ => {}
            }
            if m.waiting || now < m.retry_at || m.counter_at_start.is_none() {
                continue;
            }
            if !m.loaded {
                m.waiting = true;
                calls.push((
                    i,
                    Call::Load {
                        name: line.program.clone(),
                        text: line.text.clone(),
                    },
                ));
            } else if !m.started && count < line.parts && ready_to_start(state) {
                m.waiting = true;
                calls.push((
                    i,
                    Call::Start {
                        name: line.program.clone(),
                    },
                ));
            }
        }
        (calls, notes)
    }

    /// The machine's answer to a call at time `now`; returns the decision in words.
    pub fn answered(
        &mut self,
        i: usize,
        call: &Call,
        accepted: bool,
        message: &str,
        now: f64,
    ) -> String {
        let (Some(m), Some(line)) = (self.machines.get_mut(i), self.order.lines.get(i)) else {
            return format!("no machine {i} in the order");
        };
        m.waiting = false;
        if !accepted {
            m.retry_at = now + RETRY_SECONDS;
            return format!(
                "{}: {} refused ({message}); asked again in {RETRY_SECONDS} s",
                line.machine,
                call.command()
            );
        }
        match call {
            Call::Load { .. } => m.loaded = true,
            Call::Start { .. } => {
                m.started = true;
                m.status = CellMachine::PRODUCING;
                m.reason = "first part started".into();
            }
        }
        format!("{}: {} done", line.machine, call.command())
    }

    /// The supervisor's state topic at time `now`.
    pub fn state(&self, now: f64) -> CellState {
        CellState {
            stamp: Default::default(),
            order: self.order.name.clone(),
            complete: self.complete(),
            machines: self
                .machines
                .iter()
                .zip(&self.order.lines)
                .map(|(m, line)| CellMachine {
                    name: line.machine.clone(),
                    status: m.status,
                    reason: m.reason.clone(),
                    program: line.program.clone(),
                    target: line.parts,
                    count: count(m),
                    counter_at_start: m.counter_at_start.unwrap_or(0),
                    cycle_times: m.cycle_times.clone(),
                    silent_seconds: m.heard_at.map_or(f64::INFINITY, |t| (now - t).max(0.0)),
                })
                .collect(),
        }
    }
}

fn count(m: &Watched) -> u32 {
    match (m.counter_at_start, m.last_counter) {
        (Some(start), Some(now)) => now.saturating_sub(start),
        _ => 0,
    }
}

/// A machine takes a cycle start: it knows its axes, nothing runs and nothing is alarmed.
fn ready_to_start(s: &MachineState) -> bool {
    s.mode == MachineState::MODE_AUTO
        && matches!(
            s.execution,
            MachineState::READY | MachineState::PROGRAM_COMPLETED | MachineState::STOPPED
        )
}

fn alarm_reason(state: &MachineState, alarms: Option<&ActiveAlarms>) -> String {
    match alarms.and_then(|a| a.alarms.first()) {
        Some(a) => format!("alarm {}: {}", a.number, a.text),
        None if state.emergency_stop => "emergency stop".into(),
        None => "alarm".into(),
    }
}

pub fn status_name(status: u8) -> &'static str {
    match status {
        CellMachine::WAITING => "waiting",
        CellMachine::PRODUCING => "producing",
        CellMachine::PAUSED => "paused",
        CellMachine::UNREACHABLE => "unreachable",
        CellMachine::DONE => "done",
        _ => "unknown",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cnc_msgs::msg::Alarm;

    fn order(parts: &[u32]) -> Order {
        Order {
            name: "wo-1".into(),
            lines: parts
                .iter()
                .enumerate()
                .map(|(k, &p)| OrderLine {
                    machine: format!("lathe{}", k + 1),
                    program: "part.nc".into(),
                    text: "G0 X10\nM30\n".into(),
                    parts: p,
                })
                .collect(),
        }
    }

    fn ready(counter: u32, at: f64) -> Heard {
        Heard {
            state: Some(MachineState {
                execution: MachineState::READY,
                ..MachineState::default()
            }),
            part_count: Some(PartCount {
                count: counter,
                ..PartCount::default()
            }),
            alarms: None,
            heard_at: Some(at),
        }
    }

    /// Steps once and answers every call as accepted.
    fn step_ok(s: &mut Supervisor, heard: &[Heard], now: f64) -> Vec<(usize, Call)> {
        let (calls, _) = s.step(heard, now);
        for (i, c) in &calls {
            s.answered(*i, c, true, "ok", now);
        }
        calls
    }

    #[test]
    fn it_loads_then_starts_each_machine_once_and_counts_from_the_machine_s_counter() {
        let mut s = Supervisor::new(order(&[2, 1]), 1.0);
        let mut h = vec![ready(7, 0.0), ready(0, 0.0)];
        let calls = step_ok(&mut s, &h, 0.0);
        assert!(matches!(
            calls[..],
            [(0, Call::Load { .. }), (1, Call::Load { .. })]
        ));
        let calls = step_ok(&mut s, &h, 0.1);
        assert!(matches!(
            calls[..],
            [(0, Call::Start { .. }), (1, Call::Start { .. })]
        ));
        assert!(s.may_serve(0) && s.may_serve(1));
        // Nothing more to call while the machines produce.
        assert!(step_ok(&mut s, &h, 0.2).is_empty());
        // lathe1 counts a part (7 → 8) in 4.5 s, lathe2 its only one.
        for (k, c) in [(0, 8), (1, 1)] {
            h[k].part_count = Some(PartCount {
                count: c,
                last_cycle_time: 4.5,
                ..PartCount::default()
            });
        }
        step_ok(&mut s, &h, 0.3);
        let st = s.state(0.3);
        assert_eq!(st.machines[0].count, 1);
        assert_eq!(st.machines[0].counter_at_start, 7);
        assert_eq!(st.machines[0].cycle_times, vec![4.5]);
        assert_eq!(st.machines[0].status, CellMachine::PRODUCING);
        assert_eq!(st.machines[1].status, CellMachine::DONE);
        assert!(!s.may_serve(1));
        assert!(!st.complete);
        // The same sample again is not a second part.
        step_ok(&mut s, &h, 0.4);
        assert_eq!(s.state(0.4).machines[0].cycle_times.len(), 1);
        h[0].part_count = Some(PartCount {
            count: 9,
            last_cycle_time: 4.6,
            ..PartCount::default()
        });
        step_ok(&mut s, &h, 0.5);
        let st = s.state(0.5);
        assert!(st.complete);
        assert_eq!(st.machines[0].cycle_times, vec![4.5, 4.6]);
    }

    #[test]
    fn a_refused_call_is_asked_again_after_its_pause() {
        let mut s = Supervisor::new(order(&[1]), 1.0);
        let h = vec![ready(0, 0.0)];
        let (calls, _) = s.step(&h, 0.0);
        let note = s.answered(0, &calls[0].1, false, "memory full", 0.0);
        assert!(note.contains("refused (memory full)"), "{note}");
        assert!(s.step(&[ready(0, 1.0)], 1.0).0.is_empty());
        assert_eq!(s.step(&[ready(0, 2.1)], 2.1).0.len(), 1);
    }

    #[test]
    fn a_machine_that_alarms_is_paused_until_its_cycle_runs_again_and_the_other_goes_on() {
        let mut s = Supervisor::new(order(&[3, 3]), 1.0);
        let mut h = vec![ready(0, 0.0), ready(0, 0.0)];
        step_ok(&mut s, &h, 0.0);
        step_ok(&mut s, &h, 0.1);
        let state = h[1].state.as_mut().expect("state");
        state.alarm_active = true;
        h[1].alarms = Some(ActiveAlarms {
            alarms: vec![Alarm {
                number: 1001,
                text: "spindle overload".into(),
                ..Alarm::default()
            }],
            ..ActiveAlarms::default()
        });
        let (_, notes) = s.step(&h, 0.2);
        assert_eq!(notes, ["lathe2: paused (alarm 1001: spindle overload)"]);
        assert!(s.may_serve(0) && !s.may_serve(1));
        // Cleared but standing: still paused (the part in it may be spoilt).
        let state = h[1].state.as_mut().expect("state");
        state.alarm_active = false;
        h[1].alarms = None;
        s.step(&h, 0.3);
        assert!(!s.may_serve(1));
        h[1].state.as_mut().expect("state").execution = MachineState::ACTIVE;
        let (calls, notes) = s.step(&h, 0.4);
        assert!(calls.is_empty(), "no second first start: {calls:?}");
        assert_eq!(notes, ["lathe2: producing (its cycle runs again)"]);
        assert!(s.may_serve(1));
    }

    #[test]
    fn a_silent_machine_is_unreachable_after_the_lease_and_taken_back_when_heard() {
        let mut s = Supervisor::new(order(&[3, 3]), 0.5);
        step_ok(&mut s, &[ready(0, 0.0), ready(0, 0.0)], 0.0);
        let h = vec![ready(0, 0.1), ready(0, 0.1)];
        step_ok(&mut s, &h, 0.1);
        // lathe2 falls silent at 0.1 s; lathe1 goes on being heard.
        let mut h2 = h.clone();
        for t in [0.3, 0.55, 0.6, 0.7] {
            h2[0].heard_at = Some(t);
            h2[1].heard_at = None;
            let (_, notes) = s.step(&h2, t);
            let expect_unreachable = t - 0.1 > 0.5;
            assert_eq!(s.may_serve(1), !expect_unreachable, "at {t}");
            if t == 0.7 {
                assert_eq!(notes, ["lathe2: unreachable (nothing heard for 0.60 s)"]);
            }
        }
        assert!(s.may_serve(0));
        let st = s.state(0.7);
        assert_eq!(st.machines[1].status, CellMachine::UNREACHABLE);
        assert!((st.machines[1].silent_seconds - 0.6).abs() < 1e-9);
        // Heard again: producing as before, with no new load or start.
        h2[1].heard_at = Some(10.0);
        h2[0].heard_at = Some(10.0);
        let (calls, notes) = s.step(&h2, 10.0);
        assert!(calls.is_empty());
        assert_eq!(notes, ["lathe2: producing (heard again)"]);
        assert!(s.may_serve(1));
    }

    #[test]
    fn a_machine_not_heard_yet_gets_no_call() {
        let mut s = Supervisor::new(order(&[1]), 1.0);
        let (calls, notes) = s.step(&[Heard::default()], 5.0);
        assert!(calls.is_empty() && notes.is_empty());
        assert_eq!(s.state(5.0).machines[0].status, CellMachine::WAITING);
    }
}
