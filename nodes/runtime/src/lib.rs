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

/// Largest program text accepted into program memory, bytes.
pub const MAX_PROGRAM_BYTES: usize = 4 * 1024 * 1024;

/// The name an MDI entry runs under in program memory (decisions D43).
pub const MDI_PROGRAM: &str = "MDI";
