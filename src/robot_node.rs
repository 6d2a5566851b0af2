//! The robot's shell: the [`Robot`] core against machines over ROS 2, through their public
//! interface only (`robot_handshake`, `robot_request`), with the wall clock for the swap.

use std::time::{Duration, Instant};

use cnc_msgs::msg::RobotHandshake;

use crate::client::CellClient;
use crate::robot::Robot;

/// Tends `machines` (one client each, in the robot's order) until the robot has its parts or
/// `deadline` passes. Each request waits for the machine to answer it done or refused.
pub fn tend(
    machines: &mut [CellClient],
    robot: &mut Robot,
    deadline: Instant,
) -> Result<(), String> {
    let t0 = Instant::now();
    while !robot.finished() {
        if Instant::now() > deadline {
            return Err(format!(
                "the robot did not finish in time: {:?}",
                robot.machines
            ));
        }
        for c in machines.iter_mut() {
            c.poll();
        }
        let seen: Vec<Option<RobotHandshake>> =
            machines.iter().map(|c| c.handshake.clone()).collect();
        match robot.next(&seen, t0.elapsed().as_secs_f64()) {
            Some((i, code)) => {
                let Some(c) = machines.get_mut(i) else {
                    return Err(format!("no machine {i}"));
                };
                let (accepted, message) = match c.robot_request(code) {
                    Ok(r) => (r.accepted, r.message),
                    Err(e) => (false, e),
                };
                robot.answered(i, code, accepted, &message, t0.elapsed().as_secs_f64());
                if !accepted {
                    std::thread::sleep(Duration::from_millis(200));
                }
            }
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    }
    Ok(())
}
