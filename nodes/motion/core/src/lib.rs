//! Motion's core: block queue, look-ahead planning, interpolation at the servo period.
//!
//! A block's path: [`block`] (what arrives) → [`motion`] (queue, limits, handshake) →
//! [`planner`] (look-ahead window, corner blends) → [`profile`] (speed this tick) →
//! [`path`] (the point on the path) → setpoint; threads go through [`thread`], locked to the
//! spindle encoder (`encoder`) instead; [`alarm`] is motion's alarm table.
//!
//! Architecture invariant: no thread, clock, socket, file, DDS or iceoryx2 here; the crate's
//! dependencies cannot reach them (`tests/boundaries.rs` at the workspace root). The shell,
//! `cnc_motion`, runs [`Motion::tick`] on its own thread against iceoryx2.

pub mod alarm;
pub mod block;
pub mod config;
mod encoder;
pub mod motion;
pub mod path;
pub mod planner;
pub mod profile;
pub mod thread_cutting;

pub use block::{Aux, Block, Command};
pub use config::{AxisConfig, MotionConfig};
pub use motion::{Motion, MotionEvent, Panel, RunState, RunTimers};
