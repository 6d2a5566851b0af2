//! The `RunProgram` action server: `/<ns>/run_program/_action/{send_goal,cancel_goal,
//! get_result}` served to both service mappings ([`DualServer`]), `feedback` and `status`
//! published as ROS 2 action clients expect. One goal runs at a time; its course is
//! [`GoalRun`], its commands go through the same path as the services'.

use std::collections::VecDeque;

use byteorder::LittleEndian;
use cnc_msgs::action::*;
use cnc_msgs::msg::{Alarm, MachineState, Time};
use cnc_runtime::dds::stamp;
use cnc_runtime::raw::{Raw, RawAdapter};
use ros2_client::dds::rustdds::{
    self, no_key::DataWriter, policy, QosPolicies, QosPolicyBuilder, TopicKind,
};
use serde::Serialize;

use crate::access::Who;
use crate::doors::Front;
use crate::operation::Operation;
use crate::run_program::{check, start_at, GoalRun, Step, View};
use crate::service_server::{DualServer, Request};
use cnc_msgs::srv::StopRequest;

/// Finished goals whose results can still be asked for.
const RESULTS_KEPT: usize = 16;

struct Topic {
    writer: DataWriter<Raw, RawAdapter>,
}

impl Topic {
    fn new(
        participant: &rustdds::DomainParticipant,
        name: String,
        dds_type: &str,
        depth: i32,
    ) -> Result<Self, String> {
        // Reliable and transient-local: matches every reader a ROS 2 action client creates.
        let qos = QosPolicyBuilder::new()
            .reliability(policy::Reliability::Reliable {
                max_blocking_time: rustdds::Duration::from_millis(100),
            })
            .durability(policy::Durability::TransientLocal)
            .history(policy::History::KeepLast { depth })
            .build();
        let topic = participant
            .create_topic(name.clone(), dds_type.into(), &qos, TopicKind::NoKey)
            .map_err(|e| format!("{name}: {e:?}"))?;
        let writer = participant
            .create_publisher(&qos)
            .map_err(|e| format!("{name}: {e:?}"))?
            .create_datawriter_no_key::<Raw, RawAdapter>(&topic, None)
            .map_err(|e| format!("{name}: {e:?}"))?;
        Ok(Topic { writer })
    }

    fn publish<M: Serialize>(&self, m: &M) {
        match cdr_encoding::to_vec::<_, LittleEndian>(m) {
            Ok(bytes) => {
                if let Err(e) = self.writer.write(
                    Raw {
                        bytes,
                        little_endian: true,
                    },
                    None,
                ) {
                    log::warn!("run_program: {e:?}");
                }
            }
            Err(e) => log::error!("run_program: {e}"),
        }
    }
}

/// A finished goal: id, acceptance time, final status and result. A rejected goal is kept
/// too (status ABORTED, the reason in the result's message), so that its GetResult is
/// answered, though it never shows in the status array.
struct Done {
    id: Uuid,
    accepted: Time,
    status: i8,
    result: RunProgramResult,
    rejected: bool,
}

/// GetResult requests waiting for a running goal; more are answered at once as busy.
const WAITING_LIMIT: usize = 64;

pub struct RunProgramServer {
    send_goal: DualServer<RunProgramSendGoal>,
    cancel_goal: DualServer<CancelGoal>,
    get_result: DualServer<RunProgramGetResult>,
    feedback: Topic,
    status: Topic,
    goal: Option<(GoalRun, Time)>,
    done: VecDeque<Done>,
    waiting: Vec<Request<RunProgramGetResultRequest>>,
}

/// A request the action server decided on, for the caller's command events.
pub struct Event {
    /// `run_program` or `run_program/cancel`, or the action service that refused a malformed
    /// request.
    pub command: &'static str,
    pub detail: String,
    /// The client's writer GUID.
    pub writer: [u8; 16],
    pub accepted: bool,
    pub message: String,
}

impl RunProgramServer {
    pub fn new(
        participant: &rustdds::DomainParticipant,
        ns: &str,
        qos: QosPolicies,
    ) -> Result<Self, String> {
        let base = "run_program/_action";
        Ok(RunProgramServer {
            send_goal: DualServer::new(participant, ns, &format!("{base}/send_goal"), qos.clone())?,
            cancel_goal: DualServer::new(
                participant,
                ns,
                &format!("{base}/cancel_goal"),
                qos.clone(),
            )?,
            get_result: DualServer::new(participant, ns, &format!("{base}/get_result"), qos)?,
            feedback: Topic::new(
                participant,
                format!("rt/{ns}/{base}/feedback"),
                "cnc_msgs::action::dds_::RunProgram_FeedbackMessage_",
                100,
            )?,
            status: Topic::new(
                participant,
                format!("rt/{ns}/{base}/status"),
                "action_msgs::msg::dds_::GoalStatusArray_",
                1,
            )?,
            goal: None,
            done: VecDeque::new(),
            waiting: Vec::new(),
        })
    }

