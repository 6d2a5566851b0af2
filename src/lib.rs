//! The `cnc` launcher library: starts a cell's nodes in one process ([`cell`]), finds the
//! built-in machines ([`machines`]), writes the DDS Security keystore ([`keystore`]) and proves
//! programs without a machine ([`simulate`]). The cell's own programs (supervisor, robot, the
//! client they share) are the `cnc_cell` crate.

pub mod bench_paths;
pub mod cell;
pub mod keystore;
pub mod machines;
pub mod simulate;
