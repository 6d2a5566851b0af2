//! plc: the machine logic. [`logic`] is the scanned core; [`node`] binds it to iceoryx2 images
//! and ROS 2 topics.

pub mod logic;
pub mod node;

pub use logic::{Plc, PlcEvent};
