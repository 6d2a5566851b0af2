//! hmi_bridge: the machine's face to the cell. ROS 2 services for supervisors (both service
//! mappings, see [`mapping`]), the active-alarm list, and the state topics robots read.

pub mod access;
pub mod action_server;
pub mod alarm_list;
pub mod doors;
pub mod mapping;
pub mod node;
pub mod operation;
pub use cnc_runtime::overrides;
pub mod parameters;
pub mod program_events;
pub mod robot_door;
pub mod robot_handshake;
pub mod run_program;
pub mod service_server;
pub mod web;
