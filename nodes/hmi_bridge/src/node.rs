//! hmi_bridge node shell: serves `/<ns>/load_program`, `start_program`, `stop`, `reset`, turns
//! each request into an internal command, and keeps `/<ns>/alarms` (ActiveAlarms).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use cnc_msgs::msg::{ActiveAlarms, AlarmEvent, CommandResult, ProgramCommand};
use cnc_msgs::srv::*;
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};
use ros2_client::dds::rustdds::QosPolicies;

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

impl Commands {
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
    let reset = DualServer::<Reset>::new(&participant, &ns, "reset", sq)?;

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
        if let Some(r) = load.receive() {
            busy = true;
            let (accepted, message) =
                commands.call(ProgramCommand::LOAD, &r.request.name, &r.request.text);
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
