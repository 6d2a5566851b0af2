//! Issue 29, the cell across hosts: two lathes, each a `cnc run` process on its own host, and
//! the cell's host with the robot and the supervisor's client (this test process). The hosts
//! are network namespaces joined by veth pairs to a bridge in the test's own namespace
//! (10.77.0.0/24: cell .1, lathe1 .11, lathe2 .12); DDS runs on those interfaces only and
//! discovers across the bridge by multicast. The supervisor's client starts each lathe's first
//! part; the robot loads two more into each; every part is counted once by its machine, and
//! whenever a machine's PLC sees the robot inside, its door is open and its spindle stands.

use std::net::IpAddr;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use cnc::client::CellClient;
use cnc::robot::Robot;
use cnc_msgs::msg::{MachineState, RobotHandshake};
use cnc_runtime::config::NetworkConfig;
use cnc_runtime::dds::{qos, RosNode};
use cnc_runtime::topics;
use ros2_client::qos::History;
use ros2_client::ServiceMapping;

const DOMAIN: u16 = 83;
const PART: &str = "O0001\nG98 G97 S500 M03\nG00 X100 Z5\nG01 Z-10 F1500\nG00 X150 Z50\nM05\nM30\n";

fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("ip runs");
    assert!(
        out.status.success(),
        "ip {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The cell's network: a bridge here, and a namespace per lathe host on a veth pair to it.
struct Hosts {
    bridge: String,
    hosts: Vec<String>,
}

impl Hosts {
    fn new(lathes: usize) -> Hosts {
        let id = std::process::id();
        let bridge = format!("cbr{id}");
        ip(&[
            "link",
            "add",
            &bridge,
            "type",
            "bridge",
            "mcast_snooping",
            "0",
        ]);
        ip(&["addr", "add", "10.77.0.1/24", "dev", &bridge]);
        ip(&["link", "set", &bridge, "up"]);
        let mut hosts = Vec::new();
        for k in 1..=lathes {
            let ns = format!("cnc_l{k}_{id}");
            let port = format!("cv{k}_{id}");
            ip(&["netns", "add", &ns]);
            hosts.push(ns.clone());
            ip(&[
                "link", "add", &port, "type", "veth", "peer", "name", "eth0", "netns", &ns,
            ]);
            ip(&["link", "set", &port, "master", &bridge, "up"]);
            let addr = format!("10.77.0.{}/24", 10 + k);
            for args in [
                vec!["link", "set", "lo", "up"],
                vec!["addr", "add", &addr, "dev", "eth0"],
                vec!["link", "set", "eth0", "up"],
                vec!["route", "add", "224.0.0.0/4", "dev", "eth0"],
            ] {
                let mut all = vec!["netns", "exec", &ns, "ip"];
                all.extend(args);
                ip(&all);
            }
        }
        Hosts { bridge, hosts }
    }
}

impl Drop for Hosts {
    fn drop(&mut self) {
        for ns in &self.hosts {
            let _ = Command::new("ip").args(["netns", "del", ns]).output();
        }
        let _ = Command::new("ip")
            .args(["link", "del", &self.bridge])
            .output();
    }
}

fn cell_network() -> NetworkConfig {
    NetworkConfig {
        domain_id: Some(DOMAIN),
        interfaces: vec![IpAddr::from([10, 77, 0, 1])],
    }
}

#[test]
fn a_robot_on_the_cell_host_tends_two_lathes_on_their_own_hosts() {
    let hosts = Hosts::new(2);
    let dir = std::env::temp_dir().join(format!("cnc_cell_hosts_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let names = ["lathe1", "lathe2"];
    let mut lathes = Vec::new();
    for (k, (ns, host)) in names.iter().zip(&hosts.hosts).enumerate() {
        let config = common::sim_lathe_file(&dir, &format!("{ns}.yaml"), DOMAIN, |v| {
            v["machine"]["namespace"] = (*ns).into();
            v["network"]["interfaces"] = vec![format!("10.77.0.{}", 11 + k)].into();
            for f in [
                "memory_file",
                "position_file",
                "parameter_file",
                "program_directory",
            ] {
                v["machine"][f] = format!("state/{ns}_{f}").into();
            }
            v["plc"]["memory_file"] = format!("state/{ns}_plc.yaml").into();
        });
        let log = std::fs::File::create(dir.join(format!("{ns}.log"))).expect("log");
        let child = Command::new("ip")
            .args(["netns", "exec", host])
            .arg(env!("CARGO_BIN_EXE_cnc"))
            .arg("run")
            .arg(&config)
            .stdout(Stdio::from(log.try_clone().expect("log")))
            .stderr(Stdio::from(log))
            .spawn()
            .expect("cnc runs on its host");
        lathes.push(common::KillOnDrop(child));
    }
    let net = cell_network();
    let client = |ns: &str, who: &str| {
        let mut c = CellClient::new(&net, ns, who, ServiceMapping::Enhanced)
            .expect("client")
            .with_timeout(Duration::from_secs(20));
        c.wait_ready(Duration::from_secs(60))
            .unwrap_or_else(|e| panic!("{ns} across the bridge: {e}"));
        c
    };
    let mut observers: Vec<RosNode> = names
        .iter()
        .map(|ns| RosNode::new(&net, ns, "observer").expect("observer"))
        .collect();
    let watch: Vec<_> = observers
        .iter_mut()
        .map(|o| {
            o.dds_subscription_with_qos::<RobotHandshake>(
                &topics::ROBOT_HANDSHAKE,
                qos::state().history(History::KeepLast { depth: 10_000 }),
            )
            .expect("handshake reader")
        })
        .collect();
    let mut supervisor: Vec<CellClient> = names.iter().map(|ns| client(ns, "supervisor")).collect();
    for s in supervisor.iter_mut() {
        let r = s.load_program("part.nc", PART).expect("load");
        assert!(r.accepted, "{}", r.message);
        let r = s.start_program("part.nc").expect("start");
        assert!(r.accepted, "{}", r.message);
    }
    let mut arm: Vec<CellClient> = names.iter().map(|ns| client(ns, "robot")).collect();
    let mut robot = Robot::new(2, 1.0, 2);
    let t0 = Instant::now();
    let done = cnc::robot_node::tend(&mut arm, &mut robot, t0 + Duration::from_secs(240));
    println!(
        "robot across hosts: {:?} after {:.1} s",
        robot.machines,
        t0.elapsed().as_secs_f64()
    );
    done.expect("the robot loaded its parts");
    for (ns, s) in names.iter().zip(supervisor.iter_mut()) {
        let t = Instant::now();
        loop {
            s.poll();
            let counted = s.part_count.as_ref().map_or(0, |p| p.count);
            let ended = s
                .state
                .as_ref()
                .is_some_and(|m| m.execution == MachineState::PROGRAM_COMPLETED);
            if counted == 3 && ended {
                println!("{ns}: 3 parts counted by the machine");
                break;
            }
            assert!(
                t.elapsed() < Duration::from_secs(30),
                "{ns}: count {counted}"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    let mut inside = 0;
    for (ns, w) in names.iter().zip(&watch) {
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
    println!("samples with the robot inside: {inside}, all safe");
    assert!(
        inside >= 4,
        "the observer saw the robot inside {inside} times"
    );
    drop((arm, supervisor, watch, observers));
    drop(lathes);
    drop(hosts);
    let _ = std::fs::remove_dir_all(&dir);
}
