//! Chamfers and roundings at the end of a block (`001` §9.5.1; inventory §3.6): CHF= a
//! chamfer of that length, CHR= a chamfer with legs of that length, RND= a rounding of that
//! radius, RNDM= the same at every corner from this block on (0: off), FRC= the corner's
//! feed in this block, FRCM= from this block on (0: the path feed). Between any lines and
//! arcs of the plane; the corner is the core's (`fillet.rs`): the block's element is held
//! until the next move shows the corner. With RND and a chamfer in one block only the radius
//! is inserted (§9.5.2).

use cnc_interpreter_core::corner::Chamfer;
use cnc_interpreter_core::{Fault, MoveKind, ProgramError};

use super::exec::Words;
use super::{Motion, Sinumerik};

/// The corner a block's move ends with, and the corner's own feed.
pub type BlockCorner = Option<(Chamfer, Option<f64>)>;

impl Sinumerik {
    /// Reads CHF/CHR/RND/RNDM/FRC/FRCM: the modal ones are kept, the corner of this block
    /// returned.
    pub(super) fn block_corner(
        &mut self,
        w: &Words,
        moves: bool,
    ) -> Result<BlockCorner, ProgramError> {
        let unit = if self.inch { 25.4 } else { 1.0 };
        let length = |me: &Self, k: &str, least: f64| -> Result<Option<f64>, ProgramError> {
            match w.get(k) {
                None | Some(0.0) => Ok(None),
                Some(v) if (least..=99_999.999).contains(&v) => Ok(Some(v * unit)),
                Some(v) => Err(me.fault(
                    Fault::OutOfRange,
                    format!(
                        "{k}={} is outside {least}…99999.999",
                        cnc_interpreter_core::show(v)
                    ),
                )),
            }
        };
        let feed = |me: &Self, k: &str| -> Result<Option<f64>, ProgramError> {
            match w.get(k) {
                None => Ok(None),
                Some(v) if v >= 0.0 => Ok(Some(v)),
                Some(_) => Err(me.fault(Fault::FeedRange, format!("{k} must not be negative"))),
            }
        };
        if w.addr.contains_key("RNDM") {
            self.rndm = length(self, "RNDM", 0.010)?;
        }
        if let Some(f) = feed(self, "FRCM")? {
            self.frcm = (f > 0.0).then_some(f * if self.inch_feed { 25.4 } else { 1.0 });
        }
        let frc = feed(self, "FRC")?
            .filter(|f| *f > 0.0)
            .map(|f| f * if self.inch_feed { 25.4 } else { 1.0 });
        let explicit = match (
            length(self, "RND", 0.010)?,
            length(self, "CHF", 0.001)?,
            length(self, "CHR", 0.001)?,
        ) {
            (Some(r), _, _) => Some(Chamfer::Round(r)),
            (None, Some(c), _) => Some(Chamfer::Length(c)),
            (None, None, Some(l)) => Some(Chamfer::Line(l)),
            (None, None, None) => None,
        };
        if explicit.is_some() && !moves {
            return Err(self.fault(
                Fault::MissingWord,
                "CHF/CHR/RND end a move: the block has none",
            ));
        }
        if explicit.is_some() && self.motion == Motion::Rapid {
            return Err(self.fault(
                Fault::IllegalWord,
                "CHF/CHR/RND round or chamfer a contour: not a G0 block",
            ));
        }
        let modal = self
            .rndm
            .filter(|_| self.motion != Motion::Rapid)
            .map(Chamfer::Round);
        Ok(explicit.or(modal).map(|c| (c, frc.or(self.frcm))))
    }

    /// Emits the block's last element, held for the block's corner when it has one.
    pub(super) fn emit_element(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        if self.wab.is_some() {
            let a = self.core.plane_point(&self.core.work_position())?;
            let b = self.core.plane_point(end)?;
            let (start, line) = match kind {
                MoveKind::Arc { center, ccw, .. } => {
                    (super::wab::arc_tangent(a, center, ccw), false)
                }
                _ => (super::wab::unit(a, b), true),
            };
            if self.wab_before_element(end, start, line)? {
                // The line gave the approach its end point P4.
                self.corner = None;
                return Ok(());
            }
        }
        match self.corner.take() {
            Some((chamfer, feed)) if !matches!(kind, MoveKind::Rapid) => self
                .core
                .hold_corner_element(end.to_vec(), kind, chamfer, feed),
            _ => self.core.emit(end, kind),
        }
    }
}

/// An ANG block with no end point (`ANG=α1`): its line waits for the next block, whose end
/// point and angle close it (§9.5.2).
#[derive(Debug, Clone)]
pub struct AngPending {
    angle: f64,
    kind: MoveKind,
    corner: BlockCorner,
}

/// What an ANG word makes of the block's line.
pub enum AngStep {
    /// No ANG: the end point as programmed.
    Plain,
    /// The line waits for the next block.
    Wait,
    /// The waiting line ends at this point first (work coordinates), then this block's.
    Via(Vec<f64>),
}

impl Sinumerik {
    /// ANG= (§9.5.2): with one coordinate of the plane, the other from the angle to the
    /// abscissa (counter-clockwise); with none, the line waits; with both, after a waiting
    /// line, the two lines' intersection is the corner between them.
    pub(super) fn ang_end(
        &mut self,
        w: &Words,
        here: &[f64],
        end: &mut [f64],
        kind: MoveKind,
    ) -> Result<AngStep, ProgramError> {
        let Some(angle) = w.get("ANG") else {
            if self.ang.is_some() {
                return Err(self.fault(
                    Fault::MissingWord,
                    "ANG: the block after ANG=… alone needs the end point and its own ANG",
                ));
            }
            return Ok(AngStep::Plain);
        };
        let (h, v) = self.core.plane_axes()?;
        let given = (w.axes.contains_key(&h), w.axes.contains_key(&v));
        let (s, c) = angle.to_radians().sin_cos();
        match (given, self.ang.take()) {
            ((false, false), None) => {
                self.ang = Some(AngPending {
                    angle,
                    kind,
                    corner: self.corner.take(),
                });
                Ok(AngStep::Wait)
            }
            ((true, true), Some(first)) => {
                // The first line from here at its angle, the second through the end point at
                // this one: where they cross.
                let (s1, c1) = first.angle.to_radians().sin_cos();
                let det = c1 * s - s1 * c;
                if det.abs() < 1e-9 {
                    return Err(self.fault(
                        Fault::ArcEnd,
                        "ANG: the two lines are parallel and do not meet",
                    ));
                }
                let (dx, dy) = (end[h] - here[h], end[v] - here[v]);
                let t = (dx * s - dy * c) / det;
                let mut corner = here.to_vec();
                corner[h] = here[h] + t * c1;
                corner[v] = here[v] + t * s1;
                let mine = self.corner.take();
                self.corner = first.corner;
                self.emit_element(&corner, first.kind)?;
                self.corner = mine;
                Ok(AngStep::Via(corner))
            }
            ((true, false), None) if c.abs() > 1e-9 => {
                end[v] = here[v] + (end[h] - here[h]) * s / c;
                Ok(AngStep::Plain)
            }
            ((false, true), None) if s.abs() > 1e-9 => {
                end[h] = here[h] + (end[v] - here[v]) * c / s;
                Ok(AngStep::Plain)
            }
            (_, pending) => {
                self.ang = pending;
                Err(self.fault(
                    Fault::DataFormat,
                    format!(
                        "ANG={}: one coordinate of the plane with the angle, none (the line waits) or both after a waiting ANG line",
                        cnc_interpreter_core::show(angle)
                    ),
                ))
            }
        }
    }
}
