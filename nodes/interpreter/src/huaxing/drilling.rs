//! G83 axial and G87 radial peck drilling (`000` §5.22.7).
//!
//! The tool goes to the hole position at the level where the block starts (on a turn-mill C
//! too: the block's C, H the step from hole to hole, indexed as the tapping cycles index
//! it, D143), pecks down to the
//! bottom (high-speed: back off R after each peck, J0; deep-hole: all the way out, J1), dwells
//! P ms, and returns to the hole position at the start level, K times. The manual's figures
//! give the pecks in least-input increments (Q, decision D12) and R in mm, both radius values.
//! Decision D45 records what the manual leaves open.

use cnc_interpreter_core::cycles::{pecks, Pecking};
use cnc_interpreter_core::{show, Aux, Command, Fault, MoveKind, ProgramError};

use super::compound::MAX_CYCLE_STEPS;
use super::{Huaxing, HuaxingG};
use crate::fanuc::block::Block;
use crate::fanuc::codes::{G, M};
use crate::fanuc::Fanuc;

/// The cycle's modal words; positions, K and M are not modal.
#[derive(Debug, Clone, Copy)]
pub struct DrillWords {
    /// P: dwell at the bottom.
    dwell_ms: f64,
    /// Q: depth of one peck (0: straight to the bottom).
    peck: f64,
    /// R: back-off after each peck (`000` GS#44, default 1 mm).
    retract: f64,
    /// J1: deep-hole pecking, out of the hole after every peck.
    deep_hole: bool,
    /// The hole's bottom (work coordinate of the drilling axis): modal while the cycle stays
    /// selected (§5.22.7: every word but the position, K and M is modal).
    bottom: Option<f64>,
}

impl Default for DrillWords {
    fn default() -> Self {
        DrillWords {
            dwell_ms: 0.0,
            peck: 0.0,
            retract: 1.0,
            deep_hole: false,
            bottom: None,
        }
    }
}

/// Most repetitions of one drilling block (`000` §3.3.2: K up to 9999).
const MAX_REPEATS: f64 = 9999.0;

impl Fanuc<Huaxing> {
    /// G83/G87 selected: a bottom kept from another cycle (or before another motion code)
    /// does not carry over.
    pub(super) fn drilling_selected(&mut self, radial: bool) {
        if !matches!(self.motion, G::Own(HuaxingG::Drilling { radial: r }) if r == radial) {
            self.d.drill.bottom = None;
        }
    }

