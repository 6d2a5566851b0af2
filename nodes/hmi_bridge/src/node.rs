//! hmi_bridge node shell: serves `/<ns>/load_program`, `start_program`, `stop`, `reset`, turns
//! each request into an internal command, and keeps `/<ns>/alarms` (ActiveAlarms).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use cnc_msgs::msg::{
    ActiveAlarms, AlarmEvent, CommandResult, MachineState, MotionStatus, PartCount, ProgramCommand,
};
use cnc_msgs::srv::*;
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};
use ros2_client::dds::rustdds::QosPolicies;
use ros2_client::qos::History;

use crate::action_server::{CommandPath, RunProgramServer};
use crate::server::{DualServer, Request};

/// How long a service waits for the interpreter's answer.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(10);
/// A command published before discovery has matched the interpreter's reader is lost (the
/// command topic is volatile, so a late reader never replays old commands); it is repeated with
/// the same id at this interval, and the interpreter answers a repeated id without acting twice.
const COMMAND_REPEAT: Duration = Duration::from_millis(250);

struct Commands {
    publisher: cnc_runtime::dds::Publisher<ProgramCommand>,
    results: ros2_client::dds::Subscription<CommandResult>,
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
            while let Ok(Some((r, _))) = self.results.take() {
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
    let ns = cfg.machine.namespace.clone();
    let mut ros = RosNode::new(&cfg.network, &ns, "hmi_bridge")?;
    let mut commands = Commands {
        publisher: ros.publisher(&topics::PROGRAM_COMMAND)?,
        results: ros.subscription(&topics::COMMAND_RESULT)?,
        next_id: cnc_runtime::clock::monotonic_ns(),
    };
    let alarm_events = ros.subscription::<AlarmEvent>(&topics::ALARM_EVENTS)?;
    let alarms_pub = ros.publisher::<ActiveAlarms>(&topics::ALARMS)?;
    let participant = ros.participant();
    let sq: QosPolicies = (&qos::services()).into();
    let load = DualServer::<LoadProgram>::new(&participant, &ns, "load_program", sq.clone())?;
    let start = DualServer::<StartProgram>::new(&participant, &ns, "start_program", sq.clone())?;
    let stop = DualServer::<Stop>::new(&participant, &ns, "stop", sq.clone())?;
    let reset = DualServer::<Reset>::new(&participant, &ns, "reset", sq.clone())?;
    let mut run_program = RunProgramServer::new(&participant, &ns, sq)?;
    // Every state change, in order: the action follows the machine through them.
    let state_sub = ros.subscription_with_qos::<MachineState>(
        &topics::MACHINE_STATE,
        topics::MACHINE_STATE
            .qos()
            .history(History::KeepLast { depth: 64 }),
    )?;
    let motion_sub = ros.subscription::<MotionStatus>(&topics::MOTION_STATUS)?;
    let parts_sub = ros.subscription::<PartCount>(&topics::PART_COUNT)?;
    let mut machine: Option<MachineState> = None;
    let mut motion_run = (0u64, 0u64);
    let mut part_count = 0u32;
    let t0 = std::time::Instant::now();

    let mut active: BTreeMap<(String, u32), cnc_msgs::msg::Alarm> = BTreeMap::new();
    let publish_alarms = |active: &BTreeMap<(String, u32), cnc_msgs::msg::Alarm>| {
        let _ = alarms_pub.publish(ActiveAlarms {
            stamp: stamp(),
            alarms: active.values().cloned().collect(),
        });
    };
    publish_alarms(&active);
    while !shutdown.requested() {
        let mut busy = false;
        let mut changed = false;
        while let Ok(Some((e, _))) = alarm_events.take() {
            let key = (e.alarm.source.clone(), e.alarm.number);
            if e.kind == AlarmEvent::RAISED {
                active.insert(key, e.alarm);
            } else {
                active.remove(&key);
            }
            changed = true;
        }
        if changed {
            publish_alarms(&active);
        }
        while let Ok(Some((m, _))) = motion_sub.take() {
            motion_run = (m.run_id, m.done_seq);
        }
        while let Ok(Some((p, _))) = parts_sub.take() {
            part_count = p.count;
        }
        let alarm_list: Vec<cnc_msgs::msg::Alarm> = active.values().cloned().collect();
        // Each state in turn, so the action sees every transition (a short cycle's end too).
        let mut states = Vec::new();
        while let Ok(Some((m, _))) = state_sub.take() {
            states.push(m);
        }
        if states.is_empty() {
            states.extend(machine.clone());
        }
        for m in states {
            for e in run_program.poll(
                &mut commands,
                Some(&m),
                motion_run,
                part_count,
                &alarm_list,
                t0.elapsed().as_secs_f64(),
            ) {
                busy = true;
                log::info!("{} (from {}, accepted: {})", e.what, e.client, e.accepted);
            }
            machine = Some(m);
        }
        if machine.is_none() {
            run_program.poll(
                &mut commands,
                None,
                motion_run,
                part_count,
                &alarm_list,
                t0.elapsed().as_secs_f64(),
            );
        }
        if let Some(r) = load.receive() {
            busy = true;
            let (accepted, message) =
                commands.call(ProgramCommand::LOAD, &r.request.name, &r.request.text);
            if accepted {
                let lines = r.request.text.lines().count().min(u32::MAX as usize) as u32;
                run_program
                    .program_lines
                    .insert(r.request.name.clone(), lines);
            }
            answer(&load, &r, &LoadProgramResponse { accepted, message });
        }
        if let Some(r) = start.receive() {
            busy = true;
            let (accepted, message) = commands.call(ProgramCommand::START, &r.request.name, "");
            answer(&start, &r, &StartProgramResponse { accepted, message });
        }
        if let Some(r) = stop.receive() {
            busy = true;
            let (accepted, message) = match r.request.mode {
                StopRequest::FEED_HOLD => commands.call(ProgramCommand::FEED_HOLD, "", ""),
                StopRequest::CYCLE_STOP => commands.call(ProgramCommand::CYCLE_STOP, "", ""),
                other => (
                    false,
                    format!("unknown stop mode {other}: use 1 (FEED_HOLD) or 2 (CYCLE_STOP)"),
                ),
            };
            answer(&stop, &r, &StopResponse { accepted, message });
        }
        if let Some(r) = reset.receive() {
            busy = true;
            let (accepted, message) = commands.call(ProgramCommand::RESET, "", "");
            answer(&reset, &r, &ResetResponse { accepted, message });
        }
        if !busy {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    Ok(())
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
