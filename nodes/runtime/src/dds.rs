//! DDS: participants on the configured interfaces and domain, the QoS profiles of DESIGN.md,
//! and small helpers for publishers and subscriptions under the machine's namespace.
//!
//! A node of the machine publishes each topic on the machine bus ([`crate::bus`]) and, when the
//! topic is public, on DDS too; it subscribes only on the bus. DDS subscriptions
//! ([`RosNode::dds_subscription`]) are for clients outside the machine: the `cnc` client,
//! tests, tools.

use std::collections::BTreeMap;
use std::rc::{Rc, Weak};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

use cnc_msgs::RosMessage;

use ros2_client::dds::rustdds::{DomainParticipantBuilder, DomainParticipantSecurityConfigFiles};
use ros2_client::dds::{Context, Node};
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{Message, MessageTypeName, Name, NodeName, NodeOptions, QosProfile};

use crate::bus::{self, Bus, RawPublisher};
use crate::config::NetworkConfig;
use crate::topics::Topic;

/// A ROS 2 node of the controller with its own DDS participant and its port on the machine bus.
pub struct RosNode {
    pub node: Node,
    pub namespace: String,
    context: Context,
    domain: u16,
    bus: Bus,
    /// This node's state publishers on the bus, for [`RosNode::refresh`].
    states: Vec<Weak<RawPublisher>>,
    /// Where DDS writes go when a real-time loop publishes ([`RosNode::relay_dds`]).
    relay: Option<Sender<Job>>,
}

/// A DDS write handed to the relay thread.
type Job = Box<dyn FnOnce() + Send>;

/// Creates a participant in the configured domain that uses only the configured interfaces.
/// ros2-client's `Context::new()` would always join domain 0 on every interface. With DDS
/// Security on, the participant authenticates as its enclave (`enclave` when the config
/// names none) and DDS enforces the enclave's permissions.
pub fn context(net: &NetworkConfig, enclave: Option<&str>) -> Result<Context, String> {
    let domain = net.effective_domain_id()?;
    let mut builder =
        DomainParticipantBuilder::new(domain).with_only_networks(net.interfaces.iter().copied());
    if let Some(security) = net.effective_security()? {
        let dir = security.enclave_dir(enclave)?;
        // Keys are stored unencrypted, readable by their owner only (as SROS2 stores them).
        builder = builder.builtin_security(
            DomainParticipantSecurityConfigFiles::with_ros_default_names(dir, String::new()),
        );
    }
    let participant = builder
        .build()
        .map_err(|e| format!("DDS participant in domain {domain}: {e}"))?;
    Context::from_domain_participant(participant).map_err(|e| format!("ROS 2 context: {e}"))
}

impl RosNode {
    /// Node `name` of the machine in namespace `/namespace`, with its spinner (discovery)
    /// running; under DDS Security it is the machine's identity, `/namespace`. It serves no
    /// ROS 2 parameter services: they answered any participant, outside `allowed_clients` and
    /// without a command event, and the machine's parameters have their own door, the bridge's
    /// `get_parameters`/`set_parameter` (issue 45).
    pub fn new(net: &NetworkConfig, namespace: &str, name: &str) -> Result<Self, String> {
        Self::with_options(net, namespace, name, Some(&format!("/{namespace}")))
    }

    /// A node of a client of the machines (the `cnc` client, the supervisor, the robot): it
    /// serves no parameters, and under DDS Security it is the enclave its config or the
    /// environment names.
    pub fn client(net: &NetworkConfig, namespace: &str, name: &str) -> Result<Self, String> {
        Self::with_options(net, namespace, name, None)
    }

    fn with_options(
        net: &NetworkConfig,
        namespace: &str,
        name: &str,
        enclave: Option<&str>,
    ) -> Result<Self, String> {
        let context = context(net, enclave)?;
        let node_name = NodeName::new(&format!("/{namespace}"), name)
            .map_err(|e| format!("node name {name}: {e:?}"))?;
        let options = NodeOptions::new()
            .enable_rosout(true)
            .start_parameter_services(false);
        let mut node = context
            .new_node(node_name, options)
            .map_err(|e| format!("node {name}: {e:?}"))?;
        match node.spinner() {
            Ok(spinner) => {
                let _ = std::thread::Builder::new()
                    .name(format!("{name}-spin"))
                    .spawn(move || {
                        let _ = smol::block_on(spinner.spin());
                    });
            }
            Err(e) => log::warn!("{name}: no spinner: {e:?}"),
        }
        let domain = net.effective_domain_id()?;
        Ok(RosNode {
            node,
            namespace: namespace.to_string(),
            context,
            domain,
            bus: Bus::new(&crate::shm::instance(namespace, domain), name)?,
            states: Vec::new(),
            relay: None,
        })
    }

