//! A ROS 2 client of a running cell: calls its services and follows its state topics.

use std::time::{Duration, Instant};

use cnc_msgs::msg::{
    ActiveAlarms, AxisState, MachineState, PartCount, RobotHandshake, ServoStats, SpindleState,
};
use cnc_msgs::srv::*;
use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::{qos, RosNode};
use cnc_runtime::topics;
use ros2_client::dds::{Client, Subscription};
use ros2_client::qos::History;
use ros2_client::{Gid, MessageInfo, Name, ServiceMapping, ServiceTypeName};

pub struct CellClient {
    ros: RosNode,
    mapping: ServiceMapping,
    namespace: String,
    /// How long a service call waits for its reply.
    timeout: Duration,
    load: Door<LoadProgramRequest, LoadProgramResponse>,
    start: Door<StartProgramRequest, StartProgramResponse>,
    stop: Door<StopRequest, StopResponse>,
    reset: Door<ResetRequest, ResetResponse>,
    robot: Door<RobotRequestRequest, RobotRequestResponse>,
    list: Door<ListProgramsRequest, ListProgramsResponse>,
    delete: Door<DeleteProgramRequest, DeleteProgramResponse>,
    overrides: Door<SetOverridesRequest, SetOverridesResponse>,
    machine: Newest<MachineState>,
    spindle_sub: Newest<SpindleState>,
    live_tool_sub: Newest<SpindleState>,
    parts: Newest<PartCount>,
    alarms_sub: Newest<ActiveAlarms>,
    axes_sub: Newest<AxisState>,
    stats_sub: Newest<ServoStats>,
    handshake_sub: Newest<RobotHandshake>,
    pub state: Option<MachineState>,
    pub spindle: Option<SpindleState>,
    /// A turn-mill's live tool (D143): none on a machine without one.
    pub live_tool: Option<SpindleState>,
    pub part_count: Option<PartCount>,
    pub alarms: Option<ActiveAlarms>,
    pub axes: Option<AxisState>,
    pub servo_stats: Option<ServoStats>,
    /// The machine's side of the robot handshake.
    pub handshake: Option<RobotHandshake>,
    /// When a sample of any state topic last came (`axes` comes 25 times a second): how a
    /// supervisor knows the machine is still there.
    pub heard_at: Option<Instant>,
}

/// A state topic's reader that keeps only what is newer than what it has: a reliable reader
/// can be handed a repaired sample after newer ones (seen under DDS Security: the axes went
/// back to a position of the run after the final one), and a view of the machine must not go
/// back in time. Newer is a higher sequence number from the same writer; a new writer (a
/// restarted node) is taken as it comes.
struct Newest<M> {
    reader: Subscription<M>,
    last: Option<(Gid, i64)>,
}

impl<M: 'static + serde::de::DeserializeOwned> Newest<M> {
    fn new(reader: Subscription<M>) -> Self {
        Newest { reader, last: None }
    }

    /// Hands every waiting sample to `keep`, in order, unless it is older than the last one
    /// kept; whether any sample came.
    fn take_newer(&mut self, mut keep: impl FnMut(M)) -> bool {
        let mut heard = false;
        while let Ok(Some((m, info))) = self.reader.take() {
            heard = true;
            if newer(self.last, &info) {
                self.last = Some((info.publisher_gid(), info.sequence_number()));
                keep(m);
            }
        }
        heard
    }

    /// The newest waiting sample into `into` ([`Newest::take_newer`]).
    fn take_into(&mut self, into: &mut Option<M>) -> bool {
        self.take_newer(|m| *into = Some(m))
    }
}

/// Whether a sample described by `info` is newer than the last kept one (`last`).
fn newer(last: Option<(Gid, i64)>, info: &MessageInfo) -> bool {
    match last {
        Some((gid, seq)) if gid == info.publisher_gid() => info.sequence_number() > seq,
        _ => true,
    }
}

/// A service client, or why this client has none: under DDS Security an identity is refused
/// the request writer of a service its permissions do not grant (the robot's `start_program`),
/// and the call says so instead of the client failing as a whole.
type Door<Req, Resp> = Result<Client<Req, Resp>, String>;

fn door<Req: ros2_client::Message, Resp: ros2_client::Message>(
    d: &Door<Req, Resp>,
) -> Result<&Client<Req, Resp>, String> {
    d.as_ref().map_err(Clone::clone)
}

fn client<S: RosService>(
    ros: &mut RosNode,
    mapping: ServiceMapping,
    ns: &str,
    service: &str,
) -> Result<Client<S::Request, S::Response>, String> {
    let name = Name::new(&format!("/{ns}"), service).map_err(|e| format!("{e:?}"))?;
    let q = qos::services();
    ros.node
        .create_client::<S::Request, S::Response>(
            mapping,
            &name,
            &ServiceTypeName::new(cnc_msgs::PACKAGE, S::NAME),
            q.clone(),
            q,
        )
        .map_err(|e| format!("client {service}: {e:?}"))
}

