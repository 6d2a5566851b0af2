//! hmi_bridge node shell: serves the cell's doors — the services of [`crate::doors`], the
//! `RunProgram` action, the robot's requests ([`crate::robot_door`]) and the operator's web
//! HMI — turns each request into an [`Operation`] carried out through one command path (with
//! one access check and one command event), and keeps `/<ns>/alarms` (ActiveAlarms).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use cnc_msgs::msg::{
    ActiveAlarms, AlarmEvent, AxisState, CommandEvent, CommandResult, MachineState, MotionBlock,
    MotionStatus, Overrides, PartCount, PlcProgram, PlcSignals, ProgramEvent, SimInput,
    SpindleState, TaskCommand,
};
use cnc_msgs::task::TaskRequest;
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::topics;
use cnc_runtime::MAX_PROGRAM_BYTES;
use cnc_runtime::{LaunchConfig, Shutdown};
use ros2_client::dds::rustdds;
use ros2_client::dds::rustdds::QosPolicies;
use ros2_client::entities_info::ParticipantEntitiesInfo;

use crate::access::{self, Clients, Who};
use crate::action_server::RunProgramServer;
use crate::alarm_list::AlarmList;
use crate::doors::Front;
use crate::operation::{Answer, Operation};
use crate::parameters::Parameters;
use crate::program_events::ProgramEvents;
use crate::robot_door::RobotDoor;
use crate::web::WebHmi;

/// How long a door waits for the task's answer.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(10);
/// A command published before discovery has matched the task's reader is lost (the command
/// topic is volatile, so a late reader never replays old commands); it is repeated with the
/// same id at this interval, and the task answers a repeated id without acting twice.
const COMMAND_REPEAT: Duration = Duration::from_millis(250);

/// hmi_bridge's alarm after a parameter write: the change waits for a restart (FANUC P/S
/// alarm 000 "power off required", `003` Appendix A.4; decisions D44).
pub const PARAMETER_CHANGED_ALARM: u32 = 0;

/// The command path to the task.
struct Commands {
    publisher: cnc_runtime::dds::Publisher<TaskCommand>,
    results: cnc_runtime::bus::Subscription<CommandResult>,
    next_id: u64,
}

