//! Cylinder surface milling, `TRACYL(d)` / `TRAFOOF` (`001` §9.15, fixture 091, decisions
//! D117): the program writes on the developed side of a cylinder of machining diameter `d`,
//! Y its circumference, and the core's cylinder transformation turns the rotary axis C for it
//! while the real Y slide, on C's centre, offsets the groove walls. Each is a block of its
//! own. Under TRACYL, radius compensation refers to the groove wall: OFFN is the wall's
//! distance from the programmed centre line and the cutter runs inside it, OFFN − R from
//! the centre line on the G41/G42 side.

use cnc_interpreter_core::{Fault, ProgramError};

use super::exec::Words;
use super::expr::Expr;
use super::Sinumerik;

/// A TRACYL or TRAFOOF of the block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CylinderWord {
    On(f64),
    Off,
}

/// The machining diameter's range (§9.15's table: 1.000 … 99 999.999 mm).
const DIAMETER: std::ops::RangeInclusive<f64> = 1.0..=99_999.999;

/// The rotary axis's position where Y is 0: the machine data's, 0° on this machine.
const C_AT_Y_ZERO: f64 = 0.0;

impl Sinumerik {
    /// `TRACYL(d)` or `TRACYL(d, 1)` (the second the transformation's data set, of which
    /// this machine has one).
    pub(super) fn tracyl(
        &mut self,
        w: &mut Words,
        args: &[Option<Expr>],
    ) -> Result<(), ProgramError> {
        let (d, set) = match args {
            [Some(d)] => (self.number(d)?, None),
            [Some(d), Some(k)] => (self.number(d)?, Some(self.number(k)?)),
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    "TRACYL(d) takes the machining diameter (and the data set 1)",
                ))
            }
        };
        if !DIAMETER.contains(&d) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "TRACYL({}): the machining diameter is 1.000 … 99 999.999 mm",
                    cnc_interpreter_core::show(d)
                ),
            ));
        }
        if set.is_some_and(|k| k != 1.0) {
            return Err(self.fault(
                Fault::OutOfRange,
                "TRACYL(d, n): this machine has transformation data set 1 only",
            ));
        }
        self.set_cylinder_word(w, CylinderWord::On(d))
    }

    /// `TRAFOOF` (the manual's table writes `TRAFOFF`: both are read, D117).
    pub(super) fn set_cylinder_word(
        &mut self,
        w: &mut Words,
        word: CylinderWord,
    ) -> Result<(), ProgramError> {
        if w.cylinder.replace(word).is_some() {
            return Err(self.fault(Fault::SameGroup, "one TRACYL or TRAFOOF per block"));
        }
        Ok(())
    }

    /// Runs the block's TRACYL or TRAFOOF, which stands in a block of its own.
    pub(super) fn cylinder_block(&mut self, w: &Words) -> Result<(), ProgramError> {
        let Some(word) = w.cylinder else {
            return Ok(());
        };
        let alone = w.axes.is_empty()
            && w.addr.is_empty()
            && w.g.is_empty()
            && w.m.is_empty()
            && w.h.is_empty()
            && w.keys.is_empty()
            && w.call.is_none()
            && w.cycle.is_none();
        if !alone {
            return Err(self.fault(
                Fault::MustStartBlock,
                "TRACYL and TRAFOOF are programmed in a block of their own",
            ));
        }
        match word {
            CylinderWord::On(d) => {
                let axis = |c: char| self.core.axis(c);
                let (Some(c), Some(y), Some(_), Some(_)) =
                    (axis('C'), axis('Y'), axis('X'), axis('Z'))
                else {
                    return Err(self.fault(
                        Fault::NoSuchAxis,
                        "TRACYL needs the rotary axis C and the X, Y and Z slides: this \
                         machine lacks one",
                    ));
                };
                if !self.rotary_axis(c) {
                    return Err(self.fault(Fault::NoSuchAxis, "TRACYL: C is no rotary axis"));
                }
                self.core.cylinder_on(c, y, d, C_AT_Y_ZERO)?;
                // Where the path went before does not carry into the developed surface.
                self.tangent = None;
                Ok(())
            }
            CylinderWord::Off => {
                self.core.cylinder_off()?;
                self.tangent = None;
                Ok(())
            }
        }
    }

    /// Under TRACYL the rotary axis is the transformation's: the program writes Y.
    pub(super) fn check_cylinder_axes(&self, w: &Words) -> Result<(), ProgramError> {
        let Some(c) = self.core.cylinder else {
            return Ok(());
        };
        if w.axes.iter().any(|(i, _)| *i == c.rotary) {
            return Err(self.fault(
                Fault::AxisAddress,
                "C is turned by TRACYL: program the developed surface's Y (TRAFOOF first to \
                 move C itself)",
            ));
        }
        for (g, what) in [(53, "G53"), (153, "G153"), (74, "G74"), (75, "G75")] {
            if w.has_g(g) {
                return Err(self.fault(
                    Fault::NotSupported,
                    format!(
                        "{what} moves in machine coordinates: not under TRACYL (TRAFOOF first)"
                    ),
                ));
            }
        }
        Ok(())
    }
}