    /// The node's DDS participant, for entities ros2-client does not offer.
    pub fn participant(&self) -> ros2_client::dds::rustdds::DomainParticipant {
        self.context.domain_participant()
    }

    fn topic(
        &mut self,
        topic: &str,
        type_name: &str,
        qos: &QosProfile,
    ) -> Result<ros2_client::dds::rustdds::Topic, String> {
        let name = ros_name(&self.namespace, topic)?;
        let (pkg, ty) = split_type(type_name);
        self.node
            .create_topic(&name, MessageTypeName::new(pkg, ty), qos)
            .map_err(|e| format!("topic {topic}: {e:?}"))
    }

    /// Publisher on `/<namespace>/<topic>`: on the machine bus, and on DDS when the topic is
    /// public. Every sample it sends is counted ([`published_count`]).
    pub fn publisher<M: Message + RosMessage>(
        &mut self,
        topic: &Topic,
    ) -> Result<Publisher<M>, String> {
        let dds = match topic.internal() {
            true => None,
            false => self.dds_publisher(topic)?.dds,
        };
        let relay = self.relay.clone();
        let bus = Rc::new(self.bus.raw_publisher(topic)?);
        if topic.delivery == crate::topics::Delivery::State {
            self.states.push(Rc::downgrade(&bus));
        }
        Ok(Publisher {
            dds,
            relay,
            bus: Some(bus),
            count: counter(self.domain, &self.namespace, topic.path),
        })
    }

    /// From now on, publishers made by this node hand their DDS writes to a thread of their
    /// own (started here, so before the caller raises its priority): a real-time loop (the PLC
    /// scan) then never waits on DDS's locks, which DDS's ordinary threads hold. The bus
    /// sample still goes out at once, and DDS writes keep their order.
    pub fn relay_dds(&mut self, name: &str) -> Result<(), String> {
        let (tx, rx) = std::sync::mpsc::channel::<Job>();
        std::thread::Builder::new()
            .name(format!("{name}-dds"))
            .spawn(move || {
                while let Ok(job) = rx.recv() {
                    job();
                }
            })
            .map_err(|e| format!("{name}: DDS relay thread: {e}"))?;
        self.relay = Some(tx);
        Ok(())
    }

    /// Hands each state this node published to bus subscribers that arrived since: a node
    /// that starts later has every state at once, as DDS's transient-local delivery gives it.
    /// Cheap when nobody arrived; node loops call it every turn.
    pub fn refresh(&self) {
        for p in self.states.iter().filter_map(Weak::upgrade) {
            p.refresh();
        }
    }

    /// Publisher on DDS only, for a client outside the machine (a test playing a foreign
    /// participant, replay): the machine's nodes do not act on it.
    pub fn dds_publisher<M: Message + RosMessage>(
        &mut self,
        topic: &Topic,
    ) -> Result<Publisher<M>, String> {
        check_type::<M>(topic)?;
        let qos = topic.qos();
        let t = self.topic(topic.path, topic.type_name, &qos)?;
        let inner = self
            .node
            .create_publisher::<M>(&t, Some(qos))
            .map_err(|e| format!("publisher {}: {e:?}", topic.path))?;
        Ok(Publisher {
            dds: Some(Arc::new(inner)),
            relay: None,
            bus: None,
            // Not the machine's: its samples are not counted as published by the machine.
            count: Arc::default(),
        })
    }

    /// What the machine's nodes publish on `topic`, from the machine bus.
    pub fn subscription<M: Message + RosMessage + 'static>(
        &mut self,
        topic: &Topic,
    ) -> Result<bus::Subscription<M>, String> {
        check_type::<M>(topic)?;
        self.bus.subscription(topic)
    }

    /// The machine bus of this node, for raw ports (the recorder).
    pub fn bus(&self) -> &Bus {
        &self.bus
    }

    /// A DDS subscription, for a client outside the machine.
    pub fn dds_subscription<M: Message + RosMessage + 'static>(
        &mut self,
        topic: &Topic,
    ) -> Result<ros2_client::dds::Subscription<M>, String> {
        self.dds_subscription_with_qos(topic, topic.qos())
    }

    /// A DDS subscription with its own QoS, e.g. a deeper history than the topic's writers keep.
    pub fn dds_subscription_with_qos<M: Message + RosMessage + 'static>(
        &mut self,
        topic: &Topic,
        qos: QosProfile,
    ) -> Result<ros2_client::dds::Subscription<M>, String> {
        check_type::<M>(topic)?;
        let t = self.topic(topic.path, topic.type_name, &qos)?;
        self.node
            .create_subscription::<M>(&t, Some(qos))
            .map_err(|e| format!("subscription {}: {e:?}", topic.path))
    }

    /// The DDS topic for `topic`, for readers and writers ros2-client does not offer (the
    /// recorder's raw readers, replay's raw writers).
    pub fn dds_topic(&mut self, topic: &Topic) -> Result<ros2_client::dds::rustdds::Topic, String> {
        self.topic(topic.path, topic.type_name, &topic.qos())
    }

    pub fn domain(&self) -> u16 {
        self.domain
    }
}

