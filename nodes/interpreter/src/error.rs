//! Program errors: the core's faults and alarms. Each front end owns its manual's alarm table
//! (`huaxing::alarm`, `gtc2e::alarm`, `mill::alarm`).

pub use cnc_interpreter_core::error::{AlarmTable, Fault, ProgramError};
