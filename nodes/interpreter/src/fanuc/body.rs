//! A block's body (step 7 of `execute.rs`): one one-shot code, else the dialect's modal
//! cycle, else the block's motion in the modal motion code.

use cnc_interpreter_core::geometry::{self, ArcError, Pt};
use cnc_interpreter_core::{Command, Fault, MoveKind, ProgramError};

use super::block::Block;
use super::codes::G;
use super::{Family, Fanuc};

impl<D: Family> Fanuc<D> {
    /// The body of a block: one-shot codes, cycles, motion.
    pub(super) fn block_body(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        D::before_one_shots(self, b)?;
        // One-shot codes (group 00, and the dialect's own non-motion codes) first.
        for &(_, g, _) in &b.g {
            match g {
                G::Dwell => {
                    let seconds = D::dwell_seconds(self, b)?;
                    self.core.push(Command::Dwell { seconds });
                    return Ok(());
                }
                G::SetCoordinate => return self.set_coordinate(b, false),
                G::ReferenceReturn => return self.reference_return(b),
                G::Own(o) => {
                    if let Some(r) = D::one_shot(self, o, b) {
                        return r;
                    }
                }
                _ => {}
            }
        }
        if let Some(r) = D::before_motion(self, b) {
            return r;
        }
        if let Some(m) = b.group(1) {
            let motion = match m {
                G::Rapid | G::Linear | G::ArcCw | G::ArcCcw => true,
                G::Own(o) => D::is_motion(o),
                _ => false,
            };
            if motion {
                let changed = self.motion != m;
                self.motion = m;
                if let Some(r) = D::motion_selected(self, m, changed, b) {
                    return r;
                }
            }
        }
        // The cycle's modal words are kept even from a block without a position.
        D::motion_words(self, b)?;
        if !self.has_axis_words(b) {
            // A block of only modal words; arcs may still be full circles by I/K.
            let arc_ik = matches!(self.motion, G::ArcCw | G::ArcCcw) && (b.has('I') || b.has('K'));
            if !arc_ik && !D::moves_without_axes(self, b) {
                return Ok(());
            }
        }
        if self.core.comp.is_some()
            && !matches!(self.motion, G::Rapid | G::Linear | G::ArcCw | G::ArcCcw)
        {
            return Err(self.fault(
                Fault::CompInCycle,
                "tool-nose compensation active: cycles, threads and three-point arcs need G40 first",
            ));
        }
        match self.motion {
            G::Rapid => {
                let end = self.end_point(b)?;
                self.track_x_direction(&end);
                self.core.emit(&end, MoveKind::Rapid)
            }
            G::Linear => {
                let chamfer = D::chamfer(self, b)?;
                let end = self.end_point(b)?;
                self.track_x_direction(&end);
                let f = self.core.feed;
                match (chamfer, self.core.chip_break) {
                    (Some(c), _) => self.core.hold_corner(end, f, c),
                    (None, Some(cb)) => self.core.linear_with_chip_break(&end, f, cb),
                    (None, None) => self.core.emit(&end, MoveKind::Feed(f)),
                }
            }
            G::ArcCw | G::ArcCcw => self.arc(b),
            G::Own(o) => D::motion(self, o, b),
            other => Err(self.fault(
                Fault::UndefinedCode,
                format!("{} is not a motion", other.name()),
            )),
        }
    }

    fn track_x_direction(&mut self, end: &[f64]) {
        if let Some(i) = self.core.axis('X') {
            let d = end[i] - self.core.work_position()[i];
            if d.abs() > 1e-9 {
                self.last_x_direction = d.signum();
            }
        }
    }

    /// The centre-offset addresses of the plane's axes (I for X, J for Y, K for Z).
    fn center_letters(&self) -> (char, char) {
        let letter = |i: usize| match self.core.setup.axes.get(i) {
            Some('X') => 'I',
            Some('Y') => 'J',
            _ => 'K',
        };
        match self.core.plane_axes() {
            Ok((h, v)) => (letter(h), letter(v)),
            Err(_) => ('K', 'I'),
        }
    }

    /// G02/G03 by radius R or centre offsets.
    fn arc(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        let end = self.end_point(b)?;
        let here = self.core.work_position();
        let (a, e) = (self.core.plane_point(&here)?, self.core.plane_point(&end)?);
        let ccw = self.motion == G::ArcCcw;
        // Centre offsets of the plane's axes: K, I on the lathe (Z-X), I, J on the mill (G17).
        let (lh, lv) = self.center_letters();
        let ik = b.has(lh) || b.has(lv);
        let center = match (b.get('R'), ik) {
            (Some(_), true) => return Err(self.fault(Fault::ArcRAndIk, "arc with both R and I/K")),
            (Some(r), false) => geometry::center_from_radius(a, e, r, ccw),
            (None, true) => {
                // The vertical offset is in radius, or in diameter where the dialect says
                // so (decision D3).
                let i = b.get(lv).unwrap_or(0.0);
                let i = if D::ARC_I_DIAMETER {
                    i * self.core.x_scale()
                } else {
                    i
                };
                let c = Pt::new(a.z + b.get(lh).unwrap_or(0.0), a.r + i);
                geometry::check_center(a, e, c)
            }
            (None, false) => return Err(self.fault(Fault::ArcRadius, "arc needs R or I/K")),
        }
        .map_err(|e| self.arc_error(e))?;
        let f = self.core.feed;
        self.core.emit(
            &end,
            MoveKind::Arc {
                center,
                ccw,
                feed: f,
            },
        )
    }

    pub fn arc_error(&self, e: ArcError) -> ProgramError {
        match e {
            ArcError::RadiusTooSmall => self.fault(
                Fault::ArcRadius,
                "arc radius R smaller than half the chord, or a full circle with R",
            ),
            ArcError::EndNotOnCircle => self.fault(
                Fault::ArcEnd,
                "arc end point is not on the circle of the start and I/K",
            ),
            ArcError::Collinear => self.fault(
                Fault::ThreePointArc,
                "three-point arc: the points are on one line",
            ),
        }
    }
}
