//! Smooth approach and retraction, WAB (`001` §9.14; inventory §3.10; decision D114).
//! G147/G247/G347 approach the contour's start P4 tangentially along a line, a quarter or a
//! half circle; G148/G248/G348 leave its end P4 the same ways. DISR= is the cutter edge's
//! distance from P4 on a line, the radius of the cutter centre's path on a circle; DISCL=
//! the height above P4's plane where the fast infeed ends (P2); FAD= the slow infeed's feed.
//! G340 (the default) comes down to the contour in space (a helix on a circle), G341 in the
//! plane (perpendicular infeed first).
//!
//! The moves are made on the contour's level and go through the core's radius compensation
//! like programmed ones (the circles concentric with the cutter's path, radius DISR plus the
//! tool's), so the cutter's path is the manual's. An approach must end tangent to the element
//! after P4, which a later block gives: the WAB block keeps its place in the queue
//! ([`cnc_interpreter_core::Core::reserve_place`]) and the moves go there once that element
//! is read, before the commands of the blocks in between.

use cnc_interpreter_core::comp::Side;
use cnc_interpreter_core::geometry::Pt;
use cnc_interpreter_core::{Fault, MoveKind, ProgramError};

use super::exec::{Mode, Words};
use super::{Motion, Sinumerik};

/// Blocks without a move the manual allows between a WAB block and the next move.
const MAX_BLOCKS_BETWEEN: u32 = 5;

/// The tolerance of the infeed's direction check, mm (§9.14 "0.01 毫米的公差").
const REVERSAL_TOLERANCE: f64 = 0.01;

/// The way onto or off the contour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Line,
    Quarter,
    Half,
}

/// The WAB G code of a block: its shape and whether it approaches.
pub fn code(w: &Words) -> Option<(Shape, bool)> {
    [
        (147, Shape::Line, true),
        (148, Shape::Line, false),
        (247, Shape::Quarter, true),
        (248, Shape::Quarter, false),
        (347, Shape::Half, true),
        (348, Shape::Half, false),
    ]
    .into_iter()
    .find(|(g, ..)| w.has_g(*g))
    .map(|(_, s, a)| (s, a))
}

/// An approach waiting for the element after P4.
#[derive(Debug)]
pub struct Approach {
    shape: Shape,
    in_plane: bool,
    disr: f64,
    discl: f64,
    fad: Option<f64>,
    /// How P0→P2 moves: as the block before the WAB block did.
    before: MoveKind,
    /// The machine position the approach starts from (P0).
    p0: Vec<f64>,
    /// P4 is known (else the next move gives it).
    p4_known: bool,
    /// Blocks without a move since the WAB block or P4's block.
    between: u32,
    /// The block in hand is the WAB block or P4's block.
    fresh: bool,
}

/// The three WAB words of a block, checked.
struct Words3 {
    disr: f64,
    discl: f64,
    fad: Option<f64>,
}

fn left(t: Pt) -> Pt {
    Pt::new(-t.r, t.z)
}

fn along(p: Pt, d: Pt, k: f64) -> Pt {
    Pt::new(p.z + k * d.z, p.r + k * d.r)
}

/// The direction from `a` to `b` (None: the same point).
pub fn unit(a: Pt, b: Pt) -> Option<Pt> {
    let l = a.dist(b);
    (l > 1e-9).then(|| Pt::new((b.z - a.z) / l, (b.r - a.r) / l))
}

/// The path's direction at `p` on an arc about `c`.
pub fn arc_tangent(p: Pt, c: Pt, ccw: bool) -> Option<Pt> {
    let t = unit(c, p)?;
    Some(if ccw { left(t) } else { Pt::new(t.r, -t.z) })
}

/// A piece of the way on the contour's level: its end, and the circle it runs on.
struct Piece {
    start: Pt,
    end: Pt,
    arc: Option<(Pt, bool)>,
}

impl Piece {
    /// The piece as a move at `feed`.
    fn kind(&self, feed: f64) -> MoveKind {
        match self.arc {
            Some((c, ccw)) => MoveKind::Arc {
                center: c,
                ccw,
                feed,
            },
            None => MoveKind::Feed(feed),
        }
    }
}

/// The normal on the cutter's side of direction `t`.
fn side_normal(side: Side, t: Pt) -> Pt {
    match side {
        Side::Left => left(t),
        Side::Right => Pt::new(t.r, -t.z),
    }
}

