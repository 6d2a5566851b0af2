//! The interpreter: part program text in, canonical commands out.
//!
//! Read a block's path through it in this order: [`syntax`] (text → statements and words,
//! with [`expr`] for macro expressions), [`dialect`] (which codes exist and what they mean),
//! [`interpreter`] (modal state, offsets, program flow, cycles; [`rough`] and [`geometry`] for
//! contour work) → [`canon`] (what motion receives). [`trace`] prints the stream for checks and
//! golden files; [`node`] binds the core to the ROS 2 topics.

pub mod canon;
pub mod dialect;
pub mod error;
pub mod expr;
pub mod geometry;
pub mod interpreter;
pub mod node;
pub mod offset_page;
pub mod program;
pub mod rough;
pub mod run;
pub mod setup;
pub mod syntax;
pub mod trace;

pub use canon::{Aux, Canon, Command};
pub use dialect::Dialect;
pub use error::ProgramError;
pub use interpreter::{check, check_with_library, diagnose, Interpreter};
pub use program::Library;
pub use setup::Setup;
