//! DDS: participants on the configured interfaces and domain, the QoS profiles of DESIGN.md,
//! and small helpers for publishers and subscriptions under the machine's namespace.

use std::time::Duration;

use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::dds::{Context, Node};
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{Message, MessageTypeName, Name, NodeName, NodeOptions, QosProfile};

use crate::config::NetworkConfig;

/// A ROS 2 node of the controller with its own DDS participant.
pub struct RosNode {
    pub node: Node,
    pub namespace: String,
    context: Context,
}

/// Creates a participant in the configured domain that uses only the configured interfaces.
/// ros2-client's `Context::new()` would always join domain 0 on every interface.
pub fn context(net: &NetworkConfig) -> Result<Context, String> {
    let domain = net.effective_domain_id()?;
    let participant = DomainParticipantBuilder::new(domain)
        .with_only_networks(net.interfaces.iter().copied())
        .build()
        .map_err(|e| format!("DDS participant in domain {domain}: {e}"))?;
    Context::from_domain_participant(participant).map_err(|e| format!("ROS 2 context: {e}"))
}

impl RosNode {
    /// Node `name` in namespace `/namespace`, with its spinner (discovery, parameters) running.
    pub fn new(net: &NetworkConfig, namespace: &str, name: &str) -> Result<Self, String> {
        let context = context(net)?;
        let node_name = NodeName::new(&format!("/{namespace}"), name)
            .map_err(|e| format!("node name {name}: {e:?}"))?;
        let mut node = context
            .new_node(node_name, NodeOptions::new().enable_rosout(true))
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
        Ok(RosNode {
            node,
            namespace: namespace.to_string(),
            context,
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

    /// Publisher on `/<namespace>/<topic>`; `type_name` like `cnc_msgs/msg/SpindleState`.
    pub fn publisher<M: Message>(
        &mut self,
        topic: &str,
        type_name: &str,
        qos: QosProfile,
    ) -> Result<ros2_client::dds::Publisher<M>, String> {
        let t = self.topic(topic, type_name, &qos)?;
        self.node
            .create_publisher::<M>(&t, Some(qos))
            .map_err(|e| format!("publisher {topic}: {e:?}"))
    }

    pub fn subscription<M: Message + 'static>(
        &mut self,
        topic: &str,
        type_name: &str,
        qos: QosProfile,
    ) -> Result<ros2_client::dds::Subscription<M>, String> {
        let t = self.topic(topic, type_name, &qos)?;
        self.node
            .create_subscription::<M>(&t, Some(qos))
            .map_err(|e| format!("subscription {topic}: {e:?}"))
    }
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
