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
        match self.corner.take() {
            Some((chamfer, feed)) if !matches!(kind, MoveKind::Rapid) => self
                .core
                .hold_corner_element(end.to_vec(), kind, chamfer, feed),
            _ => self.core.emit(end, kind),
        }
    }
}