/// The approach's piece ending at `p4` with direction `t` (or, turned round, the
/// retraction's starting there), on the cutter's `side`, `k` the distance DISR plus the
/// cutter's radius (a circle's radius on the contour's level).
fn piece(shape: Shape, approach: bool, p4: Pt, t: Pt, side: Side, k: f64) -> Piece {
    let n = side_normal(side, t);
    let m = along(p4, n, k);
    let far = match shape {
        Shape::Line => along(p4, t, if approach { -k } else { k }),
        Shape::Quarter => along(m, t, if approach { -k } else { k }),
        Shape::Half => along(p4, n, 2.0 * k),
    };
    let arc = (shape != Shape::Line).then_some((m, side == Side::Left));
    if approach {
        Piece {
            start: far,
            end: p4,
            arc,
        }
    } else {
        Piece {
            start: p4,
            end: far,
            arc,
        }
    }
}

impl Sinumerik {
    fn wab_alarm(&self, number: u32, text: &str) -> ProgramError {
        let mut e = self.fault(Fault::NotSupported, format!("WAB: {text}"));
        e.number = number;
        e
    }

    /// DISR=, DISCL=, FAD= of a WAB block: DISR above 0 (10742), plain values.
    fn wab_words(&self, w: &Words) -> Result<Words3, ProgramError> {
        for k in ["DISR", "DISCL", "FAD"] {
            if let Some((_, mode)) = w.addr.get(k) {
                if *mode != Mode::Modal {
                    return Err(self.fault(
                        Fault::IllegalWord,
                        format!("{k}= takes a plain value on this control (no AC/IC)"),
                    ));
                }
            }
        }
        let disr = match w.get("DISR") {
            Some(d) if d > 0.0 && d.is_finite() => d,
            _ => return Err(self.wab_alarm(10742, "distance DISR= missing or not above 0 (mm)")),
        };
        let discl = w.get("DISCL").unwrap_or(0.0);
        let fad = w.get("FAD");
        if let Some(f) = fad {
            if !(f > 0.0 && f.is_finite()) {
                return Err(self.fault(Fault::FeedRange, "FAD= is a feed above 0"));
            }
        }
        if !discl.is_finite() || discl.abs() > 1e5 {
            return Err(self.fault(Fault::OutOfRange, "DISCL= is out of range"));
        }
        Ok(Words3 { disr, discl, fad })
    }

    /// A position's coordinate along the plane's normal (0 on a machine without one).
    fn depth_of(&self, p: &[f64]) -> f64 {
        self.core.plane_normal().map_or(0.0, |i| p[i])
    }

    /// `base` with the plane point `p`, at `z` along the plane's normal.
    fn point_at(&self, base: &[f64], p: Pt, z: f64) -> Vec<f64> {
        let mut v = self.core.with_point(base, p);
        if let Some(i) = self.core.plane_normal() {
            v[i] = z;
        }
        v
    }

    /// The DISCL height `d2` must lie between P1's `d0` and P3's `d4` (10741): the infeed
    /// does not turn back (§9.14, within 0.01 mm).
    fn no_reversal(&self, d0: f64, d2: f64, d4: f64) -> Result<(), ProgramError> {
        let (lo, hi) = (d0.min(d4), d0.max(d4));
        if d2 < lo - REVERSAL_TOLERANCE || d2 > hi + REVERSAL_TOLERANCE {
            return Err(self.wab_alarm(
                10741,
                "direction reversal on the infeed: the DISCL point does not lie between P1 \
                 and P3",
            ));
        }
        Ok(())
    }

    /// The side and radius compensation runs with (None: G40).
    fn comp_now(&self) -> Option<(Side, f64)> {
        self.core.comp.as_ref().map(|c| (c.side(), c.radius()))
    }

    /// A block with G147…G348: an approach waits for the element after P4, a retraction runs
    /// now. `end` is the block's end point (work coordinates); `plane` says whether it
    /// programs an axis of the plane, `normal` the axis normal to it.
    pub(super) fn wab_block(
        &mut self,
        w: &Words,
        (shape, approach): (Shape, bool),
        end: Vec<f64>,
        (plane, normal): (bool, bool),
    ) -> Result<(), ProgramError> {
        if self.wab.is_some() {
            return Err(self.wab_alarm(10743, "programmed again before the last one ended"));
        }
        let words = self.wab_words(w)?;
        if approach {
            self.approach_block(shape, words, end, plane)
        } else {
            self.retraction(shape, words, end, (plane, normal))
        }
    }

