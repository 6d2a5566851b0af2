//! A path filter: a chamfered or rounded corner (decision D31). The corner between a line and
//! the next move is cut by a straight chamfer whose ends lie L from the corner on both
//! elements, or rounded by an arc of radius D tangent to both lines.
//!
//! The line is held back until the next move shows the corner, like an element under radius
//! compensation; commands queued after it wait for it. A front end whose corners join arcs
//! too holds any element with [`Core::hold_corner_element`]; its corner is `fillet.rs`'s.

use crate::emit::MoveKind;
use crate::error::{Fault, ProgramError};
use crate::fillet::{self, Shape};
use crate::geometry::{Elem, Pt};
use crate::show;
use crate::state::Core;

/// What the corner gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Chamfer {
    /// A chamfer whose ends lie this far from the corner.
    Line(f64),
    Round(f64),
    /// A chamfer this long (measured along the chamfer, not its legs).
    Length(f64),
}

/// A G01 whose end is a chamfered or rounded corner, waiting for the next move.
#[derive(Debug, Clone)]
pub struct Corner {
    /// Work positions where the line starts and ends (the corner).
    pub start: Vec<f64>,
    pub end: Vec<f64>,
    pub feed: f64,
    pub line: u32,
    pub chamfer: Chamfer,
    /// The held element: a line at `feed`, or an arc.
    pub kind: MoveKind,
    /// The corner element's own feed; else, on the general corner, the feed of the move leaving
    /// the corner, on the line-only corner, the element's (D126).
    pub corner_feed: Option<f64>,
    /// Arcs may take part on either side (`fillet.rs`); else only a line is held and only a
    /// chamfer meets an arc after it.
    pub general: bool,
}

fn unit(z: f64, r: f64) -> Option<(f64, f64)> {
    let l = z.hypot(r);
    (l > 1e-9).then(|| (z / l, r / l))
}

