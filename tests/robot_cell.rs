//! Issue 29, the robot: one arm tends two lathes of one cell (`lathe1`, `lathe2`, each a full
//! controller of its own nodes, here in one process and one DDS domain) through their public
//! interface only. A supervisor's client loads the program and runs each machine's first
//! part; the robot then swaps parts and starts cycles until it has loaded two into each. The
//! machines' own `robot_handshake` topic, watched by a separate observer, is the judge of
//! safety: whenever a machine's PLC sees the robot inside (X8.0 low), its door is open, its
//! spindle stands and no emergency stop is pressed.

use std::time::{Duration, Instant};

mod common;

use cnc::cell::Cell;
use cnc::client::CellClient;
use cnc::robot::Robot;
use cnc_msgs::msg::{MachineState, RobotHandshake};
use cnc_runtime::dds::{qos, RosNode};
use cnc_runtime::topics;
use ros2_client::qos::History;
use ros2_client::ServiceMapping;

const PART: &str = "O0001\nG98 G97 S500 M03\nG00 X100 Z5\nG01 Z-10 F1500\nG00 X150 Z50\nM05\nM30\n";

#[test]
fn one_robot_tends_two_lathes_and_never_enters_one_that_is_not_safe() {
    let lathe1 = common::sim_lathe(82);
    let mut lathe2 = lathe1.clone();
    lathe2.machine.namespace = "lathe2".into();
    let cells = [
        Cell::start(&lathe1).expect("lathe1 starts"),
        Cell::start(&lathe2).expect("lathe2 starts"),
    ];
    let names = ["lathe1", "lathe2"];
    let client = |ns: &str, who: &str| {
        let mut c = CellClient::new(&lathe1.network, ns, who, ServiceMapping::Enhanced)
            .expect("client")
            .with_timeout(Duration::from_secs(20));
        c.wait_ready(Duration::from_secs(30)).expect("ready");
        c
    };
    // The observer: every handshake sample of both machines, in order.
    let mut observers: Vec<RosNode> = names
        .iter()
        .map(|ns| RosNode::new(&lathe1.network, ns, "observer").expect("observer"))
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
        "robot: {:?} after {:.1} s",
        robot.machines,
        t0.elapsed().as_secs_f64()
    );
    done.expect("the robot loaded its parts");

    // Each machine counts its first part and the robot's two.
    for s in supervisor.iter_mut() {
        let t = Instant::now();
        loop {
            s.poll();
            let counted = s.part_count.as_ref().map_or(0, |p| p.count);
            let ended = s
                .state
                .as_ref()
                .is_some_and(|m| m.execution == MachineState::PROGRAM_COMPLETED);
            if counted == 3 && ended {
                break;
            }
            assert!(t.elapsed() < Duration::from_secs(30), "count {counted}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    let mut inside_samples = 0;
    for (ns, w) in names.iter().zip(&watch) {
        let mut samples = 0;
        while let Ok(Some((h, _))) = w.take() {
            samples += 1;
            if !h.robot_clear {
                inside_samples += 1;
                assert!(
                    h.door_open && !h.spindle_turning && !h.emergency_stop && !h.cycle_active,
                    "{ns}: the robot inside an unsafe machine: {h:?}"
                );
            }
        }
        println!("{ns}: {samples} handshake samples");
    }
    println!("samples with the robot inside: {inside_samples}, all safe");
    assert!(
        inside_samples >= 4,
        "the observer saw the robot inside {inside_samples} times"
    );
    assert!(robot.machines.iter().all(|m| m.parts == 2));
    drop((arm, supervisor, watch, observers));
    for c in cells {
        let (_, failed) = c.stop();
        assert!(failed.is_empty(), "{failed:?}");
    }
}
