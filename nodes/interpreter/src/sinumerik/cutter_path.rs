//! The moves of a milling cycle's cutter centre (`thread_mill.rs`, `pocket.rs` make them as
//! pure functions of the parameters): points in the plane's 1st and 2nd axis and along the
//! infeed axis, in work coordinates of the active frame; the executor emits them.

use cnc_interpreter_core::geometry::Pt;
use cnc_interpreter_core::{MoveKind, ProgramError};

use super::Sinumerik;

/// A point: 1st and 2nd plane axis, infeed axis.
pub type P3 = (f64, f64, f64);

/// One move of the cutter's centre.
#[derive(Debug, Clone, PartialEq)]
pub enum Move {
    Rapid(P3),
    Line(P3, f64),
    /// An arc (a helix when the infeed axis moves) about a centre in the plane.
    Arc {
        end: P3,
        centre: (f64, f64),
        ccw: bool,
        feed: f64,
    },
}

impl Sinumerik {
    /// Emits a cycle's moves in the plane and along its normal.
    pub(super) fn run_path(&mut self, moves: Vec<Move>) -> Result<(), ProgramError> {
        let (h, v) = self.core.plane_axes()?;
        let d = self.core.plane_normal().ok_or_else(|| {
            self.fault(
                cnc_interpreter_core::Fault::PlaneAxis,
                "the infeed axis (the plane's normal) is not on this machine",
            )
        })?;
        for m in moves {
            let point = |me: &Self, p: P3| {
                let mut end = me.core.work_position();
                end[h] = p.0;
                end[v] = p.1;
                end[d] = p.2;
                end
            };
            match m {
                Move::Rapid(p) => self.core.emit(&point(self, p), MoveKind::Rapid)?,
                Move::Line(p, f) => self.core.emit(&point(self, p), MoveKind::Feed(f))?,
                Move::Arc {
                    end,
                    centre,
                    ccw,
                    feed,
                } => self.core.emit(
                    &point(self, end),
                    MoveKind::Arc {
                        center: Pt::new(centre.0, centre.1),
                        ccw,
                        feed,
                    },
                )?,
            }
        }
        Ok(())
    }
}