    /// Takes the modal words P, Q, R and J of a G83/G87 block.
    pub(super) fn drill_words(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        if let Some(p) = b.get('P') {
            if p.abs() > 99_999_999.0 {
                return Err(self.fault(Fault::DwellTime, "G83/G87 P dwell out of range"));
            }
            self.d.drill.dwell_ms = p.max(0.0);
        }
        if let Some(q) = self.increments(b, 'Q') {
            self.d.drill.peck = q.abs();
        }
        if let Some(r) = b.get('R') {
            if r.abs() > 9999.999 {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("G83/G87 R{}: 0–9999.999 mm", show(r)),
                ));
            }
            self.d.drill.retract = r.abs();
        }
        if let Some(j) = b.get('J') {
            self.d.drill.deep_hole = match j {
                0.0 => false,
                1.0 => true,
                _ => {
                    return Err(
                        self.fault(Fault::OutOfRange, format!("G83/G87 J{}: 0 or 1", show(j)))
                    )
                }
            };
        }
        Ok(())
    }

    pub(super) fn drilling(
        &mut self,
        b: &Block<Huaxing>,
        radial: bool,
    ) -> Result<(), ProgramError> {
        let (xi, zi) = self.core.xz()?;
        let name = if radial { "G87" } else { "G83" };
        // G83 drills along Z at hole position X; G87 along X at hole position Z.
        let (hole_axis, drill_axis) = if radial { (zi, xi) } else { (xi, zi) };
        let (bottom, bottom_inc, hole_inc) = if radial {
            ('X', 'U', 'W')
        } else {
            ('Z', 'W', 'U')
        };
        let here = self.core.work_position();
        let end = self.end_point(b)?;
        if b.has(bottom) || b.has(bottom_inc) {
            self.d.drill.bottom = Some(end[drill_axis]);
        }
        let Some(bottom_at) = self.d.drill.bottom else {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{name} needs the hole bottom {bottom}({bottom_inc})"),
            ));
        };
        let repeats = self.repeat_count(b, name)?;
        let clamp = self.clamp_code(b, name)?;
        // With an incremental hole position each repetition drills the next hole.
        let step = if b.has(hole_inc) {
            end[hole_axis] - here[hole_axis]
        } else {
            0.0
        };
        let s = if radial { self.core.x_scale() } else { 1.0 };
        let (top, depth) = (here[drill_axis] * s, bottom_at * s - here[drill_axis] * s);
        let words = self.d.drill;
        if words.peck > 0.0
            && (depth.abs() / words.peck + 1.0) * f64::from(repeats) > MAX_CYCLE_STEPS as f64
        {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("{name} gives more than {MAX_CYCLE_STEPS} pecks"),
            ));
        }
        // The hole: its position on the hole axis and C (`000` §5.22.7: "rapid to (X, C)"),
        // the drilling axis at the start point.
        let mut top_at = here.clone();
        top_at[hole_axis] = end[hole_axis];
        top_at[drill_axis] = top / s;
        for k in 0..repeats {
            if k > 0 {
                top_at[hole_axis] += step;
            }
            self.rapid_unless_there(&top_at)?;
            self.index_c(b, &mut top_at, k)?;
            let at = |p: f64| {
                let mut v = top_at.clone();
                v[drill_axis] = p / s;
                v
            };
            if let Some(m) = clamp {
                self.core.aux(Aux::M(m));
            }
            let pecking = Pecking {
                peck: words.peck,
                retract: words.retract,
                deep_hole: words.deep_hole,
            };
            for (p, kind) in pecks(top, depth, pecking) {
                let kind = if kind {
                    MoveKind::Feed(self.core.feed)
                } else {
                    MoveKind::Rapid
                };
                self.core.emit(&at(p), kind)?;
            }
            if words.dwell_ms > 0.0 {
                self.core.push(Command::Dwell {
                    seconds: words.dwell_ms / 1000.0,
                });
            }
            self.core.emit(&top_at, MoveKind::Rapid)?;
            if let Some(m) = clamp {
                // The unclamp code is the clamp code + 1 (decision D45).
                self.core.aux(Aux::M(m + 1));
            }
        }
        Ok(())
    }

    /// K of a drilling or tapping block: how many holes, 1–9999 (§3.3.2), 1 without it.
    pub(super) fn repeat_count(&self, b: &Block<Huaxing>, name: &str) -> Result<u32, ProgramError> {
        match b.get('K') {
            None => Ok(1),
            Some(k) if (1.0..=MAX_REPEATS).contains(&k) && k.fract() == 0.0 => Ok(k as u32),
            Some(k) => Err(self.fault(
                Fault::OutOfRange,
                format!("{name} K{}: repeat count 1–9999", show(k)),
            )),
        }
    }

    /// The spindle clamp code Mα of a drilling block, if it has one.
    pub(super) fn clamp_code(
        &self,
        b: &Block<Huaxing>,
        name: &str,
    ) -> Result<Option<i32>, ProgramError> {
        let mut codes =
            b.m.iter()
                .filter(|(m, _)| matches!(m, M::AuxBefore | M::AuxAfter))
                .map(|&(_, code)| code);
        let first = codes.next();
        if codes.next().is_some() {
            return Err(self.fault(
                Fault::IllegalWord,
                format!("{name} takes one spindle clamp M code"),
            ));
        }
        match first {
            Some(code) if code % 10 != 0 => Err(self.fault(
                Fault::IllegalWord,
                format!(
                    "{name}: M{} cannot clamp the spindle",
                    show(f64::from(code) / 10.0)
                ),
            )),
            Some(code) => Ok(Some((code / 10) as i32)),
            None => Ok(None),
        }
    }

    pub(super) fn rapid_unless_there(&mut self, target: &[f64]) -> Result<(), ProgramError> {
        let here = self.core.work_position();
        if here.iter().zip(target).any(|(a, b)| (a - b).abs() > 1e-9) {
            self.core.emit(target, MoveKind::Rapid)?;
        }
        Ok(())
    }
}
