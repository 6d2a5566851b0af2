//! The cell's trust boundary (issue 25), with the cell in its default one-process form and a
//! foreign participant on its domain: Eclipse Cyclone DDS (`tests/interop/intruder_peer.py`),
//! announcing no ROS 2 node, while the cell allows only `/lathe1/supervisor`.
//!
//! The intruder finds no internal topic on DDS, writes program commands, motion blocks,
//! overrides, alarms and simulator inputs on the old names anyway, and calls the commanding
//! services: the machine neither runs nor moves, and every refused call and input is a command
//! event. Then the real supervisor runs a part at the programmed spindle speed: nothing the
//! intruder wrote (override 255 %, a run id of 2^64-1, a fake alarm) is left behind.

mod common;

use std::time::{Duration, Instant};

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use ros2_client::ServiceMapping;

const PART: &str = "O0001\nG00 X60 Z5\nS800 M03\nG01 X50 Z0 F900\nZ-10\nG00 X60\nM05\nM30\n";

#[test]
fn a_foreign_participant_neither_runs_nor_moves_the_machine() {
    let domain = 61;
    let mut cfg = common::sim_lathe(domain);
    cfg.hmi.allowed_clients = Some(vec!["/lathe1/supervisor".into()]);
    let cell = Cell::start(&cfg).unwrap();
    let auditor = common::Auditor::new(&cfg);
    let mut supervisor = CellClient::new(
        &cfg.network,
        "lathe1",
        "supervisor",
        ServiceMapping::Enhanced,
    )
    .unwrap();
    supervisor.wait_ready(Duration::from_secs(30)).unwrap();
    std::thread::sleep(Duration::from_secs(2)); // the supervisor's node is announced
    let r = supervisor.load_program("good.nc", PART).unwrap();
    assert!(r.accepted, "{}", r.message);

    common::passing_peer("intruder_peer.py", domain);

    // The program the robot starts next is still there, and runs as written: the spindle at
    // 800 rpm (an override of 255 % would have made it 2040), to the end.
    let listed = supervisor.list_programs().unwrap();
    assert!(listed.names.iter().any(|n| n == "good.nc"), "{listed:?}");
    assert!(!listed.names.iter().any(|n| n == "evil.nc"), "{listed:?}");
    let r = supervisor.start_program("good.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let t0 = Instant::now();
    let mut top_rpm = 0.0f64;
    loop {
        supervisor.poll();
        if let Some(s) = &supervisor.spindle {
            top_rpm = top_rpm.max(s.actual_rpm);
        }
        if supervisor
            .state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
        {
            break;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "the supervisor's program did not finish: {:?}",
            supervisor.state
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        (top_rpm - 800.0).abs() <= 16.0,
        "spindle top speed {top_rpm} rpm, programmed 800"
    );
    assert_eq!(
        supervisor.part_count.as_ref().map(|p| p.count),
        Some(1),
        "exactly the supervisor's part is counted"
    );

    // Every refusal is a command event naming the intruder by its GUID.
    std::thread::sleep(Duration::from_millis(500));
    let seen = auditor.events();
    let refused = |command: &str| {
        seen.iter()
            .filter(|e| e.command == command && !e.accepted && e.client.starts_with("guid:"))
            .count()
    };
    for command in [
        "load_program",
        "delete_program",
        "start_program",
        "sim_input",
    ] {
        assert!(
            refused(command) >= 1,
            "no refused {command} event: {:?}",
            seen.iter()
                .map(|e| (&e.command, &e.client, e.accepted))
                .collect::<Vec<_>>()
        );
    }
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}
