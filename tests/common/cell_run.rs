//! Issue 29's run of a robot cell on `net`: the cell supervisor (its own thread) takes a work
//! order of [`SHORT_PART`](super::SHORT_PART) for each machine, loads it and starts each first
//! part; one robot arm (another thread) follows the supervisor's state and loads the rest. The
//! test's thread is free meanwhile to cut links or kill processes. Observers that are neither
//! read each machine's `robot_handshake` and `part_count` samples, to judge the run.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cnc_cell::robot::Robot;
use cnc_cell::robot_node::{Asked, CellWatch};
use cnc_cell::supervisor::{Order, OrderLine};
use cnc_cell::supervisor_node::Options;
use cnc_msgs::msg::{CellState, PartCount, RobotHandshake};
use cnc_msgs::srv::RobotRequestRequest;
use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::{qos, RosNode};
use ros2_client::dds::Subscription;
use ros2_client::qos::History;

type SupervisorRun = JoinHandle<Result<(CellState, Option<PathBuf>), String>>;
type RobotRun = JoinHandle<Result<(Robot, Vec<Asked>), String>>;

/// A cell at work.
pub struct CellRun {
    pub names: Vec<String>,
    pub parts: u32,
    stop: Arc<AtomicBool>,
    supervisor: Option<SupervisorRun>,
    robot: Option<RobotRun>,
    _observers: Vec<RosNode>,
    handshakes: Vec<Subscription<RobotHandshake>>,
    counts: Vec<Subscription<PartCount>>,
    /// The supervisor's state as the test sees it.
    pub watch: CellWatch,
}

/// What a finished run left.
pub struct Outcome {
    /// Handshake samples with the robot inside (all safe, or the run panicked).
    pub inside: usize,
    /// The supervisor's last state.
    pub state: CellState,
    pub bag: Option<PathBuf>,
    pub robot: Robot,
    pub asked: Vec<Asked>,
    /// Every part-count sample of each machine, in order.
    pub counts: Vec<Vec<PartCount>>,
}

impl CellRun {
    /// Starts the supervisor (order: `parts` parts per machine, liveliness `lease`, audit bag
    /// under `records`) and the robot.
    pub fn start(
        net: &NetworkConfig,
        names: &[&str],
        parts: u32,
        lease: Duration,
        records: Option<PathBuf>,
    ) -> CellRun {
        let mut observers: Vec<RosNode> = names
            .iter()
            .map(|ns| RosNode::new(net, ns, "observer").expect("observer"))
            .collect();
        let deep = |d| qos::state().history(History::KeepLast { depth: d });
        let mut handshakes = Vec::new();
        let mut counts = Vec::new();
        for o in observers.iter_mut() {
            handshakes.push(
                o.dds_subscription_with_qos(&cnc_runtime::topics::ROBOT_HANDSHAKE, deep(10_000))
                    .expect("handshake reader"),
            );
            counts.push(
                o.dds_subscription_with_qos(&cnc_runtime::topics::PART_COUNT, deep(1_000))
                    .expect("part count reader"),
            );
        }
        let order = Order {
            name: "wo-test".into(),
            lines: names
                .iter()
                .map(|ns| OrderLine {
                    machine: (*ns).into(),
                    program: "part.nc".into(),
                    text: super::SHORT_PART.into(),
                    parts,
                })
                .collect(),
        };
        let stop = Arc::new(AtomicBool::new(false));
        let supervisor = {
            let (net, stop) = (net.clone(), stop.clone());
            let options = Options {
                lease,
                records,
                ..Options::default()
            };
            std::thread::spawn(move || {
                cnc_cell::supervisor_node::supervise(&net, order, &options, &stop)
            })
        };
        let robot = {
            let net = net.clone();
            let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
            // The supervisor starts each first part; the robot loads the others.
            let each = vec![parts.saturating_sub(1); names.len()];
            let deadline = Instant::now() + Duration::from_secs(300);
            std::thread::spawn(move || {
                cnc_cell::robot_node::serve_cell(&net, &names, &each, 1.0, deadline)
            })
        };
        CellRun {
            names: names.iter().map(|s| s.to_string()).collect(),
            parts,
            stop,
            supervisor: Some(supervisor),
            robot: Some(robot),
            _observers: observers,
            handshakes,
            counts,
            watch: CellWatch::new(net, "test_watch").expect("cell watch"),
        }
    }

