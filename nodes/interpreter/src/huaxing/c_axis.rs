//! The turn-mill's C axis on the Huaxing (`000` §4.2.6–4.2.7, §5.7; decision D138): the main
//! spindle, switched into position control by M14.6 (or G08.6), is the C axis, its angle
//! counted from the encoder's Z pulse. G08 turns it at F r/min: C an angle reached within one
//! revolution the way its sign says, H a travel of any number of turns; X and Z in the same
//! block move along, geared to its angle (motion's rigid-tap gearing, D101). `G00 C…` turns it
//! the same way at its rapid (D141), as does a tapping block's C (D142).

use cnc_interpreter_core::{show, Aux, Fault, MoveKind, ProgramError, Turn};

use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::{Family, Fanuc};

/// The spindle's axis number on these machines: 6, C (M14.1–M14.5 would name X … B).
const C_AXIS: u8 = 6;

/// The fastest a G08 may turn the C axis, r/min (§5.7).
const MAX_RPM: f64 = 3000.0;

impl<D: Family> Fanuc<D> {
    /// M14.n: the spindle into position control where it stands; its angle is axis n's
    /// coordinate. Only C (n = 6) is the spindle's axis, and only on a turn-mill.
    pub fn position_mode(&mut self, n: u8) -> Result<(), ProgramError> {
        if !self.core.setup.spindle_c_axis || n != C_AXIS {
            let axis = ['X', 'Y', 'Z', 'A', 'B', 'C']
                .get(usize::from(n.saturating_sub(1)))
                .copied()
                .unwrap_or('?');
            return Err(self.fault(
                Fault::RotaryAxis,
                format!("M14.{n}/G08.{n}: the spindle is not axis {axis} of this machine"),
            ));
        }
        self.core.aux(Aux::Orient {
            degrees: 0.0,
            way: Turn::Incremental,
        });
        Ok(())
    }
}

impl Fanuc<Huaxing> {
    /// G08 (`orient` none) or G08.n (M14.n first): the C axis to C (or by H) at F r/min, X and
    /// Z along with it.
    pub(super) fn rotary(
        &mut self,
        b: &Block<Huaxing>,
        orient: Option<u8>,
    ) -> Result<(), ProgramError> {
        match orient {
            Some(n) => self.position_mode(n)?,
            None if !self.core.setup.spindle_c_axis => {
                return Err(self.fault(Fault::RotaryAxis, "G08: this lathe has no C axis"));
            }
            None => {}
        }
        let rpm = match b.get('F') {
            Some(f) => f,
            None => self.d.rotary_rpm.ok_or_else(|| {
                self.fault(
                    Fault::MissingWord,
                    "G08 needs F, the C axis's speed in r/min",
                )
            })?,
        };
        if !(rpm > 0.0 && rpm <= MAX_RPM) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("G08 F{rpm}: the C axis turns at 1–{MAX_RPM} r/min"),
            ));
        }
        self.d.rotary_rpm = Some(rpm);
        self.turn_c(b, rpm)
    }

    /// C and H program the C axis in G08, G00, G83/G87 and G84/G88 blocks, and the face's
    /// second coordinate in polar interpolation (D141).
    pub(super) fn c_words(&self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let motion = b.group(1).unwrap_or(self.motion);
        let c_moves = matches!(
            motion,
            G::Own(
                super::HuaxingG::Rotary { .. }
                    | super::HuaxingG::RigidTap { .. }
                    | super::HuaxingG::Drilling { .. }
            ) | G::Rapid
        ) && self.core.setup.spindle_c_axis;
        if self.core.polar.is_some() {
            return Ok(());
        }
        for c in ['C', 'H'] {
            if b.get(c).is_some() && !c_moves {
                let why = match self.core.setup.spindle_c_axis {
                    true => {
                        format!(
                            "address {c}: the C axis is programmed with G00, G08, G83/G87 or \
                             G84/G88"
                        )
                    }
                    false => format!("address {c}: no C axis on this machine"),
                };
                return Err(self.fault(Fault::RotaryAxis, why));
            }
        }
        Ok(())
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

    /// The block's C as a turn of the C axis: an absolute C within one revolution, its sign
    /// the way (C−750 turns the negative way to −30°, that is 330°; D138: the manual's "320°"
    /// is a slip), or H a travel of any number of turns; none without either.
    pub(super) fn c_target(&self, b: &Block<Huaxing>) -> Result<Option<(f64, Turn)>, ProgramError> {
        let (degrees, way) = match (b.get('C'), b.get('H')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::AbsAndInc, "C and H in one block"));
            }
            (Some(c), None) => {
                let way = if c < 0.0 { Turn::Minus } else { Turn::Plus };
                let angle = c.rem_euclid(360.0);
                (if angle >= 360.0 { 0.0 } else { angle }, way)
            }
            (None, Some(h)) => (h, Turn::Incremental),
            (None, None) => return Ok(None),
        };
        if !degrees.is_finite() || degrees.abs() > 999_999.0 {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("C axis travel {}°", show(degrees)),
            ));
        }
        Ok(Some((degrees, way)))
    }

    /// C to the block's C (or by H) at `rpm`, X and Z geared to its angle (G08's move).
    pub(super) fn turn_c(&mut self, b: &Block<Huaxing>, rpm: f64) -> Result<(), ProgramError> {
        let c_index = self.core.axis('C');
        let Some((degrees, way)) = self.c_target(b)? else {
            return Err(self.fault(Fault::RotaryWord, "no rotary axis programmed: C or H"));
        };
        let mut end = self.end_point(b)?;
        // The program's C is the angle the spindle stands at (absolute C), or goes on by H.
        if let (Some(i), Turn::Plus | Turn::Minus) = (c_index, way) {
            end[i] = degrees;
        }
        self.core.emit(&end, MoveKind::Rotary { degrees, way, rpm })
    }
}
