//! The task: the machine's control as a pure state machine (LinuxCNC's task layer), one
//! instance per channel. Program memory and its rules, the modes, MDI, cycle start, feed
//! hold, cycle stop and reset, block search and restart, the offset page, completion and the
//! alarms that stop a run ([`run`]); one run's block stream to motion under credit
//! ([`stream`]); where the program in automatic operation is ([`position`]); block search
//! ([`search`]); the offset page's writes ([`offset_page`]). Commands in, effects out: no
//! clock, thread, file or socket, and Cargo keeps the runtime and the transports out
//! (`tests/boundaries.rs`). Its shell is `cnc_task`.

pub mod offset_page;
pub mod position;
pub mod run;
pub mod search;
pub mod stream;

pub use run::{Effect, RunCore, StateView};
pub use stream::ProgramRun;
