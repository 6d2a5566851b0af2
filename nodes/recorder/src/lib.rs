//! recorder: every topic of the machine into rosbag2-compatible MCAP, for audits.
//!
//! A text follows a message from the wire to the disk in three files: [`node`] takes the CDR
//! bytes off DDS, [`bag`] decides which file and when to flush, [`writer`] lays out the MCAP
//! records ([`mcap`]) and chains each flushed segment's hash ([`chain`]). The tools that read
//! recordings back are [`reader`], [`recover`], [`audit`] and [`replay`].

pub mod audit;
pub mod bag;
pub mod chain;
pub mod mcap;
pub mod node;
pub mod reader;
pub mod recover;
pub mod replay;
pub mod schema;
pub mod writer;