    /// Polls the supervisor's state until `done` holds (panics after `timeout`); when it held.
    pub fn wait(
        &mut self,
        timeout: Duration,
        what: &str,
        done: impl Fn(&CellState) -> bool,
    ) -> Instant {
        let deadline = Instant::now() + timeout;
        loop {
            self.watch.poll();
            if self.watch.last.as_ref().is_some_and(&done) {
                return Instant::now();
            }
            assert!(Instant::now() < deadline, "{what}: {:?}", self.watch.last);
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Waits for the robot to end (the order complete), stops the supervisor, and judges
    /// safety from every handshake sample.
    pub fn finish(mut self) -> Outcome {
        let robot = self.robot.take().expect("robot thread").join();
        self.stop.store(true, Ordering::Relaxed);
        let supervisor = self.supervisor.take().expect("supervisor thread").join();
        let (robot, asked) = robot
            .expect("the robot thread ended")
            .unwrap_or_else(|e| panic!("robot: {e}"));
        let (state, bag) = supervisor
            .expect("the supervisor thread ended")
            .unwrap_or_else(|e| panic!("supervisor: {e}"));
        let mut inside = 0;
        for (ns, w) in self.names.iter().zip(&self.handshakes) {
            while let Ok(Some((h, _))) = w.take() {
                if !h.robot_clear {
                    inside += 1;
                    assert!(
                        h.door_open && !h.spindle_turning && !h.emergency_stop && !h.cycle_active,
                        "{ns}: the robot inside an unsafe machine: {h:?}"
                    );
                }
            }
        }
        let counts = self
            .counts
            .iter()
            .map(|c| {
                let mut v = Vec::new();
                while let Ok(Some((p, _))) = c.take() {
                    v.push(p);
                }
                v
            })
            .collect();
        Outcome {
            inside,
            state,
            bag,
            robot,
            asked,
            counts,
        }
    }
}

impl Drop for CellRun {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

impl Outcome {
    /// Cycles the robot started at machine `i` (accepted cycle-start requests).
    pub fn cycles_started(&self, i: usize) -> usize {
        self.asked
            .iter()
            .filter(|a| a.machine == i && a.accepted && a.code == RobotRequestRequest::CYCLE_START)
            .count()
    }

    /// The supervisor's counts and cycle times equal each machine's own: its part counter
    /// from where the order began, and the cycle time of every part it counted since.
    pub fn check_counts(&self, parts: u32) {
        assert!(self.state.complete, "{:?}", self.state);
        for (m, samples) in self.state.machines.iter().zip(&self.counts) {
            let last = samples.last().map_or(0, |p| p.count);
            assert_eq!(m.count, parts, "{}: {m:?}", m.name);
            assert_eq!(
                last - m.counter_at_start,
                parts,
                "{}: the machine's counter",
                m.name
            );
            let mut own = Vec::new();
            let mut seen = m.counter_at_start;
            for p in samples {
                if p.count > seen {
                    own.push(p.last_cycle_time);
                    seen = p.count;
                }
            }
            assert_eq!(m.cycle_times, own, "{}: cycle times", m.name);
            println!(
                "{}: {} parts, cycle times {:?} s (the machine's own part counter {} → {last})",
                m.name, m.count, m.cycle_times, m.counter_at_start
            );
        }
    }
}

/// `cnc audit verify` on a bag: its verdict; fails the test unless the chain is intact.
pub fn audit_verify(bag: &std::path::Path) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["audit", "verify"])
        .arg(bag)
        .output()
        .expect("cnc audit verify runs");
    let verdict = String::from_utf8_lossy(&out.stdout).trim().to_string();
    assert!(out.status.success(), "{verdict}");
    verdict
}

/// A whole run on `net` without faults: `parts_each` parts per machine after the first the
/// supervisor starts; counts and safety judged. Returns the samples with the robot inside.
pub fn robot_tends(net: &NetworkConfig, names: &[&str], parts_each: u32) -> usize {
    let t0 = Instant::now();
    let run = CellRun::start(net, names, 1 + parts_each, Duration::from_secs(2), None);
    let out = run.finish();
    println!(
        "cell: order complete after {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    out.check_counts(1 + parts_each);
    for i in 0..names.len() {
        assert_eq!(
            out.cycles_started(i),
            parts_each as usize,
            "{:?}",
            out.robot.machines
        );
    }
    println!("samples with the robot inside: {}, all safe", out.inside);
    out.inside
}
