//! A service server that answers rmw_cyclonedds-style and rmw_fastrtps-style clients on the same
//! topics, built on rustdds directly because ros2-client's `Server` speaks one mapping only.
//!
//! No request goes unanswered by silence (issue 26): requests are taken from DDS as they come
//! (a reader history of [`READER_DEPTH`]) into a queue of [`QUEUE_LIMIT`]; one that finds the
//! queue full is answered at once with a refusal that says "busy" (a service whose response
//! has no room for a reason logs it).

use std::cell::RefCell;
use std::collections::VecDeque;
use std::marker::PhantomData;

use byteorder::LittleEndian;
use cnc_runtime::raw::{Raw, RawAdapter};
use ros2_client::dds::rustdds::{
    self,
    no_key::{DataWriter, SimpleDataReader},
    rpc::SampleIdentity,
    QosPolicies, QosPolicyBuilder, SequenceNumber, Timestamp, TopicKind, WriteOptionsBuilder,
};

/// Requests of one service DDS holds until the bridge takes them: a burst larger than the
/// bridge's queue still reaches it, to be refused as busy rather than lost (rustdds keeps at
/// most 32 MiB of samples per topic whatever the depth, D63).
pub const READER_DEPTH: i32 = 1024;
/// Replies of one service kept until the client has acknowledged them: a reliable writer with
/// a shallower history overwrites replies a slow client has not yet taken, and they are lost
/// (seen under load: 25 of 2,000 replies of a burst). Replies are small (no service returns a
/// program text), so this bounds memory at a few MiB per service.
pub const REPLY_DEPTH: i32 = 1024;
/// Requests of one service waiting to be served; more are refused as busy.
pub const QUEUE_LIMIT: usize = 256;
use serde::{de::DeserializeOwned, Serialize};

use crate::mapping::{classify, guess_mapping, Mapping};
use cnc_msgs::srv::RosService;

/// A server whose DDS requests can be taken into its queue ([`DualServer::drain`]).
pub trait Drain {
    fn drain(&self);
}

impl<S: RosService> Drain for DualServer<S>
where
    S::Request: DeserializeOwned,
    S::Response: Serialize,
{
    fn drain(&self) {
        DualServer::drain(self)
    }
}

/// One received request, ready to be answered.
#[derive(Clone)]
pub struct Request<Req> {
    pub request: Req,
    pub mapping: Mapping,
    identity: SampleIdentity,
    /// GUID of the client's writer, for logs and events.
    pub client: String,
    /// The same GUID as bytes: its first 12 name the client's participant.
    pub writer: [u8; 16],
}

pub struct DualServer<S: RosService> {
    reader: SimpleDataReader<Raw, RawAdapter>,
    writer: DataWriter<Raw, RawAdapter>,
    name: String,
    /// How to say no to a request that cannot be decoded, if the response type can say it.
    refuse: Option<Box<dyn Fn(String) -> S::Response>>,
    /// Undecodable requests seen since the last [`DualServer::take_malformed`]: writer GUID and
    /// what was wrong.
    malformed: RefCell<Vec<([u8; 16], String)>>,
    queue: RefCell<VecDeque<Request<S::Request>>>,
    _service: PhantomData<S>,
}

