//! io: the hardware boundary. The default backend is the simulated machine, `cnc_sim_machine`
//! (pure, re-exported here as [`sim`]); [`node`] is its shell on the servo and signal images.

pub mod drive_clock;
pub mod node;

pub use cnc_sim_machine as sim;
pub use sim::{SimConfig, SimLathe};
