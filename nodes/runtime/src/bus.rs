//! The machine bus: how the nodes of one machine hear each other, over iceoryx2 on this host and
//! never over DDS. DDS carries only what the machine shows and offers the cell (the public
//! topics, services and action); what a node *acts on* comes from the bus or from a service
//! that checked who asked. So a participant on the domain can read the machine's state but
//! cannot feed a node a block, a command, an override, an alarm or a position (issue 25,
//! decisions D58).
//!
//! A sample is the message's CDR bytes with the 4-byte encapsulation header, exactly what
//! DDS would carry, so the recorder writes bus samples into the bag unchanged. The user header
//! is the publish time (wall clock, ns), the recorder's `publish_time`.
//!
//! Services are `cnc/<instance>/bus/<topic path>`; the instance is namespace plus domain
//! ([`crate::shm::instance`]), so two machines, or two tests, never share one.

use std::fmt::Debug;
use std::marker::PhantomData;

use cdr_encoding::{from_bytes, to_vec};
use iceoryx2::port::publisher::Publisher as IoxPublisher;
use iceoryx2::port::subscriber::Subscriber as IoxSubscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::topics::{Delivery, Topic, MOTION_BLOCKS, TASK_COMMAND};

/// Ports of one service: the nodes of a machine and the recorder, with room for a node that
/// restarts before its old ports are cleaned up.
const MAX_PORTS: usize = 8;
/// Slice length a publisher starts with; larger samples grow it (power of two).
const INITIAL_SLICE: usize = 512;

fn err(what: &str, e: impl Debug) -> String {
    format!("machine bus {what}: {e:?}")
}

/// How many samples a subscriber of `topic` holds between two takes. The motion block stream
/// is bounded by the credit (`servo.queue_capacity` at most 1,024 unfinished blocks beyond what
/// motion took), the command streams by the bridge's one-at-a-time calls; a full buffer drops
/// the oldest sample, which only the recorder could ever see.
pub fn depth(topic: &Topic) -> usize {
    match topic.delivery {
        Delivery::State => 64,
        Delivery::Events(n) => n.max(16),
        Delivery::Commands if topic.path == MOTION_BLOCKS.path => 1024,
        // Program texts travel here (up to 4 MiB; the bridge repeats a command until it is
        // answered): few, since every sample slot of a publisher grows to the largest sample.
        Delivery::Commands if topic.path == TASK_COMMAND.path => 4,
        Delivery::Commands => 16,
    }
}

/// Ports of `topic`'s service: the task command stream has one writer (the bridge) and two
/// readers (the task, the recorder), and few ports keep its shared memory small when a large
/// program passes.
fn ports(topic: &Topic) -> usize {
    match topic.path == TASK_COMMAND.path {
        true => 4,
        false => MAX_PORTS,
    }
}

/// One iceoryx2 node of a machine's node (iceoryx2 nodes stay on the thread that made them).
pub struct Bus {
    node: Node<ipc::Service>,
    instance: String,
}

impl Bus {
    pub fn new(instance: &str, node_name: &str) -> Result<Bus, String> {
        let name: NodeName = format!("{node_name}-bus")
            .as_str()
            .try_into()
            .map_err(|e| err("node name", e))?;
        let node = NodeBuilder::new()
            .name(&name)
            .config(crate::shm::quiet_global_config())
            .create::<ipc::Service>()
            .map_err(|e| err("node", e))?;
        Ok(Bus {
            node,
            instance: instance.to_string(),
        })
    }

    fn service(
        &self,
        topic: &Topic,
    ) -> Result<
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [u8], u64>,
        String,
    > {
        let name: ServiceName = format!("cnc/{}/bus/{}", self.instance, topic.path)
            .as_str()
            .try_into()
            .map_err(|e| err("service name", e))?;
        let history = match topic.delivery {
            Delivery::State => 1,
            _ => 0,
        };
        self.node
            .service_builder(&name)
            .publish_subscribe::<[u8]>()
            .user_header::<u64>()
            .subscriber_max_buffer_size(depth(topic))
            .history_size(history)
            .max_publishers(ports(topic))
            .max_subscribers(ports(topic))
            .max_nodes(2 * ports(topic))
            .open_or_create()
            .map_err(|e| err(topic.path, e))
    }

    /// A publisher of encoded samples on `topic`.
    pub fn raw_publisher(&self, topic: &Topic) -> Result<RawPublisher, String> {
        let publisher = self
            .service(topic)?
            .publisher_builder()
            .initial_max_slice_len(INITIAL_SLICE)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| err(topic.path, e))?;
        Ok(RawPublisher { publisher })
    }

    /// A subscriber of encoded samples on `topic` (the recorder's).
    pub fn raw_subscription(&self, topic: &Topic) -> Result<RawSubscription, String> {
        let subscriber = self
            .service(topic)?
            .subscriber_builder()
            .create()
            .map_err(|e| err(topic.path, e))?;
        Ok(RawSubscription {
            subscriber,
            path: topic.path,
        })
    }

    pub fn subscription<M: DeserializeOwned>(
        &self,
        topic: &Topic,
    ) -> Result<Subscription<M>, String> {
        Ok(Subscription {
            raw: self.raw_subscription(topic)?,
            _message: PhantomData,
        })
    }
}

