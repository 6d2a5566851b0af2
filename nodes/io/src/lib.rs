//! io: the hardware boundary. The default backend is [`sim`], a simulated lathe.

pub mod node;
pub mod sim;

pub use sim::{SimConfig, SimLathe};
