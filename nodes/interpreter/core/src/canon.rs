//! What the interpreter hands to motion: a canonical command (`cnc_msgs::canon`, shared with
//! motion) with the source line it came from.

pub use cnc_msgs::canon::{Aux, Command};

#[derive(Debug, Clone, PartialEq)]
pub struct Canon {
    pub line: u32,
    pub command: Command,
}
