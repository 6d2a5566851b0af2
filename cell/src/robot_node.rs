//! The robot's shell: the [`Robot`] core against machines over ROS 2, through their public
//! interface only (`robot_handshake`, `robot_request`), with the wall clock for the swap. In a
//! cell with a supervisor it follows `/cell/state` and serves only the machines the supervisor
//! has producing: not one that is paused, unreachable or done.

use std::time::{Duration, Instant};

use cnc_msgs::msg::{CellMachine, CellState, RobotHandshake};
use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::RosNode;
use ros2_client::dds::Subscription;

use crate::client::CellClient;
use crate::robot::Robot;
use crate::supervisor_node::{CELL_NAMESPACE, CELL_STATE};

/// The supervisor's state topic, as the robot follows it.
pub struct CellWatch {
    _node: RosNode,
    state: Subscription<CellState>,
    /// The supervisor's last state.
    pub last: Option<CellState>,
    /// When it came.
    heard_at: Option<Instant>,
}

/// The supervisor publishes its state at least once a second; a robot that has heard nothing
/// for this long takes no machine (the supervisor is gone, or the robot's link to it).
const SUPERVISOR_SILENCE: Duration = Duration::from_secs(5);

impl CellWatch {
    pub fn new(net: &NetworkConfig, who: &str) -> Result<CellWatch, String> {
        let mut node = RosNode::client(net, CELL_NAMESPACE, who)?;
        let state = node.dds_subscription(&CELL_STATE)?;
        Ok(CellWatch {
            _node: node,
            state,
            last: None,
            heard_at: None,
        })
    }

    /// Takes the new states; whether the supervisor has one.
    pub fn poll(&mut self) -> bool {
        while let Ok(Some((s, _))) = self.state.take() {
            self.last = Some(s);
            self.heard_at = Some(Instant::now());
        }
        self.last.is_some()
    }

    /// Whether the supervisor, heard lately, has machine `name` producing.
    pub fn producing(&self, name: &str) -> bool {
        let silence = self.heard_at.map(|t| t.elapsed());
        serves(self.last.as_ref(), silence, name)
    }

    /// Whether the supervisor has machine `name` unreachable.
    pub fn unreachable(&self, name: &str) -> bool {
        lost(self.last.as_ref(), name)
    }

    /// Whether the supervisor's order is complete.
    pub fn complete(&self) -> bool {
        self.last.as_ref().is_some_and(|s| s.complete)
    }
}

/// A robot in a cell with a supervisor: connects to the machines `names` on `net` (each given
/// a minute to become ready), loads `parts[i]` parts into machine `i` (a swap takes
/// `swap_seconds`) while the supervisor lets it, until the supervisor's order is complete or
/// `deadline` passes. Returns the robot and the requests it made.
pub fn serve_cell(
    net: &NetworkConfig,
    names: &[String],
    parts: &[u32],
    swap_seconds: f64,
    deadline: Instant,
) -> Result<(Robot, Vec<Asked>), String> {
    // Under DDS Security the robot is the cell's identity `/cell/robot`.
    let net = &net.with_default_enclave("/cell/robot")?;
    let mut arm = Vec::new();
    for ns in names {
        let mut c = CellClient::new(net, ns, "robot", ros2_client::ServiceMapping::Enhanced)?
            .with_timeout(Duration::from_secs(5));
        c.wait_ready(Duration::from_secs(60))
            .map_err(|e| format!("{ns}: {e}"))?;
        arm.push(c);
    }
    let mut watch = CellWatch::new(net, "robot")?;
    let mut robot = Robot::with_parts(swap_seconds, parts);
    let asked = tend(&mut arm, &mut robot, Some(&mut watch), deadline)?;
    Ok((robot, asked))
}

/// Whether the robot may serve machine `name`, from the supervisor's last state and how long
/// ago it came.
fn serves(last: Option<&CellState>, silence: Option<Duration>, name: &str) -> bool {
    silence.is_some_and(|d| d < SUPERVISOR_SILENCE)
        && status_of(last, name) == Some(CellMachine::PRODUCING)
}