fn check_type<M: RosMessage>(topic: &Topic) -> Result<(), String> {
    if M::TYPE_NAME == topic.type_name {
        Ok(())
    } else {
        Err(format!(
            "topic {} carries {}, not {}",
            topic.path,
            topic.type_name,
            M::TYPE_NAME
        ))
    }
}

/// A publisher that counts what it sends, so a test can compare a recording with what the
/// nodes published.
pub struct Publisher<M: Message> {
    dds: Option<Arc<ros2_client::dds::Publisher<M>>>,
    relay: Option<Sender<Job>>,
    bus: Option<Rc<RawPublisher>>,
    count: Arc<AtomicU64>,
}

impl<M: Message + Send + Sync + 'static> Publisher<M> {
    /// Sends `message` on the bus and on DDS; an error on one does not keep it from the other.
    pub fn publish(&self, message: M) -> Result<(), String> {
        let on_bus = match &self.bus {
            Some(b) => bus::encode(&message).and_then(|d| b.send(&d, crate::clock::wall_ns())),
            None => Ok(()),
        };
        let on_dds = match (&self.dds, &self.relay) {
            (Some(d), Some(relay)) => {
                let d = d.clone();
                relay
                    .send(Box::new(move || {
                        if let Err(e) = d.publish(message) {
                            log::warn!("DDS write: {e}");
                        }
                    }))
                    .map_err(|_| "DDS relay thread gone".to_string())
            }
            (Some(d), None) => d.publish(message).map_err(|e| e.to_string()),
            (None, _) => Ok(()),
        };
        on_bus.and(on_dds)?;
        self.count.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }
}

type Counters = Mutex<BTreeMap<(u16, String), Arc<AtomicU64>>>;

fn counters() -> &'static Counters {
    static COUNTERS: OnceLock<Counters> = OnceLock::new();
    COUNTERS.get_or_init(Default::default)
}

fn counter(domain: u16, namespace: &str, path: &str) -> Arc<AtomicU64> {
    let key = (domain, format!("/{namespace}/{path}"));
    let mut map = counters().lock().unwrap_or_else(|e| e.into_inner());
    map.entry(key).or_default().clone()
}

/// Samples published so far in this process on `/<namespace>/<path>` in `domain`, by every
/// publisher of that topic together.
pub fn published_count(domain: u16, namespace: &str, path: &str) -> u64 {
    counter(domain, namespace, path).load(Ordering::Relaxed)
}

/// `/<namespace>/<path>` as a ROS name; `path` may have segments (`sim/input`).
pub fn ros_name(namespace: &str, path: &str) -> Result<Name, String> {
    let (prefix, base) = match path.rsplit_once('/') {
        Some((p, b)) => (format!("/{namespace}/{p}"), b),
        None => (format!("/{namespace}"), path),
    };
    Name::new(&prefix, base).map_err(|e| format!("name /{namespace}/{path}: {e:?}"))
}

/// `cnc_msgs/msg/SpindleState` → (`cnc_msgs`, `SpindleState`).
pub fn split_type(full: &str) -> (&str, &str) {
    let pkg = full.split('/').next().unwrap_or(full);
    let ty = full.rsplit('/').next().unwrap_or(full);
    (pkg, ty)
}

/// QoS profiles: what a topic means decides how it is delivered.
pub mod qos {
    use super::*;

    /// State topics: the current value, delivered to late joiners at once.
    pub fn state() -> QosProfile {
        QosProfile::publisher_default()
            .reliability_reliable(WhenFull::Wait(Duration::from_millis(20)))
            .durability(Durability::TransientLocal)
            .history(History::KeepLast { depth: 1 })
    }

    /// Event streams: every event, in order, the last `depth` kept for slow readers.
    pub fn events(depth: usize) -> QosProfile {
        QosProfile::publisher_default()
            .reliability_reliable(WhenFull::Wait(Duration::from_millis(100)))
            .durability(Durability::Volatile)
            .history(History::KeepLast { depth })
    }

    /// High-rate telemetry: newest wins, losses tolerated.
    pub fn telemetry() -> QosProfile {
        QosProfile::subscription_default().history(History::KeepLast { depth: 1 })
    }

    /// Command and block streams between nodes: reliable, deep enough for a full queue.
    pub fn commands() -> QosProfile {
        events(1024)
    }

    /// Service request and reply topics, as ROS 2's default services profile.
    pub fn services() -> QosProfile {
        events(10)
    }
}

/// Message stamp from the wall clock.
pub fn stamp() -> cnc_msgs::msg::Time {
    cnc_msgs::msg::Time::from_nanos(crate::clock::wall_ns())
}
