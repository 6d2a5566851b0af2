//! G74 face grooving / peck drilling and G75 radial grooving (`000` §5.22.5–5.22.6).
//!
//! Both peck along one axis ("peck axis") in steps of Q (G74, Z) or P (G75, X), retracting e
//! after each peck, then step along the other axis ("shift axis") by P (G74) or Q (G75) until
//! the end point. Steps are in least-input increments without a decimal point (decision D12)
//! and radius values (decision D23).

use cnc_interpreter_core::{Fault, MoveKind, ProgramError};

use super::compound::MAX_CYCLE_STEPS;
use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::Fanuc;

impl Fanuc<Huaxing> {
    pub(super) fn grooving(
        &mut self,
        b: &Block<Huaxing>,
        radial: bool,
    ) -> Result<(), ProgramError> {
        let runs = if radial {
            b.has('X') || b.has('U')
        } else {
            b.has('Z') || b.has('W')
        };
        let step_word = if radial { 'P' } else { 'Q' };
        if !runs || !b.has(step_word) {
            // First block `G74 R(e)` / `G75 R(e)`: the retract per peck.
            if let Some(e) = b.get('R') {
                self.d.groove_retract = e.abs();
            }
            return Ok(());
        }
        let here = self.core.work_position();
        let (xi, zi) = self.core.xz()?;
        let end = self.end_point(b)?;
        let s = self.core.x_scale();
        // Work in the plane: peck coordinate p and shift coordinate q.
        let (p0, q0, pe, qe) = if radial {
            (here[xi] * s, here[zi], end[xi] * s, end[zi])
        } else {
            (here[zi], here[xi] * s, end[zi], end[xi] * s)
        };
        let peck = self
            .increments(b, if radial { 'P' } else { 'Q' })
            .unwrap_or(0.0)
            .abs();
        let shift = self
            .increments(b, if radial { 'Q' } else { 'P' })
            .unwrap_or(0.0)
            .abs();
        let bottom_retract = b.get('R').unwrap_or(0.0).abs() * if radial { 1.0 } else { 0.5 };
        let e = self.d.groove_retract;
        if peck <= 0.0 {
            return Err(self.fault(Fault::MissingWord, "peck depth is 0"));
        }
        let passes = if shift > 0.0 {
            (qe - q0).abs() / shift
        } else {
            0.0
        } + 1.0;
        if passes * ((pe - p0).abs() / peck + 1.0) > MAX_CYCLE_STEPS as f64 {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("grooving steps give more than {MAX_CYCLE_STEPS} pecks"),
            ));
        }
        let dir_p = if pe < p0 { -1.0 } else { 1.0 };
        let dir_q = if qe < q0 { -1.0 } else { 1.0 };
        let point = |p: f64, q: f64| {
            let mut v = here.clone();
            if radial {
                v[xi] = p / s;
                v[zi] = q;
            } else {
                v[zi] = p;
                v[xi] = q / s;
            }
            v
        };
        let feed = self.core.feed;
        let mut q = q0;
        loop {
            // Pecks down to the end along the peck axis.
            let mut p = p0;
            while (pe - p) * dir_p > 1e-9 {
                let next = if (pe - (p + dir_p * peck)) * dir_p > 0.0 {
                    p + dir_p * peck
                } else {
                    pe
                };
                self.core.emit(&point(next, q), MoveKind::Feed(feed))?;
                p = next;
                if (pe - p) * dir_p > 1e-9 && e > 0.0 {
                    self.core
                        .emit(&point(p - dir_p * e.min(peck), q), MoveKind::Rapid)?;
                    self.core.emit(&point(p, q), MoveKind::Feed(feed))?;
                }
            }
            // At the bottom: retract along the shift axis, away from the end, then back out.
            let last = (qe - q) * dir_q <= 1e-9;
            let q_out = if last { q } else { q - dir_q * bottom_retract };
            if (q_out - q).abs() > 1e-12 {
                self.core.emit(&point(pe, q_out), MoveKind::Rapid)?;
            }
            self.core.emit(&point(p0, q_out), MoveKind::Rapid)?;
            if last {
                break;
            }
            let next_q = if shift > 0.0 && (qe - (q + dir_q * shift)) * dir_q > 0.0 {
                q + dir_q * shift
            } else {
                qe
            };
            if shift <= 0.0 && (qe - q).abs() > 1e-9 {
                return Err(self.fault(Fault::MissingWord, "shift between passes is 0"));
            }
            self.core.emit(&point(p0, next_q), MoveKind::Rapid)?;
            q = next_q;
        }
        self.core.emit(&point(p0, q0), MoveKind::Rapid)?;
        Ok(())
    }
}
