//! The robot's requests as a door: the service, the robot signal that carries a request to
//! the PLC, and the wait for the PLC's handshake to say it is done (the rules are
//! [`crate::robot_handshake`]'s). Copies of a pending request (a client repeats one it has no answer to
//! yet) are answered together.

use cnc_msgs::msg::{MachineState, RobotHandshake, SimInput};
use cnc_msgs::srv::{RobotRequest, RobotRequestRequest, RobotRequestResponse};
use cnc_runtime::dds::RosNode;
use cnc_runtime::topics;
use cnc_runtime::MDI_PROGRAM;
use ros2_client::dds::rustdds::{DomainParticipant, QosPolicies};

use crate::access::Who;
use crate::doors::{reply, Front};
use crate::operation::{Answer, Operation};
use crate::robot_handshake;
use crate::service_server::{DualServer, Request};

const NAME: &str = "robot_request";

/// A robot request waiting for the machine to carry it out.
struct Pending {
    op: robot_handshake::Op,
    requests: Vec<Request<RobotRequestRequest>>,
    since: std::time::Instant,
}

enum Decision {
    Refused(String),
    /// A copy of the pending request: answered with it.
    Joined,
    Go(robot_handshake::Op),
}

pub struct RobotDoor {
    server: DualServer<RobotRequest>,
    signals: cnc_runtime::dds::Publisher<SimInput>,
    handshake_sub: cnc_runtime::bus::Subscription<RobotHandshake>,
    handshake: Option<RobotHandshake>,
    pending: Option<Pending>,
}

impl RobotDoor {
    pub fn new(
        ros: &mut RosNode,
        participant: &DomainParticipant,
        ns: &str,
        qos: &QosPolicies,
    ) -> Result<RobotDoor, String> {
        Ok(RobotDoor {
            server: DualServer::new(participant, ns, NAME, qos.clone())?
                .refusing(RobotRequestResponse::refused),
            signals: ros.publisher(&topics::ROBOT_SIGNALS)?,
            handshake_sub: ros.subscription(&topics::ROBOT_HANDSHAKE)?,
            handshake: None,
            pending: None,
        })
    }

    pub fn drain(&self) {
        self.server.drain();
    }

    /// Serves the next request and finishes the pending one when the PLC has done it (or
    /// not in time); `machine` names the selected program a cycle start runs. Returns whether
    /// a request came.
    pub fn serve(&mut self, front: &mut dyn Front, machine: Option<&MachineState>) -> bool {
        for (writer, why) in self.server.take_malformed() {
            front.record(NAME, "malformed", &Who::Dds(writer), false, &why);
        }
        while let Ok(Some(h)) = self.handshake_sub.take() {
            self.handshake = Some(h);
        }
        let request = self.server.receive();
        let came = request.is_some();
        if let Some(r) = request {
            match self.decide(&r, &*front) {
                Decision::Joined => {}
                Decision::Refused(why) => {
                    front.record(NAME, "", &Who::Dds(r.writer), false, &why);
                    reply(&self.server, &r, &RobotRequestResponse::refused(why));
                }
                Decision::Go(robot_handshake::Op::CycleStart) => {
                    let a = cycle_start(front, machine, &r);
                    let response = RobotRequestResponse {
                        accepted: a.accepted,
                        message: a.message,
                    };
                    reply(&self.server, &r, &response);
                }
                Decision::Go(op) => self.signal(op, r),
            }
        }
        self.finish(&*front);
        came
    }

    fn decide(&mut self, r: &Request<RobotRequestRequest>, front: &dyn Front) -> Decision {
        let op = match robot_handshake::Op::from_request(r.request.request) {
            Ok(op) => op,
            Err(why) => return Decision::Refused(why),
        };
        if let Some(p) = self.pending.as_mut() {
            if p.op == op && p.requests.iter().any(|q| q.writer == r.writer) {
                p.requests.push(r.clone());
                return Decision::Joined;
            }
            return Decision::Refused(format!("{} refused: busy with {}", op.name(), p.op.name()));
        }
        if op.moves() {
            if let Err(why) = front.may_move(&Who::Dds(r.writer)) {
                return Decision::Refused(why);
            }
        }
        let Some(h) = &self.handshake else {
            return Decision::Refused("no handshake state from the PLC yet".into());
        };
        match robot_handshake::refusal(op, h) {
            Some(why) => Decision::Refused(why),
            None => Decision::Go(op),
        }
    }

    /// Sets the robot signal that carries `op` to the PLC; the answer waits for the handshake.
    fn signal(&mut self, op: robot_handshake::Op, r: Request<RobotRequestRequest>) {
        let Some((input, _)) = op.signal() else {
            return;
        };
        let value = !matches!(op, robot_handshake::Op::Clear(false));
        if let Err(e) = self.signals.publish(SimInput { input, value }) {
            log::error!("robot signal not sent: {e}");
        }
        self.pending = Some(Pending {
            op,
            requests: vec![r],
            since: std::time::Instant::now(),
        });
    }

    /// Answers the pending request once the handshake shows it done, or after
    /// [`robot_handshake::ACTUATION_TIMEOUT`]; a signal not held is dropped then.
    fn finish(&mut self, front: &dyn Front) {
        let Some(p) = self.pending.take() else {
            return;
        };
        let done = self.handshake.as_ref().is_some_and(|h| p.op.done(h));
        let late = p.since.elapsed().as_secs_f64() > robot_handshake::ACTUATION_TIMEOUT;
        if !(done || late) {
            self.pending = Some(p);
            return;
        }
        if let Some((input, false)) = p.op.signal() {
            let _ = self.signals.publish(SimInput {
                input,
                value: false,
            });
        }
        let (accepted, message) = if done {
            (true, format!("{} done", p.op.name()))
        } else {
            (
                false,
                format!(
                    "{} not done within {} s (see the PLC's alarms)",
                    p.op.name(),
                    robot_handshake::ACTUATION_TIMEOUT
                ),
            )
        };
        for r in &p.requests {
            front.record(NAME, p.op.name(), &Who::Dds(r.writer), accepted, &message);
            let response = RobotRequestResponse {
                accepted,
                message: message.clone(),
            };
            reply(&self.server, r, &response);
        }
    }
}

/// Cycle start runs the selected program, as the panel's key does: the one the machine ran
/// last, never an MDI entry.
fn cycle_start(
    front: &mut dyn Front,
    machine: Option<&MachineState>,
    r: &Request<RobotRequestRequest>,
) -> Answer {
    let selected = machine
        .map(|m| m.program.clone())
        .filter(|p| !p.is_empty() && p != MDI_PROGRAM);
    match selected {
        Some(name) => front.perform(
            Operation::Start {
                name,
                at: String::new(),
            },
            &Who::Dds(r.writer),
        ),
        None => {
            let why =
                "cycle start refused: no program started yet (start_program or RunProgram first)";
            front.record(
                NAME,
                robot_handshake::Op::CycleStart.name(),
                &Who::Dds(r.writer),
                false,
                why,
            );
            Answer::refused(why)
        }
    }
}