impl Commands {
    /// Sends a request to the task and waits for its answer (which may be motion's refusal).
    fn call(&mut self, request: &TaskRequest) -> CommandResult {
        self.next_id += 1;
        let id = self.next_id;
        let msg = request.to_command(id);
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        let mut last_sent: Option<Instant> = None;
        while Instant::now() < deadline {
            if last_sent.is_none_or(|t| t.elapsed() >= COMMAND_REPEAT) {
                if let Err(e) = self.publisher.publish(msg.clone()) {
                    return refused(format!("command not delivered: {e:?}"));
                }
                last_sent = Some(Instant::now());
            }
            while let Ok(Some(r)) = self.results.take() {
                if r.id == id {
                    return r;
                }
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        refused("no answer from the interpreter node".into())
    }
}

fn refused(message: String) -> CommandResult {
    CommandResult {
        accepted: false,
        message,
        ..CommandResult::default()
    }
}

/// What the doors act on: the command path, the panel switches, the bridge's parameters and
/// alarm list, who the clients are, and the command events.
struct Bridge {
    commands: Commands,
    panel: cnc_runtime::dds::Publisher<Overrides>,
    /// Lines of each program loaded through this bridge, for the action's percentage.
    program_lines: BTreeMap<String, u32>,
    parameters: Parameters,
    alarms: AlarmList,
    reporter: AlarmReporter,
    alarms_pub: cnc_runtime::dds::Publisher<ActiveAlarms>,
    /// Set when the active list changed (to be published).
    alarms_changed: bool,
    machine: Option<MachineState>,
    allowed: Vec<String>,
    clients: Clients,
    events: cnc_runtime::dds::Publisher<CommandEvent>,
    /// Something was served this turn.
    busy: bool,
}

impl Front for Bridge {
    fn perform(&mut self, op: Operation, who: &Who) -> Answer {
        let checked = if op.moves() {
            self.may_move(who)
        } else {
            Ok(())
        };
        let answer = match checked {
            Ok(()) => self.carry_out(&op),
            Err(why) => Answer::refused(why),
        };
        // Reading is not a command: only what changes something, or is refused, is an event.
        if !op.reads() || !answer.accepted {
            self.record(
                op.command(),
                &op.detail(),
                who,
                answer.accepted,
                &answer.message,
            );
        }
        self.busy = true;
        answer
    }

    fn carry_out(&mut self, op: &Operation) -> Answer {
        match op {
            Operation::Load { text, .. } if text.len() > MAX_PROGRAM_BYTES => {
                Answer::refused(format!(
                    "program too large: {} bytes, limit {MAX_PROGRAM_BYTES}",
                    text.len()
                ))
            }
            Operation::Overrides(o) => {
                match cnc_runtime::overrides::check(o)
                    .and_then(|o| self.panel.publish(o).map_err(|e| format!("not sent: {e}")))
                {
                    Ok(()) => Answer::said(true, format!("overrides set: {}", op.detail())),
                    Err(why) => Answer::refused(why),
                }
            }
            Operation::Parameters { prefix } => {
                let parameters = self.parameters.read(prefix);
                Answer {
                    accepted: true,
                    message: format!("{} parameters", parameters.len()),
                    parameters,
                    ..Answer::default()
                }
            }
            Operation::SetParameter { name, value } => self.set_parameter(name, value),
            Operation::Acknowledge { source, number } => {
                match self.alarms.acknowledge(source, *number) {
                    Ok(message) => {
                        self.alarms_changed = true;
                        Answer::said(true, message)
                    }
                    Err(why) => Answer::refused(why),
                }
            }
            _ => match op.task_request() {
                Ok(Some(request)) => {
                    let answer = Answer::of_task(self.commands.call(&request));
                    self.note_program(op, answer.accepted);
                    answer
                }
                Ok(None) => Answer::refused(format!("{} is not the task's", op.command())),
                Err(why) => Answer::refused(why),
            },
        }
    }

    fn may_move(&self, who: &Who) -> Result<(), String> {
        match who {
            Who::Dds(writer) => access::may_move(
                &self.allowed,
                self.clients.nodes_of(writer),
                &self.clients.describe(writer),
            ),
            // A web page is known by its address (`web@127.0.0.1`), and `hmi.allowed_clients`
            // names it as it names ROS 2 nodes.
            Who::Web(name) => access::may_move(&self.allowed, std::slice::from_ref(name), name),
        }
    }

    fn record(&self, command: &str, detail: &str, who: &Who, accepted: bool, message: &str) {
        let client = match who {
            Who::Dds(writer) => self.clients.describe(writer),
            Who::Web(name) => name.clone(),
        };
        log::info!("{command} {detail} from {client}: accepted {accepted}: {message}");
        if let Err(e) = self.events.publish(CommandEvent {
            stamp: stamp(),
            command: command.into(),
            detail: detail.into(),
            client,
            accepted,
            message: message.into(),
        }) {
            log::warn!("hmi_bridge: command event not published: {e}");
        }
    }

    fn program_lines(&self, name: &str) -> u32 {
        self.program_lines.get(name).copied().unwrap_or(0)
    }
}

impl Bridge {
    /// Keeps the line count of programs loaded (and forgets deleted ones) for the action.
    fn note_program(&mut self, op: &Operation, accepted: bool) {
        match op {
            Operation::Load { name, text } if accepted => {
                let lines = text.lines().count().min(u32::MAX as usize) as u32;
                self.program_lines.insert(name.clone(), lines);
            }
            Operation::Delete { name } if accepted => {
                self.program_lines.remove(name);
            }
            _ => {}
        }
    }

    fn set_parameter(&mut self, name: &str, value: &str) -> Answer {
        match self.parameters.write(name, value, self.machine.as_ref()) {
            Ok(message) => {
                // A control asks for a power-off after a parameter change.
                let text = format!(
                    "parameter changed ({} pending): restart the cell to apply",
                    self.parameters.pending()
                );
                let alarm = self.reporter.alarm(
                    PARAMETER_CHANGED_ALARM,
                    cnc_msgs::msg::Alarm::SEVERITY_WARNING,
                    &text,
                    "",
                    0,
                );
                self.alarms.on_event(AlarmEvent {
                    kind: AlarmEvent::RAISED,
                    alarm: alarm.clone(),
                });
                self.reporter.raise(alarm);
                self.alarms_changed = true;
                Answer::said(true, message)
            }
            Err(why) => Answer::refused(why),
        }
    }

    fn publish_alarms(&self, web: Option<&mut WebHmi>) {
        let _ = self.alarms_pub.publish(ActiveAlarms {
            stamp: stamp(),
            alarms: self.alarms.alarms(),
        });
        if let Some(w) = web {
            w.view.set_active_alarms(self.alarms.alarms());
        }
    }
}

/// The topics the bridge follows.
struct Feeds {
    alarm_events: cnc_runtime::bus::Subscription<AlarmEvent>,
    /// Every state change, in order (the bus keeps 64 per subscriber): the action follows the
    /// machine through them.
    states: cnc_runtime::bus::Subscription<MachineState>,
    motion: cnc_runtime::bus::Subscription<MotionStatus>,
    parts: cnc_runtime::bus::Subscription<PartCount>,
    /// Only a simulated machine has inputs a client may set (`sim.client_inputs`).
    sim_inputs: Option<ros2_client::Subscription<SimInput>>,
    sim_forward: cnc_runtime::dds::Publisher<SimInput>,
    program_events: cnc_runtime::dds::Publisher<ProgramEvent>,
    /// Which nodes each participant hosts, as they announce it on `ros_discovery_info`.
    discovery: DiscoveryReader,
    /// What only the panel shows, read only when there is a panel.
    panel: Option<PanelFeeds>,
}

/// What the bridge has seen of the machine.
#[derive(Default)]
struct Seen {
    motion_run: (u64, u64),
    part_count: u32,
    program_events: ProgramEvents,
}

pub fn run(cfg: LaunchConfig, shutdown: Shutdown) -> Result<(), String> {
    crate::web::check(&cfg.hmi)?;
    let ns = cfg.machine.namespace.clone();
    let mut ros = RosNode::new(&cfg.network, &ns, "hmi_bridge")?;
    let participant = ros.participant();
    let sq: QosPolicies = (&qos::services()).into();
    let doors = crate::doors::services(&participant, &ns, &sq)?;
    let mut robot = RobotDoor::new(&mut ros, &participant, &ns, &sq)?;
    let mut run_program = RunProgramServer::new(&participant, &ns, sq)?;
    let allowed = cfg.hmi.allowed_clients();
    let secured = cfg.network.effective_security()?.is_some();
    if !allowed.iter().any(|p| p == "*") && !secured {
        log::warn!(
            "hmi_bridge: hmi.allowed_clients {allowed:?} are node names that clients announce \
             on ros_discovery_info: claims, not proof (no DDS Security: network.security); \
             keep DDS on a network only the cell reaches"
        );
    }
    let mut bridge = Bridge {
        commands: Commands {
            publisher: ros.publisher(&topics::TASK_COMMAND)?,
            results: ros.subscription(&topics::COMMAND_RESULT)?,
            next_id: cnc_runtime::clock::monotonic_ns(),
        },
        panel: ros.publisher(&topics::PANEL_OVERRIDES)?,
        program_lines: BTreeMap::new(),
        parameters: Parameters::new(&cfg),
        alarms: AlarmList::default(),
        alarms_pub: ros.publisher(&topics::ALARMS)?,
        reporter: AlarmReporter::new(&mut ros, "hmi_bridge")?,
        alarms_changed: false,
        machine: None,
        allowed,
        clients: Clients::default(),
        events: ros.publisher(&topics::COMMAND_EVENTS)?,
        busy: false,
    };
    let mut web = start_web(&cfg);
    let feeds = Feeds {
        alarm_events: ros.subscription(&topics::ALARM_EVENTS)?,
        states: ros.subscription(&topics::MACHINE_STATE)?,
        motion: ros.subscription(&topics::MOTION_STATUS)?,
        parts: ros.subscription(&topics::PART_COUNT)?,
        sim_inputs: match cfg.sim.client_inputs {
            true => Some(ros.dds_subscription(&topics::SIM_INPUT)?),
            false => None,
        },
        sim_forward: ros.publisher(&topics::SIM_INPUT_CHECKED)?,
        program_events: ros.publisher(&topics::PROGRAM_EVENTS)?,
        discovery: discovery_reader(&participant)?,
        panel: match web {
            Some(_) => Some(PanelFeeds::new(&mut ros)?),
            None => None,
        },
    };
    let mut seen = Seen::default();
    let t0 = Instant::now();
    bridge.publish_alarms(None);
    while !shutdown.requested() {
        ros.refresh();
        // Every door's requests into its queue first: a burst on one is taken off DDS before
        // the others are served (a full queue refuses as busy).
        doors.iter().for_each(|d| d.drain());
        robot.drain();
        run_program.drain();
        bridge.busy = false;
        bridge.alarms_changed = false;
        learn_clients(&feeds.discovery, &mut bridge.clients);
        forward_sim_inputs(&feeds, &mut bridge);
        follow_alarms(&feeds, &mut bridge, web.as_mut());
        follow_machine(
            &feeds,
            &mut seen,
            &mut bridge,
            &mut run_program,
            web.as_mut(),
            t0,
        );
        for door in &doors {
            door.serve(&mut bridge);
        }
        if let Some(web) = web.as_mut() {
            for (who, op, pending) in web.take_operations() {
                let answer = bridge.perform(op, &who);
                web.answer(pending, answer);
            }
            for (client, operator, accepted, message) in web.take_logins() {
                bridge.record(
                    "web_login",
                    &operator,
                    &Who::Web(client),
                    accepted,
                    &message,
                );
            }
        }
        let machine = bridge.machine.clone();
        let robot_busy = robot.serve(&mut bridge, machine.as_ref());
        if bridge.alarms_changed {
            bridge.publish_alarms(web.as_mut());
        }
        if let (Some(w), Some(panel)) = (web.as_mut(), feeds.panel.as_ref()) {
            panel.feed(w);
            w.tick();
        }
        if !bridge.busy && !robot_busy {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    Ok(())
}

/// The web HMI, if configured. A port already taken is reported and the bridge serves the
/// cell without it.
fn start_web(cfg: &LaunchConfig) -> Option<WebHmi> {
    if cfg.hmi.web_address.is_empty() {
        return None;
    }
    let axes = cfg.machine.axes.iter().map(|a| a.name.clone()).collect();
    match WebHmi::start(&cfg.hmi, &cfg.machine.namespace, axes, cfg.diameter_axes()) {
        Ok(w) => Some(w),
        Err(e) => {
            log::error!("hmi_bridge: {e}; the web HMI is not served");
            None
        }
    }
}

/// Which nodes each participant hosts: a reader of our own, transient-local, so every
/// participant's last announcement is there whenever the bridge looks (ros2-client's node
/// events drop what a full queue cannot take).
fn learn_clients(discovery: &DiscoveryReader, clients: &mut Clients) {
    discovery.drain_read_notifications();
    while let Ok(Some(sample)) = discovery.try_take_one() {
        let info = sample.into_value();
        let mut prefix = [0u8; 12];
        prefix.copy_from_slice(&info.gid().as_bytes()[..12]);
        let nodes = info
            .nodes()
            .iter()
            .map(|n| n.fully_qualified_name())
            .collect();
        clients.learn(prefix, nodes);
    }
}

/// The simulated machine's inputs (emergency stop, forced door, keys) from the network: an
/// allowed client's go on to io, anyone else's are refused; both are command events.
fn forward_sim_inputs(feeds: &Feeds, bridge: &mut Bridge) {
    let Some(inputs) = feeds.sim_inputs.as_ref() else {
        return;
    };
    while let Ok(Some((input, info))) = inputs.take() {
        bridge.busy = true;
        let who = Who::Dds(info.publisher_gid().to_bytes16());
        let detail = format!("input {} = {}", input.input, input.value);
        let (accepted, message) = match bridge.may_move(&who) {
            Ok(()) => match feeds.sim_forward.publish(input) {
                Ok(()) => (true, "passed to the simulated machine".to_string()),
                Err(e) => (false, format!("not delivered: {e}")),
            },
            Err(why) => (false, why),
        };
        bridge.record("sim_input", &detail, &who, accepted, &message);
    }
}

fn follow_alarms(feeds: &Feeds, bridge: &mut Bridge, mut web: Option<&mut WebHmi>) {
    let mut changed = false;
    while let Ok(Some(e)) = feeds.alarm_events.take() {
        if let Some(w) = web.as_deref_mut() {
            w.view.on_alarm_event(&e);
        }
        changed |= bridge.alarms.on_event(e);
    }
    if changed {
        bridge.publish_alarms(web);
    }
}

/// Follows motion, the part counter and each machine state in turn: program events, and the
/// `RunProgram` action through every transition (a short cycle's end too).
fn follow_machine(
    feeds: &Feeds,
    seen: &mut Seen,
    bridge: &mut Bridge,
    run_program: &mut RunProgramServer,
    mut web: Option<&mut WebHmi>,
    t0: Instant,
) {
    while let Ok(Some(m)) = feeds.motion.take() {
        seen.motion_run = (m.run_id, m.done_seq);
        if let Some(w) = web.as_deref_mut() {
            w.view.on_motion_status(m);
        }
    }
    while let Ok(Some(p)) = feeds.parts.take() {
        seen.part_count = p.count;
        if let Some(w) = web.as_deref_mut() {
            w.view.on_parts(p);
        }
    }
    let alarm_list = bridge.alarms.alarms();
    let mut states = Vec::new();
    while let Ok(Some(m)) = feeds.states.take() {
        if let Some(w) = web.as_deref_mut() {
            w.view.on_machine_state(m.clone());
        }
        states.push(m);
    }
    if states.is_empty() {
        states.extend(bridge.machine.clone());
    }
    let now = t0.elapsed().as_secs_f64();
    let (run, parts) = (seen.motion_run, seen.part_count);
    for m in states {
        for e in seen.program_events.update(&m, &alarm_list, now) {
            let e = ProgramEvent {
                stamp: stamp(),
                ..e
            };
            if let Err(err) = feeds.program_events.publish(e) {
                log::warn!("hmi_bridge: program event not published: {err}");
            }
        }
        let events = run_program.poll(bridge, Some(&m), run, parts, &alarm_list, now);
        record_all(bridge, events);
        bridge.machine = Some(m);
    }
    if bridge.machine.is_none() {
        let events = run_program.poll(bridge, None, run, parts, &alarm_list, now);
        record_all(bridge, events);
    }
}

fn record_all(bridge: &mut Bridge, events: Vec<crate::action_server::Event>) {
    for e in events {
        bridge.busy = true;
        bridge.record(
            e.command,
            &e.detail,
            &Who::Dds(e.writer),
            e.accepted,
            &e.message,
        );
    }
}

type DiscoveryReader = rustdds::no_key::SimpleDataReader<
    ParticipantEntitiesInfo,
    rustdds::CDRDeserializerAdapter<ParticipantEntitiesInfo>,
>;

/// A reader of `ros_discovery_info`, where ROS 2 participants say which nodes they host.
fn discovery_reader(participant: &rustdds::DomainParticipant) -> Result<DiscoveryReader, String> {
    use rustdds::policy::{Durability, History, Reliability};
    let qos = rustdds::QosPolicyBuilder::new()
        .durability(Durability::TransientLocal)
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::ZERO,
        })
        .history(History::KeepLast { depth: 256 })
        .build();
    let topic = participant
        .create_topic(
            "ros_discovery_info".into(),
            "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_".into(),
            &qos,
            rustdds::TopicKind::NoKey,
        )
        .map_err(|e| format!("ros_discovery_info: {e:?}"))?;
    participant
        .create_subscriber(&qos)
        .map_err(|e| format!("ros_discovery_info: {e:?}"))?
        .create_simple_datareader_no_key(&topic, Some(qos))
        .map_err(|e| format!("ros_discovery_info: {e:?}"))
}

/// The topics only the web panel shows.
struct PanelFeeds {
    axes: cnc_runtime::bus::Subscription<AxisState>,
    spindle: cnc_runtime::bus::Subscription<SpindleState>,
    blocks: cnc_runtime::bus::Subscription<MotionBlock>,
    signals: cnc_runtime::bus::Subscription<PlcSignals>,
    ladder: cnc_runtime::bus::Subscription<PlcProgram>,
    commands: cnc_runtime::bus::Subscription<CommandEvent>,
    overrides: cnc_runtime::bus::Subscription<Overrides>,
}

impl PanelFeeds {
    fn new(ros: &mut RosNode) -> Result<PanelFeeds, String> {
        Ok(PanelFeeds {
            axes: ros.subscription(&topics::AXES)?,
            spindle: ros.subscription(&topics::SPINDLE)?,
            blocks: ros.subscription(&topics::MOTION_BLOCKS)?,
            signals: ros.subscription(&topics::PLC_SIGNALS)?,
            ladder: ros.subscription(&topics::PLC_PROGRAM)?,
            commands: ros.subscription(&topics::COMMAND_EVENTS)?,
            overrides: ros.subscription(&topics::PANEL_OVERRIDES)?,
        })
    }

    /// Hands everything that arrived to the panel.
    fn feed(&self, w: &mut WebHmi) {
        while let Ok(Some(a)) = self.axes.take() {
            w.view.on_axes(a);
        }
        while let Ok(Some(s)) = self.spindle.take() {
            w.view.on_spindle(s);
        }
        while let Ok(Some(b)) = self.blocks.take() {
            w.view.on_block(b);
        }
        while let Ok(Some(s)) = self.signals.take() {
            w.view.on_plc_signals(s);
        }
        while let Ok(Some(p)) = self.ladder.take() {
            w.set_ladder(&p);
        }
        while let Ok(Some(e)) = self.commands.take() {
            w.view.on_command_event(&e);
        }
        while let Ok(Some(o)) = self.overrides.take() {
            w.view.on_overrides(o);
        }
    }
}
