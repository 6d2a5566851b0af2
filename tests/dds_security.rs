//! Issue 25, must-show 2: the machine's nodes as separate processes (`cnc node`), DDS Security
//! on with a keystore made by `cnc security init`. The supervisor's identity runs a part; the
//! robot's may call `robot_request` and not `start_program`; an observer's reads state and
//! commands nothing; a participant without credentials (rustdds, and Cyclone DDS) hears
//! nothing and moves nothing.

mod common;

use std::process::{Child, Command, Stdio};
use std::time::Duration;

use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_msgs::srv::RobotRequestRequest;
use cnc_runtime::config::{DdsSecurity, NetworkConfig};
use ros2_client::ServiceMapping;

const DOMAIN: u16 = 93;
const NODES: [&str; 5] = ["io", "plc", "motion", "interpreter", "hmi-bridge"];

fn network(keystore: &std::path::Path, enclave: Option<&str>) -> NetworkConfig {
    NetworkConfig {
        domain_id: Some(DOMAIN),
        interfaces: vec![[127, 0, 0, 1].into()],
        security: Some(DdsSecurity {
            keystore: keystore.to_path_buf(),
            enclave: enclave.map(String::from),
        }),
    }
}

fn client(net: &NetworkConfig, name: &str) -> CellClient {
    CellClient::new(net, "lathe1", name, ServiceMapping::Enhanced)
        .expect("client")
        .with_timeout(Duration::from_secs(10))
}

/// A client with the identity `enclave`, once it hears the machine (at most `wait` seconds).
fn hearing(keystore: &std::path::Path, enclave: &str, wait: u64) -> CellClient {
    let name = enclave.rsplit('/').next().unwrap_or(enclave);
    let mut c = client(&network(keystore, Some(enclave)), name);
    if let Err(e) = c.wait_ready(Duration::from_secs(wait)) {
        panic!("{enclave}: {e}");
    }
    c
}

/// Each node of the machine in a process of its own, killed when the test ends.
struct Nodes(Vec<Child>);