    fn publish_status(&self) {
        let mut list: Vec<GoalStatus> = self
            .done
            .iter()
            .filter(|d| !d.rejected)
            .map(|d| GoalStatus {
                goal_info: GoalInfo {
                    goal_id: d.id,
                    stamp: d.accepted.clone(),
                },
                status: d.status,
            })
            .collect();
        if let Some((g, accepted)) = &self.goal {
            list.push(GoalStatus {
                goal_info: GoalInfo {
                    goal_id: g.id,
                    stamp: accepted.clone(),
                },
                status: g.status(),
            });
        }
        self.status.publish(&GoalStatusArray { status_list: list });
    }

    /// Moves a finished goal to the results and answers whoever waits for it.
    fn retire(&mut self) {
        let Some((g, accepted)) = self.goal.take_if(|(g, _)| g.finished()) else {
            return;
        };
        if self.done.len() == RESULTS_KEPT {
            self.done.pop_front();
        }
        self.done.push_back(Done {
            id: g.id,
            accepted,
            status: g.status(),
            result: g.result().clone(),
            rejected: false,
        });
        self.answer_waiting();
        self.publish_status();
    }

    /// Answers every GetResult whose goal has ended; one for a goal this server does not
    /// know is answered STATUS_UNKNOWN at once, as rclcpp's action server does. Only
    /// requests for the running goal wait, at most [`WAITING_LIMIT`] of them.
    fn answer_waiting(&mut self) {
        let waiting = std::mem::take(&mut self.waiting);
        for r in waiting {
            let id = r.request.goal_id;
            let running = self.goal.as_ref().is_some_and(|(g, _)| g.id == id);
            let response = match self.done.iter().find(|d| d.id == id) {
                Some(d) => RunProgramGetResultResponse {
                    status: d.status,
                    result: d.result.clone(),
                },
                None if running && self.waiting.len() < WAITING_LIMIT => {
                    self.waiting.push(r);
                    continue;
                }
                None => RunProgramGetResultResponse {
                    status: GoalStatus::STATUS_UNKNOWN,
                    result: RunProgramResult {
                        message: if running {
                            format!("busy: {WAITING_LIMIT} result requests wait; try again")
                        } else {
                            "unknown goal id (never sent, or its result was dropped)".into()
                        },
                        ..Default::default()
                    },
                },
            };
            if let Err(e) = self.get_result.reply(&r, &response) {
                log::error!("{e}");
            }
        }
    }

    /// Whether a goal of this id runs or has ended here.
    fn knows(&self, id: &Uuid) -> bool {
        self.goal.as_ref().is_some_and(|(g, _)| &g.id == id)
            || self.done.iter().any(|d| &d.id == id)
    }

    /// Takes the action's requests off DDS into their queues.
    pub fn drain(&self) {
        self.send_goal.drain();
        self.cancel_goal.drain();
        self.get_result.drain();
    }

    /// Serves requests and follows the running goal; returns the requests decided, for
    /// events. Each request becomes an [`Operation`] carried out by `front`, which also says
    /// whether a client may start the machine.
    pub fn poll(
        &mut self,
        front: &mut dyn Front,
        state: Option<&MachineState>,
        (run_id, done_blocks): (u64, u64),
        part_count: u32,
        alarms: &[Alarm],
        now: f64,
    ) -> Vec<Event> {
        let mut events = self.malformed();
        if let Some(r) = self.send_goal.receive() {
            events.push(self.send_goal(r, front, run_id, now));
        }
        if let Some(r) = self.cancel_goal.receive() {
            events.push(self.cancel_goal(r, front));
        }
        if let Some(r) = self.get_result.receive() {
            self.waiting.push(r);
            self.answer_waiting();
        }
        if let Some(state) = state {
            let view = View {
                state,
                run_id,
                done_blocks,
                part_count,
                alarms,
                now,
            };
            self.follow(&view, front);
        }
        self.retire();
        events
    }

    /// Malformed requests to the action's services since the last turn, as events.
    fn malformed(&self) -> Vec<Event> {
        let mut events = Vec::new();
        let malformed = [
            (
                "run_program/_action/send_goal",
                self.send_goal.take_malformed(),
            ),
            (
                "run_program/_action/cancel_goal",
                self.cancel_goal.take_malformed(),
            ),
            (
                "run_program/_action/get_result",
                self.get_result.take_malformed(),
            ),
        ];
        for (command, list) in malformed {
            for (writer, why) in list {
                events.push(Event {
                    command,
                    detail: "malformed".into(),
                    writer,
                    accepted: false,
                    message: why,
                });
            }
        }
        events
    }

