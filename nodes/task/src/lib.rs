//! The task's shell: binds the task's core ([`cnc_task_core`]) to the machine bus, DDS, the
//! memory and position files, program memory on disk and the external drives. Everything
//! that does IO or keeps time for the task is here, in [`node`] (the node), [`msg_service`]
//! (the 802D's MSG service file), [`external`] (the drives EXTCALL reads) and [`library`]
//! (a folder of subprograms for `cnc check`).

pub mod external;
pub mod library;
pub mod msg_service;
pub mod node;

pub use cnc_task_core::*;