/// Whether the supervisor's last state has machine `name` unreachable.
fn lost(last: Option<&CellState>, name: &str) -> bool {
    status_of(last, name) == Some(CellMachine::UNREACHABLE)
}

/// Machine `name`'s status in the supervisor's last state.
fn status_of(last: Option<&CellState>, name: &str) -> Option<u8> {
    last?
        .machines
        .iter()
        .find(|m| m.name == name)
        .map(|m| m.status)
}

/// One request the robot made.
#[derive(Debug, Clone)]
pub struct Asked {
    pub at: Instant,
    pub machine: usize,
    /// The `RobotRequest` code.
    pub code: u8,
    pub accepted: bool,
}

/// Tends `machines` (one client each, in the robot's order) until the robot has its parts, the
/// supervisor followed through `cell` says its order is complete, or `deadline` passes. Each
/// request waits for the machine to answer it done or refused. Returns the requests made.
pub fn tend(
    machines: &mut [CellClient],
    robot: &mut Robot,
    mut cell: Option<&mut CellWatch>,
    deadline: Instant,
) -> Result<Vec<Asked>, String> {
    let t0 = Instant::now();
    let mut asked = Vec::new();
    loop {
        if let Some(w) = cell.as_deref_mut() {
            w.poll();
            if w.complete() {
                return Ok(asked);
            }
            for (i, c) in machines.iter().enumerate() {
                robot.allow(i, w.producing(c.namespace()));
            }
        } else if robot.finished() {
            return Ok(asked);
        }
        if Instant::now() > deadline {
            return Err(format!(
                "the robot did not finish in time: {:?}",
                robot.machines
            ));
        }
        for c in machines.iter_mut() {
            c.poll();
        }
        let seen: Vec<Option<RobotHandshake>> =
            machines.iter().map(|c| c.handshake.clone()).collect();
        match robot.next(&seen, t0.elapsed().as_secs_f64()) {
            Some((i, code)) => {
                let Some(c) = machines.get_mut(i) else {
                    return Err(format!("no machine {i}"));
                };
                let at = Instant::now();
                // A machine the supervisor marks unreachable meanwhile is not waited for: the
                // robot serves the others and asks again once it is back (the machine checks
                // every request against its state, so asking again is safe).
                let ns = c.namespace().to_string();
                let mut watch = cell.as_deref_mut();
                let answer = c.robot_request_unless(code, || {
                    watch.as_deref_mut().is_some_and(|w| {
                        w.poll();
                        w.unreachable(&ns)
                    })
                });
                let (accepted, message) = match answer {
                    Ok(r) => (r.accepted, r.message),
                    Err(e) => (false, e),
                };
                asked.push(Asked {
                    at,
                    machine: i,
                    code,
                    accepted,
                });
                robot.answered(i, code, accepted, &message, t0.elapsed().as_secs_f64());
                if !accepted {
                    std::thread::sleep(Duration::from_millis(200));
                }
            }
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_machine_a_supervisor_heard_lately_has_producing_is_served() {
        let state = CellState {
            machines: vec![
                CellMachine {
                    name: "lathe1".into(),
                    status: CellMachine::PRODUCING,
                    ..CellMachine::default()
                },
                CellMachine {
                    name: "lathe2".into(),
                    status: CellMachine::UNREACHABLE,
                    ..CellMachine::default()
                },
            ],
            ..CellState::default()
        };
        let now = Some(Duration::from_millis(100));
        assert!(serves(Some(&state), now, "lathe1"));
        assert!(!serves(Some(&state), now, "lathe2"));
        assert!(!serves(Some(&state), now, "lathe3"));
        assert!(!serves(None, now, "lathe1"));
        assert!(!serves(Some(&state), None, "lathe1"));
        assert!(!serves(
            Some(&state),
            Some(Duration::from_secs(6)),
            "lathe1"
        ));
        // A request to lathe2 is no longer waited for; to lathe1 (or before any state) it is.
        assert!(lost(Some(&state), "lathe2"));
        assert!(!lost(Some(&state), "lathe1"));
        assert!(!lost(None, "lathe2"));
    }
}
