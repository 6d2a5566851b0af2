//! G31, the skip move (`000` §5.17; decision D139): a feed move that ends when the skip input
//! comes, the next block running from there. The input is the one the machine wires to the
//! drives' measuring input (`machine.skip_input`, S#46), which latches the axes at its edge as
//! the 802D's MEAS does (D116); `K m.n` names it active high, `L m.n` active low. B19.6
//! (`machine.skip_keeps_actual`): the axes keep their actual coordinates where the skip came,
//! or the programmed end point is written over them.

use cnc_interpreter_core::{Fault, ProgramError};

use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::Fanuc;

impl Fanuc<Huaxing> {
    /// G31 X(U) Z(W) F L/K m.n.
    pub(super) fn skip(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let Some(wired) = self.core.setup.skip_input else {
            return Err(self.fault(Fault::NotSupported, "G31: this machine has no skip input"));
        };
        let (named, rising) = match (b.get('K'), b.get('L')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::RepeatedWord, "G31 with both K and L"));
            }
            (Some(k), None) => (Some(k), true),
            (None, Some(l)) => (Some(l), false),
            (None, None) => (None, true),
        };
        if let Some(v) = named {
            let input = ((v.trunc()) as u32, ((v.fract() * 10.0).round()) as u32);
            if input != wired {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!(
                        "G31 input X{v}: the drives latch X{}.{}, the skip input (S#46)",
                        wired.0, wired.1
                    ),
                ));
            }
        }
        let end = self.end_point(b)?;
        let feed = self.core.feed;
        if !self.core.setup.skip_keeps_actual {
            self.d.skip_end = Some(end.clone());
        }
        self.core.measure(&end, feed, rising, true)
    }

    /// Before the block after a skip, with B19.6 = 0: the programmed end point written over
    /// the coordinates of the point where the skip came (the latched one, not where the axes
    /// braked to: a gauged face reads as programmed). No skip (the end reached): nothing.
    pub(super) fn after_skip(&mut self) {
        let Some(end) = self.d.skip_end.take() else {
            return;
        };
        let Some(latched) = self
            .core
            .measurement
            .as_ref()
            .filter(|m| m.triggered)
            .map(|m| m.position.clone())
        else {
            return;
        };
        let here = self.core.work_position();
        let rest = self.core.pos.clone();
        for (i, e) in end.iter().enumerate() {
            let (Some(h), Some(l), Some(r)) = (here.get(i), latched.get(i), rest.get(i)) else {
                continue;
            };
            // The latched point in work coordinates: where the axes stand, less the braking.
            let at = h + (l - r);
            if let Some(s) = self.core.shift.get_mut(i) {
                *s -= e - at;
            }
        }
    }
}
