//! The cell supervisor's shell: the [`Supervisor`] core against the machines over ROS 2, through
//! their public interface only. It publishes its view on `/cell/state` (transient-local) and
//! each decision on `/cell/decisions`, and records both, with every command event of every
//! machine (whoever sent the command: the supervisor, the robot, an operator), in an audit bag
//! on its own host (`cnc audit verify` checks it).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use cnc_msgs::msg::{CellState, CommandEvent};
use cnc_recorder::bag::{offered_qos, Bag, BagOptions, BagTopic};
use cnc_recorder::mcap::Compression;
use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::{stamp, Publisher, RosNode};
use cnc_runtime::topics::{self, Delivery, Topic};
use ros2_client::ServiceMapping;

use crate::client::CellClient;
use crate::supervisor::{Call, Heard, Order, Supervisor};

/// The cell's own namespace: `/cell/state`, `/cell/decisions`.
pub const CELL_NAMESPACE: &str = "cell";
/// The supervisor's view of its work order.
pub const CELL_STATE: Topic = Topic {
    path: "state",
    type_name: "cnc_msgs/msg/CellState",
    delivery: Delivery::State,
};
/// Each decision the supervisor takes and each call it makes, with the machine's answer.
pub const CELL_DECISIONS: Topic = Topic {
    path: "decisions",
    type_name: "cnc_msgs/msg/CommandEvent",
    delivery: Delivery::Events(100),
};

/// How the supervisor runs.
#[derive(Debug, Clone)]
pub struct Options {
    /// A machine not heard from for this long is unreachable.
    pub lease: Duration,
    /// How long a call to a machine waits for its answer.
    pub call_timeout: Duration,
    /// Where its audit bag goes (a folder per run); none: no bag.
    pub records: Option<PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            lease: Duration::from_secs(1),
            call_timeout: Duration::from_secs(5),
            records: None,
        }
    }
}

/// The audit bag: the supervisor's state and decisions and every machine's command events.
struct Audit {
    bag: Bag,
}

impl Audit {
    fn create(root: &Path, machines: &[String]) -> Result<Audit, String> {
        let mut topics = vec![
            bag_topic(CELL_NAMESPACE, &CELL_STATE),
            bag_topic(CELL_NAMESPACE, &CELL_DECISIONS),
        ];
        for m in machines {
            topics.push(bag_topic(m, &topics::COMMAND_EVENTS));
        }
        let now = cnc_runtime::clock::wall_ns();
        let name = format!("cell_{}", cnc_recorder::node::utc_stamp(now));
        let options = BagOptions {
            compression: Compression::Zstd,
            flush_ns: 1_000_000_000,
            split_bytes: 64 << 20,
            split_ns: 3_600_000_000_000,
        };
        Ok(Audit {
            bag: Bag::create(root, &name, topics, options, now)?,
        })
    }

    fn record<M: serde::Serialize>(&mut self, topic: usize, message: &M) -> Result<(), String> {
        let now = cnc_runtime::clock::wall_ns();
        let data = cnc_runtime::bus::encode(message)?;
        self.bag.record(topic, now, now, &data)?;
        self.bag.tick(now)
    }
}

fn bag_topic(ns: &str, t: &Topic) -> BagTopic {
    BagTopic {
        name: format!("/{ns}/{}", t.path),
        type_name: t.type_name.into(),
        qos: offered_qos(t.delivery),
    }
}

/// Bag topic indices.
const STATE_TOPIC: usize = 0;
const DECISION_TOPIC: usize = 1;
const FIRST_MACHINE_TOPIC: usize = 2;