    /// A goal: started if the client may and the machine accepts; refused with why.
    fn send_goal(
        &mut self,
        r: Request<RunProgramSendGoalRequest>,
        front: &mut dyn Front,
        run_id: u64,
        now: f64,
    ) -> Event {
        let goal = r.request.goal.clone();
        let outcome = if let Err(why) = front.may_move(&Who::Dds(r.writer)) {
            Err(why)
        } else if self.goal.is_some() {
            Err("a RunProgram goal is running: cancel it first".to_string())
        } else {
            check(&goal, true).and_then(|()| {
                let a = front.carry_out(&Operation::Start {
                    name: goal.program.clone(),
                    at: start_at(&goal),
                });
                if a.accepted {
                    Ok(a.message)
                } else {
                    Err(a.message)
                }
            })
        };
        let accepted = outcome.is_ok();
        let response = RunProgramSendGoalResponse {
            accepted,
            stamp: stamp(),
        };
        if accepted {
            let lines = front.program_lines(&goal.program);
            let run = GoalRun::new(r.request.goal_id, goal.clone(), lines, run_id, now);
            self.goal = Some((run, response.stamp.clone()));
        } else if let (Err(why), false) = (&outcome, self.knows(&r.request.goal_id)) {
            // The reason reaches the client through GetResult, not only the log.
            if self.done.len() == RESULTS_KEPT {
                self.done.pop_front();
            }
            self.done.push_back(Done {
                id: r.request.goal_id,
                accepted: response.stamp.clone(),
                status: GoalStatus::STATUS_ABORTED,
                result: RunProgramResult {
                    message: format!("goal rejected: {why}"),
                    ..Default::default()
                },
                rejected: true,
            });
        }
        if let Err(e) = self.send_goal.reply(&r, &response) {
            log::error!("{e}");
        }
        self.publish_status();
        Event {
            command: "run_program",
            detail: format!("{} x{}", goal.program, goal.cycles),
            writer: r.writer,
            accepted,
            message: match outcome {
                Ok(m) | Err(m) => m,
            },
        }
    }

    /// A cancel: the goal stops on the path, then the machine is reset for the next goal.
    fn cancel_goal(&mut self, r: Request<CancelGoalRequest>, front: &mut dyn Front) -> Event {
        let wanted = r.request.goal_info.goal_id;
        let all = wanted == [0; 16];
        let mut response = CancelGoalResponse::default();
        match self.goal.as_mut() {
            Some((g, accepted)) if (all || g.id == wanted) && !g.finished() => {
                g.cancel();
                response.return_code = CancelGoalResponse::ERROR_NONE;
                response.goals_canceling.push(GoalInfo {
                    goal_id: g.id,
                    stamp: accepted.clone(),
                });
            }
            _ if self.done.iter().any(|d| d.id == wanted) => {
                response.return_code = CancelGoalResponse::ERROR_GOAL_TERMINATED
            }
            _ => response.return_code = CancelGoalResponse::ERROR_UNKNOWN_GOAL_ID,
        }
        if let Err(e) = self.cancel_goal.reply(&r, &response) {
            log::error!("{e}");
        }
        let event = Event {
            command: "run_program/cancel",
            detail: String::new(),
            writer: r.writer,
            accepted: response.return_code == CancelGoalResponse::ERROR_NONE,
            message: format!("return code {}", response.return_code),
        };
        let canceling = self
            .goal
            .as_ref()
            .is_some_and(|(g, _)| g.status() == GoalStatus::STATUS_CANCELING);
        if canceling {
            self.publish_status();
            // Stop on the path, then reset: the machine is ready for the next goal.
            let stop = front.carry_out(&Operation::Stop {
                mode: StopRequest::CYCLE_STOP,
            });
            let reset = front.carry_out(&Operation::Reset);
            if let Some((g, _)) = self.goal.as_mut() {
                g.canceled(&format!("{}, {}", stop.message, reset.message));
            }
        }
        event
    }

    /// The running goal through the machine's state: feedback, the next cycle's start.
    fn follow(&mut self, view: &View, front: &mut dyn Front) {
        let Some((g, _)) = self.goal.as_mut() else {
            return;
        };
        let before = g.status();
        for step in g.update(view) {
            match step {
                Step::Feedback(feedback) => self.feedback.publish(&RunProgramFeedbackMessage {
                    goal_id: g.id,
                    feedback,
                }),
                Step::StartCycle => {
                    let a = front.carry_out(&Operation::Start {
                        name: g.goal.program.clone(),
                        at: String::new(),
                    });
                    if a.accepted {
                        g.cycle_started(view.now, view.run_id);
                    } else {
                        g.abort(&format!("next cycle refused: {}", a.message), view.alarms);
                    }
                }
            }
        }
        if g.status() != before {
            self.publish_status();
        }
    }
}