impl CellClient {
    /// A client node named `name` that speaks the given service mapping.
    pub fn new(
        net: &NetworkConfig,
        ns: &str,
        name: &str,
        mapping: ServiceMapping,
    ) -> Result<Self, String> {
        let mut ros = RosNode::client(net, ns, name)?;
        Ok(CellClient {
            load: client::<LoadProgram>(&mut ros, mapping, ns, "load_program"),
            start: client::<StartProgram>(&mut ros, mapping, ns, "start_program"),
            stop: client::<Stop>(&mut ros, mapping, ns, "stop"),
            reset: client::<Reset>(&mut ros, mapping, ns, "reset"),
            robot: client::<RobotRequest>(&mut ros, mapping, ns, "robot_request"),
            list: client::<ListPrograms>(&mut ros, mapping, ns, "list_programs"),
            delete: client::<DeleteProgram>(&mut ros, mapping, ns, "delete_program"),
            overrides: client::<SetOverrides>(&mut ros, mapping, ns, "set_overrides"),
            // Every transition, in order: a start that fails at once goes ACTIVE then STOPPED
            // within a millisecond, and a depth-1 reader would see only STOPPED.
            machine: Newest::new(ros.dds_subscription_with_qos(
                &topics::MACHINE_STATE,
                qos::state().history(History::KeepLast { depth: 64 }),
            )?),
            spindle_sub: Newest::new(ros.dds_subscription(&topics::SPINDLE)?),
            live_tool_sub: Newest::new(ros.dds_subscription(&topics::LIVE_TOOL)?),
            parts: Newest::new(ros.dds_subscription(&topics::PART_COUNT)?),
            alarms_sub: Newest::new(ros.dds_subscription(&topics::ALARMS)?),
            axes_sub: Newest::new(ros.dds_subscription(&topics::AXES)?),
            stats_sub: Newest::new(ros.dds_subscription(&topics::SERVO_STATS)?),
            handshake_sub: Newest::new(ros.dds_subscription(&topics::ROBOT_HANDSHAKE)?),
            ros,
            mapping,
            namespace: ns.into(),
            timeout: Duration::from_secs(20),
            state: None,
            spindle: None,
            live_tool: None,
            part_count: None,
            alarms: None,
            axes: None,
            servo_stats: None,
            handshake: None,
            heard_at: None,
        })
    }

    /// This client with service calls that wait at most `timeout` for their reply (default
    /// 20 s).
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// Waits until the machine reports a state other than WAIT (the interpreter knows where the
    /// axes are, so a cycle start can be accepted).
    pub fn wait_ready(&mut self, timeout: Duration) -> Result<(), String> {
        let ready = |c: &CellClient| {
            c.state
                .as_ref()
                .is_some_and(|s| s.execution != MachineState::WAIT)
        };
        if self.wait_until(timeout, ready).0 {
            Ok(())
        } else {
            Err(format!(
                "the machine did not become ready within {} s",
                timeout.as_secs()
            ))
        }
    }

