//! The `cnc` launcher library: starts a cell's nodes in one process ([`cell`]) and talks to a
//! running cell over ROS 2 ([`client`]), as a supervisor or a robot would.

pub mod bench_paths;
pub mod cell;
pub mod cell_launch;
pub mod client;
pub mod keystore;
pub mod machines;
pub mod robot;
pub mod robot_node;
pub mod simulate;
pub mod supervisor;
pub mod supervisor_node;
