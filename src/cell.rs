//! Starts every node of one machine in this process, each with its own DDS participant and its
//! own threads, exactly as they would run as separate processes.

use std::path::PathBuf;
use std::thread::JoinHandle;

use cnc_runtime::instance_lock::{self, InstanceLock};
use cnc_runtime::shm::instance;
use cnc_runtime::{LaunchConfig, Shutdown};

pub struct Cell {
    /// Each node's hold on this machine's instance on the host, taken before anything starts
    /// (a second controller of the same namespace and domain is refused untouched), released
    /// after every node has stopped.
    locks: Vec<InstanceLock>,
    shutdown: Shutdown,
    threads: Vec<(&'static str, JoinHandle<Result<String, String>>)>,
    /// The recorder stops after the other nodes, so it keeps what they sent last.
    recorder: Option<(Shutdown, JoinHandle<Result<PathBuf, String>>)>,
}

/// How long the recorder goes on taking samples after the other nodes stopped.
const RECORDER_GRACE: std::time::Duration = std::time::Duration::from_millis(300);

impl Cell {
    pub fn start(cfg: &LaunchConfig) -> Result<Cell, String> {
        // Not the panel on the network without logins: refused before anything runs.
        cnc_hmi_bridge::web::check(&cfg.hmi)?;
        let domain = cfg.network.effective_domain_id()?;
        let inst = instance(&cfg.machine.namespace, domain);
        let nodes = [
            "io",
            "plc",
            "motion",
            "interpreter",
            "hmi_bridge",
            "recorder",
        ];
        let locks = nodes
            .iter()
            .filter(|n| **n != "recorder" || cfg.recorder.enabled)
            .map(|n| instance_lock::acquire(&inst, n))
            .collect::<Result<Vec<_>, _>>()?;
        // The instance is ours now: what a killed run of it left in shared memory goes before
        // any node opens a channel.
        clean_dead_nodes();
        let shutdown = Shutdown::default();
        let mut cell = Cell {
            locks,
            shutdown: shutdown.clone(),
            threads: Vec::new(),
            recorder: None,
        };
        // The recorder first, so it hears the other nodes from their first message.
        if cfg.recorder.enabled {
            let (c, s) = (cfg.clone(), Shutdown::default());
            let stop = s.clone();
            let (tx, rx) = std::sync::mpsc::channel();
            let h = std::thread::Builder::new()
                .name("recorder".into())
                .spawn(move || {
                    cnc_recorder::node::run_then(c, s, move || {
                        let _ = tx.send(());
                    })
                })
                .map_err(|e| format!("recorder: {e}"))?;
            // The other nodes start once the recorder listens (or has failed: its error is
            // reported by `failed_node`).
            let _ = rx.recv_timeout(std::time::Duration::from_secs(10));
            cell.recorder = Some((stop, h));
        }
        let spawn = |name: &'static str, f: Box<dyn FnOnce() -> Result<String, String> + Send>| {
            std::thread::Builder::new()
                .name(name.into())
                .spawn(f)
                .map_err(|e| format!("{name}: {e}"))
        };
        // io first: motion starts from the position the drives report.
        let (c, i, s) = (cfg.clone(), inst.clone(), shutdown.clone());
        cell.threads.push((
            "io",
            spawn("io", Box::new(move || cnc_io::node::run(c, i, s)))?,
        ));
        let (c, i, s) = (cfg.clone(), inst.clone(), shutdown.clone());
        cell.threads.push((
            "plc",
            spawn(
                "plc",
                Box::new(move || cnc_plc::node::run(c, i, s).map(|_| String::new())),
            )?,
        ));
        let (c, i, s) = (cfg.clone(), inst.clone(), shutdown.clone());
        cell.threads.push((
            "motion",
            spawn("motion", Box::new(move || cnc_motion::node::run(c, i, s)))?,
        ));
        let (c, i, s) = (cfg.clone(), inst.clone(), shutdown.clone());
        cell.threads.push((
            "interpreter",
            spawn(
                "interpreter",
                Box::new(move || cnc_task::node::run(c, i, s).map(|_| String::new())),
            )?,
        ));
        let (c, s) = (cfg.clone(), shutdown);
        cell.threads.push((
            "hmi_bridge",
            spawn(
                "hmi_bridge",
                Box::new(move || cnc_hmi_bridge::node::run(c, s).map(|_| String::new())),
            )?,
        ));
        Ok(cell)
    }

    /// A node that has stopped on its own, with its error.
    pub fn failed_node(&self) -> Option<&'static str> {
        if self.recorder.as_ref().is_some_and(|(_, h)| h.is_finished()) {
            return Some("recorder");
        }
        self.threads
            .iter()
            .find(|(_, h)| h.is_finished())
            .map(|(n, _)| *n)
    }

    /// Stops every node; returns the servo statistics line and any node errors.
    pub fn stop(self) -> (String, Vec<String>) {
        self.shutdown.request();
        let mut summary = String::new();
        let mut errors = Vec::new();
        for (name, h) in self.threads {
            match h.join() {
                Ok(Ok(s)) if !s.is_empty() => {
                    if !summary.is_empty() {
                        summary.push('\n');
                    }
                    summary.push_str(&s);
                }
                Ok(Ok(_)) => {}
                Ok(Err(e)) => errors.push(format!("{name}: {e}")),
                Err(_) => errors.push(format!("{name}: panicked")),
            }
        }
        if let Some((stop, h)) = self.recorder {
            std::thread::sleep(RECORDER_GRACE);
            stop.request();
            match h.join() {
                Ok(Ok(dir)) => log::info!("recording in {}", dir.display()),
                Ok(Err(e)) => errors.push(format!("recorder: {e}")),
                Err(_) => errors.push("recorder: panicked".into()),
            }
        }
        drop(self.locks);
        (summary, errors)
    }
}

/// Removes the iceoryx2 resources of dead processes (D65's instance lock is held, so none of
/// them is this instance's live node); a failure is logged, not fatal: the nodes' own cleanup
/// still runs.
pub fn clean_dead_nodes() {
    match cnc_runtime::shm::clean_dead_nodes() {
        Ok((0, 0)) => {}
        Ok((cleaned, 0)) => log::info!("shared memory: {cleaned} dead nodes' resources removed"),
        Ok((cleaned, failed)) => log::warn!(
            "shared memory: {cleaned} dead nodes' resources removed, {failed} could not be"
        ),
        Err(e) => log::warn!("shared memory: dead nodes not cleaned: {e}"),
    }
}
