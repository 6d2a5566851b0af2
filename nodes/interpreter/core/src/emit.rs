//! The emitter: a move in work coordinates becomes a canonical command in machine
//! coordinates. It passes three stages, each handing its moves to the next and none calling
//! back into an earlier one:
//!
//! 1. [`Core::emit`]: a chamfered or rounded corner waiting for the move after it
//!    ([`crate::corner`]) is resolved by this move: the held line, cut back, and the chamfer
//!    or rounding go on to stage 2, then this move does;
//! 2. [`Core::after_corner`]: radius compensation ([`crate::comp`]) takes the move and gives
//!    back the moves of the controlled point that are now certain (it holds one element back
//!    until the next one shows how the two meet);
//! 3. [`Core::machine`]: the range check, the feed check, the spindle speed under constant
//!    surface speed, the transform chain, and the command in the queue.
//!
//! While a stage holds an element back, the queue has a hold point: commands queued after it
//! (a block's M codes, say) wait behind it, and the element's moves, once released, go in at
//! the hold point, so commands leave in program order. Each stage has its own: the corner's
//! slot (`corner_slot`) and compensation's (`hold_at`), which is the earlier of the two
//! since compensation holds an older element; nothing leaves the queue past the earlier.

use crate::canon::{Canon, Command};
use crate::comp::{self, CompError, RadiusComp};
use crate::error::{Fault, ProgramError};
use crate::geometry::{Elem, Pt};
use crate::rough::Move;
use crate::show;
use crate::state::Core;

/// The commands queued after a kept place, waiting aside while it is filled
/// ([`Core::open_place`]).
#[derive(Debug)]
pub struct Waiting {
    at: usize,
    later: std::collections::VecDeque<Canon>,
}

impl Waiting {
    /// The queue index where the place's moves start.
    pub fn at(&self) -> usize {
        self.at
    }
}

/// How a move is made.
#[derive(Debug, Clone, Copy)]
pub enum MoveKind {
    Rapid,
    Feed(f64),
    /// An arc around `center` (a plane point) at the feed.
    Arc {
        center: Pt,
        ccw: bool,
        feed: f64,
    },
    /// A thread locked to the spindle, with its lead and start angle.
    Thread {
        lead: f64,
        angle: f64,
    },
    /// Rigid tapping: the positioned spindle turns at `rpm`, the sign of `lead` its
    /// direction, and the axes follow its angle.
    Tap {
        lead: f64,
        rpm: f64,
    },
    /// The turn-mill's C axis: the positioned spindle turns to `degrees` the way `way` says
    /// at `rpm`, and the axes follow its angle (D138).
    Rotary {
        degrees: f64,
        way: crate::canon::Turn,
        rpm: f64,
    },
    /// A measuring line at the feed: the probe's edge latches the axes, `stop` brakes there
    /// ([`crate::measure`]).
    Probe {
        feed: f64,
        rising: bool,
        stop: bool,
    },
}

/// Largest feed per revolution, mm/rev.
const MAX_FEED_PER_REV: f64 = 500.0;
/// Smallest feed of either unit (mm/min, mm/rev): the least increment F takes.
const MIN_FEED: f64 = 0.001;

impl Core {
    /// Emits a move to work position `end` and makes it the current position (stage 1).
    pub fn emit(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        if self.corner.is_some() {
            self.resolve_corner(Some((end, kind)))?;
        }
        self.after_corner(end, kind)
    }

    /// Coupled motion: each following axis's end moves on by its factor times its leading
    /// axis's travel in this move (the leaders in definition order, so a follower that leads
    /// another passes its whole travel on). A leading axis of an arc's plane would have to
    /// be followed along the arc, which a straight following move cannot do: refused.
    fn couple(&mut self, m: &mut [f64], kind: MoveKind) -> Result<(), ProgramError> {
        if matches!(kind, MoveKind::Arc { .. }) {
            let (h, v) = self.plane_axes()?;
            if let Some(c) = self.couplings.iter().find(|c| c.lead == h || c.lead == v) {
                return Err(self.fault(
                    Fault::NotSupported,
                    format!(
                        "{} leads {} in coupled motion: a circle of its plane is not followed                          (straight moves only)",
                        self.setup.axes[c.lead], self.setup.axes[c.follow]
                    ),
                ));
            }
        }
        for k in 0..self.couplings.len() {
            let c = self.couplings[k];
            let travel = c.factor * (m[c.lead] - self.pos[c.lead]);
            m[c.follow] += travel;
            self.coupled[c.follow] += travel;
        }
        Ok(())
    }

