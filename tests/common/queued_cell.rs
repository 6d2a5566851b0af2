//! The machine's nodes as separate processes with the drives' setpoint queue (issue 48), and
//! their drive trace: what `tests/drive_queue.rs` and `tests/drive_queue_spindle.rs` cut with.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_runtime::config::NetworkConfig;
use ros2_client::ServiceMapping;

use super::common;

const NODES: [&str; 5] = ["io", "plc", "motion", "interpreter", "hmi-bridge"];

/// Lines, arcs both ways and a thread at a speed whose revolution is a whole number of ticks
/// (1000 rpm: 15 ticks of 4 ms), so the thread's start angle is the same in every run.
pub const PART: &str = "O0480
G00 X60 Z5
M03 S1000
G01 X50 Z0 F300
G01 Z-20 F200
G02 X60 Z-25 R5
G03 X70 Z-30 R5
G00 X80 Z5
G00 X48 Z5
G32 Z-15 F1.5
G00 X80
Z5
G00 X47.4
G32 Z-15 F1.5
G00 X80
Z5
M05
M30
";

/// The test's network: loopback, its own domain.
pub fn net(domain: u16) -> NetworkConfig {
    NetworkConfig {
        domain_id: Some(domain),
        interfaces: vec![[127, 0, 0, 1].into()],
        security: None,
    }
}