/// Sends encoded samples.
pub struct RawPublisher {
    publisher: IoxPublisher<ipc::Service, [u8], u64>,
}

impl RawPublisher {
    /// Sends `data` (encapsulation header and CDR) stamped with `published_ns`.
    pub fn send(&self, data: &[u8], published_ns: u64) -> Result<(), String> {
        let mut sample = self
            .publisher
            .loan_slice_uninit(data.len())
            .map_err(|e| err("loan", e))?;
        *sample.user_header_mut() = published_ns;
        let sample = sample.write_from_slice(data);
        sample.send().map_err(|e| err("send", e))?;
        Ok(())
    }

    /// Hands the last state sample to subscribers that arrived since the last send: a state
    /// that changes rarely (the PLC program, the part count) reaches a node that started late.
    pub fn refresh(&self) {
        let _ = self.publisher.update_connections();
    }
}

/// Encodes `message` as DDS would carry it: encapsulation header (CDR, little endian), then CDR.
pub fn encode<M: Serialize>(message: &M) -> Result<Vec<u8>, String> {
    let body = to_vec::<M, byteorder::LittleEndian>(message).map_err(|e| err("encode", e))?;
    let mut out = Vec::with_capacity(4 + body.len());
    out.extend_from_slice(&[0, 1, 0, 0]);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decodes what [`encode`] wrote; anything else is an error, never a panic (another process on
/// the host may write to a bus service).
pub fn decode<M: DeserializeOwned>(data: &[u8]) -> Result<M, String> {
    match data {
        [0, 1, _, _, body @ ..] => from_bytes::<M, byteorder::LittleEndian>(body)
            .map(|(m, _)| m)
            .map_err(|e| err("decode", e)),
        _ => Err("machine bus: not a little-endian CDR sample".into()),
    }
}

/// Receives encoded samples.
pub struct RawSubscription {
    subscriber: IoxSubscriber<ipc::Service, [u8], u64>,
    path: &'static str,
}

impl RawSubscription {
    /// The next sample and its publish time, if any.
    pub fn take(&self) -> Result<Option<(Vec<u8>, u64)>, String> {
        match self.subscriber.receive().map_err(|e| err("receive", e))? {
            Some(sample) => Ok(Some((sample.payload().to_vec(), *sample.user_header()))),
            None => Ok(None),
        }
    }
}

/// Receives messages of type `M`.
pub struct Subscription<M> {
    raw: RawSubscription,
    _message: PhantomData<M>,
}

impl<M: DeserializeOwned> Subscription<M> {
    /// The next message, if any. A sample that does not decode is logged and skipped.
    pub fn take(&self) -> Result<Option<M>, String> {
        while let Some((data, _)) = self.raw.take()? {
            match decode(&data) {
                Ok(m) => return Ok(Some(m)),
                Err(e) => log::warn!("{}: sample dropped: {e}", self.raw.path),
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topics;
    use cnc_msgs::msg::{MachineState, MotionBlock, TaskCommand};

    fn bus(tag: &str) -> Bus {
        Bus::new(&format!("test_bus_{tag}_{}", std::process::id()), "t").unwrap()
    }

    #[test]
    fn messages_cross_the_bus_as_dds_would_carry_them() {
        let bus = bus("cross");
        let sub = bus
            .subscription::<TaskCommand>(&topics::TASK_COMMAND)
            .unwrap();
        let publisher = bus.raw_publisher(&topics::TASK_COMMAND).unwrap();
        // A program near the memory's limit grows the publisher's slices.
        let text = "G01 X1. Z2.\n".repeat(300_000);
        let command = TaskCommand {
            id: 7,
            kind: TaskCommand::LOAD,
            program: "O0001".into(),
            text,
            ..TaskCommand::default()
        };
        publisher.send(&encode(&command).unwrap(), 42).unwrap();
        let got = sub.take().unwrap().unwrap();
        assert_eq!(got.id, 7);
        assert_eq!(got.text.len(), command.text.len());
        assert!(sub.take().unwrap().is_none());
    }

    #[test]
    fn a_state_reaches_a_late_subscriber_and_garbage_is_skipped() {
        let bus = bus("state");
        let publisher = bus.raw_publisher(&topics::MACHINE_STATE).unwrap();
        let state = MachineState {
            program: "O0002".into(),
            ..Default::default()
        };
        publisher.send(&encode(&state).unwrap(), 1).unwrap();
        let late = bus
            .subscription::<MachineState>(&topics::MACHINE_STATE)
            .unwrap();
        publisher.refresh();
        assert_eq!(late.take().unwrap().unwrap().program, "O0002");
        // Another process on the host writes bytes that are no message.
        let blocks = bus
            .subscription::<MotionBlock>(&topics::MOTION_BLOCKS)
            .unwrap();
        let raw = bus.raw_publisher(&topics::MOTION_BLOCKS).unwrap();
        raw.send(&[0, 1, 0, 0, 9], 0).unwrap();
        raw.send(&[7; 3], 0).unwrap();
        assert!(blocks.take().unwrap().is_none());
    }
}