impl<S: RosService> DualServer<S>
where
    S::Request: DeserializeOwned,
    S::Response: Serialize,
{
    /// Serves `/<namespace>/<service>` as DDS topics `rq/<ns>/<service>Request` and `rr/…Reply`.
    pub fn new(
        participant: &rustdds::DomainParticipant,
        namespace: &str,
        service: &str,
        qos: QosPolicies,
    ) -> Result<Self, String> {
        // `cnc_msgs/srv/Stop` → `cnc_msgs::srv::dds_::Stop_Request_`; actions' services are
        // `cnc_msgs/action/RunProgram_SendGoal`, `action_msgs/srv/CancelGoal`.
        let (prefix, ty) = S::TYPE_NAME
            .rsplit_once('/')
            .ok_or_else(|| format!("{service}: bad type name {}", S::TYPE_NAME))?;
        let dds_type = |part: &str| format!("{}::dds_::{ty}_{part}_", prefix.replace('/', "::"));
        let rq = participant
            .create_topic(
                format!("rq/{namespace}/{service}Request"),
                dds_type("Request"),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(|e| format!("{service}: {e:?}"))?;
        let rr = participant
            .create_topic(
                format!("rr/{namespace}/{service}Reply"),
                dds_type("Response"),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(|e| format!("{service}: {e:?}"))?;
        let deep = qos.modify_by(
            &QosPolicyBuilder::new()
                .history(rustdds::policy::History::KeepLast {
                    depth: READER_DEPTH,
                })
                .build(),
        );
        let subscriber = participant
            .create_subscriber(&deep)
            .map_err(|e| format!("{service}: {e:?}"))?;
        let replies = qos.modify_by(
            &QosPolicyBuilder::new()
                .history(rustdds::policy::History::KeepLast { depth: REPLY_DEPTH })
                .build(),
        );
        let publisher = participant
            .create_publisher(&replies)
            .map_err(|e| format!("{service}: {e:?}"))?;
        // Given explicitly: an endpoint created without QoS takes the topic's history over its
        // subscriber's or publisher's (rustdds follows DDS 2.2.2.4.1.5), which left both at 10.
        let reader = subscriber
            .create_simple_datareader_no_key::<Raw, RawAdapter>(&rq, Some(deep))
            .map_err(|e| format!("{service}: {e:?}"))?;
        let writer = publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&rr, Some(replies))
            .map_err(|e| format!("{service}: {e:?}"))?;
        Ok(DualServer {
            reader,
            writer,
            name: service.into(),
            refuse: None,
            malformed: RefCell::new(Vec::new()),
            queue: RefCell::new(VecDeque::new()),
            _service: PhantomData,
        })
    }

    /// Answers undecodable requests (a string that is not UTF-8, a payload of the wrong type)
    /// with `refuse(reason)` instead of only logging them.
    pub fn refusing(mut self, refuse: impl Fn(String) -> S::Response + 'static) -> Self {
        self.refuse = Some(Box::new(refuse));
        self
    }

    /// The service's name under the machine's namespace.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The undecodable requests seen since the last call, for command events.
    pub fn take_malformed(&self) -> Vec<([u8; 16], String)> {
        std::mem::take(&mut *self.malformed.borrow_mut())
    }

    /// The next request, if any, after taking what DDS holds into the queue ([`Self::drain`]).
    pub fn receive(&self) -> Option<Request<S::Request>> {
        self.drain();
        self.queue.borrow_mut().pop_front()
    }

    /// Takes every request DDS holds into the queue; one that finds it full is refused as
    /// busy. The bridge calls it for every service each turn of its loop, before serving any.
    pub fn drain(&self) {
        while let Some(r) = self.take() {
            let mut queue = self.queue.borrow_mut();
            if queue.len() < QUEUE_LIMIT {
                queue.push_back(r);
                continue;
            }
            drop(queue);
            let why = format!(
                "busy: {QUEUE_LIMIT} {} requests are waiting; try again",
                self.name
            );
            match &self.refuse {
                Some(refuse) => {
                    if let Err(e) = self.reply(&r, &refuse(why)) {
                        log::warn!("{e}");
                    }
                }
                None => log::warn!("{why} (dropped: the response cannot say so)"),
            }
        }
    }

    /// The next request DDS holds. Undecodable requests are logged and dropped: without a valid
    /// request there is no reliable way to address a reply to the client.
    fn take(&self) -> Option<Request<S::Request>> {
        self.reader.drain_read_notifications();
        loop {
            let dcc = match self.reader.try_take_one() {
                Ok(Some(d)) => d,
                Ok(None) => return None,
                Err(e) => {
                    log::warn!("{}: request not readable: {e:?}", self.name);
                    continue;
                }
            };
            let related = dcc.related_sample_identity();
            let own = SampleIdentity {
                writer_guid: dcc.writer_guid,
                sequence_number: dcc.sequence_number,
            };
            let client = format!("{:?}", dcc.writer_guid);
            let dcc_writer = dcc.writer_guid;
            let raw = dcc.into_value();
            let related_seq = related.map(|r| i64::from(r.sequence_number));
            match classify::<S::Request>(&raw.bytes, raw.little_endian, related_seq) {
                Some((mapping, request)) => {
                    let identity = match related {
                        // rmw_fastrtps names the reply reader with an unknown sequence number.
                        Some(r) if r.sequence_number != SequenceNumber::UNKNOWN => r,
                        Some(r) => SampleIdentity {
                            writer_guid: r.writer_guid,
                            sequence_number: own.sequence_number,
                        },
                        None => own,
                    };
                    return Some(Request {
                        request,
                        mapping,
                        identity,
                        client,
                        writer: own.writer_guid.to_bytes(),
                    });
                }
                None => {
                    let why = format!(
                        "malformed {} request ({} bytes): not a valid {} (strings must be UTF-8)",
                        self.name,
                        raw.bytes.len(),
                        S::TYPE_NAME
                    );
                    log::warn!("{why} from {client}");
                    self.malformed
                        .borrow_mut()
                        .push((dcc_writer.to_bytes(), why.clone()));
                    if let Some(refuse) = &self.refuse {
                        let mapping = guess_mapping(&raw.bytes, raw.little_endian, related_seq);
                        let identity = match related {
                            Some(r) if r.sequence_number != SequenceNumber::UNKNOWN => r,
                            _ => own,
                        };
                        if let Err(e) = self.send(mapping, identity, &refuse(why)) {
                            log::warn!("{e}");
                        }
                    }
                }
            }
        }
    }

    pub fn reply(&self, to: &Request<S::Request>, response: &S::Response) -> Result<(), String> {
        self.send(to.mapping, to.identity, response)
    }

    fn send(
        &self,
        mapping: Mapping,
        identity: SampleIdentity,
        response: &S::Response,
    ) -> Result<(), String> {
        let body = cdr_encoding::to_vec::<_, LittleEndian>(response)
            .map_err(|e| format!("{}: {e}", self.name))?;
        let bytes = match mapping {
            Mapping::Enhanced => body,
            Mapping::Cyclone(header) => {
                let mut b = header.to_vec();
                b.extend(body);
                b
            }
        };
        let options = WriteOptionsBuilder::new()
            .source_timestamp(Timestamp::now())
            .related_sample_identity(identity)
            .build();
        self.writer
            .write_with_options(
                Raw {
                    bytes,
                    little_endian: true,
                },
                options,
            )
            .map(|_| ())
            .map_err(|e| format!("{}: reply not sent: {e:?}", self.name))
    }
}
