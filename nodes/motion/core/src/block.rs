//! Blocks as motion keeps them: a canonical command (`cnc_msgs::canon`) plus where it came from.

pub use cnc_msgs::canon::{Aux, Command, Turn};

/// A queued block. Positions are in display units (X in diameter).
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub run_id: u64,
    pub seq: u64,
    pub line: u32,
    pub kind: Command,
}