    /// Stage 2: radius compensation, when it is active.
    pub(crate) fn after_corner(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        if self.comp.is_some() {
            self.emit_compensated(end, kind)
        } else {
            self.machine(end, kind)
        }
    }

    /// Stage 3: the move as a command in machine coordinates.
    fn machine(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        for (i, v) in end.iter().enumerate() {
            if !v.is_finite() || v.abs() > 1e6 {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("{} end point {v} out of range", self.setup.axes[i]),
                ));
            }
        }
        // Feed and lead are checked before anything changes: a bad block moves nothing.
        let feed = match kind {
            MoveKind::Feed(feed) | MoveKind::Arc { feed, .. } | MoveKind::Probe { feed, .. } => {
                self.check_feed(feed)?
            }
            MoveKind::Rapid => 0.0,
            MoveKind::Thread { lead, .. } => {
                if !(lead > 0.0 && lead.is_finite()) {
                    return Err(self.fault(
                        Fault::ThreadLead,
                        format!("thread lead {lead} is not valid"),
                    ));
                }
                0.0
            }
            MoveKind::Tap { lead, rpm } => {
                if !(lead != 0.0 && lead.is_finite()) {
                    return Err(self.fault(
                        Fault::ThreadLead,
                        format!("tapping lead {lead} is not valid"),
                    ));
                }
                if !(rpm > 0.0 && rpm.is_finite()) {
                    return Err(self.fault(
                        Fault::CssWithoutS,
                        "rigid tapping needs a spindle speed S above 0",
                    ));
                }
                0.0
            }
            MoveKind::Rotary { degrees, way, rpm } => {
                if !(way.accepts(degrees) && rpm > 0.0 && rpm.is_finite()) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!("C axis to {degrees}° at {rpm} rpm"),
                    ));
                }
                0.0
            }
        };
        if matches!(kind, MoveKind::Arc { .. }) {
            self.arc_under_frame()?;
        }
        self.spindle_for(end);
        let mut m = self.to_machine(end);
        if !self.couplings.is_empty() {
            self.couple(&mut m, kind)?;
        }
        // Under the cylinder transformation the position is the basic system's and the
        // command is mapped onto the machine from where the controlled point stands (under
        // compensation `pos` is the programmed point, not the cutter's).
        let from = (self.cylinder.is_some() || self.polar.is_some())
            .then(|| std::mem::replace(&mut self.controlled, m.clone()));
        // The machine position becomes `m`; the command takes `m` itself (no copy per move).
        self.pos.copy_from_slice(&m);
        let command = match kind {
            MoveKind::Rapid => Command::Rapid { end: m },
            MoveKind::Feed(_) => Command::Linear { end: m, feed },
            MoveKind::Arc { center, ccw, .. } => {
                // Axes outside the plane keep the end's value (a helix's centre is at its end).
                let c = self.to_machine(&self.with_point(end, center));
                // A mirroring frame turns the circle the other way (checked before the
                // position changed: see `arc_under_frame`).
                let ccw = ccw != self.arc_under_frame()?;
                let plane = self
                    .plane_axes()
                    .ok()
                    .and_then(|(h, v)| Some([u8::try_from(h).ok()?, u8::try_from(v).ok()?]));
                Command::Arc {
                    end: m,
                    center: c,
                    clockwise: !ccw,
                    feed,
                    plane,
                }
            }
            MoveKind::Thread { lead, angle } => Command::Thread {
                end: m,
                lead,
                start_angle: angle,
            },
            MoveKind::Tap { lead, rpm } => Command::Tap { end: m, lead, rpm },
            MoveKind::Rotary { degrees, way, rpm } => Command::Rotary {
                end: m,
                degrees,
                way,
                rpm,
            },
            MoveKind::Probe { rising, stop, .. } => Command::Probe {
                end: m,
                feed,
                rising,
                stop,
            },
        };
        match (self.cylinder, self.polar, from) {
            (Some(c), _, Some(from)) => self.push_on_cylinder(c, &from, command)?,
            (_, Some(p), Some(from)) => self.push_on_polar(p, &from, command)?,
            _ => self.push(command),
        }
        Ok(())
    }

    /// Whether the frame mirrors the working plane (an arc then turns the other way); an
    /// alarm when the frame would make a circle of the plane an ellipse or tilt it.
    pub fn arc_under_frame(&self) -> Result<bool, ProgramError> {
        if self.frame.is_identity() {
            return Ok(false);
        }
        let (h, v) = self.plane_axes()?;
        self.frame
            .plane_similarity(h, v)
            .map(|(_, mirrored)| mirrored)
            .ok_or_else(|| {
                self.fault(
                    Fault::ArcRadius,
                    "a circle under this frame is no circle in the plane: both plane axes \
                     need the same scale factor, and a rotation must stay in the plane",
                )
            })
    }

    /// The largest feed of the active unit (per minute or per revolution).
    pub fn feed_limit(&self) -> f64 {
        if self.feed_per_rev {
            MAX_FEED_PER_REV
        } else {
            self.rules.max_feed
        }
    }

    /// A feed a cutting move can use: above 0 and within the control's range.
    pub fn check_feed(&self, feed: f64) -> Result<f64, ProgramError> {
        if feed.is_nan() || feed <= 0.0 {
            return Err(self.fault(
                Fault::FeedRange,
                "no feed programmed for a cutting move (F missing or 0)",
            ));
        }
        // Below the least increment F takes (D125): a move that would not end (issue 45).
        if feed < MIN_FEED {
            return Err(self.fault(
                Fault::FeedRange,
                format!("feed F{} out of range (min {MIN_FEED})", show(feed)),
            ));
        }
        let limit = self.feed_limit();
        if feed > limit {
            return Err(self.fault(
                Fault::FeedRange,
                format!("feed F{} out of range (max {limit})", show(feed)),
            ));
        }
        Ok(feed)
    }

    /// A rapid to a point computed from known positions (it cannot fail the range check).
    pub fn rapid_to(&mut self, work: &[f64]) {
        let _ = self.emit(work, MoveKind::Rapid);
    }

    /// Emits moves given in the plane (radius), starting from the current position.
    pub fn emit_plane(&mut self, moves: &[Move], feed: f64) -> Result<(), ProgramError> {
        let mut end = self.work_position();
        for m in moves {
            // `end` is the work position the last move reached; only the plane axes change.
            match *m {
                Move::Rapid(p) => {
                    self.set_plane_point(&mut end, p);
                    self.emit(&end, MoveKind::Rapid)?
                }
                Move::Feed(p) => {
                    self.set_plane_point(&mut end, p);
                    self.emit(&end, MoveKind::Feed(feed))?
                }
                Move::Arc { to, c, ccw } => {
                    self.set_plane_point(&mut end, to);
                    self.emit(
                        &end,
                        MoveKind::Arc {
                            center: c,
                            ccw,
                            feed,
                        },
                    )?
                }
            }
        }
        Ok(())
    }

    // ------------------------------------------------------------------ compensation

    /// Starts radius compensation on `side` with the tool's `radius` and tip direction.
    pub fn start_comp(
        &mut self,
        side: comp::Side,
        radius: f64,
        tip: u8,
        startup: comp::Startup,
    ) -> Result<(), ProgramError> {
        let from = self.plane_point(&self.work_position())?;
        self.comp = Some(RadiusComp::new(side, radius, tip, from, startup));
        self.comp_cancel = false;
        self.comp_restart = None;
        Ok(())
    }

    /// The alarm for a compensation error.
    pub fn comp_fault(&self, e: CompError) -> ProgramError {
        let what = self.rules.comp.name;
        let (fault, text) = match e {
            CompError::NoIntersection => (
                Fault::CompNoIntersection,
                "the offset path has no intersection here",
            ),
            CompError::ArcVanishes => (
                Fault::CompArcVanishes,
                "arc radius smaller than the tool radius",
            ),
            CompError::ArcStartup => (
                Fault::CompStartNotLine,
                "it cannot start in an arc: start it in a G00/G01 block",
            ),
            CompError::RadiusChangeOnArc => (
                Fault::NotSupported,
                "a new tool radius changes along a straight block: program the new edge before a \
                 G1 block, not an arc",
            ),
            CompError::Interference => (
                Fault::CompInterference,
                "the tool would cut into the contour here (interference)",
            ),
        };
        self.fault(fault, format!("{what}: {text}"))
    }

    /// A move while compensation is active: handed to the compensation, which returns the
    /// moves of the controlled point that are now certain.
    fn emit_compensated(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        let here = self.work_position();
        let from = self.plane_point(&here)?;
        let to = self.plane_point(end)?;
        let normal = self.plane_normal();
        let depth = normal.map_or(0.0, |i| end[i]);
        // Compensation carries the plane and its normal; a rotary axis would be left behind.
        let (h, v) = self.plane_axes()?;
        let other = (0..end.len())
            .find(|&i| i != h && i != v && Some(i) != normal && (end[i] - here[i]).abs() > 1e-9);
        if let Some(i) = other {
            return Err(self.fault(
                Fault::CompInCycle,
                format!(
                    "{} cannot move while compensation is active: G40 first",
                    self.setup.axes[i]
                ),
            ));
        }
        let (path, ck) = match kind {
            MoveKind::Rapid if self.rules.comp.refuse_rapid => {
                return Err(self.fault(
                    Fault::CompRapid,
                    "G00 while tool-nose compensation is active: cancel with G40 first",
                ))
            }
            MoveKind::Rapid => (Elem::Line { a: from, b: to }, comp::Kind::Rapid),
            MoveKind::Feed(f) => (Elem::Line { a: from, b: to }, comp::Kind::Feed(f)),
            MoveKind::Arc { center, ccw, feed } => (
                Elem::Arc {
                    a: from,
                    b: to,
                    c: center,
                    ccw,
                },
                comp::Kind::Feed(feed),
            ),
            MoveKind::Thread { .. } | MoveKind::Tap { .. } | MoveKind::Rotary { .. } => {
                return Err(self.fault(
                    Fault::CompInCycle,
                    "thread cutting, tapping or a C-axis move while tool-nose compensation is \
                     active",
                ))
            }
            // `Core::measure` refuses it before it comes here.
            MoveKind::Probe { .. } => {
                return Err(self.fault(
                    Fault::NotSupported,
                    "a measuring move under radius compensation is not built",
                ))
            }
        };
        let line = self.line;
        let held_line = self.comp.as_ref().and_then(|c| c.held_line());
        // No move in the plane; an arc never is one: ending where it starts it is a full
        // circle (with a normal move, a helix).
        let still =
            !matches!(kind, MoveKind::Arc { .. }) && (from.z - to.z).hypot(from.r - to.r) < 1e-9;
        let outs = if self.comp_cancel {
            self.comp_cancel = false;
            match self.comp.take() {
                Some(mut comp) => comp.cancel(to, depth, ck, line),
                None => Vec::new(),
            }
        } else if still {
            // No move in the plane: a move along the normal waits for the held element's
            // end (decision D48); no move at all compensates nothing.
            match (normal, self.comp.as_mut()) {
                (Some(i), Some(comp)) if (end[i] - here[i]).abs() > 1e-9 => {
                    comp.push_still(from, depth, ck, line)
                }
                _ => return Ok(()),
            }
        } else {
            let rules = crate::comp::ElementRules {
                feed_on_contour: self.feed_on_contour,
                max_feed: self.feed_limit(),
                outer_intersection: self.outer_intersection,
            };
            let restart = self.comp_restart.take();
            let pushed = match self.comp.as_mut() {
                Some(comp) => {
                    // A new side or radius: the old ends normal to its last element, this
                    // element starts the new (D104).
                    let mut outs = match restart {
                        Some((side, radius)) => comp.restart(side, radius, from),
                        None => Vec::new(),
                    };
                    comp.push(path, depth, ck, line, rules).map(|more| {
                        outs.extend(more);
                        outs
                    })
                }
                None => Ok(Vec::new()),
            };
            pushed.map_err(|e| self.comp_fault(e))?
        };
        self.emit_outs(outs, end, held_line)
    }

    /// Where nothing may leave the queue yet: the earlier hold point.
    pub(crate) fn gate(&self) -> Option<usize> {
        [self.hold_at, self.corner_slot, self.reserved]
            .into_iter()
            .flatten()
            .min()
    }

    /// The queue's hold points (compensation's, the corner's, a front end's kept place), to
    /// move on with the commands before them.
    pub(crate) fn hold_points(&mut self) -> impl Iterator<Item = &mut usize> {
        [
            self.hold_at.as_mut(),
            self.corner_slot.as_mut(),
            self.reserved.as_mut(),
        ]
        .into_iter()
        .flatten()
    }

    /// Keeps the queue's present end for moves the front end can make only after a later
    /// block (an approach that must end tangent to the element after it): what later blocks
    /// queue meanwhile waits behind it. Nothing may be held (a corner or compensation's
    /// element) while a place is kept: the front end checks [`Core::holding`] first.
    pub fn reserve_place(&mut self) {
        self.reserved = Some(self.pending.len());
    }

    /// Whether a path filter holds an element back.
    pub fn holding(&self) -> bool {
        self.hold_at.is_some() || self.corner_slot.is_some()
    }

    /// Opens the kept place: the commands queued after it wait aside (in [`Waiting`]) while
    /// the front end emits the moves the place was for, then [`Core::put_back`] queues them
    /// after those moves. An element a filter holds at the end then holds them back as it
    /// holds any later command. `None` when no place is kept.
    pub fn open_place(&mut self) -> Option<Waiting> {
        let at = self.reserved.take()?.min(self.pending.len());
        Some(Waiting {
            at,
            later: self.pending.split_off(at),
        })
    }

    /// Queues the commands that waited aside behind the place's moves.
    pub fn put_back(&mut self, waiting: Waiting) {
        self.pending.extend(waiting.later);
    }

    /// Runs `f`, which queues the moves of an element that was held back, and moves what it
    /// queued to index `at`, where the element was in program order: before the commands of
    /// later blocks queued meanwhile. A hold point at or behind `at` moves on with them.
    /// Returns `f`'s result and the index just after the moved commands. The source line is
    /// restored afterwards.
    pub(crate) fn insert_queued(
        &mut self,
        at: usize,
        f: impl FnOnce(&mut Self) -> Result<(), ProgramError>,
    ) -> (Result<(), ProgramError>, usize) {
        let before = self.pending.len();
        let at = at.min(before);
        let saved_line = self.line;
        let result = f(self);
        self.line = saved_line;
        let moved: Vec<Canon> = self.pending.drain(before..).collect();
        let n = moved.len();
        for (k, c) in moved.into_iter().enumerate() {
            self.pending.insert(at + k, c);
        }
        for h in self.hold_points() {
            if *h >= at {
                *h += n;
            }
        }
        (result, at + n)
    }

    /// Queues compensated moves where they belong in program order, then puts the program's
    /// position back on the programmed end point: incremental words and the next element
    /// start there. The moves of the element compensation held (`held_line`, and the moves
    /// along the normal after it) go in at its hold point, before the commands queued after
    /// it; those of the element just given (this line) where it belongs: the held corner's
    /// slot, or the end of the queue. Compensation then holds the new element there.
    pub(crate) fn emit_outs(
        &mut self,
        mut outs: Vec<comp::Out>,
        programmed_end: &[f64],
        held_line: Option<u32>,
    ) -> Result<(), ProgramError> {
        let hold = self.hold_at.take();
        let line = self.line;
        // Without an older element held (or one of this very line) all go in together.
        let newer = if held_line.is_some_and(|h| h != line) {
            outs.iter().rev().take_while(|o| o.line == line).count()
        } else {
            0
        };
        let new = outs.split_off(outs.len() - newer);
        let slot = |me: &Self| me.corner_slot.unwrap_or(me.pending.len());
        let at = hold.unwrap_or_else(|| slot(self));
        let (result, old_end) = self.insert_queued(at, |me| me.queue_outs(outs));
        let held_end = if held_line.is_some_and(|h| h != line) {
            let at = slot(self);
            let (r, end) = self.insert_queued(at, |me| me.queue_outs(new));
            result.and(r).map(|()| end)
        } else {
            result.map(|()| old_end)
        };
        self.hold_at = match held_end {
            Ok(end) => self.comp.as_ref().filter(|c| c.holding()).map(|_| end),
            Err(_) => None,
        };
        self.pos = self.to_machine(programmed_end);
        held_end.map(|_| ())
    }

    /// The compensated moves as commands, each on its source line.
    fn queue_outs(&mut self, outs: Vec<comp::Out>) -> Result<(), ProgramError> {
        for o in outs {
            self.line = o.line;
            let base = self.work_position();
            let mut end = self.with_point(&base, o.path.end());
            if let Some(i) = self.plane_normal() {
                end[i] = o.depth;
            }
            let kind = match (o.path, o.kind) {
                (Elem::Arc { c, ccw, .. }, comp::Kind::Feed(feed)) => MoveKind::Arc {
                    center: c,
                    ccw,
                    feed,
                },
                (_, comp::Kind::Feed(f)) => MoveKind::Feed(f),
                (_, comp::Kind::Rapid) => MoveKind::Rapid,
            };
            if self.cylinder.is_some() {
                self.out_offset = Some(o.offset.unwrap_or(self.wall));
            }
            self.machine(&end, kind)?;
        }
        Ok(())
    }
}
