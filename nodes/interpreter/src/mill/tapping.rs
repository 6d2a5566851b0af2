//! Tapping on the mill: G63's tapping mode, where linear moves are taps in a floating holder
//! (D131), and M29's rigid tapping, where G84 and G74 tap with the axis following the
//! spindle's angle (D130) — the same canonical moves the 802D's G63 and CYCLE84 make (D93,
//! D101), so motion and the simulated mill need nothing new.

use cnc_interpreter_core::{Command, Fault, MoveKind, ProgramError, SpindleDir, Turn};

use super::{HoleKind, Mill};
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

impl Fanuc<Mill> {
    /// The tap's pitch from F and S: F itself under G95, F / S under G94 (F = S × pitch).
    fn tap_pitch(&self, what: &str) -> Result<f64, ProgramError> {
        let (feed, rpm) = (self.core.feed, self.core.rpm);
        if rpm <= 0.0 {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{what} needs the spindle speed S (F = S × pitch)"),
            ));
        }
        if feed <= 0.0 {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{what} needs F (S × pitch, or the pitch under G95)"),
            ));
        }
        Ok(if self.core.feed_per_rev() {
            feed
        } else {
            feed / rpm
        })
    }

    /// M29 S (`003` §6.4): the spindle stops and holds its angle in position control (a
    /// positioning of 0° the incremental way), and G84/G74 tap rigidly until G80 or a group-01
    /// code. The speed is the block's S or the last one.
    pub(super) fn rigid_tapping_on(&mut self) -> Result<(), ProgramError> {
        if self.core.rpm <= 0.0 {
            return Err(self.fault(Fault::MissingWord, "M29 needs the tapping speed S (M29 S…)"));
        }
        self.core.orient_spindle(0.0, Turn::Incremental);
        self.d.rigid_tapping = true;
        Ok(())
    }

    /// G84 (or G74, left hand) after M29: in to the bottom with the axis locked to the
    /// spindle, the dwell, out to R turning the other way. The spindle must still be in the
    /// position control M29 gave it (no M03/M04 since).
    pub(super) fn rigid_tap(
        &mut self,
        kind: HoleKind,
        d: usize,
        bottom: f64,
        r_level: f64,
        dwell_ms: f64,
    ) -> Result<(), ProgramError> {
        let what = if kind == HoleKind::Tap { "G84" } else { "G74" };
        if self.core.spindle() != SpindleDir::Stopped {
            return Err(self.fault(
                Fault::MissingWord,
                format!(
                    "{what} rigid: M03/M04 since M29 took the spindle out of position control: \
                     give M29 S again"
                ),
            ));
        }
        let pitch = self.tap_pitch(&format!("{what} rigid tapping"))?;
        // + is the way M03 turns: a right-hand tap goes in turning M03's way.
        let hand = if kind == HoleKind::Tap { 1.0 } else { -1.0 };
        let rpm = self.core.rpm;
        self.cycle_move(
            d,
            bottom,
            MoveKind::Tap {
                lead: hand * pitch,
                rpm,
            },
        )?;
        if dwell_ms > 0.0 {
            self.core.push(Command::Dwell {
                seconds: dwell_ms / 1000.0,
            });
        }
        self.cycle_move(
            d,
            r_level,
            MoveKind::Tap {
                lead: -hand * pitch,
                rpm,
            },
        )
    }

    /// Under G63 a linear move is a tap in a floating holder: cut as a thread of the pitch
    /// F/S (F under G95), which holds the feed to the spindle and keeps the overrides out, as
    /// the 802D's G63 (D93, D131). Rapids stay rapids; an arc is no tap (P/S 010).
    pub(super) fn tapping_move(&mut self, b: &Block<Mill>) -> Option<Result<(), ProgramError>> {
        if !self.d.tapping_mode || !self.has_axis_words(b) {
            return None;
        }
        let motion = b.group(1).unwrap_or(self.motion);
        match motion {
            G::Linear => {}
            G::ArcCw | G::ArcCcw => {
                return Some(Err(self.fault(
                    Fault::NotSupported,
                    format!(
                        "{}: an arc in G63 tapping mode is no tap: G64 first",
                        motion.name()
                    ),
                )))
            }
            _ => return None,
        }
        self.motion = motion;
        Some(self.floating_tap(b))
    }

    fn floating_tap(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let lead = self.tap_pitch("G63 tapping")?;
        let end = self.end_point(b)?;
        self.core.emit(&end, MoveKind::Thread { lead, angle: 0.0 })
    }
}
