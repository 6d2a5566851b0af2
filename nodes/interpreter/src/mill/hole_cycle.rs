//! The mill's hole-machining canned cycles G73, G74, G76 and G81–G89 (`003` §8.1, whose text
//! the seed lacks; inventory Appendix A.1), with G98/G99 and G80.
//!
//! A cycle block positions over the hole at the current level, goes to the R level, machines
//! the hole down to Z, and returns to R (G99) or to the initial level (G98), L (or K) times.
//! The drilling axis is the one normal to the plane (Z in G17). Hole data (Z, R, Q, P) are
//! modal until G80 or a group-01 code. Decision D47 records what the appendix leaves open.

use cnc_interpreter_core::{show, Aux, Command, Fault, MoveKind, ProgramError, SpindleDir};

use super::{HoleKind, Mill, MillG};
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

/// Most passes or pecks one cycle block may generate.
const MAX_CYCLE_STEPS: usize = 1_000_000;

/// The clearance of a peck: G73 backs off this far after each peck; G83 comes back down to
/// this far above the last depth (FANUC parameters 531/532; the value LinuxCNC uses).
pub(super) const PECK_CLEARANCE: f64 = 0.254;
/// Most repetitions of one hole block (`003` table 7.1: repeat counts 1–999).
const MAX_REPEATS: f64 = 999.0;

/// The cycle that is modal, with its hole data.
#[derive(Debug, Clone, Copy)]
pub struct HoleCycle {
    kind: HoleKind,
    /// Z word as written: the bottom (G90) or its distance from R (G91).
    z: Option<f64>,
    /// R word as written: the R level (G90) or its distance from the initial level (G91).
    r: Option<f64>,
    /// Peck depth (G73/G83) or shift (G76/G87), mm.
    q: f64,
    /// Dwell at the bottom, ms.
    dwell_ms: f64,
    /// The drilling axis's work position when the cycles began.
    initial: f64,
}

impl Fanuc<Mill> {
    /// The drilling axis: the one normal to the plane (G17 Z, G18 Y, G19 X).
    fn drill_axis(&self) -> Result<usize, ProgramError> {
        let letter = match self.d.plane {
            G::PlaneZx => 'Y',
            G::PlaneYz => 'X',
            _ => 'Z',
        };
        self.core.axis(letter).ok_or_else(|| {
            self.fault(
                Fault::AxisAddress,
                format!(
                    "canned cycles in this plane drill along {letter}, which the machine lacks"
                ),
            )
        })
    }

    /// The canned cycle in force, if any.
    pub(super) fn hole_kind(&self) -> Option<HoleKind> {
        self.d.hole.map(|h| h.kind)
    }

    /// The block machines a hole: a cycle code in it, or a cycle in force and no group-01
    /// code or G80 (its K is then a repeat count).
    pub(super) fn cycle_block(&self, b: &Block<Mill>) -> bool {
        match b.group(9) {
            Some(G::Own(MillG::HoleCycle(_))) => true,
            Some(_) => false,
            None => self.d.hole.is_some() && b.group(1).is_none(),
        }
    }

    /// G73/G74/G76/G81–G89: makes the cycle modal, keeping the hole data of one that is
    /// already modal.
    pub(super) fn select_hole_cycle(&mut self, kind: HoleKind) -> Result<(), ProgramError> {
        let d = self.drill_axis()?;
        let initial = self.core.work_position()[d];
        self.d.hole = Some(match self.d.hole {
            Some(h) => HoleCycle { kind, ..h },
            None => HoleCycle {
                kind,
                z: None,
                r: None,
                q: 0.0,
                dwell_ms: 0.0,
                initial,
            },
        });
        Ok(())
    }