/// The machine's nodes, each its own process; stopped with SIGTERM so the drives flush their
/// trace.
pub struct Nodes(Vec<(&'static str, Child)>);

impl Nodes {
    pub fn start(config: &Path, dir: &Path) -> Nodes {
        let mut nodes = Nodes(Vec::new());
        for name in NODES {
            let log = std::fs::File::create(dir.join(format!("{name}.log"))).expect("log");
            let child = Command::new(env!("CARGO_BIN_EXE_cnc"))
                .args(["node", name])
                .arg(config)
                .env("RUST_LOG", "warn")
                .stdout(Stdio::from(log.try_clone().expect("log")))
                .stderr(Stdio::from(log))
                .spawn()
                .expect("cnc node runs");
            nodes.0.push((name, child));
        }
        nodes
    }

    pub fn pid(&self, name: &str) -> i32 {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .expect("node")
            .1
            .id() as i32
    }
}

impl Drop for Nodes {
    fn drop(&mut self) {
        for (_, c) in &mut self.0 {
            // SAFETY: kill(2) on our own child's pid.
            unsafe { libc::kill(c.id() as i32, libc::SIGCONT) };
            unsafe { libc::kill(c.id() as i32, libc::SIGTERM) };
        }
        for (_, c) in &mut self.0 {
            let deadline = Instant::now() + Duration::from_secs(10);
            while Instant::now() < deadline && matches!(c.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// One row of the drive trace: tick, depth, underrun, emergency stop, feed hold, index on the
/// queued path, rate and target rate, per axis setpoint, actual, following error, then the spindle's speed
/// and angle.
pub struct Row {
    pub depth: u32,
    pub underrun: bool,
    pub emergency_stop: bool,
    pub hold: bool,
    /// Standing at a block's end for single block (`hold` 2 in the trace).
    pub block_stop: bool,
    pub scale: f64,
    pub target: f64,
    pub setpoint: Vec<f64>,
    pub actual: Vec<f64>,
    pub spindle_rpm: f64,
    pub spindle_angle: f64,
}

pub fn read_trace(path: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(path).expect("drive trace");
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            let num = |s: &str| s.parse::<f64>().expect("number");
            const FIRST_AXIS: usize = 8;
            let axes = (v.len() - FIRST_AXIS - 2) / 3;
            let spindle = FIRST_AXIS + 3 * axes;
            Row {
                spindle_rpm: num(v[spindle]),
                spindle_angle: num(v[spindle + 1]),
                depth: v[1].parse().expect("depth"),
                underrun: v[2] == "1",
                emergency_stop: v[3] == "1",
                hold: v[4] == "1",
                block_stop: v[4] == "2",
                scale: num(v[6]),
                target: num(v[7]),
                setpoint: (0..axes).map(|i| num(v[FIRST_AXIS + 3 * i])).collect(),
                actual: (0..axes).map(|i| num(v[FIRST_AXIS + 1 + 3 * i])).collect(),
            }
        })
        .collect()
}

/// The distinct setpoints in order (bit patterns, so equal means equal to the last bit).
/// How two runs' paths compare: the same number of distinct setpoints, how many of them
/// differ in any bit, and the largest difference (mm).
pub struct Comparison {
    pub same_length: bool,
    pub differing: usize,
    pub largest: f64,
}

impl Comparison {
    /// The paths are the same: bit for bit, except the spindle-locked moves' last bits.
    /// Those follow the simulated spindle's angle, a float summed tick by tick since power-on,
    /// and how many ticks it has summed when a thread starts depends on the PLC's timing (its
    /// own clock), not on the stalls: two undisturbed runs differ there too, by 1e-14 mm.
    pub fn same(&self) -> bool {
        self.same_length && self.largest <= 1e-9
    }

    pub fn word(&self) -> String {
        match (self.same(), self.differing) {
            (true, 0) => "identical".into(),
            (true, n) => format!("same ({n} setpoints differ by ≤ {:.0e} mm)", self.largest),
            (false, _) => format!("DIFFERENT (by {:.3e} mm)", self.largest),
        }
    }
}

pub fn compare(a: &[Vec<u64>], b: &[Vec<u64>]) -> Comparison {
    let mut c = Comparison {
        same_length: a.len() == b.len(),
        differing: 0,
        largest: 0.0,
    };
    for (x, y) in a.iter().zip(b) {
        if x != y {
            c.differing += 1;
            for (p, q) in x.iter().zip(y) {
                let d = (f64::from_bits(*p) - f64::from_bits(*q)).abs();
                c.largest = c.largest.max(d);
            }
        }
    }
    c
}

pub fn moves(rows: &[Row]) -> Vec<Vec<u64>> {
    let mut out: Vec<Vec<u64>> = Vec::new();
    for r in rows {
        let bits: Vec<u64> = r.setpoint.iter().map(|v| v.to_bits()).collect();
        if out.last() != Some(&bits) {
            out.push(bits);
        }
    }
    out
}

/// A machine to cut on: its built-in launch config and namespace.
pub struct Machine {
    pub config: &'static str,
    pub namespace: &'static str,
    pub program: &'static str,
}

pub const LATHE: Machine = Machine {
    config: "sim_lathe.yaml",
    namespace: "lathe1",
    program: PART,
};

/// The mill's part: lines and arcs both ways in X-Y, plunges in Z.
pub const MILL: Machine = Machine {
    config: "sim_mill.yaml",
    namespace: "mill1",
    program: "O0481\nG90 G17 G00 X0 Y0 Z50\nM03 S1000\n",
};

/// A run of `PART` on a lathe with a 100 ms queue, the machine's nodes in their own processes.
pub struct Cut {
    pub nodes: Nodes,
    pub client: CellClient,
    trace: PathBuf,
    pub t0: Instant,
}

impl Cut {
    /// Starts the nodes on `domain` and the part.
    pub fn start(dir: &Path, name: &str, domain: u16) -> Cut {
        Cut::start_program(dir, name, PART, domain)
    }

    /// Starts the nodes of the lathe on `domain` and `program`.
    pub fn start_program(dir: &Path, name: &str, program: &str, domain: u16) -> Cut {
        Cut::start_on(&LATHE, dir, name, program, domain)
    }

    /// Starts the nodes of `machine` on `domain` and `program`.
    pub fn start_on(machine: &Machine, dir: &Path, name: &str, program: &str, domain: u16) -> Cut {
        Cut::start_queued(machine, dir, name, program, (domain, 100.0))
    }

    /// Starts the nodes of `machine` on DDS domain `at.0` with a queue of `at.1` ms, and
    /// `program`.
    pub fn start_queued(
        machine: &Machine,
        dir: &Path,
        name: &str,
        program: &str,
        (domain, queue_ms): (u16, f64),
    ) -> Cut {
        let trace: PathBuf = dir.join(format!("{name}.csv"));
        let base = format!(
            "{}/launch_configs/{}",
            env!("CARGO_MANIFEST_DIR"),
            machine.config
        );
        let text = std::fs::read_to_string(&base).expect("launch config");
        let mut v: serde_yaml::Value = serde_yaml::from_str(&text).expect("yaml");
        v["network"]["domain_id"] = domain.into();
        v["recorder"]["enabled"] = false.into();
        v["hmi"]["web_address"] = "".into();
        v["servo"]["drive_queue_ms"] = queue_ms.into();
        v["servo"]["drive_trace"] = trace.to_string_lossy().to_string().into();
        for file in ["position_file", "memory_file", "parameter_file"] {
            v["machine"][file] = serde_yaml::Value::Null;
        }
        v["plc"]["memory_file"] = serde_yaml::Value::Null;
        let config = dir.join(format!("{name}.yaml"));
        std::fs::write(&config, serde_yaml::to_string(&v).expect("yaml")).expect("config");
        let nodes = Nodes::start(&config, dir);
        let ns = machine.namespace;
        let mut client = CellClient::new(&net(domain), ns, name, ServiceMapping::Enhanced)
            .expect("client")
            .with_timeout(Duration::from_secs(10));
        client
            .wait_ready(Duration::from_secs(90))
            .expect("the machine is ready");
        let r = client.load_program("o0480.nc", program).expect("load");
        assert!(r.accepted, "{}", r.message);
        let r = client.start_program("o0480.nc").expect("start");
        assert!(r.accepted, "{}", r.message);
        Cut {
            nodes,
            client,
            trace,
            t0: Instant::now(),
        }
    }

    /// Stops the motion process `after_ms` after the cycle start for `for_ms`.
    pub fn stall(&self, after_ms: u64, for_ms: u64) {
        let at = self.t0 + Duration::from_millis(after_ms);
        std::thread::sleep(at.saturating_duration_since(Instant::now()));
        let motion = self.nodes.pid("motion");
        // SAFETY: kill(2) on our own child's pid.
        unsafe { libc::kill(motion, libc::SIGSTOP) };
        std::thread::sleep(Duration::from_millis(for_ms));
        unsafe { libc::kill(motion, libc::SIGCONT) };
    }

    /// Waits for the finished part, stops the nodes and returns the drive trace.
    pub fn finish(mut self) -> Vec<Row> {
        common::wait(
            &mut self.client,
            Duration::from_secs(120),
            "the part",
            |c| {
                c.part_count.as_ref().is_some_and(|p| p.count == 1)
                    && c.state
                        .as_ref()
                        .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
            },
        );
        // The drives play the queue's last 100 ms after motion finished.
        std::thread::sleep(Duration::from_millis(500));
        self.stop()
    }

    /// Stops the nodes and returns the drive trace.
    pub fn stop(self) -> Vec<Row> {
        let Cut {
            nodes,
            client,
            trace,
            ..
        } = self;
        drop(client);
        drop(nodes);
        read_trace(&trace)
    }
}

/// Runs `PART` once, stopping the motion process for each `(after_ms, for_ms)` of `stalls`.
pub fn cut(dir: &Path, name: &str, domain: u16, stalls: &[(u64, u64)]) -> Vec<Row> {
    let run = Cut::start(dir, name, domain);
    for &(after, stall) in stalls {
        run.stall(after, stall);
    }
    run.finish()
}
/// The SINUMERIK 802D mill (rigid tapping, G331/G332).
pub const MILL_802D: Machine = Machine {
    config: "sim_mill_802d.yaml",
    namespace: "mill2",
    program: "",
};
