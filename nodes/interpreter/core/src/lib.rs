//! The interpreter's core, shared by every dialect and knowing none: a front end reads its
//! language and lowers each block onto the operations here.
//!
//! - [`Core`] (`state.rs`) holds the machine as the program sees it: positions, the coordinate
//!   transform chain ([`transform`]), the working plane, modal feed and spindle state, the
//!   variable store, and the stream of canonical commands ([`canon`]).
//! - [`emit`] turns a move in work coordinates into a canonical command in machine
//!   coordinates, through the path filters: corner chamfers and roundings ([`corner`]), chip
//!   breaking ([`chip_break`]) and radius compensation ([`comp`]).
//! - [`flow`] is program flow: call levels, block-range repeats, counted loops, jumps.
//! - [`driver`] is the loop a front end plugs into ([`FrontEnd`]).
//! - Pure geometry: [`geometry`] (points, lines, arcs), [`rough`] (contour roughing),
//!   [`cycles`] (cycle move sequences from their parameters).
//!
//! Architecture invariant: no dialect is named here; `cargo test` checks this crate's text
//! for the dialects' names, and the crate cannot see a front end (it depends on none).

pub mod canon;
pub mod chip_break;
pub mod comp;
pub mod corner;
pub mod cycles;
pub mod cylinder;
pub mod driver;
pub mod emit;
pub mod error;
pub mod fillet;
pub mod flow;
pub mod geometry;
pub mod live_tool;
pub mod measure;
pub mod polar;
pub mod rough;
pub mod setup;
pub mod state;
pub mod text;
pub mod transform;
pub mod variables;

pub use canon::{Aux, Canon, Command, Turn, MAX_H_ADDRESS};
pub use driver::{next_command, FrontEnd};
pub use emit::{MoveKind, Waiting};
pub use error::{AlarmTable, Fault, ProgramError};
pub use flow::{CallLevel, Repeat};
pub use measure::{MachineTimers, Measurement};
pub use setup::{Offsets, Setup, ToolOffset};
pub use state::{CompRules, Core, Coupling, CssRule, Plane, Rules, ServiceOutput, SpindleDir};
pub use text::{find_number, line_number, read_line, Library, Pos};
pub use transform::{Frame, NO_WORK_OFFSET};
pub use variables::Value;

/// Shows a number without trailing zeros (alarm texts).
pub fn show(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}