impl Core {
    /// A G01 to `end` with a chamfer at its end: held until the next move.
    pub fn hold_corner(
        &mut self,
        end: Vec<f64>,
        feed: f64,
        chamfer: Chamfer,
    ) -> Result<(), ProgramError> {
        if self.comp.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "chamfer L / rounding D while tool-nose compensation is active",
            ));
        }
        self.resolve_corner(Some((&end, MoveKind::Feed(feed))))?;
        let start = self.work_position();
        self.check_feed(feed)?;
        self.corner_slot = Some(self.pending.len());
        self.corner = Some(Corner {
            start,
            end: end.clone(),
            feed,
            line: self.line,
            chamfer,
            kind: MoveKind::Feed(feed),
            corner_feed: None,
            general: false,
        });
        // The program goes on from the corner: incremental words of the next block start there.
        self.pos = self.to_machine(&end);
        Ok(())
    }

    /// A line or an arc (`kind`) to `end` with a chamfer or rounding at its end, whichever
    /// element follows: held until the next move.
    pub fn hold_corner_element(
        &mut self,
        end: Vec<f64>,
        kind: MoveKind,
        chamfer: Chamfer,
        corner_feed: Option<f64>,
    ) -> Result<(), ProgramError> {
        let feed = match kind {
            MoveKind::Feed(f) | MoveKind::Arc { feed: f, .. } => f,
            _ => {
                return Err(self.fault(
                    Fault::NotSupported,
                    "a chamfer or rounding ends a line or an arc, not a rapid or a thread",
                ))
            }
        };
        self.resolve_corner(Some((&end, kind)))?;
        let start = self.work_position();
        self.check_feed(feed)?;
        if let Some(f) = corner_feed {
            self.check_feed(f)?;
        }
        self.corner_slot = Some(self.pending.len());
        self.corner = Some(Corner {
            start,
            end: end.clone(),
            feed,
            line: self.line,
            chamfer,
            kind,
            corner_feed,
            general: true,
        });
        self.pos = self.to_machine(&end);
        Ok(())
    }

    /// Emits the held line, cut back for the corner the next move (`next`, if any, ending at
    /// the given work position) makes with it, and the chamfer or rounding; the current
    /// position is then where the next move starts. Without a usable next move (program end,
    /// a rapid, a cycle) the line runs to its corner unchamfered.
    pub fn resolve_corner(&mut self, next: Option<(&[f64], MoveKind)>) -> Result<(), ProgramError> {
        let Some(corner) = self.corner.take() else {
            return Ok(());
        };
        // The line and the chamfer go where the line was in program order (the corner's
        // slot), on its line; under compensation, which places them there itself.
        let release = |me: &mut Self| {
            me.line = corner.line;
            // The held element starts where it started (the program has gone on to its end):
            // the stages after this one take their start from the position.
            me.pos = me.to_machine(&corner.start);
            me.corner_moves(&corner, next)
        };
        let result = if self.comp.is_some() {
            let saved = self.line;
            let r = release(self);
            self.line = saved;
            r
        } else {
            let at = self.corner_slot.unwrap_or(self.pending.len());
            self.insert_queued(at, release).0
        };
        self.corner_slot = None;
        result
    }

    fn corner_moves(
        &mut self,
        corner: &Corner,
        next: Option<(&[f64], MoveKind)>,
    ) -> Result<(), ProgramError> {
        if corner.general {
            return self.general_corner(corner, next);
        }
        let feed = MoveKind::Feed(corner.feed);
        let a = self.plane_point(&corner.start)?;
        let p = self.plane_point(&corner.end)?;
        let plain = |me: &mut Self| me.after_corner(&corner.end, feed);
        let Some(t1) = unit(p.z - a.z, p.r - a.r) else {
            return plain(self);
        };
        let len1 = a.dist(p);
        let Some((next_end, next_kind)) = next else {
            return plain(self);
        };
        let b = self.plane_point(next_end)?;
        let base = corner.end.clone();
        match (corner.chamfer, next_kind) {
            (
                _,
                MoveKind::Rapid
                | MoveKind::Thread { .. }
                | MoveKind::Tap { .. }
                | MoveKind::Rotary { .. }
                | MoveKind::Probe { .. },
            ) => plain(self),
            (chamfer, MoveKind::Feed(_)) => {
                let Some(t2) = unit(b.z - p.z, b.r - p.r) else {
                    return plain(self);
                };
                let cross = t1.0 * t2.1 - t1.1 * t2.0;
                let dot = t1.0 * t2.0 + t1.1 * t2.1;
                if cross.abs() < 1e-9 && dot > 0.0 {
                    return plain(self); // collinear: nothing to cut
                }
                let len2 = p.dist(b);
                let (d, round) = match chamfer {
                    Chamfer::Line(l) | Chamfer::Length(l) => (l, None),
                    Chamfer::Round(r) => {
                        // Tangent length of a radius-r arc in the corner.
                        let turn = cross.atan2(dot).abs();
                        (r * (turn / 2.0).tan(), Some(r))
                    }
                };
                if d > len1 + 1e-9 || d > len2 + 1e-9 {
                    return Err(self.fault(
                        Fault::ChamferTooShort,
                        format!(
                            "chamfer/rounding needs {} mm on each side of the corner; the lines are {} and {} mm",
                            show(d),
                            show(len1),
                            show(len2)
                        ),
                    ));
                }
                let q1 = Pt::new(p.z - d * t1.0, p.r - d * t1.1);
                let q2 = Pt::new(p.z + d * t2.0, p.r + d * t2.1);
                self.after_corner(&self.with_point(&base, q1), feed)?;
                match round {
                    None => self.after_corner(&self.with_point(&base, q2), feed),
                    Some(r) => {
                        // The centre lies on the inside of the turn, r from both lines.
                        let side = cross.signum();
                        let n = (-t1.1 * side, t1.0 * side);
                        let center = Pt::new(q1.z + r * n.0, q1.r + r * n.1);
                        self.after_corner(
                            &self.with_point(&base, q2),
                            MoveKind::Arc {
                                center,
                                ccw: cross > 0.0,
                                feed: corner.feed,
                            },
                        )
                    }
                }
            }
            (Chamfer::Line(l) | Chamfer::Length(l), MoveKind::Arc { center, ccw, .. }) => {
                // The chamfer ends on the arc, l from the corner, in the arc's direction.
                let rho = center.dist(p);
                // The arc's own sweep from the corner to its end, in its direction.
                let tau = std::f64::consts::TAU;
                let a0 = (p.r - center.r).atan2(p.z - center.z);
                let a1 = (b.r - center.r).atan2(b.z - center.z);
                let sweep = if ccw {
                    (a1 - a0).rem_euclid(tau)
                } else {
                    (a0 - a1).rem_euclid(tau)
                };
                let needed = 2.0 * (l / (2.0 * rho)).min(1.0).asin();
                if l > len1 + 1e-9 || l >= 2.0 * rho || needed > sweep + 1e-9 {
                    return Err(self.fault(
                        Fault::ChamferTooShort,
                        format!("chamfer L{} does not fit the line or the arc", show(l)),
                    ));
                }
                // Points at distance l from p on the circle: p rotated about the centre by
                // ±2·asin(l / 2ρ); the arc's direction picks the sign.
                let ang = 2.0 * (l / (2.0 * rho)).asin() * if ccw { 1.0 } else { -1.0 };
                let (rz, rr) = (p.z - center.z, p.r - center.r);
                let q2 = Pt::new(
                    center.z + rz * ang.cos() - rr * ang.sin(),
                    center.r + rz * ang.sin() + rr * ang.cos(),
                );
                let q1 = Pt::new(p.z - l * t1.0, p.r - l * t1.1);
                self.after_corner(&self.with_point(&base, q1), feed)?;
                self.after_corner(&self.with_point(&base, q2), feed)
            }
            (Chamfer::Round(_), MoveKind::Arc { .. }) => Err(self.fault(
                Fault::NotSupported,
                "corner rounding D between a line and an arc: the manual leaves it \"to be extended\"",
            )),
        }
    }

    /// The corner of `fillet.rs` between the held element and the next move: lines and arcs
    /// in the plane; a rapid, a thread or a move across the plane after it leaves the
    /// element as it is.
    fn general_corner(
        &mut self,
        corner: &Corner,
        next: Option<(&[f64], MoveKind)>,
    ) -> Result<(), ProgramError> {
        let plain = |me: &mut Self| me.after_corner(&corner.end, corner.kind);
        let a = self.plane_point(&corner.start)?;
        let p = self.plane_point(&corner.end)?;
        let element = |a: Pt, b: Pt, kind: MoveKind| match kind {
            MoveKind::Feed(_) if a.dist(b) > 1e-9 => Some(Elem::Line { a, b }),
            MoveKind::Arc { center, ccw, .. } => Some(Elem::Arc {
                a,
                b,
                c: center,
                ccw,
            }),
            _ => None,
        };
        let (Some(first), Some((next_end, next_kind))) = (element(a, p, corner.kind), next) else {
            return plain(self);
        };
        let b = self.plane_point(next_end)?;
        let Some(second) = element(p, b, next_kind) else {
            return plain(self);
        };
        let (h, v) = self.plane_axes()?;
        let across = |x: &[f64], y: &[f64]| {
            (0..x.len()).any(|i| i != h && i != v && (x[i] - y[i]).abs() > 1e-9)
        };
        if across(&corner.start, &corner.end) || across(&corner.end, next_end) {
            return Err(self.fault(
                Fault::NotSupported,
                "a chamfer or rounding between moves that leave the plane is not built",
            ));
        }
        let shape = match corner.chamfer {
            Chamfer::Line(d) => Shape::Legs(d),
            Chamfer::Length(l) => Shape::Length(l),
            Chamfer::Round(r) => Shape::Round(r),
        };
        let cut = match fillet::corner(first, second, shape) {
            Ok(Some(cut)) => cut,
            Ok(None) => return plain(self),
            Err(why) => return Err(self.fault(Fault::ChamferTooShort, why)),
        };
        let base = corner.end.clone();
        if cut.first.start().dist(cut.first.end()) > 1e-9 {
            self.after_corner(&self.with_point(&base, cut.first.end()), corner.kind)?;
        }
        // The element's own feed, else the feed of the move leaving the corner (D126).
        let leaving = match next_kind {
            MoveKind::Feed(f) | MoveKind::Arc { feed: f, .. } => f,
            _ => corner.feed,
        };
        let feed = corner.corner_feed.unwrap_or(leaving);
        match cut.corner {
            Elem::Line { b, .. } => {
                self.after_corner(&self.with_point(&base, b), MoveKind::Feed(feed))
            }
            Elem::Arc { b, c, ccw, .. } => self.after_corner(
                &self.with_point(&base, b),
                MoveKind::Arc {
                    center: c,
                    ccw,
                    feed,
                },
            ),
        }
    }
}
