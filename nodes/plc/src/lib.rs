//! plc: the node that scans the ladder program. Its core, the program, instructions and scan,
//! is `cnc_plc_core` (pure, re-exported here); [`node`] binds it to the iceoryx2 images, the
//! machine bus and ROS 2 topics, keeps its retained memory and reloads its program file.

pub mod node;

pub use cnc_plc_core::{address, engine, memory, monitor, program, scan};
pub use cnc_plc_core::{LoadError, Plc, PlcEvent, Program, Value, LATHE_STANDARD};
