//! iceoryx2 channels for the fixed-size payloads of `cnc_msgs::servo` and `cnc_msgs::signals`.
//!
//! Service names are `cnc/<instance>/<channel>`, where the instance is unique per running cell
//! (namespace plus DDS domain), so two cells, or two tests, never share a channel.

use std::fmt::Debug;
use std::time::Duration;

use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;

/// One iceoryx2 node per thread (iceoryx2 nodes are not shared across threads).
pub struct ShmNode {
    node: Node<ipc::Service>,
    instance: String,
}

/// Sends the latest value of `T`.
pub struct Sender<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Option<Notifier<ipc::Service>>,
}

/// Receives values of `T`; `latest` drains to the newest.
pub struct Receiver<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T, ()>,
    listener: Option<Listener<ipc::Service>>,
}

fn err(what: &str, e: impl Debug) -> String {
    format!("iceoryx2 {what}: {e:?}")
}

/// iceoryx2's global config, looked up once with its log at errors only: without an
/// `iceoryx2.toml` (the usual case; its defaults are what the cell is built for) the lookup
/// warns "No config file was loaded" on every start, which tells a user nothing. After the
/// lookup the log level is `IOX2_LOG_LEVEL`, else iceoryx2's default (info).
pub(crate) fn quiet_global_config() -> &'static iceoryx2::config::Config {
    static CONFIG: std::sync::OnceLock<&'static iceoryx2::config::Config> =
        std::sync::OnceLock::new();
    CONFIG.get_or_init(|| {
        set_log_level(LogLevel::Error);
        let config = iceoryx2::config::Config::global_config();
        set_log_level_from_env_or(LogLevel::Info);
        config
    })
}

/// Removes what the iceoryx2 nodes of dead processes left behind (a controller killed with
/// SIGKILL leaves its publishers registered in its services), waiting for a cleanup another
/// process is doing, before this controller's nodes open their channels. iceoryx2 also cleans
/// when a node is created, but without waiting: the nodes of one cell start together, and one
/// skipped a dead publisher another was still removing. Returns the nodes cleaned and those that
/// could not be.
pub fn clean_dead_nodes() -> Result<(u64, u64), String> {
    let node = NodeBuilder::new()
        .config(quiet_global_config())
        .create::<ipc::Service>()
        .map_err(|e| err("node", e))?;
    let state = node.blocking_cleanup_dead_nodes(Duration::from_secs(2));
    Ok((state.cleanups, state.failed_cleanups))
}

impl ShmNode {
    pub fn new(instance: &str, node_name: &str) -> Result<Self, String> {
        let name: NodeName = node_name.try_into().map_err(|e| err("node name", e))?;
        let node = NodeBuilder::new()
            .name(&name)
            .config(quiet_global_config())
            .create::<ipc::Service>()
            .map_err(|e| err("node", e))?;
        Ok(ShmNode {
            node,
            instance: instance.to_string(),
        })
    }

    fn service_name(&self, channel: &str) -> Result<ServiceName, String> {
        format!("cnc/{}/{}", self.instance, channel)
            .as_str()
            .try_into()
            .map_err(|e| err("service name", e))
    }

    /// The publish-subscribe service of `channel`: `depth` values buffered for a subscriber
    /// (4 for a channel read as its newest value), the newest kept for late subscribers.
    fn service<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        channel: &str,
        depth: usize,
    ) -> Result<PortFactory<ipc::Service, T, ()>, String> {
        self.node
            .service_builder(&self.service_name(channel)?)
            .publish_subscribe::<T>()
            .subscriber_max_buffer_size(depth)
            .history_size(1)
            .open_or_create()
            .map_err(|e| err(channel, e))
    }

    /// The event service that wakes the receiver of `channel`.
    fn wake_event(&self, channel: &str) -> Result<EventFactory<ipc::Service>, String> {
        self.node
            .service_builder(&self.service_name(&format!("{channel}/wake"))?)
            .event()
            .open_or_create()
            .map_err(|e| err(channel, e))
    }

    /// Sender on `channel`; with `wake`, it also notifies the receiver's listener on each send.
    pub fn sender<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        channel: &str,
        wake: bool,
    ) -> Result<Sender<T>, String> {
        self.stream_sender(channel, wake, LATEST_DEPTH)
    }

    /// Sender on a stream `channel` whose receiver takes every value in order (up to
    /// `depth` unread): the drives' setpoint queue and their per-tick feedback.
    pub fn stream_sender<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        channel: &str,
        wake: bool,
        depth: usize,
    ) -> Result<Sender<T>, String> {
        let publisher = self
            .service::<T>(channel, depth)?
            .publisher_builder()
            .create()
            .map_err(|e| err(channel, e))?;
        let notifier = match wake {
            true => Some(
                self.wake_event(channel)?
                    .notifier_builder()
                    .create()
                    .map_err(|e| err(channel, e))?,
            ),
            false => None,
        };
        Ok(Sender {
            publisher,
            notifier,
        })
    }

    pub fn receiver<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        channel: &str,
        wake: bool,
    ) -> Result<Receiver<T>, String> {
        self.stream_receiver(channel, wake, LATEST_DEPTH)
    }

    /// Receiver of a stream `channel` (see [`ShmNode::stream_sender`]), read with
    /// [`Receiver::take_all`].
    pub fn stream_receiver<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        channel: &str,
        wake: bool,
        depth: usize,
    ) -> Result<Receiver<T>, String> {
        let subscriber = self
            .service::<T>(channel, depth)?
            .subscriber_builder()
            .create()
            .map_err(|e| err(channel, e))?;
        let listener = match wake {
            true => Some(
                self.wake_event(channel)?
                    .listener_builder()
                    .create()
                    .map_err(|e| err(channel, e))?,
            ),
            false => None,
        };
        Ok(Receiver {
            subscriber,
            listener,
        })
    }
}

