//! What every node shares: launch config, DDS participants and QoS, iceoryx2 channels, clocks,
//! lifecycle, and the alarm reporting helper.

pub mod alarms;
pub mod bus;
pub mod clock;
pub mod config;
pub mod dds;
pub mod heap;
pub mod instance_lock;
pub mod lifecycle;
pub mod limits;
pub mod overrides;
pub mod parameter_rules;
pub mod parameters;
pub mod persist;
pub mod program_store;
pub mod raw;
pub mod realtime;
pub mod shm;
pub mod tool_table;
pub mod topics;

pub use config::LaunchConfig;
pub use lifecycle::Shutdown;

pub use cnc_machine::programs::{MAX_PROGRAM_BYTES, MDI_PROGRAM};