impl Drop for Nodes {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

#[test]
fn only_credentials_open_the_machine() {
    let dir = common::fresh_dir("dds_security");
    let keystore = dir.join("keystore");
    let init = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["security", "init"])
        .arg(&keystore)
        .args(["--machine", "lathe1"])
        .output()
        .expect("cnc security init runs");
    assert!(init.status.success(), "{init:?}");
    // A second init would replace the cell's authority: refused.
    let again = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["security", "init"])
        .arg(&keystore)
        .args(["--machine", "lathe1"])
        .output()
        .expect("cnc security init runs");
    assert!(!again.status.success());

    let ks = keystore.to_string_lossy().to_string();
    let config = common::sim_lathe_file(&dir, "secure.yaml", DOMAIN, |v| {
        v["network"]["security"]["keystore"] = ks.clone().into();
    });
    let mut nodes = Nodes(Vec::new());
    for name in NODES {
        let log = std::fs::File::create(dir.join(format!("{name}.log"))).expect("log");
        nodes.0.push(
            Command::new(env!("CARGO_BIN_EXE_cnc"))
                .args(["node", name])
                .arg(&config)
                .env("RUST_LOG", "warn")
                .stdout(Stdio::from(log.try_clone().expect("log")))
                .stderr(Stdio::from(log))
                .spawn()
                .expect("cnc node runs"),
        );
    }

    // The supervisor's identity: loads, starts, and the part is made.
    let mut supervisor = hearing(&keystore, "/cell/supervisor", 90);
    let r = supervisor
        .load_program("secure.nc", common::SHORT_PART)
        .expect("load answered");
    assert!(r.accepted, "{}", r.message);
    let r = supervisor
        .start_program("secure.nc")
        .expect("start answered");
    assert!(r.accepted, "{}", r.message);
    common::wait(&mut supervisor, Duration::from_secs(60), "one part", |c| {
        c.part_count.as_ref().is_some_and(|p| p.count == 1)
            && c.state
                .as_ref()
                .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
    });
    // The axes are telemetry: where they stand is what the samples say once they agree. The
    // first sample heard under DDS Security may be one the writer repairs from before the
    // run (the power-on position was seen here), so one sample is not enough.
    let axes_after_part = settled_positions(&mut supervisor);

    // The robot's identity: robot_request is answered; start and load are refused by DDS
    // Security before anything is sent.
    let mut robot = hearing(&keystore, "/cell/robot", 60);
    let r = robot
        .robot_request(RobotRequestRequest::CLEAR)
        .expect("robot_request answered");
    println!("robot_request CLEAR: {} {}", r.accepted, r.message);
    assert!(r.accepted, "{}", r.message);
    for (what, result) in [
        (
            "start_program",
            robot.start_program("secure.nc").map(|r| r.message),
        ),
        (
            "load_program",
            robot.load_program("x.nc", "M30\n").map(|r| r.message),
        ),
    ] {
        let e = result.expect_err(what);
        assert!(e.contains("not allowed by security"), "{what}: {e}");
    }

    // An observer hears state and may call nothing, not even robot_request.
    let mut observer = hearing(&keystore, "/cell/observer", 60);
    let e = observer
        .robot_request(RobotRequestRequest::CYCLE_START)
        .expect_err("an observer's robot_request");
    assert!(e.contains("not allowed by security"), "{e}");

    // Without credentials (rustdds): the machine is not heard.
    let open = NetworkConfig {
        domain_id: Some(DOMAIN),
        interfaces: vec![[127, 0, 0, 1].into()],
        security: None,
    };
    let mut stranger = client(&open, "stranger");
    assert!(
        stranger.wait_ready(Duration::from_secs(8)).is_err(),
        "a participant without credentials heard the machine: {:?}",
        stranger.state
    );
    drop(stranger);

    // Without credentials (Cyclone DDS): hears nothing, its writes and calls reach nothing.
    common::passing_peer("outsider_secure_peer.py", DOMAIN);

    // Nothing moved: the supervisor still sees the finished part.
    std::thread::sleep(Duration::from_secs(1));
    supervisor.poll();
    assert_eq!(
        supervisor.part_count.as_ref().map(|p| p.count),
        Some(1),
        "no further part"
    );
    assert_eq!(
        supervisor.state.as_ref().map(|s| s.execution),
        Some(MachineState::PROGRAM_COMPLETED)
    );
    assert_eq!(positions(&supervisor), axes_after_part, "no axis moved");

    drop(nodes);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The axes' positions once four readings half a second apart agree (within 30 s): the axes
/// come 25 times a second, so two seconds of one value is where they stand.
fn settled_positions(c: &mut CellClient) -> Vec<(String, i64)> {
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    let (mut last, mut same) = (Vec::new(), 0);
    while std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(500));
        c.poll();
        let now = positions(c);
        same = if !now.is_empty() && now == last {
            same + 1
        } else {
            0
        };
        if same == 3 {
            return now;
        }
        last = now;
    }
    panic!("the axes did not settle within 30 s: last {last:?}");
}

fn positions(c: &CellClient) -> Vec<(String, i64)> {
    c.axes
        .as_ref()
        .map(|a| {
            a.axes
                .iter()
                .map(|x| (x.name.clone(), (x.actual_position * 1000.0).round() as i64))
                .collect()
        })
        .unwrap_or_default()
}

/// A cell launch file whose machines run DDS Security is refused with the reason (D113): the
/// one-process demo cell does not work under security.
#[test]
fn a_one_process_cell_under_security_is_refused_with_the_reason() {
    let dir = common::fresh_dir("dds_security_cell");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let lathe = std::fs::read_to_string(root.join("launch_configs/sim_lathe.yaml"))
        .expect("sim_lathe.yaml")
        .replacen(
            "network:\n",
            "network:\n  security: {keystore: keystore}\n",
            1,
        );
    std::fs::write(dir.join("sim_lathe.yaml"), lathe).expect("written");
    std::fs::write(
        dir.join("cell.yaml"),
        std::fs::read_to_string(root.join("launch_configs/cell_two_lathes.yaml"))
            .expect("cell file")
            .replace(
                "../examples/lathe/robot_part.nc",
                &root.join("examples/lathe/robot_part.nc").to_string_lossy(),
            ),
    )
    .expect("written");
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(dir.join("cell.yaml"))
        .output()
        .expect("cnc runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("DDS Security is on: run each machine in its own process"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
