//! A robot cell program (issue 29): one arm tends the named machines of a running cell
//! through their public ROS 2 interface only (`robot_handshake`, `robot_request`).
//!
//! ```text
//! cargo run --example robot -- <domain> <interface address> <parts each> <machine>...
//! cargo run --example robot -- 0 127.0.0.1 5 lathe1 lathe2
//! ```
//! Each machine's first part is started by its supervisor (`start_program`); the robot then
//! swaps parts (2 s a swap) and starts cycles until it has loaded the parts asked for.

use std::net::IpAddr;
use std::time::{Duration, Instant};

use cnc_cell::client::CellClient;
use cnc_cell::robot::Robot;
use cnc_runtime::config::NetworkConfig;
use ros2_client::ServiceMapping;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [domain, address, parts, machines @ ..] = &args[..] else {
        return Err("usage: robot <domain> <interface address> <parts each> <machine>...".into());
    };
    if machines.is_empty() {
        return Err("name at least one machine (its namespace, e.g. lathe1)".into());
    }
    let net = NetworkConfig {
        domain_id: Some(domain.parse().map_err(|_| format!("domain {domain:?}"))?),
        interfaces: vec![address
            .parse::<IpAddr>()
            .map_err(|_| format!("interface address {address:?}"))?],
        security: None,
    };
    let parts: u32 = parts.parse().map_err(|_| format!("parts {parts:?}"))?;
    let mut arm = Vec::new();
    for ns in machines {
        let mut c = CellClient::new(&net, ns, "robot", ServiceMapping::Enhanced)?;
        c.wait_ready(Duration::from_secs(60))
            .map_err(|e| format!("{ns}: {e}"))?;
        arm.push(c);
    }
    let mut robot = Robot::new(arm.len(), 2.0, parts);
    let deadline = Instant::now() + Duration::from_secs(24 * 3600);
    cnc_cell::robot_node::tend(&mut arm, &mut robot, None, deadline)?;
    for (ns, m) in machines.iter().zip(&robot.machines) {
        println!("{ns}: {} parts loaded, {:?}", m.parts, m.phase);
    }
    Ok(())
}
