//! The machine as its builder describes it in the launch config's `machine` section, in the
//! manuals' terms: axes and their ratings, the offset page's numbering, the work offsets, the
//! tool post, the dialect a program is read in. Pure data and the rules that check it: no
//! files, no network, no clock. The runtime reads it from the launch file; the interpreter,
//! the task and motion's core take it from here, so none of them needs the runtime
//! (issue 47).

pub mod machine;
pub mod programs;
pub mod tools;

pub use machine::*;

/// How speed changes along the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileShape {
    /// Acceleration limited: the acceleration jumps between +a, 0 and −a.
    Trapezoidal,
    /// Jerk limited: the acceleration ramps, so the drives see no steps in force.
    #[default]
    SCurve,
}
