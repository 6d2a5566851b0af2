//! What the cell tests share: the simulated lathe's launch config for one test.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use cnc_runtime::LaunchConfig;

pub mod cell_run;
pub mod wire;
#[allow(unused_imports)]
pub use cell_run::robot_tends;

/// `launch_configs/sim_lathe.yaml` for a cell run as its own process (`cnc run`), written as
/// `name` into `dir`, where its kept files go too (the config's paths are relative to it): DDS
/// `domain`, no recorder, no web panel, no alarms for servo lateness; `edit` changes more.
#[allow(dead_code)]
pub fn sim_lathe_file(
    dir: &Path,
    name: &str,
    domain: u16,
    edit: impl FnOnce(&mut serde_yaml::Value),
) -> PathBuf {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/launch_configs/sim_lathe.yaml");
    let text = std::fs::read_to_string(path).expect("sim_lathe.yaml");
    let mut v: serde_yaml::Value = serde_yaml::from_str(&text).expect("yaml");
    v["network"]["domain_id"] = domain.into();
    v["recorder"]["enabled"] = false.into();
    v["hmi"]["web_address"] = "".into();
    v["servo"]["late_warning_ms"] = 60000.0.into();
    v["servo"]["late_alarm_ticks"] = 1_000_000u32.into();
    edit(&mut v);
    let file = dir.join(name);
    std::fs::write(&file, serde_yaml::to_string(&v).expect("yaml")).expect("config written");
    file
}

/// `cnc run <config>` as its own process, its output in `log`.
#[allow(dead_code)]
pub fn cnc_run(config: &Path, log: &Path) -> Child {
    let out = std::fs::File::create(log).expect("log");
    Command::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(config)
        .stdout(Stdio::from(out.try_clone().expect("log")))
        .stderr(Stdio::from(out))
        .spawn()
        .expect("cnc runs")
}

/// A `cnc run` process that is killed when the test ends, passed or failed.
#[allow(dead_code)]
pub struct KillOnDrop(pub Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `launch_configs/sim_lathe.yaml` for one test: see [`machine`].
#[allow(dead_code)]
pub fn sim_lathe(domain: u16) -> LaunchConfig {
    machine("sim_lathe", domain)
}

/// `launch_configs/<name>.yaml` in DDS `domain` (one per test, so tests never hear each
/// other), with no kept memory (part count, variables, position and programs start empty; the
/// PLC comes up as at its first power-up), no parameter file, no recorder
/// (`tests/recording.rs` tests that), no web panel and no alarms for servo lateness.
#[allow(dead_code)]
pub fn machine(name: &str, domain: u16) -> LaunchConfig {
    let path = format!("{}/launch_configs/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("the launch config");
    let mut cfg = LaunchConfig::from_yaml(&text).expect("the launch config parses");
    cfg.network.domain_id = Some(domain);
    cfg.plc.memory_file = None;
    cfg.machine.memory_file = None;
    cfg.machine.msg_file = None;
    cfg.machine.position_file = None;
    cfg.machine.parameter_file = None;
    cfg.machine.program_directory = None;
    cfg.recorder.enabled = false;
    cfg.hmi.web_address = String::new();
    // Timing is not what the cell tests test: on a busy machine a late servo tick must not
    // raise the lateness warning or the overrun alarm (`tests/realtime.rs` and the unit
    // tests of `LateWatch` test those).
    cfg.servo.late_warning_ms = Some(60_000.0);
    cfg.servo.late_alarm_ticks = u32::MAX;
    cfg
}

/// Runs `tests/interop/<script>` with the venv's Python (PyPI `cyclonedds`) as a participant in
/// `domain`, on loopback only like the cell. `scripts/test.sh` creates the venv; without it the
/// calling test fails, it does not skip.
#[allow(dead_code)]
pub fn cyclone_peer(script: &str, domain: u16) -> std::process::Output {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let python = std::env::var("CNC_PYTHON")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|_| root.join("target/venv/bin/python"));
    assert!(
        python.exists(),
        "{} missing: run scripts/test.sh, which creates the venv with cyclonedds",
        python.display()
    );
    let mut peer = std::process::Command::new(&python);
    peer.arg(root.join("tests/interop").join(script))
        .args(["--domain", &domain.to_string()])
        .env("CYCLONEDDS_URI", "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" multicast=\"true\"/></Interfaces></General></Domain></CycloneDDS>")
        .env("PEER_LIMIT_S", PEER_LIMIT.as_secs().to_string());
    output_within(&mut peer, PEER_LIMIT + std::time::Duration::from_secs(30))
}

/// How long a peer may run: it prints its threads' stacks and exits after this (its own
/// watchdog), and is killed 30 s later if even that did not happen.
const PEER_LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

/// The output of `cmd`, which must end within `limit`: a process nobody here wrote (a DDS
/// peer, a browser, a protocol client) that hangs is killed, and the test fails with what it
/// printed so far instead of waiting for CI's own timeout.
pub fn output_within(cmd: &mut Command, limit: std::time::Duration) -> std::process::Output {
    use std::io::Read;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{cmd:?} does not start: {e}"));
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut bytes);
            }
            bytes
        })
    };
    let out = drain(child.stdout.take().map(|p| Box::new(p) as _));
    let err = drain(child.stderr.take().map(|p| Box::new(p) as _));
    let deadline = std::time::Instant::now() + limit;
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for a child") {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            let (out, err) = (
                out.join().unwrap_or_default(),
                err.join().unwrap_or_default(),
            );
            panic!(
                "{cmd:?} still ran after {limit:?} and was killed; it printed:\n{}\n{}",
                String::from_utf8_lossy(&out),
                String::from_utf8_lossy(&err)
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    std::process::Output {
        status,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
    }
}