    /// A block while a cycle is modal: takes its hole data and machines the hole when the
    /// block has a position, Z or R (`003` Appendix A.1).
    pub(super) fn hole_block(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let Some(mut h) = self.d.hole else {
            return Ok(());
        };
        let d = self.drill_axis()?;
        let drill_letter = self.core.setup.axes[d];
        if let Some(z) = b.get(drill_letter) {
            h.z = Some(z);
        }
        if let Some(r) = b.get('R') {
            h.r = Some(r);
        }
        if let Some(q) = b.get('Q') {
            if q <= 0.0 && matches!(h.kind, HoleKind::HighSpeedPeck | HoleKind::Peck) {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("Q{}: the peck depth must be above 0", show(q)),
                ));
            }
            h.q = q.abs();
        }
        if let Some(p) = b.get('P') {
            if !(0.0..=99_999_999.0).contains(&p) {
                return Err(self.fault(
                    Fault::DwellTime,
                    format!("P{}: dwell 0–99999999 ms", show(p)),
                ));
            }
            h.dwell_ms = p;
        }
        self.d.hole = Some(h);
        let repeats = match (b.get('L'), b.get('K')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::RepeatedWord, "L and K both give the repeat count"))
            }
            (Some(n), None) | (None, Some(n)) => n,
            (None, None) => 1.0,
        };
        if repeats.fract() != 0.0 || !(0.0..=MAX_REPEATS).contains(&repeats) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("repeat count {}: 0–{MAX_REPEATS}", show(repeats)),
            ));
        }
        if !(self.has_axis_words(b) || b.has('R')) {
            return Ok(());
        }
        let (Some(z), Some(r)) = (h.z, h.r) else {
            return Err(self.fault(
                Fault::MissingWord,
                format!("canned cycle without {drill_letter} (hole bottom) or R (R level)"),
            ));
        };
        let (r_level, bottom) = if self.incremental {
            (h.initial + r, h.initial + r + z)
        } else {
            (r, z)
        };
        if matches!(h.kind, HoleKind::HighSpeedPeck | HoleKind::Peck) {
            // Checked before any move: a peck of nothing, or of a hair, never ends.
            if h.q <= 0.0 {
                return Err(self.fault(Fault::MissingWord, "G73/G83 need Q (peck depth)"));
            }
            if (r_level - bottom) / h.q > MAX_CYCLE_STEPS as f64 {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("Q{}: more than {MAX_CYCLE_STEPS} pecks", show(h.q)),
                ));
            }
        }
        if h.kind == HoleKind::BackBore {
            if self.d.cycle_return_r {
                return Err(self.fault(Fault::IllegalWord, "G87 back boring returns only in G98"));
            }
            if r_level > bottom {
                return Err(self.fault(Fault::OutOfRange, "G87: the R level must lie below Z"));
            }
        } else if r_level < bottom {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "the R level {} lies below the hole bottom {}",
                    show(r_level),
                    show(bottom)
                ),
            ));
        }
        for _ in 0..repeats as u32 {
            let mut target = self.core.work_position();
            for (i, &letter) in self.core.setup.axes.iter().enumerate() {
                if i == d {
                    continue;
                }
                if let Some(v) = b.get(letter) {
                    target[i] = if self.incremental { target[i] + v } else { v };
                }
            }
            self.one_hole(h, d, &target, r_level, bottom)?;
        }
        Ok(())
    }

    /// Positions over `target`, machines one hole and returns.
    fn one_hole(
        &mut self,
        h: HoleCycle,
        d: usize,
        target: &[f64],
        r_level: f64,
        bottom: f64,
    ) -> Result<(), ProgramError> {
        let clear = if self.d.cycle_return_r {
            r_level
        } else {
            h.initial.max(r_level)
        };
        // Below the R level, rise to it before moving across (never drag the tool sideways
        // through the part).
        if self.core.work_position()[d] < r_level && h.kind != HoleKind::BackBore {
            self.cycle_move(d, r_level, MoveKind::Rapid)?;
        }
        let mut over = target.to_vec();
        over[d] = self.core.work_position()[d];
        if over != self.core.work_position() {
            self.core.emit(&over, MoveKind::Rapid)?;
        }
        let feed = self.core.feed;
        let dwell = |it: &mut Self| {
            if h.dwell_ms > 0.0 {
                it.core.push(Command::Dwell {
                    seconds: h.dwell_ms / 1000.0,
                });
            }
        };
        if h.kind != HoleKind::BackBore {
            self.rapid_to_level(d, r_level)?;
        }
        match h.kind {
            HoleKind::HighSpeedPeck | HoleKind::Peck => {
                let mut depth = r_level;
                while depth > bottom {
                    let next = (depth - h.q).max(bottom);
                    if depth != r_level && h.kind == HoleKind::Peck {
                        // G83: back out to R, then rapid down to just above the last depth.
                        self.cycle_move(d, r_level, MoveKind::Rapid)?;
                        self.cycle_move(d, depth + PECK_CLEARANCE, MoveKind::Rapid)?;
                    }
                    self.cycle_move(d, next, MoveKind::Feed(feed))?;
                    if next > bottom && h.kind == HoleKind::HighSpeedPeck {
                        self.cycle_move(d, next + PECK_CLEARANCE, MoveKind::Rapid)?;
                    }
                    depth = next;
                }
                dwell(self);
                self.cycle_move(d, clear, MoveKind::Rapid)
            }
            HoleKind::Drill | HoleKind::Counterbore => {
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.cycle_move(d, clear, MoveKind::Rapid)
            }
            HoleKind::Bore | HoleKind::BoreDwell => {
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.cycle_move(d, r_level, MoveKind::Feed(feed))?;
                self.rapid_to_level(d, clear)
            }
            HoleKind::Tap | HoleKind::LeftTap if self.d.rigid_tapping => {
                self.rigid_tap(h.kind, d, bottom, r_level, h.dwell_ms)?;
                self.rapid_to_level(d, clear)
            }
            HoleKind::Tap | HoleKind::LeftTap => {
                // The spindle turns the way of the tap in, reverses at the bottom and turns
                // back once the tap is out at R.
                let (out, back) = if h.kind == HoleKind::Tap {
                    (4, 3)
                } else {
                    (3, 4)
                };
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.spindle_code(out);
                self.cycle_move(d, r_level, MoveKind::Feed(feed))?;
                self.spindle_code(back);
                self.rapid_to_level(d, clear)
            }
            HoleKind::BoreSpindleStop | HoleKind::BoreManual => {
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.stop_spindle();
                if h.kind == HoleKind::BoreManual {
                    // G88: the operator retracts by hand during this stop (decision D47);
                    // the automatic return follows cycle start.
                    self.core.aux(Aux::M(0));
                }
                self.cycle_move(d, clear, MoveKind::Rapid)?;
                self.spindle_on();
                Ok(())
            }
            HoleKind::FineBore => {
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.leave_oriented(d, clear, h.q)
            }
            HoleKind::BackBore => {
                // Shifted off the bore down to R under the part, then bore upwards to Z.
                self.leave_oriented(d, r_level, h.q)?;
                self.cycle_move(d, bottom, MoveKind::Feed(feed))?;
                dwell(self);
                self.leave_oriented(d, clear, h.q)
            }
        }
    }

    /// Moves the drilling axis alone to `level`.
    pub(super) fn cycle_move(
        &mut self,
        d: usize,
        level: f64,
        kind: MoveKind,
    ) -> Result<(), ProgramError> {
        let mut end = self.core.work_position();
        end[d] = level;
        self.core.emit(&end, kind)
    }

    fn rapid_to_level(&mut self, d: usize, level: f64) -> Result<(), ProgramError> {
        if self.core.work_position()[d] != level {
            self.cycle_move(d, level, MoveKind::Rapid)?;
        }
        Ok(())
    }

    fn spindle_code(&mut self, m: i32) {
        self.core.spindle_code(m);
    }

    /// M05, remembering which way the spindle turned for [`Self::spindle_on`].
    fn stop_spindle(&mut self) {
        if self.core.spindle() != SpindleDir::Stopped {
            self.d.cycle_spindle = self.core.spindle();
        }
        self.spindle_code(5);
    }

    /// The spindle back on in the direction it turned before the cycle stopped it (M03 if
    /// it was not turning: boring runs clockwise).
    fn spindle_on(&mut self) {
        let m = if self.d.cycle_spindle == SpindleDir::Ccw {
            4
        } else {
            3
        };
        self.spindle_code(m);
    }

    /// G76/G87: orients the spindle, shifts off the bore wall, rapids the drilling axis to
    /// `level`, shifts back and starts the spindle again.
    fn leave_oriented(&mut self, d: usize, level: f64, q: f64) -> Result<(), ProgramError> {
        self.orient_and_shift(q, true)?;
        self.cycle_move(d, level, MoveKind::Rapid)?;
        self.orient_and_shift(q, false)?;
        self.spindle_on();
        Ok(())
    }

    /// G76/G87: `away` orients the spindle (M19) and moves the tool off the bore wall by the
    /// shift Q along +X (FANUC's default shift direction); otherwise it moves back.
    fn orient_and_shift(&mut self, q: f64, away: bool) -> Result<(), ProgramError> {
        if away {
            if self.core.spindle() != SpindleDir::Stopped {
                self.d.cycle_spindle = self.core.spindle();
            }
            self.core.spindle_code(19);
        }
        if q == 0.0 {
            return Ok(());
        }
        let x = self
            .core
            .axis('X')
            .ok_or_else(|| self.fault(Fault::AxisAddress, "the G76/G87 shift needs an X axis"))?;
        let mut end = self.core.work_position();
        end[x] += if away { q } else { -q };
        self.core.emit(&end, MoveKind::Rapid)
    }
}
