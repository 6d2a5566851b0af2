//! Huaxing program flow: the block-range repeats G25 (jump), G26 (call) and G27 (loop)
//! (§5.13), the input-conditioned repeats G21/G23 (§5.12), and G07 linear chip breaking
//! (§5.6), a path filter of the core switched by a one-shot code.

use cnc_interpreter_core::chip_break::ChipBreak;
use cnc_interpreter_core::{find_number, show, Fault, ProgramError, Repeat};

use super::{Huaxing, HuaxingG};
use crate::fanuc::block::{code_x10, whole, Block};
use crate::fanuc::Fanuc;

impl Fanuc<Huaxing> {
    pub(super) fn range(&mut self, b: &Block<Huaxing>, g: HuaxingG) -> Result<(), ProgramError> {
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::RangeError, "P (first block) missing"))?;
        let q = b
            .get('Q')
            .ok_or_else(|| self.fault(Fault::RangeError, "Q (last block) missing"))?;
        let count = match b.get('L') {
            Some(l) => Some(
                code_x10(l)
                    .map(|c| c / 10)
                    .filter(|&c| c >= 1)
                    .ok_or_else(|| self.fault(Fault::RangeError, "L must be a count ≥ 1"))?,
            ),
            None if g == HuaxingG::LoopRange => None,
            None => Some(1),
        };
        if g == HuaxingG::LoopRange
            && self.core.level().repeats.iter().any(|r| {
                matches!(
                    r,
                    Repeat::Range {
                        remaining: None,
                        ..
                    }
                )
            })
        {
            return Err(self.fault(Fault::RangeError, "G27 inside G27"));
        }
        let (p, q) = (whole(p), whole(q));
        let text = self.core.level().text.clone();
        let first = find_number(&text, self.core.level().pos, p)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{p} not found")))?;
        let last = find_number(&text, first, q)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{q} not found")))?;
        if last.offset < first.offset || (g == HuaxingG::LoopRange && b.number == Some(q)) {
            return Err(self.fault(Fault::RangeError, format!("block range N{p}–N{q} is wrong")));
        }
        let here = self.core.level().pos;
        let then = match g {
            // G25: continue after Q; G26: come back after the G26 block; G27: after the G27 block.
            HuaxingG::JumpRange => None,
            _ => Some(here),
        };
        let f = self.core.level();
        f.repeats.push(Repeat::Range {
            first,
            last: q,
            remaining: count,
            then,
            home: None,
            end_code: None,
        });
        f.pos = first;
        Ok(())
    }

    pub(super) fn conditional_repeat(
        &mut self,
        b: &Block<Huaxing>,
        high: bool,
    ) -> Result<(), ProgramError> {
        // G21/G23 (`000` §5.12): the manual's worked examples run the range when the input has
        // a signal (G21) or has none (G23), the opposite of the headings (decision D21).
        let run = match b.get('X') {
            None => false,
            Some(x) => {
                let byte = x.trunc() as u32;
                let bit = ((x.fract() * 10.0).round() as u8).min(7);
                let on = self.core.setup.inputs.contains(&(byte, bit));
                if high {
                    !on
                } else {
                    on
                }
            }
        };
        if !run {
            return Ok(());
        }
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::RangeError, "P missing"))?;
        let text = self.core.level().text.clone();
        let q = b.get('Q').map(whole);
        let first = find_number(&text, self.core.level().pos, whole(p))
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{} not found", show(p))))?;
        let Some(q) = q else {
            // Q omitted: to the end of the program.
            self.core.level().pos = first;
            return Ok(());
        };
        let count = b.get('L').map(whole).unwrap_or(1).max(1);
        let f = self.core.level();
        f.repeats.push(Repeat::Range {
            first,
            last: q,
            remaining: Some(count),
            then: None,
            home: None,
            end_code: None,
        });
        f.pos = first;
        Ok(())
    }

    pub(super) fn set_chip_break(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        if b.has('P') || b.has('Q') {
            // The format line prints thread chip breaking as `G07 P Q L` (inventory §14.3).
            return Err(self.fault(
                Fault::NotSupported,
                "G07 P Q L (thread chip breaking) needs an oscillation superimposed in motion",
            ));
        }
        self.core.chip_break = match (b.get('K'), b.get('L')) {
            (None, None) => None,
            (Some(pause), Some(length)) => {
                if !(0.0..=9999.999).contains(&pause) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!("G07 K{}: pause 0–9999.999 s", show(pause)),
                    ));
                }
                if !(length > 0.0 && length <= 99_999.0) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!("G07 L{}: length above 0 mm", show(length)),
                    ));
                }
                Some(ChipBreak { pause, length })
            }
            _ => {
                return Err(self.fault(
                    Fault::MissingWord,
                    "G07 needs both K (pause) and L (length), or neither to cancel",
                ))
            }
        };
        Ok(())
    }
}
