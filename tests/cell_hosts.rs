//! Issue 29, the cell across hosts: two lathes, each a `cnc run` process on its own host, and
//! the cell's host with the robot and the supervisor's client (this test process). The hosts
//! are network namespaces joined by veth pairs to a bridge in the test's own namespace
//! (10.77.0.0/24: cell .1, lathe1 .11, lathe2 .12); DDS runs on those interfaces only and
//! discovers across the bridge by multicast. The supervisor's client starts each lathe's first
//! part; the robot loads two more into each; every part is counted once by its machine, and
//! whenever a machine's PLC sees the robot inside, its door is open and its spindle stands.

use std::net::IpAddr;
use std::process::{Command, Stdio};

mod common;

use cnc_runtime::config::NetworkConfig;

const DOMAIN: u16 = 83;

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
    let dir = common::fresh_dir("cnc_cell_hosts");
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
    let inside = common::robot_tends(&cell_network(), &names, 2);
    assert!(
        inside >= 4,
        "the observer saw the robot inside {inside} times"
    );
    drop(lathes);
    drop(hosts);
    let _ = std::fs::remove_dir_all(&dir);
}
