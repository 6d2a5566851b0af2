//! The interpreter: part program text in, canonical commands out.
//!
//! The dialect-free core is its own crate, `cnc_interpreter_core`: machine state, transforms,
//! program flow, path filters, the canonical command stream. This crate holds the front ends
//! that read the dialects and lower them onto the core: the FANUC family base ([`fanuc`]) and
//! its dialects [`huaxing`], [`gtc2e`], [`iso`] and [`mill`], and the SINUMERIK 802D's own
//! front end [`sinumerik`], named in one place
//! ([`dialect`]). Around them: the public [`interpreter`], program libraries ([`library`]),
//! the program run ([`run`]) and where it is ([`position`]), [`trace`] (the stream as text for checks and golden files) and
//! [`node`] (the ROS 2 shell).

pub mod dialect;
pub mod error;
pub mod external;
pub mod fanuc;
pub mod gtc2e;
pub mod huaxing;
pub mod interpreter;
pub mod iso;
pub mod library;
pub mod mill;
pub mod msg_service;
pub mod node;
pub mod offset_page;
pub mod position;
pub mod run;
pub mod search;
pub mod setup;
pub mod sinumerik;
pub mod stream;
pub mod trace;

pub use cnc_interpreter_core::{
    canon, geometry, rough, Aux, Canon, Command, Library, MachineTimers, Measurement,
};
pub use dialect::Dialect;
pub use error::ProgramError;
pub use fanuc::syntax;
pub use interpreter::{check, check_with_library, diagnose, Interpreter};
pub use setup::Setup;
