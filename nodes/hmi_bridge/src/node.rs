//! hmi_bridge node shell: serves the cell's services and the `RunProgram` action, the robot
//! requests and the operator's web HMI, turns each request into an [`Operation`] carried out
//! through one command path (with one access check and one command event), and keeps
//! `/<ns>/alarms` (ActiveAlarms).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use cnc_msgs::msg::{
    ActiveAlarms, AlarmEvent, AxisState, CommandEvent, CommandResult, MachineState, MotionBlock,
    MotionStatus, Overrides, PartCount, PlcProgram, PlcSignals, ProgramCommand, ProgramEvent,
    RobotHandshake, SimInput, SpindleState,
};
use cnc_msgs::srv::*;
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};
use cnc_runtime::{MAX_PROGRAM_BYTES, MDI_PROGRAM};
use ros2_client::dds::rustdds;
use ros2_client::dds::rustdds::QosPolicies;
use ros2_client::entities_info::ParticipantEntitiesInfo;

use crate::access::{self, may_move, Clients, Who};
use crate::action_server::{CommandPath, RunProgramServer};
use crate::alarm_list::AlarmList;
use crate::operation::Operation;
use crate::parameters::Parameters;
use crate::program_events::ProgramEvents;
use crate::robot;
use crate::server::{Drain, DualServer, Request};
use crate::web::WebHmi;

/// How long a service waits for the interpreter's answer.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(10);
/// A command published before discovery has matched the interpreter's reader is lost (the
/// command topic is volatile, so a late reader never replays old commands); it is repeated with
/// the same id at this interval, and the interpreter answers a repeated id without acting twice.
const COMMAND_REPEAT: Duration = Duration::from_millis(250);

struct Commands {
    publisher: cnc_runtime::dds::Publisher<ProgramCommand>,
    results: cnc_runtime::bus::Subscription<CommandResult>,
    next_id: u64,
}

