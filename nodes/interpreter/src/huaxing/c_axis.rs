//! The turn-mill's C axis on the Huaxing (`000` §4.2.6–4.2.7, §5.7; decision D138): the main
//! spindle, switched into position control by M14.6 (or G08.6), is the C axis, its angle
//! counted from the encoder's Z pulse. G08 turns it at F r/min: C an angle reached within one
//! revolution the way its sign says, H a travel of any number of turns; X and Z in the same
//! block move along, geared to its angle (motion's rigid-tap gearing, D101).

use cnc_interpreter_core::{Aux, Fault, ProgramError, Turn};

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

    /// C and H program the C axis in G08, G00 and G84/G88 blocks, and the face's second
    /// coordinate in polar interpolation (D141).
    pub(super) fn c_words(&self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let motion = b.group(1).unwrap_or(self.motion);
        let c_moves = matches!(
            motion,
            G::Own(super::HuaxingG::Rotary { .. } | super::HuaxingG::RigidTap { .. }) | G::Rapid
        ) && self.core.setup.spindle_c_axis;
        if self.core.polar.is_some() {
            return Ok(());
        }
        for c in ['C', 'H'] {
            if b.get(c).is_some() && !c_moves {
                let why = match self.core.setup.spindle_c_axis {
                    true => {
                        format!("address {c}: the C axis is programmed with G00, G08 or G84/G88")
                    }
                    false => format!("address {c}: no C axis on this machine"),
                };
                return Err(self.fault(Fault::RotaryAxis, why));
            }
        }
        Ok(())
    }
}
