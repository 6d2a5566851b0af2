//! The bridge's ROS 2 services as one table of doors (issue 47): each entry names the
//! service, its type, how its request becomes an [`Operation`] and how an [`Answer`] becomes
//! its response. Creating the servers, taking requests off DDS, refusing malformed ones with a
//! `CommandEvent`, and answering all come from [`Door`], written once: a service added to the
//! table has them all. Who may use a door is the operation's to say ([`Operation::moves`]).
//!
//! The robot's requests (a handshake with the PLC) and the `RunProgram` action (a goal that
//! follows the run) are doors of their own kind, in `node.rs` and `action_server.rs`.

use cnc_msgs::msg::Overrides;
use cnc_msgs::srv::*;
use ros2_client::dds::rustdds::{DomainParticipant, QosPolicies};
use serde::{de::DeserializeOwned, Serialize};

use crate::access::Who;
use crate::operation::{Answer, Operation};
use crate::service_server::{DualServer, Request};

/// What every door acts on: the bridge.
pub trait Front {
    /// Carries out an operation for a client: access checked, the command event recorded.
    fn perform(&mut self, op: Operation, who: &Who) -> Answer;
    /// Carries out an operation a door has authorised and records itself (the action's).
    fn carry_out(&mut self, op: &Operation) -> Answer;
    /// Whether `who` may move the machine (`hmi.allowed_clients`).
    fn may_move(&self, who: &Who) -> Result<(), String>;
    /// Records a command event.
    fn record(&self, command: &str, detail: &str, who: &Who, accepted: bool, message: &str);
    /// Lines of a program loaded through the bridge (0: unknown), for progress.
    fn program_lines(&self, name: &str) -> u32;
}

/// One service door.
pub trait Door {
    /// The service's name under the machine's namespace.
    fn name(&self) -> &str;
    /// Takes what DDS holds into the door's queue (a burst on one door is taken off DDS before
    /// any door is served; a full queue refuses as busy).
    fn drain(&self);
    /// Serves the next waiting request, if any, through `front`; records every malformed
    /// request refused since the last call. Returns whether it served one.
    fn serve(&self, front: &mut dyn Front) -> bool;
}

/// A service door: the server, and the two conversions of its table entry.
struct ServiceDoor<S: RosService> {
    server: DualServer<S>,
    /// The request's operation; `Err`: a request no operation can carry (a malformed one).
    operation: fn(&S::Request) -> Result<Operation, String>,
    response: fn(Answer) -> S::Response,
}

impl<S: RosService> Door for ServiceDoor<S>
where
    S::Request: DeserializeOwned,
    S::Response: Serialize,
{
    fn name(&self) -> &str {
        self.server.name()
    }

    fn drain(&self) {
        self.server.drain();
    }

    fn serve(&self, front: &mut dyn Front) -> bool {
        let name = self.server.name();
        for (writer, why) in self.server.take_malformed() {
            front.record(name, "malformed", &Who::Dds(writer), false, &why);
        }
        let Some(r) = self.server.receive() else {
            return false;
        };
        let who = Who::Dds(r.writer);
        let answer = match (self.operation)(&r.request) {
            Ok(op) => front.perform(op, &who),
            Err(why) => {
                front.record(name, "malformed", &who, false, &why);
                Answer::refused(why)
            }
        };
        reply(&self.server, &r, &(self.response)(answer));
        true
    }
}

/// Answers `request`, logged.
pub fn reply<S: RosService>(
    server: &DualServer<S>,
    request: &Request<S::Request>,
    response: &S::Response,
) where
    S::Request: DeserializeOwned,
    S::Response: Serialize + std::fmt::Debug,
{
    log::info!(
        "{}: {:?} via {:?} from {}",
        S::NAME,
        response,
        request.mapping,
        request.client
    );
    if let Err(e) = server.reply(request, response) {
        log::error!("{e}");
    }
}

/// A door of the table.
fn door<S: RosService + 'static>(
    participant: &DomainParticipant,
    namespace: &str,
    qos: &QosPolicies,
    name: &str,
    operation: fn(&S::Request) -> Result<Operation, String>,
    response: fn(Answer) -> S::Response,
) -> Result<Box<dyn Door>, String>
where
    S::Request: DeserializeOwned,
    S::Response: Serialize,
{
    let server = DualServer::<S>::new(participant, namespace, name, qos.clone())?
        .refusing(move |why| response(Answer::refused(why)));
    Ok(Box::new(ServiceDoor {
        server,
        operation,
        response,
    }))
}

/// A yes or no with a reason, as most responses are.
macro_rules! said {
    ($response:ident) => {
        |a: Answer| $response {
            accepted: a.accepted,
            message: a.message,
        }
    };
}

/// The services' doors, one entry each: program memory and the run, then the machine's
/// switches, offsets, parameters and alarms.
pub fn services(
    p: &DomainParticipant,
    ns: &str,
    qos: &QosPolicies,
) -> Result<Vec<Box<dyn Door>>, String> {
    let mut doors = program_doors(p, ns, qos)?;
    doors.extend(machine_doors(p, ns, qos)?);
    Ok(doors)
}