impl CommandPath for Commands {
    /// Sends a command and waits for its result.
    fn call(&mut self, command: u8, program: &str, text: &str) -> (bool, String) {
        self.next_id += 1;
        let id = self.next_id;
        let msg = ProgramCommand {
            id,
            command,
            program: program.into(),
            text: text.into(),
        };
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        let mut last_sent: Option<Instant> = None;
        while Instant::now() < deadline {
            if last_sent.is_none_or(|t| t.elapsed() >= COMMAND_REPEAT) {
                if let Err(e) = self.publisher.publish(msg.clone()) {
                    return (false, format!("command not delivered: {e:?}"));
                }
                last_sent = Some(Instant::now());
            }
            while let Ok(Some(r)) = self.results.take() {
                if r.id == id {
                    return (r.accepted, r.message);
                }
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        (false, "no answer from the interpreter node".into())
    }
}

pub fn run(cfg: LaunchConfig, shutdown: Shutdown) -> Result<(), String> {
    crate::web::check(&cfg.hmi)?;
    let ns = cfg.machine.namespace.clone();
    let mut ros = RosNode::new(&cfg.network, &ns, "hmi_bridge")?;
    let mut commands = Commands {
        publisher: ros.publisher(&topics::PROGRAM_COMMAND)?,
        results: ros.subscription(&topics::COMMAND_RESULT)?,
        next_id: cnc_runtime::clock::monotonic_ns(),
    };
    let alarm_events = ros.subscription::<AlarmEvent>(&topics::ALARM_EVENTS)?;
    let alarms_pub = ros.publisher::<ActiveAlarms>(&topics::ALARMS)?;
    let alarm_reporter = AlarmReporter::new(&mut ros, "hmi_bridge")?;
    let mut parameters = Parameters::new(&cfg);
    let participant = ros.participant();
    let sq: QosPolicies = (&qos::services()).into();
    let load = DualServer::<LoadProgram>::new(&participant, &ns, "load_program", sq.clone())?
        .refusing(LoadProgramResponse::refused);
    let start = DualServer::<StartProgram>::new(&participant, &ns, "start_program", sq.clone())?
        .refusing(StartProgramResponse::refused);
    let stop = DualServer::<Stop>::new(&participant, &ns, "stop", sq.clone())?
        .refusing(StopResponse::refused);
    let reset = DualServer::<Reset>::new(&participant, &ns, "reset", sq.clone())?
        .refusing(ResetResponse::refused);
    let list = DualServer::<ListPrograms>::new(&participant, &ns, "list_programs", sq.clone())?
        .refusing(ListProgramsResponse::refused);
    let delete = DualServer::<DeleteProgram>::new(&participant, &ns, "delete_program", sq.clone())?
        .refusing(DeleteProgramResponse::refused);
    let overrides_srv =
        DualServer::<SetOverrides>::new(&participant, &ns, "set_overrides", sq.clone())?
            .refusing(SetOverridesResponse::refused);
    let panel = ros.publisher::<Overrides>(&topics::PANEL_OVERRIDES)?;
    let mode_srv = DualServer::<SetMode>::new(&participant, &ns, "set_mode", sq.clone())?
        .refusing(SetModeResponse::refused);
    let mdi_srv = DualServer::<Mdi>::new(&participant, &ns, "mdi", sq.clone())?
        .refusing(MdiResponse::refused);
    let jog_srv = DualServer::<Jog>::new(&participant, &ns, "jog", sq.clone())?
        .refusing(JogResponse::refused);
    let offsets_srv = DualServer::<GetOffsets>::new(&participant, &ns, "get_offsets", sq.clone())?
        .refusing(GetOffsetsResponse::refused);
    let tool_offset_srv =
        DualServer::<SetToolOffset>::new(&participant, &ns, "set_tool_offset", sq.clone())?
            .refusing(SetToolOffsetResponse::refused);
    let work_offset_srv =
        DualServer::<SetWorkOffset>::new(&participant, &ns, "set_work_offset", sq.clone())?
            .refusing(SetWorkOffsetResponse::refused);
    let get_parameters_srv =
        DualServer::<GetParameters>::new(&participant, &ns, "get_parameters", sq.clone())?
            .refusing(GetParametersResponse::refused);
    let set_parameter_srv =
        DualServer::<SetParameter>::new(&participant, &ns, "set_parameter", sq.clone())?
            .refusing(SetParameterResponse::refused);
    let acknowledge_srv =
        DualServer::<AcknowledgeAlarm>::new(&participant, &ns, "acknowledge_alarm", sq.clone())?
            .refusing(AcknowledgeAlarmResponse::refused);
    let robot_srv =
        DualServer::<RobotRequest>::new(&participant, &ns, "robot_request", sq.clone())?
            .refusing(RobotRequestResponse::refused);
    let mut run_program = RunProgramServer::new(&participant, &ns, sq)?;
    let robot_signals = ros.publisher::<SimInput>(&topics::ROBOT_SIGNALS)?;
    // Only a simulated machine has inputs a client may set (`sim.client_inputs`).
    let sim_inputs = match cfg.sim.client_inputs {
        true => Some(ros.dds_subscription::<SimInput>(&topics::SIM_INPUT)?),
        false => None,
    };
    let sim_forward = ros.publisher::<SimInput>(&topics::SIM_INPUT_CHECKED)?;
    let handshake_sub = ros.subscription::<RobotHandshake>(&topics::ROBOT_HANDSHAKE)?;
    let mut handshake: Option<RobotHandshake> = None;
    let mut pending: Option<PendingRobot> = None;
    let events = ros.publisher::<CommandEvent>(&topics::COMMAND_EVENTS)?;
    let program_events_pub = ros.publisher::<ProgramEvent>(&topics::PROGRAM_EVENTS)?;
    let mut program_events = ProgramEvents::default();
    // Which nodes each participant hosts, as they announce it on `ros_discovery_info`: a
    // reader of our own, transient-local, so every participant's last announcement is there
    // whenever the bridge looks (ros2-client's node events drop what a full queue cannot take).
    let discovery = discovery_reader(&participant)?;
    let mut clients = Clients::default();
    let allowed = cfg.hmi.allowed_clients();
    let secured = cfg.network.effective_security()?.is_some();
    if !allowed.iter().any(|p| p == "*") && !secured {
        log::warn!(
            "hmi_bridge: hmi.allowed_clients {allowed:?} are node names that clients announce \
             on ros_discovery_info: claims, not proof (no DDS Security: network.security); \
             keep DDS on a network only the cell reaches"
        );
    }
    // Every state change, in order (the bus keeps 64 per subscriber): the action follows the
    // machine through them.
    let state_sub = ros.subscription::<MachineState>(&topics::MACHINE_STATE)?;
    let motion_sub = ros.subscription::<MotionStatus>(&topics::MOTION_STATUS)?;
    let parts_sub = ros.subscription::<PartCount>(&topics::PART_COUNT)?;
    let mut machine: Option<MachineState> = None;
    let mut motion_run = (0u64, 0u64);
    let mut part_count = 0u32;
    let t0 = std::time::Instant::now();
    // The web HMI and what only it shows. A port already taken is reported and the bridge
    // serves the cell without it.
    let mut web = if cfg.hmi.web_address.is_empty() {
        None
    } else {
        let axes = cfg.machine.axes.iter().map(|a| a.name.clone()).collect();
        match WebHmi::start(&cfg.hmi, &cfg.machine.namespace, axes, cfg.diameter_axes()) {
            Ok(w) => Some(w),
            Err(e) => {
                log::error!("hmi_bridge: {e}; the web HMI is not served");
                None
            }
        }
    };
    // What only the panel shows is read only when there is a panel.
    let panel_feeds = match web {
        Some(_) => Some(PanelFeeds::new(&mut ros)?),
        None => None,
    };

    let mut active = AlarmList::default();
    let publish_alarms = |active: &AlarmList| {
        let _ = alarms_pub.publish(ActiveAlarms {
            stamp: stamp(),
            alarms: active.alarms(),
        });
    };
    publish_alarms(&active);
    while !shutdown.requested() {
        ros.refresh();
        // Every service's requests into its queue first: a burst on one is taken off DDS
        // before the others are served (a full queue refuses as busy).
        let servers: [&dyn Drain; 16] = [
            &load,
            &start,
            &stop,
            &reset,
            &list,
            &delete,
            &overrides_srv,
            &mode_srv,
            &mdi_srv,
            &jog_srv,
            &offsets_srv,
            &tool_offset_srv,
            &work_offset_srv,
            &get_parameters_srv,
            &set_parameter_srv,
            &acknowledge_srv,
        ];
        servers.iter().for_each(|s| s.drain());
        robot_srv.drain();
        run_program.drain();
        let mut busy = false;
        let mut changed = false;
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
        let may_move = |writer: &[u8; 16]| {
            may_move(
                &allowed,
                clients.nodes_of(writer),
                &clients.describe(writer),
            )
        };
        // A web page is known by its address (`web@127.0.0.1`), and `hmi.allowed_clients`
        // names it as it names ROS 2 nodes.
        let may_move_who = |who: &Who| match who {
            Who::Dds(writer) => may_move(writer),
            Who::Web(name) => access::may_move(&allowed, std::slice::from_ref(name), name),
        };
        let record = |command: &str, detail: &str, who: &Who, accepted: bool, message: &str| {
            let client = match who {
                Who::Dds(writer) => clients.describe(writer),
                Who::Web(name) => name.clone(),
            };
            log::info!("{command} {detail} from {client}: accepted {accepted}: {message}");
            if let Err(e) = events.publish(CommandEvent {
                stamp: stamp(),
                command: command.into(),
                detail: detail.into(),
                client,
                accepted,
                message: message.into(),
            }) {
                log::warn!("hmi_bridge: command event not published: {e}");
            }
        };
        // The simulated machine's inputs (emergency stop, forced door, keys) from the network:
        // an allowed client's go on to io, anyone else's are refused; both are command events.
        while let Some(Ok(Some((input, info)))) = sim_inputs.as_ref().map(|s| s.take()) {
            busy = true;
            let who = Who::Dds(info.publisher_gid().to_bytes16());
            let detail = format!("input {} = {}", input.input, input.value);
            let (accepted, message) = match may_move_who(&who) {
                Ok(()) => match sim_forward.publish(input) {
                    Ok(()) => (true, "passed to the simulated machine".to_string()),
                    Err(e) => (false, format!("not delivered: {e}")),
                },
                Err(why) => (false, why),
            };
            record("sim_input", &detail, &who, accepted, &message);
        }
        while let Ok(Some(e)) = alarm_events.take() {
            if let Some(w) = web.as_mut() {
                w.view.on_alarm_event(&e);
            }
            changed |= active.on_event(e);
        }
        if changed {
            publish_alarms(&active);
            if let Some(w) = web.as_mut() {
                w.view.set_active_alarms(active.alarms());
            }
        }
        while let Ok(Some(m)) = motion_sub.take() {
            motion_run = (m.run_id, m.done_seq);
            if let Some(w) = web.as_mut() {
                w.view.on_motion_status(m);
            }
        }
        while let Ok(Some(p)) = parts_sub.take() {
            if let Some(w) = web.as_mut() {
                w.view.on_parts(p.clone());
            }
            part_count = p.count;
        }
        let alarm_list: Vec<cnc_msgs::msg::Alarm> = active.alarms();
        // Each state in turn, so the action sees every transition (a short cycle's end too).
        let mut states = Vec::new();
        while let Ok(Some(m)) = state_sub.take() {
            if let Some(w) = web.as_mut() {
                w.view.on_machine_state(m.clone());
            }
            states.push(m);
        }
        if states.is_empty() {
            states.extend(machine.clone());
        }
        for m in states {
            for e in program_events.update(&m, &alarm_list, t0.elapsed().as_secs_f64()) {
                let e = ProgramEvent {
                    stamp: stamp(),
                    ..e
                };
                if let Err(err) = program_events_pub.publish(e) {
                    log::warn!("hmi_bridge: program event not published: {err}");
                }
            }
            for e in run_program.poll(
                &mut commands,
                &may_move,
                Some(&m),
                motion_run,
                part_count,
                &alarm_list,
                t0.elapsed().as_secs_f64(),
            ) {
                busy = true;
                record(
                    e.command,
                    &e.detail,
                    &Who::Dds(e.writer),
                    e.accepted,
                    &e.message,
                );
            }
            machine = Some(m);
        }
        if machine.is_none() {
            run_program.poll(
                &mut commands,
                &may_move,
                None,
                motion_run,
                part_count,
                &alarm_list,
                t0.elapsed().as_secs_f64(),
            );
        }
        // The services: each request becomes an operation, carried out as the web HMI's are.
        let mut alarms_changed = false;
        let mut perform = |op: Operation, who: &Who| -> (bool, String) {
            let checked = if op.moves() {
                may_move_who(who)
            } else {
                Ok(())
            };
            let (accepted, message) = match checked {
                Ok(()) => {
                    let mut desk = Desk {
                        commands: &mut commands,
                        panel: &panel,
                        program_lines: &mut run_program.program_lines,
                        parameters: &mut parameters,
                        alarms: &mut active,
                        reporter: &alarm_reporter,
                        machine: machine.as_ref(),
                        alarms_changed: false,
                    };
                    let outcome = execute(&op, &mut desk);
                    alarms_changed |= desk.alarms_changed;
                    outcome
                }
                Err(why) => (false, why),
            };
            // Reading is not a command: only what changes something, or is refused, is an event.
            if !op.reads() || !accepted {
                record(op.command(), &op.detail(), who, accepted, &message);
            }
            busy = true;
            (accepted, message)
        };
        if let Some(r) = load.receive() {
            let (name, text) = (r.request.name.clone(), r.request.text.clone());
            let (accepted, message) = perform(Operation::Load { name, text }, &Who::Dds(r.writer));
            answer(&load, &r, &LoadProgramResponse { accepted, message });
        }
        if let Some(r) = start.receive() {
            let name = r.request.name.clone();
            let (accepted, message) = perform(
                Operation::Start {
                    name,
                    at: String::new(),
                },
                &Who::Dds(r.writer),
            );
            answer(&start, &r, &StartProgramResponse { accepted, message });
        }
        if let Some(r) = stop.receive() {
            let mode = r.request.mode;
            let (accepted, message) = perform(Operation::Stop { mode }, &Who::Dds(r.writer));
            answer(&stop, &r, &StopResponse { accepted, message });
        }
        if let Some(r) = overrides_srv.receive() {
            let q = &r.request;
            let o = Overrides {
                feed_percent: q.feed_percent,
                spindle_percent: q.spindle_percent,
                rapid_percent: q.rapid_percent,
            };
            let (accepted, message) = perform(Operation::Overrides(o), &Who::Dds(r.writer));
            answer(
                &overrides_srv,
                &r,
                &SetOverridesResponse { accepted, message },
            );
        }
        if let Some(r) = list.receive() {
            let (accepted, text) = perform(Operation::List, &Who::Dds(r.writer));
            let mut response = ListProgramsResponse {
                accepted,
                ..Default::default()
            };
            if accepted {
                for (name, size) in crate::operation::program_list(&text) {
                    response.names.push(name);
                    response.sizes.push(size);
                }
            } else {
                response.message = text;
            }
            answer(&list, &r, &response);
        }
        if let Some(r) = delete.receive() {
            let name = r.request.name.clone();
            let (accepted, message) = perform(Operation::Delete { name }, &Who::Dds(r.writer));
            answer(&delete, &r, &DeleteProgramResponse { accepted, message });
        }
        if let Some(r) = reset.receive() {
            let (accepted, message) = perform(Operation::Reset, &Who::Dds(r.writer));
            answer(&reset, &r, &ResetResponse { accepted, message });
        }
        if let Some(r) = mode_srv.receive() {
            let mode = r.request.mode;
            let (accepted, message) = perform(Operation::Mode { mode }, &Who::Dds(r.writer));
            answer(&mode_srv, &r, &SetModeResponse { accepted, message });
        }
        if let Some(r) = jog_srv.receive() {
            let q = &r.request;
            let op = Operation::Jog {
                axis: q.axis.clone(),
                direction: q.direction,
                feed: q.feed,
                increment: q.increment,
            };
            let (accepted, message) = perform(op, &Who::Dds(r.writer));
            answer(&jog_srv, &r, &JogResponse { accepted, message });
        }
        if let Some(r) = mdi_srv.receive() {
            let text = r.request.text.clone();
            let (accepted, message) = perform(Operation::Mdi { text }, &Who::Dds(r.writer));
            answer(&mdi_srv, &r, &MdiResponse { accepted, message });
        }
        if let Some(r) = offsets_srv.receive() {
            let (accepted, text) = perform(Operation::Offsets, &Who::Dds(r.writer));
            let response = if accepted {
                let (tools, work) = crate::offsets::parse_page(&text);
                GetOffsetsResponse {
                    accepted,
                    message: format!("{} tool offsets, {} work offsets", tools.len(), work.len()),
                    tools,
                    work,
                }
            } else {
                GetOffsetsResponse::refused(text)
            };
            answer(&offsets_srv, &r, &response);
        }
        if let Some(r) = tool_offset_srv.receive() {
            let (number, values) = crate::offsets::tool_command(&r.request.offset);
            let op = Operation::SetToolOffset { number, values };
            let (accepted, message) = perform(op, &Who::Dds(r.writer));
            answer(
                &tool_offset_srv,
                &r,
                &SetToolOffsetResponse { accepted, message },
            );
        }
        if let Some(r) = work_offset_srv.receive() {
            let (accepted, message) = match crate::offsets::work_command(&r.request.offset) {
                Ok((code, values)) => perform(
                    Operation::SetWorkOffset { code, values },
                    &Who::Dds(r.writer),
                ),
                Err(why) => {
                    record(
                        "set_work_offset",
                        "malformed",
                        &Who::Dds(r.writer),
                        false,
                        &why,
                    );
                    (false, why)
                }
            };
            answer(
                &work_offset_srv,
                &r,
                &SetWorkOffsetResponse { accepted, message },
            );
        }
        if let Some(r) = get_parameters_srv.receive() {
            let prefix = r.request.prefix.clone();
            let (accepted, text) = perform(Operation::Parameters { prefix }, &Who::Dds(r.writer));
            let mut response = GetParametersResponse {
                accepted,
                ..Default::default()
            };
            if accepted {
                for (name, value, pending) in crate::operation::parameter_rows(&text) {
                    response.names.push(name);
                    response.values.push(value);
                    response.pending.push(pending);
                }
            } else {
                response.message = text;
            }
            answer(&get_parameters_srv, &r, &response);
        }
        if let Some(r) = set_parameter_srv.receive() {
            let (name, value) = (r.request.name.clone(), r.request.value.clone());
            let op = Operation::SetParameter { name, value };
            let (accepted, message) = perform(op, &Who::Dds(r.writer));
            answer(
                &set_parameter_srv,
                &r,
                &SetParameterResponse { accepted, message },
            );
        }
        if let Some(r) = acknowledge_srv.receive() {
            let (source, number) = (r.request.source.clone(), r.request.number);
            let op = Operation::Acknowledge { source, number };
            let (accepted, message) = perform(op, &Who::Dds(r.writer));
            answer(
                &acknowledge_srv,
                &r,
                &AcknowledgeAlarmResponse { accepted, message },
            );
        }
        if let Some(web) = web.as_mut() {
            for (who, op, pending) in web.take_operations() {
                let (accepted, message) = perform(op, &who);
                web.answer(pending, accepted, message);
            }
            for (client, operator, accepted, message) in web.take_logins() {
                record(
                    "web_login",
                    &operator,
                    &Who::Web(client),
                    accepted,
                    &message,
                );
            }
        }
        while let Ok(Some(h)) = handshake_sub.take() {
            handshake = Some(h);
        }
        let robot_request = robot_srv.receive();
        let robot_busy = robot_request.is_some();
        if let Some(r) = robot_request {
            let decided = decide_robot(&r, handshake.as_ref(), &may_move, pending.as_mut());
            match decided {
                RobotDecision::Joined => {}
                RobotDecision::Refused(why) => {
                    record("robot_request", "", &Who::Dds(r.writer), false, &why);
                    answer(&robot_srv, &r, &RobotRequestResponse::refused(why));
                }
                RobotDecision::Go(op) => match op.signal() {
                    None => {
                        // Cycle start runs the selected program, as the panel's key does: the
                        // one the machine ran last, never an MDI entry.
                        let selected = machine
                            .as_ref()
                            .map(|m| m.program.clone())
                            .filter(|p| !p.is_empty() && p != MDI_PROGRAM);
                        let (accepted, message) = match selected {
                            Some(name) => perform(
                                Operation::Start {
                                    name,
                                    at: String::new(),
                                },
                                &Who::Dds(r.writer),
                            ),
                            None => {
                                let why = "cycle start refused: no program started yet (start_program or RunProgram first)";
                                record("robot_request", op.name(), &Who::Dds(r.writer), false, why);
                                (false, why.to_string())
                            }
                        };
                        answer(&robot_srv, &r, &RobotRequestResponse { accepted, message });
                    }
                    Some((input, _)) => {
                        let value = !matches!(op, robot::Op::Clear(false));
                        if let Err(e) = robot_signals.publish(SimInput { input, value }) {
                            log::error!("robot signal not sent: {e}");
                        }
                        pending = Some(PendingRobot {
                            op,
                            requests: vec![r],
                            since: std::time::Instant::now(),
                        });
                    }
                },
            }
        }
        if alarms_changed {
            publish_alarms(&active);
            if let Some(w) = web.as_mut() {
                w.view.set_active_alarms(active.alarms());
            }
        }
        if let Some(p) = pending.take() {
            let done = handshake.as_ref().is_some_and(|h| p.op.done(h));
            let late = p.since.elapsed().as_secs_f64() > robot::ACTUATION_TIMEOUT;
            if done || late {
                if let Some((input, hold)) = p.op.signal() {
                    if !hold {
                        let _ = robot_signals.publish(SimInput {
                            input,
                            value: false,
                        });
                    }
                }
                let (accepted, message) = if done {
                    (true, format!("{} done", p.op.name()))
                } else {
                    (
                        false,
                        format!(
                            "{} not done within {} s (see the PLC's alarms)",
                            p.op.name(),
                            robot::ACTUATION_TIMEOUT
                        ),
                    )
                };
                for r in &p.requests {
                    record(
                        "robot_request",
                        p.op.name(),
                        &Who::Dds(r.writer),
                        accepted,
                        &message,
                    );
                    answer(
                        &robot_srv,
                        r,
                        &RobotRequestResponse {
                            accepted,
                            message: message.clone(),
                        },
                    );
                }
            } else {
                pending = Some(p);
            }
        }
        let malformed = [
            ("load_program", load.take_malformed()),
            ("start_program", start.take_malformed()),
            ("stop", stop.take_malformed()),
            ("reset", reset.take_malformed()),
            ("delete_program", delete.take_malformed()),
            ("set_overrides", overrides_srv.take_malformed()),
            ("robot_request", robot_srv.take_malformed()),
            ("set_mode", mode_srv.take_malformed()),
            ("get_offsets", offsets_srv.take_malformed()),
            ("get_parameters", get_parameters_srv.take_malformed()),
            ("mdi", mdi_srv.take_malformed()),
            ("jog", jog_srv.take_malformed()),
            ("set_tool_offset", tool_offset_srv.take_malformed()),
            ("set_work_offset", work_offset_srv.take_malformed()),
            ("set_parameter", set_parameter_srv.take_malformed()),
            ("acknowledge_alarm", acknowledge_srv.take_malformed()),
        ];
        for (command, list) in malformed {
            for (writer, why) in list {
                record(command, "malformed", &Who::Dds(writer), false, &why);
            }
        }
        if let (Some(w), Some(feeds)) = (web.as_mut(), panel_feeds.as_ref()) {
            feeds.feed(w);
            w.tick();
        }
        if !busy && !robot_busy {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    Ok(())
}

/// hmi_bridge's alarm after a parameter write: the change waits for a restart (FANUC P/S
/// alarm 000 "power off required", `003` Appendix A.4; decisions D44).
pub const PARAMETER_CHANGED_ALARM: u32 = 0;

/// A robot request waiting for the machine to carry it out; copies of it (a client repeats a
/// request it has no answer to yet) are answered together.
struct PendingRobot {
    op: robot::Op,
    requests: Vec<Request<RobotRequestRequest>>,
    since: std::time::Instant,
}

enum RobotDecision {
    Refused(String),
    /// A copy of the pending request: answered with it.
    Joined,
    Go(robot::Op),
}

fn decide_robot(
    r: &Request<RobotRequestRequest>,
    handshake: Option<&RobotHandshake>,
    may_move: &dyn Fn(&[u8; 16]) -> Result<(), String>,
    pending: Option<&mut PendingRobot>,
) -> RobotDecision {
    let op = match robot::Op::from_request(r.request.request) {
        Ok(op) => op,
        Err(why) => return RobotDecision::Refused(why),
    };
    if let Some(p) = pending {
        if p.op == op && p.requests.iter().any(|q| q.writer == r.writer) {
            p.requests.push(r.clone());
            return RobotDecision::Joined;
        }
        return RobotDecision::Refused(format!("{} refused: busy with {}", op.name(), p.op.name()));
    }
    if op.moves() {
        if let Err(why) = may_move(&r.writer) {
            return RobotDecision::Refused(why);
        }
    }
    let Some(h) = handshake else {
        return RobotDecision::Refused("no handshake state from the PLC yet".into());
    };
    match robot::refusal(op, h) {
        Some(why) => RobotDecision::Refused(why),
        None => RobotDecision::Go(op),
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

/// What operations act on: the interpreter's command path, the panel switches, and the
/// bridge's own parameters and alarm list.
struct Desk<'a> {
    commands: &'a mut Commands,
    panel: &'a cnc_runtime::dds::Publisher<Overrides>,
    program_lines: &'a mut BTreeMap<String, u32>,
    parameters: &'a mut Parameters,
    alarms: &'a mut AlarmList,
    reporter: &'a AlarmReporter,
    machine: Option<&'a MachineState>,
    /// Set when the active list changed (to be published).
    alarms_changed: bool,
}

/// Carries out one operation (access was checked by the caller): the one place every door's
/// commands go through.
fn execute(op: &Operation, desk: &mut Desk) -> (bool, String) {
    let commands = &mut *desk.commands;
    match op {
        Operation::Load { name, text } => {
            if text.len() > MAX_PROGRAM_BYTES {
                return (
                    false,
                    format!(
                        "program too large: {} bytes, limit {MAX_PROGRAM_BYTES}",
                        text.len()
                    ),
                );
            }
            let (accepted, message) = commands.call(ProgramCommand::LOAD, name, text);
            if accepted {
                let lines = text.lines().count().min(u32::MAX as usize) as u32;
                desk.program_lines.insert(name.clone(), lines);
            }
            (accepted, message)
        }
        Operation::Start { name, at } => commands.call(ProgramCommand::START, name, at),
        Operation::Stop { mode } => match *mode {
            StopRequest::FEED_HOLD => commands.call(ProgramCommand::FEED_HOLD, "", ""),
            StopRequest::CYCLE_STOP => commands.call(ProgramCommand::CYCLE_STOP, "", ""),
            other => (
                false,
                format!("unknown stop mode {other}: use 1 (FEED_HOLD) or 2 (CYCLE_STOP)"),
            ),
        },
        Operation::Reset => commands.call(ProgramCommand::RESET, "", ""),
        Operation::List => commands.call(ProgramCommand::LIST, "", ""),
        Operation::Delete { name } => {
            let (accepted, message) = commands.call(ProgramCommand::DELETE, name, "");
            if accepted {
                desk.program_lines.remove(name);
            }
            (accepted, message)
        }
        Operation::Overrides(o) => {
            let request = Overrides {
                feed_percent: o.feed_percent,
                spindle_percent: o.spindle_percent,
                rapid_percent: o.rapid_percent,
            };
            match cnc_runtime::overrides::check(&request)
                .and_then(|o| desk.panel.publish(o).map_err(|e| format!("not sent: {e}")))
            {
                Ok(()) => (true, format!("overrides set: {}", op.detail())),
                Err(why) => (false, why),
            }
        }
        Operation::Mode { mode } => commands.call(ProgramCommand::MODE, "", &mode.to_string()),
        Operation::Jog {
            axis,
            direction,
            feed,
            increment,
        } => match cnc_msgs::jog::JogText::new(axis, *direction, *feed, *increment) {
            Ok(j) => commands.call(ProgramCommand::JOG, "", &j.to_text()),
            Err(why) => (false, why),
        },
        Operation::Mdi { text } => commands.call(ProgramCommand::MDI, "", text),
        Operation::Read { name } => commands.call(ProgramCommand::READ, name, ""),
        Operation::Offsets => commands.call(ProgramCommand::OFFSETS, "", ""),
        Operation::SetToolOffset { number, values } => {
            commands.call(ProgramCommand::SET_TOOL_OFFSET, number, values)
        }
        Operation::SetWorkOffset { code, values } => {
            commands.call(ProgramCommand::SET_WORK_OFFSET, code, values)
        }
        Operation::Parameters { prefix } => (
            true,
            crate::operation::parameter_text(&desk.parameters.read(prefix)),
        ),
        Operation::SetParameter { name, value } => {
            match desk.parameters.write(name, value, desk.machine) {
                Ok(message) => {
                    // A control asks for a power-off after a parameter change.
                    let text = format!(
                        "parameter changed ({} pending): restart the cell to apply",
                        desk.parameters.pending()
                    );
                    let alarm = desk.reporter.alarm(
                        PARAMETER_CHANGED_ALARM,
                        cnc_msgs::msg::Alarm::SEVERITY_WARNING,
                        &text,
                        "",
                        0,
                    );
                    desk.alarms.on_event(AlarmEvent {
                        kind: AlarmEvent::RAISED,
                        alarm: alarm.clone(),
                    });
                    desk.reporter.raise(alarm);
                    desk.alarms_changed = true;
                    (true, message)
                }
                Err(why) => (false, why),
            }
        }
        Operation::Acknowledge { source, number } => match desk.alarms.acknowledge(source, *number)
        {
            Ok(message) => {
                desk.alarms_changed = true;
                (true, message)
            }
            Err(why) => (false, why),
        },
    }
}

fn answer<S: RosService>(
    server: &DualServer<S>,
    request: &Request<S::Request>,
    response: &S::Response,
) where
    S::Request: serde::de::DeserializeOwned,
    S::Response: serde::Serialize + std::fmt::Debug,
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
