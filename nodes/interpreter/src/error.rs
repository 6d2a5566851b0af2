//! Program errors: every rejection is an alarm with the manual's number, a text and the line.
//!
//! Numbers and texts follow the Huaxing alarm list (`000` Appendix 1, inventory §11.1), the
//! table the lathe dialects share until each dialect gets its own (see docs/decisions.md).

use std::fmt;

/// A program error, raised before any motion of the bad block.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramError {
    pub number: u32,
    pub text: String,
    /// 1-based source line; 0 when the error is not tied to a line.
    pub line: u32,
}

impl fmt::Display for ProgramError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "alarm {} at line {}: {}",
            self.number, self.line, self.text
        )
    }
}

impl std::error::Error for ProgramError {}

/// Alarm numbers used by the interpreter.
pub mod alarm {
    pub const DWELL_TIME: u32 = 1;
    pub const UNDEFINED_CODE: u32 = 7;
    pub const GROUP_00_WITH_01: u32 = 8;
    pub const ABS_AND_INC_SAME_AXIS: u32 = 9;
    pub const TOO_MANY_M: u32 = 10;
    pub const ARC_RADIUS_TOO_SMALL: u32 = 11;
    pub const DATA_FORMAT: u32 = 13;
    pub const AXIS_ADDRESS: u32 = 14;
    pub const ARC_R_AND_IJK: u32 = 15;
    pub const FEED_OUT_OF_RANGE: u32 = 16;
    pub const PROGRAM_NOT_FOUND: u32 = 22;
    pub const ARC_END_NOT_ON_CIRCLE: u32 = 50;
}

impl ProgramError {
    pub fn new(number: u32, line: u32, text: impl Into<String>) -> Self {
        ProgramError {
            number,
            text: text.into(),
            line,
        }
    }
}
