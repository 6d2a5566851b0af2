//! What the interpreter hands to motion: a canonical command (`cnc_msgs::canon`, shared with
//! motion) with the source line it came from.

pub use cnc_msgs::canon::{Aux, Command, Turn, MAX_H_ADDRESS};

#[derive(Debug, Clone, PartialEq)]
pub struct Canon {
    pub line: u32,
    /// The main program's line being run when the command was made: the command's own line
    /// in the main program, the calling line for a called program's. Block search finds a
    /// main-program line by it (`search.rs` of the interpreter).
    pub main_line: u32,
    pub command: Command,
}
