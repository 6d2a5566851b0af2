//! Polar interpolation on the Huaxing turn-mill, G12.1/G13.1 (`000` §5.8; decision D141):
//! the front end's rules — S#20 = 16 (X linear, C rotary, the XOY plane with I/J), the start
//! at X > 0 and C 0 (alarm 108), the tool's offset before it, what may not run inside
//! (alarm 106) — and C's rapid positioning `G00 C…` that brings C to 0 before it. The
//! transformation itself is the core's (`cnc_interpreter_core::polar`).

use cnc_interpreter_core::{show, Fault, MoveKind, ProgramError, Turn};

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

    /// `G00 C…` / `G00 H…` on a turn-mill outside polar interpolation: C positioned at its
    /// rapid rate as G08 turns it (C within one turn the way its sign says, H any travel),
    /// X and Z along; how a program brings C to 0 before G12.1 (the manual's example).
    pub(super) fn rapid_c(&mut self, b: &Block<Huaxing>) -> Option<Result<(), ProgramError>> {
        let rapid = b.group(1).unwrap_or(self.motion) == G::Rapid;
        if !rapid || !(b.has('C') || b.has('H')) || self.core.polar.is_some() {
            return None;
        }
        if !self.core.setup.spindle_c_axis {
            return None; // `c_words` has refused it
        }
        self.motion = G::Rapid;
        let rpm = self.core.setup.c_rapid_rpm;
        Some(self.turn_c(b, rpm))
    }

    /// C to the block's C (or by H) at `rpm`, X and Z geared to its angle (G08's move).
    pub(super) fn turn_c(&mut self, b: &Block<Huaxing>, rpm: f64) -> Result<(), ProgramError> {
        let c_index = self.core.axis('C');
        let (degrees, way) = match (b.get('C'), b.get('H')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::AbsAndInc, "C and H in one block"));
            }
            // An absolute C within one revolution, its sign the way: C−750 turns the negative
            // way to −30°, that is 330° (D138: the manual's "320°" is a slip).
            (Some(c), None) => {
                let way = if c < 0.0 { Turn::Minus } else { Turn::Plus };
                let angle = c.rem_euclid(360.0);
                (if angle >= 360.0 { 0.0 } else { angle }, way)
            }
            (None, Some(h)) => (h, Turn::Incremental),
            (None, None) => {
                return Err(self.fault(Fault::RotaryWord, "no rotary axis programmed: C or H"));
            }
        };
        if !degrees.is_finite() || degrees.abs() > 999_999.0 {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("C axis travel {}°", show(degrees)),
            ));
        }
        let mut end = self.end_point(b)?;
        // The program's C is the angle the spindle stands at (absolute C), or goes on by H.
        if let (Some(i), Turn::Plus | Turn::Minus) = (c_index, way) {
            end[i] = degrees;
        }
        self.core.emit(&end, MoveKind::Rotary { degrees, way, rpm })
    }
}
