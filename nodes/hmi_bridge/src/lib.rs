//! hmi_bridge: the machine's face to the cell. ROS 2 services for supervisors (both service
//! mappings, see [`mapping`]), the active-alarm list, and the state topics robots read.

pub mod mapping;
pub mod node;
pub mod server;