/// Runs `order` until `stop` is set; returns the last state and the bag's folder.
pub fn supervise(
    net: &NetworkConfig,
    order: Order,
    options: &Options,
    stop: &AtomicBool,
) -> Result<(CellState, Option<PathBuf>), String> {
    // Under DDS Security the supervisor is the cell's identity `/cell/supervisor`.
    let net = &net.with_default_enclave("/cell/supervisor")?;
    let mut node = RosNode::client(net, CELL_NAMESPACE, "supervisor")?;
    let state_pub: Publisher<CellState> = node.dds_publisher(&CELL_STATE)?;
    let decision_pub: Publisher<CommandEvent> = node.dds_publisher(&CELL_DECISIONS)?;
    let names: Vec<String> = order.lines.iter().map(|l| l.machine.clone()).collect();
    let mut machines = Vec::new();
    let mut events = Vec::new();
    for ns in &names {
        let mut c = CellClient::new(net, ns, "supervisor", ServiceMapping::Enhanced)?
            .with_timeout(options.call_timeout);
        events.push(
            c.node_mut()
                .dds_subscription::<CommandEvent>(&topics::COMMAND_EVENTS)?,
        );
        machines.push(c);
    }
    let mut audit = match &options.records {
        Some(root) => Some(Audit::create(root, &names)?),
        None => None,
    };
    let mut core = Supervisor::new(order, options.lease.as_secs_f64());
    let t0 = Instant::now();
    let secs = |t: Instant| t.saturating_duration_since(t0).as_secs_f64();
    let decide = |audit: &mut Option<Audit>, command: &str, detail: String, ok, msg: String| {
        log::info!("supervisor: {detail} {msg}");
        let event = CommandEvent {
            stamp: stamp(),
            command: command.into(),
            detail,
            client: format!("/{CELL_NAMESPACE}/supervisor"),
            accepted: ok,
            message: msg,
        };
        if let Some(a) = audit.as_mut() {
            a.record(DECISION_TOPIC, &event)?;
        }
        decision_pub.publish(event)
    };
    let mut last_published: Option<(CellState, Instant)> = None;
    while !stop.load(Ordering::Relaxed) {
        let mut heard = Vec::new();
        for (k, c) in machines.iter_mut().enumerate() {
            c.poll();
            heard.push(Heard {
                state: c.state.clone(),
                part_count: c.part_count.clone(),
                alarms: c.alarms.clone(),
                heard_at: c.heard_at.map(secs),
            });
            while let Ok(Some((e, _))) = events[k].take() {
                if let Some(a) = audit.as_mut() {
                    a.record(FIRST_MACHINE_TOPIC + k, &e)?;
                }
            }
        }
        let now = secs(Instant::now());
        let (calls, notes) = core.step(&heard, now);
        for note in notes {
            decide(&mut audit, "decision", note, true, String::new())?;
        }
        for (i, call) in calls {
            let Some(c) = machines.get_mut(i) else {
                continue;
            };
            let answer = match &call {
                Call::Load { name, text } => {
                    c.load_program(name, text).map(|r| (r.accepted, r.message))
                }
                Call::Start { name } => c.start_program(name).map(|r| (r.accepted, r.message)),
            };
            let (ok, message) = answer.unwrap_or_else(|e| (false, e));
            let note = core.answered(i, &call, ok, &message, secs(Instant::now()));
            decide(&mut audit, call.command(), note, ok, message)?;
        }
        // The state when it changes, and once a second as its heartbeat.
        let mut state = core.state(secs(Instant::now()));
        let changed = last_published.as_ref().is_none_or(|(last, at)| {
            !same_view(last, &state) || at.elapsed() >= Duration::from_secs(1)
        });
        if changed {
            state.stamp = stamp();
            if let Some(a) = audit.as_mut() {
                a.record(STATE_TOPIC, &state)?;
            }
            state_pub.publish(state.clone())?;
            last_published = Some((state, Instant::now()));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let state = core.state(secs(Instant::now()));
    let dir = match audit {
        Some(a) => {
            let dir = a.bag.dir().to_path_buf();
            a.bag.close()?;
            Some(dir)
        }
        None => None,
    };
    Ok((state, dir))
}

/// Whether two states say the same, apart from their stamps and the machines' silence.
fn same_view(a: &CellState, b: &CellState) -> bool {
    let strip = |s: &CellState| {
        let mut s = s.clone();
        s.stamp = Default::default();
        for m in &mut s.machines {
            m.silent_seconds = 0.0;
        }
        s
    };
    strip(a) == strip(b)
}