fn program_doors(
    p: &DomainParticipant,
    ns: &str,
    qos: &QosPolicies,
) -> Result<Vec<Box<dyn Door>>, String> {
    Ok(vec![
        door::<LoadProgram>(
            p,
            ns,
            qos,
            "load_program",
            |q| {
                Ok(Operation::Load {
                    name: q.name.clone(),
                    text: q.text.clone(),
                })
            },
            said!(LoadProgramResponse),
        )?,
        door::<StartProgram>(
            p,
            ns,
            qos,
            "start_program",
            |q| {
                Ok(Operation::Start {
                    name: q.name.clone(),
                    at: String::new(),
                })
            },
            said!(StartProgramResponse),
        )?,
        door::<Stop>(
            p,
            ns,
            qos,
            "stop",
            |q| Ok(Operation::Stop { mode: q.mode }),
            said!(StopResponse),
        )?,
        door::<Reset>(
            p,
            ns,
            qos,
            "reset",
            |_| Ok(Operation::Reset),
            said!(ResetResponse),
        )?,
        door::<ListPrograms>(
            p,
            ns,
            qos,
            "list_programs",
            |_| Ok(Operation::List),
            |a| {
                let (names, sizes) = a.programs.into_iter().unzip();
                ListProgramsResponse {
                    names,
                    sizes,
                    accepted: a.accepted,
                    message: if a.accepted { String::new() } else { a.message },
                }
            },
        )?,
        door::<DeleteProgram>(
            p,
            ns,
            qos,
            "delete_program",
            |q| {
                Ok(Operation::Delete {
                    name: q.name.clone(),
                })
            },
            said!(DeleteProgramResponse),
        )?,
        door::<Mdi>(
            p,
            ns,
            qos,
            "mdi",
            |q| {
                Ok(Operation::Mdi {
                    text: q.text.clone(),
                })
            },
            said!(MdiResponse),
        )?,
    ])
}

fn machine_doors(
    p: &DomainParticipant,
    ns: &str,
    qos: &QosPolicies,
) -> Result<Vec<Box<dyn Door>>, String> {
    Ok(vec![
        door::<SetOverrides>(
            p,
            ns,
            qos,
            "set_overrides",
            |q| {
                Ok(Operation::Overrides(Overrides {
                    feed_percent: q.feed_percent,
                    spindle_percent: q.spindle_percent,
                    rapid_percent: q.rapid_percent,
                }))
            },
            said!(SetOverridesResponse),
        )?,
        door::<SetMode>(
            p,
            ns,
            qos,
            "set_mode",
            |q| Ok(Operation::Mode { mode: q.mode }),
            said!(SetModeResponse),
        )?,
        door::<Jog>(
            p,
            ns,
            qos,
            "jog",
            |q| {
                Ok(Operation::Jog {
                    axis: q.axis.clone(),
                    direction: q.direction,
                    feed: q.feed,
                    increment: q.increment,
                })
            },
            said!(JogResponse),
        )?,
        door::<GetOffsets>(
            p,
            ns,
            qos,
            "get_offsets",
            |_| Ok(Operation::Offsets),
            |a| GetOffsetsResponse {
                accepted: a.accepted,
                message: a.message,
                tools: a.tools,
                work: a.work,
            },
        )?,
        door::<SetToolOffset>(
            p,
            ns,
            qos,
            "set_tool_offset",
            |q| Ok(Operation::SetToolOffset(q.offset.clone())),
            said!(SetToolOffsetResponse),
        )?,
        door::<SetWorkOffset>(
            p,
            ns,
            qos,
            "set_work_offset",
            |q| {
                let w = &q.offset;
                if w.axes.len() != w.values.len() {
                    return Err(format!(
                        "work offset {}: {} axes but {} values",
                        w.code,
                        w.axes.len(),
                        w.values.len()
                    ));
                }
                Ok(Operation::SetWorkOffset(w.clone()))
            },
            said!(SetWorkOffsetResponse),
        )?,
        door::<GetParameters>(
            p,
            ns,
            qos,
            "get_parameters",
            |q| {
                Ok(Operation::Parameters {
                    prefix: q.prefix.clone(),
                })
            },
            |a| {
                let mut r = GetParametersResponse {
                    accepted: a.accepted,
                    message: if a.accepted { String::new() } else { a.message },
                    ..Default::default()
                };
                for (name, value, pending) in a.parameters {
                    r.names.push(name);
                    r.values.push(value);
                    r.pending.push(pending);
                }
                r
            },
        )?,
        door::<SetParameter>(
            p,
            ns,
            qos,
            "set_parameter",
            |q| {
                Ok(Operation::SetParameter {
                    name: q.name.clone(),
                    value: q.value.clone(),
                })
            },
            said!(SetParameterResponse),
        )?,
        door::<AcknowledgeAlarm>(
            p,
            ns,
            qos,
            "acknowledge_alarm",
            |q| {
                Ok(Operation::Acknowledge {
                    source: q.source.clone(),
                    number: q.number,
                })
            },
            said!(AcknowledgeAlarmResponse),
        )?,
    ])
}
