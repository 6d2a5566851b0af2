//! The cell's own programs: the supervisor that loads and starts programs and watches alarms
//! ([`supervisor`], its shell [`supervisor_node`]), the robot that tends the machines
//! ([`robot`], [`robot_node`]), the cell's launch file ([`launch`]) and the ROS 2 client they
//! share ([`client`]). They talk to the machines through the machines' public interface only,
//! as a program nobody here wrote would: the crate depends on no node crate
//! (`tests/boundaries.rs`).

pub mod client;
pub mod launch;
pub mod robot;
pub mod robot_node;
pub mod supervisor;
pub mod supervisor_node;