    /// Polls the state topics until `done` holds or `timeout` passes: whether it held, and
    /// every machine state seen on the way, in order.
    pub fn wait_until(
        &mut self,
        timeout: Duration,
        mut done: impl FnMut(&CellClient) -> bool,
    ) -> (bool, Vec<MachineState>) {
        let deadline = Instant::now() + timeout;
        let mut seen = Vec::new();
        loop {
            seen.extend(self.poll());
            if done(self) {
                return (true, seen);
            }
            if Instant::now() >= deadline {
                return (false, seen);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Takes every new sample of the state topics; returns the machine states seen, in order.
    pub fn poll(&mut self) -> Vec<MachineState> {
        let mut states = Vec::new();
        self.machine.take_newer(|m| states.push(m));
        if let Some(last) = states.last() {
            self.state = Some(last.clone());
        }
        let heard = [
            self.spindle_sub.take_into(&mut self.spindle),
            self.live_tool_sub.take_into(&mut self.live_tool),
            self.parts.take_into(&mut self.part_count),
            self.alarms_sub.take_into(&mut self.alarms),
            self.axes_sub.take_into(&mut self.axes),
            self.stats_sub.take_into(&mut self.servo_stats),
            self.handshake_sub.take_into(&mut self.handshake),
        ]
        .contains(&true);
        if heard || !states.is_empty() {
            self.heard_at = Some(Instant::now());
        }
        states
    }

    pub fn load_program(&mut self, name: &str, text: &str) -> Result<LoadProgramResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.load)?,
            LoadProgramRequest {
                name: name.into(),
                text: text.into(),
            },
            Copies::Allowed,
        )
    }
    pub fn start_program(&mut self, name: &str) -> Result<StartProgramResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.start)?,
            StartProgramRequest { name: name.into() },
            Copies::Never,
        )
    }
    pub fn stop(&mut self, mode: u8) -> Result<StopResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.stop)?,
            StopRequest { mode },
            Copies::Allowed,
        )
    }
    pub fn reset(&mut self) -> Result<ResetResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.reset)?,
            ResetRequest::default(),
            Copies::Allowed,
        )
    }

    /// A robot handshake request (`RobotRequestRequest::DOOR_OPEN` …).
    pub fn robot_request(&mut self, request: u8) -> Result<RobotRequestResponse, String> {
        self.robot_request_unless(request, || false)
    }

    /// [`CellClient::robot_request`], no longer waited for once `give_up` says so (checked
    /// every 50 ms): a robot does not stand idle for a machine the cell has lost.
    pub fn robot_request_unless(
        &mut self,
        request: u8,
        give_up: impl FnMut() -> bool,
    ) -> Result<RobotRequestResponse, String> {
        let robot = door(&self.robot)?;
        wait_for_server(&self.ros.node, robot, self.timeout)?;
        exchange_unless(
            self.timeout,
            robot,
            RobotRequestRequest { request },
            Copies::Never,
            give_up,
        )
    }

    pub fn list_programs(&mut self) -> Result<ListProgramsResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.list)?,
            ListProgramsRequest::default(),
            Copies::Allowed,
        )
    }
    pub fn delete_program(&mut self, name: &str) -> Result<DeleteProgramResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.delete)?,
            DeleteProgramRequest { name: name.into() },
            Copies::Never,
        )
    }

    pub fn set_overrides(
        &mut self,
        feed_percent: u8,
        spindle_percent: u8,
        rapid_percent: u8,
    ) -> Result<SetOverridesResponse, String> {
        call(
            &self.ros.node,
            self.timeout,
            door(&self.overrides)?,
            SetOverridesRequest {
                feed_percent,
                spindle_percent,
                rapid_percent,
            },
            Copies::Allowed,
        )
    }

    pub fn node(&self) -> &RosNode {
        &self.ros
    }

    /// This client's node, to follow more of the machine's topics.
    pub fn node_mut(&mut self) -> &mut RosNode {
        &mut self.ros
    }

    /// The machine's namespace.
    pub fn namespace(&self) -> &str {
        &self.namespace
    }

    /// A client of any other service of the cell (`set_mode`, `mdi`, `get_offsets`,
    /// `set_tool_offset`, `set_work_offset`, `get_parameters`, `set_parameter`,
    /// `acknowledge_alarm`), on this client's node and mapping.
    /// Waits (at most this client's timeout) until the service's server is matched.
    pub fn service<S: RosService>(&mut self, service: &str) -> Result<ServiceClient<S>, String> {
        let ns = self.namespace.clone();
        let client = client::<S>(&mut self.ros, self.mapping, &ns, service)?;
        wait_for_server(&self.ros.node, &client, self.timeout)
            .map_err(|e| format!("{service}: {e}"))?;
        Ok(ServiceClient {
            client,
            timeout: self.timeout,
        })
    }
}

/// One service of the cell; see [`CellClient::service`].
pub struct ServiceClient<S: RosService> {
    client: Client<S::Request, S::Response>,
    timeout: Duration,
}

impl<S: RosService> ServiceClient<S> {
    /// Sends the request once (its server was matched when this client was made) and waits for
    /// the reply.
    pub fn call(&self, request: S::Request) -> Result<S::Response, String> {
        exchange(self.timeout, &self.client, request, Copies::Never)
    }

    /// As [`ServiceClient::call`] for a request that only reads (`get_offsets`,
    /// `get_parameters`): without a reply it is sent again (D77). Just after a server starts,
    /// the client can match it before the server has matched the client's reply reader, and
    /// the first reply is lost.
    pub fn query(&self, request: S::Request) -> Result<S::Response, String> {
        exchange(self.timeout, &self.client, request, Copies::Allowed)
    }
}

/// Whether a lost reply may be made good by sending the request again: only for requests whose
/// second execution changes nothing (a copy of an increment jog or of a cycle start would move the
/// machine twice).
#[derive(Clone, Copy, PartialEq)]
enum Copies {
    Allowed,
    Never,
}

/// The least time a new client waits to match a server. Discovery on a busy host (a test run
/// on two cores, a cell starting) took more than 10 s in CI although the server was up; a reply
/// timeout shorter than this does not cut the match short.
const DISCOVERY_WAIT: Duration = Duration::from_secs(30);

