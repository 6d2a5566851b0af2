//! The interpreter: part program text in, canonical commands out.
//!
//! The dialect-free core is its own crate, `cnc_interpreter_core`: machine state, transforms,
//! program flow, path filters, the canonical command stream. This crate holds the front ends
//! that read the dialects and lower them onto the core: the FANUC family base ([`fanuc`]) and
//! its dialects [`huaxing`], [`gtc2e`], [`iso`] and [`mill`], and the SINUMERIK 802D's own
//! front end [`sinumerik`], named in one place
//! ([`dialect`]). Around them: the public [`interpreter`], program libraries ([`library`]) and
//! [`trace`] (the stream as text for checks and golden files). Text in, canonical commands
//! out: the program's run, its memory and its shell are the task's (`cnc_task_core`,
//! `cnc_task`), and Cargo keeps this crate from the runtime and the transports
//! (`tests/boundaries.rs`).

pub mod dialect;
pub mod error;
pub mod fanuc;
pub mod gtc2e;
pub mod huaxing;
pub mod interpreter;
pub mod iso;
pub mod library;
pub mod mill;
pub mod setup;
pub mod sinumerik;
pub mod trace;

pub use cnc_interpreter_core::{
    canon, geometry, rough, Aux, Canon, Command, Library, MachineTimers, Measurement, Turn,
};
pub use dialect::Dialect;
pub use error::ProgramError;
pub use fanuc::syntax;
pub use interpreter::{check, check_with_library, diagnose, Interpreter};
pub use setup::Setup;
