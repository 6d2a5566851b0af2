//! Rigid tapping on the Huaxing turn-mill, G84 (face) and G88 (side) after M29 (`000`
//! §5.23.4; decision D142). M29 S puts the tapping spindle — on this machine the live tool —
//! into position control at S r/min; each G84/G88 block then taps a hole at (X, C) to the
//! bottom Z (G84) or at (Z, C) to the bottom X (G88): C indexed at its rapid, the clamp code
//! Mα, the tap in with the live tool geared to the slide by the pitch F (F < 0: left hand; I
//! threads per inch), P ms at the bottom, out to the hole's start turning back, Mα+1 — K
//! times, an incremental position (U/W, H) stepping to the next hole. G80, another group-01
//! code or reset ends it; G80 restores the motion code before it.

use cnc_interpreter_core::{Command, Fault, MoveKind, ProgramError, Turn};

use super::{Huaxing, HuaxingG};
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

/// Rigid tapping's state: M29's speed, the modal words, the motion code G80 brings back.
#[derive(Debug, Clone, Copy, Default)]
pub struct RigidTap {
    /// M29 given: the tapping spindle's speed, r/min.
    pub rpm: Option<f64>,
    /// F/I: the pitch, signed.
    lead: Option<f64>,
    /// P: the dwell at the bottom, ms.
    dwell_ms: f64,
    /// The hole's bottom (work coordinate of the drilling axis), kept for following blocks.
    bottom: Option<f64>,
    /// The group-01 code before G84/G88.
    before: Option<G<HuaxingG>>,
}

impl Fanuc<Huaxing> {
    /// M29 S: the tapping spindle into position control at the speed S (the block's or the
    /// last one).
    pub(super) fn rigid_mode_on(&mut self) -> Result<(), ProgramError> {
        if self.core.setup.live_tool.is_none() {
            return Err(self.fault(
                Fault::RotaryAxis,
                "M29: rigid tapping here taps with a live tool, and this lathe has none",
            ));
        }
        if self.core.rpm <= 0.0 {
            return Err(self.fault(Fault::MissingWord, "M29 needs the tapping speed S (M29 S…)"));
        }
        self.d.rigid.rpm = Some(self.core.rpm);
        Ok(())
    }

    /// G84/G88 selected (or left): the modal words and what G80 brings back.
    pub(super) fn rigid_tap_selected(&mut self, was: G<HuaxingG>) {
        if !matches!(was, G::Own(HuaxingG::RigidTap { .. })) {
            self.d.rigid.before = Some(was);
            self.d.rigid.bottom = None;
        }
    }

    /// G80: rigid tapping off, the motion code before it back.
    pub(super) fn rigid_tap_cancel(&mut self) {
        if let Some(before) = self.d.rigid.before.take() {
            if matches!(self.motion, G::Own(HuaxingG::RigidTap { .. })) {
                self.motion = before;
            }
        }
        self.d.rigid = RigidTap::default();
    }

    /// Takes the modal words P and F/I of a G84/G88 block.
    pub(super) fn rigid_tap_words(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        if let Some(p) = b.get('P') {
            if !(0.0..=99_999_999.0).contains(&p) {
                return Err(self.fault(Fault::DwellTime, "G84/G88 P dwell out of range"));
            }
            self.d.rigid.dwell_ms = p;
        }
        match (b.get('F'), b.get('I')) {
            (Some(_), Some(_)) => Err(self.fault(Fault::ThreadLead, "F and I in one block")),
            (Some(f), None) => {
                self.d.rigid.lead = Some(f);
                Ok(())
            }
            (None, Some(i)) if i != 0.0 => {
                self.d.rigid.lead = Some(25.4 / i);
                Ok(())
            }
            (None, Some(_)) => Err(self.fault(Fault::ThreadLead, "I0: no threads per inch")),
            (None, None) => Ok(()),
        }
    }

    /// One G84 (`side` false) or G88 block: K holes.
    pub(super) fn rigid_tap(&mut self, b: &Block<Huaxing>, side: bool) -> Result<(), ProgramError> {
        let name = if side { "G88" } else { "G84" };
        let Some(rpm) = self.d.rigid.rpm else {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{name}: rigid tapping needs M29 S first"),
            ));
        };
        let lead = self.d.rigid.lead.ok_or_else(|| {
            self.fault(
                Fault::ThreadLead,
                format!("{name} needs the pitch F (or I)"),
            )
        })?;
        let (xi, zi) = self.core.xz()?;
        // G84 taps along Z at the hole (X, C); G88 along X at (Z, C).
        let (hole, drill, bottom_abs, bottom_inc, hole_inc) = if side {
            (zi, xi, 'X', 'U', 'W')
        } else {
            (xi, zi, 'Z', 'W', 'U')
        };
        let here = self.core.work_position();
        let end = self.end_point(b)?;
        if b.has(bottom_abs) || b.has(bottom_inc) {
            self.d.rigid.bottom = Some(end[drill]);
        }
        let bottom = self.d.rigid.bottom.ok_or_else(|| {
            self.fault(
                Fault::MissingWord,
                format!("{name} needs the hole bottom {bottom_abs}({bottom_inc})"),
            )
        })?;
        let repeats = self.repeat_count(b, name)?;
        let clamp = self.clamp_code(b, name)?;
        let step = if b.has(hole_inc) {
            end[hole] - here[hole]
        } else {
            0.0
        };
        let mut at = here.clone();
        at[hole] = end[hole];
        for k in 0..repeats {
            if k > 0 {
                at[hole] += step;
            }
            self.rapid_unless_there(&at)?;
            self.index_c(b, &mut at, k)?;
            if let Some(m) = clamp {
                self.core.aux(cnc_interpreter_core::Aux::M(m));
            }
            let mut down = at.clone();
            down[drill] = bottom;
            self.core.live_tool_tap(&down, lead, rpm)?;
            if self.d.rigid.dwell_ms > 0.0 {
                self.core.push(Command::Dwell {
                    seconds: self.d.rigid.dwell_ms / 1000.0,
                });
            }
            self.core.live_tool_tap(&at, -lead, rpm)?;
            if let Some(m) = clamp {
                self.core.aux(cnc_interpreter_core::Aux::M(m + 1));
            }
        }
        Ok(())
    }

    /// Hole `k`'s C in a drilling or tapping cycle (the sections' "(X, C)" and "(Z, C)"):
    /// the block's absolute C for the first hole, its H for every hole, at C's rapid.
    pub(super) fn index_c(
        &mut self,
        b: &Block<Huaxing>,
        at: &mut [f64],
        k: u32,
    ) -> Result<(), ProgramError> {
        let (degrees, way) = match self.c_target(b)? {
            Some((_, Turn::Plus | Turn::Minus)) if k > 0 => return Ok(()),
            Some(target) => target,
            None => return Ok(()),
        };
        let Some(c) = self.core.axis('C') else {
            return Err(self.fault(Fault::RotaryAxis, "address C: no C axis on this machine"));
        };
        at[c] = if way == Turn::Incremental {
            at[c] + degrees
        } else {
            degrees
        };
        let rpm = self.core.setup.c_rapid_rpm;
        self.core.emit(at, MoveKind::Rotary { degrees, way, rpm })
    }
}
