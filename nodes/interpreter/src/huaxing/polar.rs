//! Polar interpolation on the Huaxing turn-mill, G12.1/G13.1 (`000` §5.8; decision D141):
//! the front end's rules — S#20 = 16 (X linear, C rotary, the XOY plane with I/J), the start
//! at X > 0 and C 0 (alarm 108), the tool's offset before it, what may not run inside
//! (alarm 106). C is brought to 0 before it by `G00 C0` (`c_axis.rs`); the transformation
//! itself is the core's (`cnc_interpreter_core::polar`).

use cnc_interpreter_core::{Fault, ProgramError};

use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

impl Fanuc<Huaxing> {
    /// G12.1: on a turn-mill (S#20 = 16), from G98 with no compensation, the tool's offset
    /// applied; the core checks the start point.
    pub(super) fn polar_on(&mut self) -> Result<(), ProgramError> {
        if !self.core.setup.spindle_c_axis {
            return Err(self.fault(
                Fault::PolarAxes,
                "G12.1: S#20 names C as the rotary axis, and this lathe has no C axis",
            ));
        }
        if self.offset_number == 0 {
            return Err(self.fault(
                Fault::PolarMode,
                "G12.1 needs the tool's offset first (T with its offset number, §5.8)",
            ));
        }
        self.core.polar_on()
    }

    /// What polar interpolation refuses inside it (alarm 106): a tool change, G99, a plane,
    /// rapids and every motion but G01/G02/G03 (D141 takes FANUC's list where §5.8 is
    /// silent), a coordinate system or a reference return.
    pub(super) fn polar_restrictions(&self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        if self.core.polar.is_none() {
            return Ok(());
        }
        let refuse = |what: &str| {
            Err(self.fault(
                Fault::PolarMode,
                format!("{what} in polar interpolation (G13.1 first)"),
            ))
        };
        if b.has('T') {
            return refuse("a tool change");
        }
        for &(_, g, _) in &b.g {
            match g {
                G::FeedPerRevolution => return refuse("G99"),
                G::PlaneXy | G::PlaneZx | G::PlaneYz => return refuse("a plane G17/G18/G19"),
                G::SetCoordinate | G::ReferenceReturn | G::WorkSystem(_) => {
                    return refuse(g.name().as_str())
                }
                _ => {}
            }
        }
        let motion = b.group(1).unwrap_or(self.motion);
        let moves = self.has_axis_words(b) || b.group(1).is_some();
        match motion {
            G::Linear | G::ArcCw | G::ArcCcw => Ok(()),
            _ if !moves => Ok(()),
            other => refuse(&other.name()),
        }
    }
}