    fn approach_block(
        &mut self,
        shape: Shape,
        words: Words3,
        end: Vec<f64>,
        plane: bool,
    ) -> Result<(), ProgramError> {
        if self.core.comp.is_some() || self.core.holding() {
            return Err(self.fault(
                Fault::CompBlocks,
                "WAB: an approach starts radius compensation: G40 before it",
            ));
        }
        if shape != Shape::Line && self.comp_side.is_none() {
            return Err(self.wab_alarm(
                10744,
                "no direction: an approach on a circle needs G41 or G42",
            ));
        }
        let (before_motion, before_feed) = self.block_entry;
        let before = if before_motion == Motion::Rapid {
            MoveKind::Rapid
        } else {
            MoveKind::Feed(before_feed)
        };
        self.wab = Some(Approach {
            shape,
            in_plane: self.approach_in_plane,
            disr: words.disr,
            discl: words.discl,
            fad: words.fad,
            before,
            p0: self.core.pos.clone(),
            p4_known: plane,
            between: 0,
            fresh: true,
        });
        self.core.reserve_place();
        // The program continues from P4 (as far as this block gives it).
        self.core.pos = self.core.to_machine(&end);
        Ok(())
    }

    /// Before an element of a move is emitted: a waiting approach takes this line as the
    /// one that gives P4 (`true`: the element is taken), or, P4 known, is made now to end
    /// tangent to the element (`start`: its direction at its start).
    pub(super) fn wab_before_element(
        &mut self,
        end: &[f64],
        start: Option<Pt>,
        line: bool,
    ) -> Result<bool, ProgramError> {
        let Some(mut a) = self.wab.take() else {
            return Ok(false);
        };
        if !a.p4_known {
            if !line {
                return Err(self.wab_alarm(
                    10745,
                    "end position P4 not defined: the block after an approach without plane \
                     axes gives it with a straight move",
                ));
            }
            self.core.pos = self.core.to_machine(end);
            a.p4_known = true;
            a.fresh = true;
            self.wab = Some(a);
            return Ok(true);
        }
        let Some(t) = start else {
            return Err(self.wab_alarm(
                10744,
                "no direction: the block after P4 must move in the plane",
            ));
        };
        self.approach(a, t)?;
        Ok(false)
    }

    /// The approach's moves from P0 to P4, in the place the WAB block kept.
    fn approach(&mut self, a: Approach, t: Pt) -> Result<(), ProgramError> {
        let p4 = self.core.work_position();
        self.core.pos.clone_from(&a.p0);
        let p0 = self.core.work_position();
        let place = self.core.open_place();
        let made = self.approach_moves(&a, t, &p0, &p4);
        let checked = made.and_then(|()| match &place {
            Some(p) => self.check_work_area(p.at(), &a.p0),
            None => Ok(()),
        });
        if let Some(p) = place {
            self.moved_before += self.core.queued() - p.at();
            self.core.put_back(p);
        }
        checked
    }

    fn approach_moves(
        &mut self,
        a: &Approach,
        t: Pt,
        p0: &[f64],
        p4: &[f64],
    ) -> Result<(), ProgramError> {
        self.begin_compensation()?;
        let comp = self.comp_now();
        let (side, r) = comp.unwrap_or((Side::Left, 0.0));
        let q4 = self.core.plane_point(p4)?;
        let way = piece(a.shape, true, q4, t, side, a.disr + r);
        let (d0, d4) = (self.depth_of(p0), self.depth_of(p4));
        let d2 = d4 + a.discl;
        let at = |me: &Self, p: Pt, z: f64| me.point_at(p4, p, z);
        let feed = self.core.feed;
        let slow = MoveKind::Feed(a.fad.unwrap_or(feed));
        let mut steps: Vec<(Vec<f64>, MoveKind)> = Vec::new();
        if a.discl == 0.0 && !a.in_plane {
            // G340, DISCL=0: P1, P2 and P3 are one point; two blocks (§9.14, D114).
            steps.push((at(self, way.start, d4), a.before));
            steps.push((p4.to_vec(), way.kind(a.fad.unwrap_or(feed))));
        } else {
            self.no_reversal(d0, d2, d4)?;
            steps.push((at(self, way.start, d0), a.before));
            steps.push((at(self, way.start, d2), a.before));
            if a.in_plane {
                steps.push((at(self, way.start, d4), slow));
                steps.push((p4.to_vec(), way.kind(feed)));
            } else {
                steps.push((p4.to_vec(), way.kind(a.fad.unwrap_or(feed))));
            }
        }
        self.run_steps(steps)
    }

    /// Emits the steps that go somewhere (a circle always does). F holds at the cutter's
    /// centre on them, whatever CFC says: DISR gives the centre's path (D114).
    fn run_steps(&mut self, steps: Vec<(Vec<f64>, MoveKind)>) -> Result<(), ProgramError> {
        let on_contour = std::mem::replace(&mut self.core.feed_on_contour, false);
        let mut done = Ok(());
        for (to, kind) in steps {
            let here = self.core.work_position();
            let moves = here.iter().zip(&to).any(|(x, y)| (x - y).abs() > 1e-9);
            if moves || matches!(kind, MoveKind::Arc { .. }) {
                done = self.core.emit(&to, kind);
                if done.is_err() {
                    break;
                }
            }
        }
        self.core.feed_on_contour = on_contour;
        done
    }