/// Runs `tests/interop/<script>` as [`cyclone_peer`] does, prints what it printed and fails the
/// calling test unless the peer passed; returns its output.
#[allow(dead_code)]
pub fn passing_peer(script: &str, domain: u16) -> String {
    let out = cyclone_peer(script, domain);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{script} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Starts the cell of `cfg`, runs a [`passing_peer`] on its domain, stops the cell and fails
/// if any node ended with an error (a panic included); returns the peer's output.
#[allow(dead_code)]
pub fn peer_against_cell(cfg: &LaunchConfig, script: &str) -> String {
    let domain = cfg.network.domain_id.expect("a test's own domain");
    let cell = cnc::cell::Cell::start(cfg).expect("the cell starts");
    let stdout = passing_peer(script, domain);
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    stdout
}

/// A node outside the machine that follows `/lathe1/command_events`, as an auditor would.
#[allow(dead_code)]
pub struct Auditor {
    pub node: cnc_runtime::dds::RosNode,
    events: ros2_client::dds::Subscription<cnc_msgs::msg::CommandEvent>,
}

#[allow(dead_code)]
impl Auditor {
    pub fn new(cfg: &LaunchConfig) -> Auditor {
        use cnc_runtime::topics::COMMAND_EVENTS;
        let mut node = cnc_runtime::dds::RosNode::new(&cfg.network, "lathe1", "auditor")
            .expect("auditor node");
        let qos = COMMAND_EVENTS
            .qos()
            .history(ros2_client::qos::History::KeepLast { depth: 1000 });
        let events = node
            .dds_subscription_with_qos(&COMMAND_EVENTS, qos)
            .expect("command events");
        Auditor { node, events }
    }

    /// The command events that arrived since the last call.
    pub fn events(&self) -> Vec<cnc_msgs::msg::CommandEvent> {
        let mut seen = Vec::new();
        while let Ok(Some((e, _))) = self.events.take() {
            seen.push(e);
        }
        seen
    }
}

/// A client of the machine `lathe1` under the node name `name` (10 s per call), once the
/// machine reports a state other than WAIT, within `wait`.
#[allow(dead_code)]
pub fn ready_client(
    cfg: &LaunchConfig,
    name: &str,
    wait: std::time::Duration,
) -> cnc_cell::client::CellClient {
    let mut c = cnc_cell::client::CellClient::new(
        &cfg.network,
        "lathe1",
        name,
        ros2_client::ServiceMapping::Enhanced,
    )
    .expect("client")
    .with_timeout(std::time::Duration::from_secs(10));
    c.wait_ready(wait).expect("the machine ready");
    c
}

/// Turns the mode switch through the `set_mode` service; a refusal fails the test.
#[allow(dead_code)]
pub fn set_mode(c: &mut cnc_cell::client::CellClient, mode: u8) {
    let r = c
        .service::<cnc_msgs::srv::SetMode>("set_mode")
        .and_then(|s| s.call(cnc_msgs::srv::SetModeRequest { mode }))
        .expect("set_mode answered");
    assert!(r.accepted, "mode {mode}: {}", r.message);
}

/// The `RunProgram` action's client, as a cell supervisor makes it.
#[allow(dead_code)]
pub type RunProgramClient = ros2_client::ActionClient<
    cnc_msgs::action::RunProgramGoal,
    cnc_msgs::action::RunProgramResult,
    cnc_msgs::action::RunProgramFeedback,
>;

/// The `RunProgram` action client of `lathe1` on `ros`'s participant.
#[allow(dead_code)]
pub fn run_program_client(ros: &mut cnc_runtime::dds::RosNode) -> RunProgramClient {
    use cnc_runtime::dds::qos;
    let q = qos::services();
    let policies = ros2_client::action::ActionClientQosPolicies {
        goal_service: q.clone(),
        result_service: q.clone(),
        cancel_service: q.clone(),
        feedback_subscription: qos::events(100),
        status_subscription: qos::state(),
    };
    ros.node
        .create_action_client(
            ros2_client::ServiceMapping::Enhanced,
            &ros2_client::Name::new("/lathe1", "run_program").expect("name"),
            &ros2_client::ActionTypeName::new("cnc_msgs", "RunProgram"),
            policies,
        )
        .expect("action client")
}

/// Polls `client` until `done` holds; fails the test with `what` and the machine's state
/// after `timeout`.
#[allow(dead_code)]
pub fn wait(
    client: &mut cnc_cell::client::CellClient,
    timeout: std::time::Duration,
    what: &str,
    done: impl FnMut(&cnc_cell::client::CellClient) -> bool,
) {
    let (ok, _) = client.wait_until(timeout, done);
    assert!(
        ok,
        "{what}: state {:?}, alarms {:?}",
        client.state, client.alarms
    );
}

/// An empty folder `name` in the temp directory, for one test's files.
#[allow(dead_code)]
pub fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A part program short enough for the robot tests: spindle on, one cut, M30.
#[allow(dead_code)]
pub const SHORT_PART: &str =
    "O0001\nG98 G97 S500 M03\nG00 X100 Z5\nG01 Z-10 F1500\nG00 X150 Z50\nM05\nM30\n";