impl<T: Debug + ZeroCopySend + Copy + 'static> Sender<T> {
    pub fn send(&self, value: T) -> Result<(), String> {
        self.publisher
            .send_copy(value)
            .map_err(|e| err("send", e))?;
        if let Some(n) = &self.notifier {
            n.notify().map_err(|e| err("notify", e))?;
        }
        Ok(())
    }
}

impl<T: Debug + ZeroCopySend + Copy + 'static> Receiver<T> {
    /// The newest value received since the last call, if any.
    pub fn latest(&self) -> Result<Option<T>, String> {
        let mut last = None;
        while let Some(sample) = self.subscriber.receive().map_err(|e| err("receive", e))? {
            last = Some(*sample);
        }
        Ok(last)
    }

    /// Every value received since the last call, oldest first, appended to `out`.
    pub fn take_all(&self, out: &mut Vec<T>) -> Result<(), String> {
        while let Some(sample) = self.subscriber.receive().map_err(|e| err("receive", e))? {
            out.push(*sample);
        }
        Ok(())
    }

    /// Waits up to `timeout` until a value is there to take (needs `wake`); false if none
    /// came. The value stays for [`Receiver::take_all`].
    pub fn wait_for_any(&self, timeout: Duration) -> Result<bool, String> {
        if self
            .subscriber
            .has_samples()
            .map_err(|e| err("receive", e))?
        {
            return Ok(true);
        }
        match &self.listener {
            Some(l) if !timeout.is_zero() => match l.timed_wait(|_| {}, timeout) {
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(e) => return Err(err("wait", e)),
            },
            _ => {}
        }
        self.subscriber.has_samples().map_err(|e| err("receive", e))
    }

    /// Waits up to `timeout` for a value (needs `wake`) and returns the newest. A wake-up whose
    /// value was already taken by [`Receiver::latest`] does not end the wait.
    pub fn wait(&self, timeout: Duration) -> Result<Option<T>, String> {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if let Some(value) = self.latest()? {
                return Ok(Some(value));
            }
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            match &self.listener {
                Some(l) if !left.is_zero() => match l.timed_wait(|_| {}, left) {
                    // A signal, or the process stopped and continued: wait on for what is left.
                    Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                    Err(e) => return Err(err("wait", e)),
                },
                _ => return Ok(None),
            }
        }
    }
}

/// The buffer of a channel read as its newest value.
const LATEST_DEPTH: usize = 4;

/// Channel names.
pub mod channel {
    pub const SETPOINT: &str = "servo/setpoint";
    pub const FEEDBACK: &str = "servo/feedback";
    pub const F_IMAGE: &str = "signals/f";
    pub const G_IMAGE: &str = "signals/g";
    pub const X_IMAGE: &str = "signals/x";
    pub const Y_IMAGE: &str = "signals/y";
    /// With the drives' setpoint queue (issue 48): setpoints stamped with their drive tick,
    /// the brake tail, and the drives' feedback of every tick.
    pub const SETPOINT_QUEUE: &str = "servo/queue";
    pub const BRAKE_TAIL: &str = "servo/brake_tail";
    pub const FEEDBACK_STREAM: &str = "servo/feedback_stream";
    /// Motion's feed hold, cycle starts and resets, to the drives (issue 48).
    pub const DRIVE_CONTROL: &str = "servo/drive_control";
}

/// Instance name of a cell: namespace plus domain, so cells and tests never share channels.
pub fn instance(namespace: &str, domain: u16) -> String {
    format!("{namespace}_d{domain}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use cnc_msgs::servo::ServoSetpoint;

    #[test]
    fn values_cross_shared_memory_with_wake_up() {
        let instance = format!("test_shm_{}", std::process::id());
        let node = ShmNode::new(&instance, "test_node").unwrap();
        let tx = node
            .sender::<ServoSetpoint>(channel::SETPOINT, true)
            .unwrap();
        let rx = node
            .receiver::<ServoSetpoint>(channel::SETPOINT, true)
            .unwrap();
        let other = node.receiver::<ServoSetpoint>("other", false).unwrap();
        for seq in 1..=3 {
            tx.send(ServoSetpoint {
                seq,
                ..Default::default()
            })
            .unwrap();
        }
        assert_eq!(other.latest().unwrap(), None, "channels are separate");
        let got = rx.wait(Duration::from_millis(100)).unwrap().unwrap();
        assert_eq!(got.seq, 3, "latest wins");
        // The three wake-ups are still pending but their values are taken: wait must not return
        // early with nothing.
        let t0 = std::time::Instant::now();
        assert_eq!(rx.wait(Duration::from_millis(30)).unwrap(), None);
        assert!(
            t0.elapsed() >= Duration::from_millis(30),
            "returned after {:?}",
            t0.elapsed()
        );
        // Values sent periodically from another thread end the wait early. (A publisher that
        // sends once right after it is created can lose that sample before the subscriber has
        // connected to it; the real senders send every period.)
        let sender = std::thread::spawn(move || {
            let node = ShmNode::new(&instance, "test_sender").unwrap();
            let tx = node
                .sender::<ServoSetpoint>(channel::SETPOINT, true)
                .unwrap();
            for _ in 0..100 {
                std::thread::sleep(Duration::from_millis(5));
                tx.send(ServoSetpoint {
                    seq: 9,
                    ..Default::default()
                })
                .unwrap();
            }
        });
        let t0 = std::time::Instant::now();
        assert_eq!(
            rx.wait(Duration::from_secs(5)).unwrap().map(|s| s.seq),
            Some(9)
        );
        assert!(t0.elapsed() < Duration::from_secs(4));
        sender.join().unwrap();
    }
}