    /// G148/G248/G348: off the contour from here (P4) tangentially, up to DISCL and to the
    /// block's end point P0. Without plane axes the way ends at P2, with only the normal
    /// axis at P1 (§9.14 说明). The way off runs at the feed before the block, FAD (if
    /// given) on the slow part, the block's F (or rapid, G0) from P2 on.
    fn retraction(
        &mut self,
        shape: Shape,
        words: Words3,
        end: Vec<f64>,
        (plane, normal): (bool, bool),
    ) -> Result<(), ProgramError> {
        let comp = self.comp_now();
        let Some(t) = self.tangent else {
            return Err(self.wab_alarm(
                10744,
                "no direction: a retraction follows a move in the plane",
            ));
        };
        if shape != Shape::Line && comp.is_none() {
            return Err(self.wab_alarm(
                10744,
                "no direction: a retraction on a circle needs G41 or G42 active",
            ));
        }
        let (side, r) = comp.unwrap_or((Side::Left, 0.0));
        let p4 = self.core.work_position();
        let q4 = self.core.plane_point(&p4)?;
        let way = piece(shape, false, q4, t, side, words.disr + r);
        let (d0, d4) = (self.depth_of(&end), self.depth_of(&p4));
        let d2 = d4 + words.discl;
        let at = |me: &Self, p: Pt, z: f64| me.point_at(&p4, p, z);
        let old_f = self.block_entry.1;
        let new = if self.motion == Motion::Rapid {
            MoveKind::Rapid
        } else {
            MoveKind::Feed(self.core.feed)
        };
        let slow = MoveKind::Feed(words.fad.unwrap_or(old_f));
        // Compensation ends on the last move (G40 in this block), not on the way off.
        let cancel = std::mem::take(&mut self.core.comp_cancel);
        // Where the cutter's centre is at the way's end: a cancel without plane axes ends
        // there, so the tool does not move sideways as compensation goes (§9.14 说明).
        let end_dir = match way.arc {
            Some((c, ccw)) => arc_tangent(way.end, c, ccw).unwrap_or(t),
            None => t,
        };
        let centre_end = along(way.end, side_normal(side, end_dir), r);
        let mut steps: Vec<(Vec<f64>, MoveKind)> = Vec::new();
        let space_direct = words.discl == 0.0 && !self.approach_in_plane;
        if !space_direct && (plane || normal) {
            self.no_reversal(d0, d2, d4)?;
        }
        if self.approach_in_plane || space_direct {
            steps.push((at(self, way.end, d4), way.kind(old_f)));
            if !space_direct {
                steps.push((at(self, way.end, d2), slow));
            }
        } else {
            steps.push((at(self, way.end, d2), way.kind(words.fad.unwrap_or(old_f))));
        }
        let last_point = if cancel { centre_end } else { way.end };
        if plane {
            if !space_direct {
                steps.push((at(self, way.end, d0), new));
            }
            steps.push((end, new));
        } else if normal {
            steps.push((at(self, last_point, d0), new));
        } else {
            steps.push((at(self, last_point, d2), new));
        }
        // Every step but the last, then the last as the cancel when G40 is in the block.
        let last = steps.pop();
        self.run_steps(steps)?;
        if let Some((to, kind)) = last {
            let here = self.core.work_position();
            let moves = here.iter().zip(&to).any(|(x, y)| (x - y).abs() > 1e-9);
            if moves || cancel {
                self.core.comp_cancel = cancel;
                let made = self.core.emit(&to, kind);
                self.core.comp_cancel = false;
                made?;
            }
        }
        self.tangent = None;
        Ok(())
    }

    /// After each block: a waiting approach counts the blocks without a move (at most 5,
    /// else 10740).
    pub(super) fn wab_after_block(&mut self) -> Result<(), ProgramError> {
        let Some(a) = self.wab.as_mut() else {
            return Ok(());
        };
        if std::mem::take(&mut a.fresh) {
            return Ok(());
        }
        a.between += 1;
        if a.between > MAX_BLOCKS_BETWEEN {
            return Err(self.wab_alarm(
                10740,
                "more than 5 blocks without a move after the WAB block",
            ));
        }
        Ok(())
    }

    /// A program may not end or return while an approach waits for its contour.
    pub(super) fn no_approach_waits(&self) -> Result<(), ProgramError> {
        if self.wab.is_some() {
            return Err(self.wab_alarm(
                10745,
                "end position not defined: the program ends or returns before the contour \
                 after the approach",
            ));
        }
        Ok(())
    }
}
