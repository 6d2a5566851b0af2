//! The interpreter: part program text in, canonical commands out.
//!
//! Read a block's path through it in this order: [`lexer`] (text → words), [`dialect`] (which
//! codes exist and what they mean), [`interpreter`] (modal state, end points, arc centres) →
//! [`canon`] (what motion receives). [`node`] binds the core to the ROS 2 topics.

pub mod canon;
pub mod dialect;
pub mod error;
pub mod interpreter;
pub mod lexer;
pub mod node;

pub use canon::{Aux, Canon, Command};
pub use dialect::Dialect;
pub use error::ProgramError;
pub use interpreter::{check, Interpreter};
