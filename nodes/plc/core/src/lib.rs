//! The PLC's core: the machine logic as a ladder program, FANUC-PMC style (`000` §18,
//! inventory §9). Pure: time comes into [`Plc::scan`] as milliseconds, and the crate cannot
//! reach a thread, DDS or iceoryx2 (`tests/boundaries.rs`).
//!
//! [`program`] parses and checks the mnemonic text, [`engine`] executes its instructions over
//! [`memory`], [`scan`] is the two-level scan cycle with the NC and machine images;
//! [`monitor`] shows a running program's rungs. The node (`cnc_plc`) binds it to iceoryx2
//! images and ROS 2 topics. `nodes/plc/programs/lathe_standard.plc` is the standard lathe logic.

pub mod address;
pub mod engine;
pub mod memory;
pub mod monitor;
pub mod program;
pub mod scan;

pub use program::{LoadError, Program};
pub use scan::{Plc, PlcEvent, Value};

/// The standard lathe program, built in so a machine runs without a PLC file.
pub const LATHE_STANDARD: &str = include_str!("../../programs/lathe_standard.plc");