/// How often a wait for a server reads the match state again (see [`wait_for_server`]).
const RECHECK: Duration = Duration::from_millis(250);

/// Waits until this node has matched the service's server (its request reader and its reply
/// writer), at most `timeout` (and at least [`DISCOVERY_WAIT`]). A request written before that
/// match would be lost.
fn wait_for_server<Req: ros2_client::Message + 'static, Resp: ros2_client::Message + 'static>(
    node: &ros2_client::Node,
    client: &Client<Req, Resp>,
    timeout: Duration,
) -> Result<(), String> {
    let timeout = timeout.max(DISCOVERY_WAIT);
    let deadline = Instant::now() + timeout;
    // ros2-client's wait hears of a match through a channel of 8 events that drops what does
    // not fit, so in a burst of discovery (a cell starting, a busy host) the event of this
    // match can be lost and the wait would run its whole time although the server matched
    // (CI: "no server of the service found within 30 s"). A fresh wait reads the match state
    // as it stands when made: the wait is made again every RECHECK.
    let mut matched = false;
    while !matched && Instant::now() < deadline {
        let slice = RECHECK.min(deadline.saturating_duration_since(Instant::now()));
        matched = smol::block_on(smol::future::or(
            async {
                client.wait_for_service(node).await;
                true
            },
            async {
                smol::Timer::after(slice).await;
                false
            },
        ));
    }
    if matched {
        Ok(())
    } else {
        Err(format!(
            "no server of the service found within {} s",
            timeout.as_secs()
        ))
    }
}

/// Calls a service once its server is matched, so the request is not lost in discovery; the
/// reply is awaited until `timeout`. Where `copies` allows, the request is sent again every 2 s
/// without a reply (at most 3 copies), the first reply to any copy being the answer.
fn call<Req: ros2_client::Message + Clone + 'static, Resp: ros2_client::Message + 'static>(
    node: &ros2_client::Node,
    timeout: Duration,
    client: &Client<Req, Resp>,
    req: Req,
    copies: Copies,
) -> Result<Resp, String> {
    wait_for_server(node, client, timeout)?;
    exchange(timeout, client, req, copies)
}

/// Sends the request and waits at most `timeout` for its reply; see [`call`].
fn exchange<Req: ros2_client::Message + Clone + 'static, Resp: ros2_client::Message + 'static>(
    timeout: Duration,
    client: &Client<Req, Resp>,
    req: Req,
    copies: Copies,
) -> Result<Resp, String> {
    exchange_unless(timeout, client, req, copies, || false)
}

/// [`exchange`], ended early (an error) once `give_up` says so.
fn exchange_unless<
    Req: ros2_client::Message + Clone + 'static,
    Resp: ros2_client::Message + 'static,
>(
    timeout: Duration,
    client: &Client<Req, Resp>,
    req: Req,
    copies: Copies,
    mut give_up: impl FnMut() -> bool,
) -> Result<Resp, String> {
    let deadline = Instant::now() + timeout;
    let mut asked = Instant::now();
    let mut ids = Vec::new();
    let mut last_send: Option<Instant> = None;
    while Instant::now() < deadline {
        let again = copies == Copies::Allowed
            && ids.len() < 3
            && last_send.is_some_and(|t| t.elapsed() > Duration::from_secs(2));
        if last_send.is_none() || again {
            ids.push(
                client
                    .send_request(req.clone())
                    .map_err(|e| format!("request not sent: {e:?}"))?,
            );
            last_send = Some(Instant::now());
        }
        while let Ok(Some((id, resp))) = client.receive_response() {
            if ids.contains(&id) {
                return Ok(resp);
            }
        }
        if asked.elapsed() > Duration::from_millis(50) {
            asked = Instant::now();
            if give_up() {
                return Err("no longer waited for: the machine is out of reach".into());
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Err(format!(
        "no reply from the cell within {} s",
        timeout.as_secs()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(writer: u8, seq: i64) -> MessageInfo {
        MessageInfo::new(None, None, seq, Gid::from([writer; 16]), None)
    }

    #[test]
    fn a_state_view_never_goes_back_to_an_older_sample_of_its_writer() {
        assert!(newer(None, &info(1, 7)));
        let last = Some((Gid::from([1; 16]), 7));
        assert!(newer(last, &info(1, 8)));
        // A repaired sample handed over after newer ones is not taken.
        assert!(!newer(last, &info(1, 5)));
        assert!(!newer(last, &info(1, 7)));
        // Another writer (a restarted node) counts from its own start.
        assert!(newer(last, &info(2, 1)));
    }
}
