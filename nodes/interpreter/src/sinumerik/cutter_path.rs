//! The moves of a milling cycle's cutter centre (`thread_mill.rs`, `pocket.rs` make them as
//! pure functions of the parameters): points in the plane's 1st and 2nd axis and along the
//! infeed axis, in work coordinates of the active frame; the executor emits them.

use cnc_interpreter_core::geometry::Pt;
use cnc_interpreter_core::{MoveKind, ProgramError};

use super::drilling::CycleAlarm;
use super::Sinumerik;

/// Most moves one cycle call makes: a call whose parameters would make more (a MID of a
/// micrometre on a deep pocket) is refused with 12140 before anything moves.
pub const MAX_MOVES: usize = 200_000;

fn too_many() -> CycleAlarm {
    CycleAlarm {
        number: 12140,
        text: format!("the call would make more than {MAX_MOVES} moves: its steps are too fine for this controller"),
    }
}

/// `x` rounded up to a whole number of steps (at least `least`), refused beyond what one
/// cycle may make.
pub fn steps(x: f64, least: usize) -> Result<usize, CycleAlarm> {
    let n = (x - 1e-9).ceil();
    if !n.is_finite() || n > MAX_MOVES as f64 {
        return Err(too_many());
    }
    Ok((n.max(0.0) as usize).max(least))
}

/// The active cutting edge's radius: none is 61000, one not above 0 61117.
pub fn cutter(tool_radius: Option<f64>) -> Result<f64, CycleAlarm> {
    let wr = tool_radius.ok_or_else(|| CycleAlarm::new(61000, "no tool offset active (D)"))?;
    if wr <= 0.0 {
        return Err(CycleAlarm::new(61117, "active tool radius ≤ 0"));
    }
    Ok(wr)
}

/// Which way the infeed goes from RFP to DP (−1 or +1); DP on RFP, or RTP not before RFP,
/// is 61101.
pub fn infeed(rtp: f64, rfp: f64, dp: f64) -> Result<f64, CycleAlarm> {
    let down = (dp - rfp).signum();
    if dp == rfp || (rtp - rfp) * down >= 0.0 {
        return Err(CycleAlarm::new(
            61101,
            "reference plane defined incorrectly: RTP before RFP, DP beyond it",
        ));
    }
    Ok(down)
}

/// MIDA, the widest step in the plane: 0 is 80 % of the cutter's diameter; wider than the
/// cutter 61111.
pub fn width_step(mida: f64, wr: f64) -> Result<f64, CycleAlarm> {
    let mida = if mida > 0.0 { mida } else { 1.6 * wr };
    if mida > 2.0 * wr {
        return Err(CycleAlarm::new(61111, "infeed width MIDA > tool diameter"));
    }
    Ok(mida)
}

/// Feeds of a cycle, each above 0, else 61003.
pub fn feeds(feeds: &[f64], names: &str) -> Result<(), CycleAlarm> {
    if feeds.iter().any(|f| *f <= 0.0) {
        return Err(CycleAlarm::new(
            61003,
            format!("no feed programmed in the cycle: {names}"),
        ));
    }
    Ok(())
}

/// Refuses a path grown beyond [`MAX_MOVES`].
pub fn within_budget(m: &[Move]) -> Result<(), CycleAlarm> {
    if m.len() > MAX_MOVES {
        return Err(too_many());
    }
    Ok(())
}

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

/// A cycle's own frame: points about its centre, turned so its long side runs along x.
pub struct Frame {
    pub centre: (f64, f64),
    pub cos: f64,
    pub sin: f64,
}

impl Frame {
    pub fn put(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (
            self.centre.0 + x * self.cos - y * self.sin,
            self.centre.1 + x * self.sin + y * self.cos,
        )
    }
    pub fn line(&self, p: (f64, f64), z: f64, feed: f64) -> Move {
        let q = self.put(p);
        Move::Line((q.0, q.1, z), feed)
    }
    pub fn arc(&self, end: (f64, f64), centre: (f64, f64), z: f64, ccw: bool, feed: f64) -> Move {
        let (e, c) = (self.put(end), self.put(centre));
        Move::Arc {
            end: (e.0, e.1, z),
            centre: c,
            ccw,
            feed,
        }
    }
    pub fn point(&self, p: (f64, f64), z: f64) -> P3 {
        let q = self.put(p);
        (q.0, q.1, z)
    }
}

/// A point the path goes to, and the centre of the corner arc that ends there (a side ends
/// with none).
pub type Corner = ((f64, f64), Option<(f64, f64)>);

/// One turn round the rounded rectangle of half sizes `a` × `b` and corner radius `r`, from
/// the middle of its +x side and back there.
pub fn round_rect(f: &Frame, a: f64, b: f64, r: f64, z: f64, ccw: bool, feed: f64) -> Vec<Move> {
    let r = r.min(a).min(b).max(0.0);
    let (ia, ib) = (a - r, b - r);
    // Counter-clockwise: the sides and the corner arcs in turn.
    let mut pts: Vec<Corner> = vec![
        ((a, ib), None),
        ((ia, b), Some((ia, ib))),
        ((-ia, b), None),
        ((-a, ib), Some((-ia, ib))),
        ((-a, -ib), None),
        ((-ia, -b), Some((-ia, -ib))),
        ((ia, -b), None),
        ((a, -ib), Some((ia, -ib))),
        ((a, 0.0), None),
    ];
    if !ccw {
        // The same points the other way round: each arc keeps its centre, ending where the
        // side before it began.
        let mut back = Vec::new();
        let n = pts.len();
        for k in (0..n - 1).rev() {
            back.push((pts[k].0, pts[k + 1].1));
        }
        back.push(((a, 0.0), None));
        pts = back;
    }
    let mut m = Vec::new();
    let mut here = (a, 0.0);
    for (end, centre) in pts {
        match centre {
            Some(c) if r > 1e-9 => m.push(f.arc(end, c, z, ccw, feed)),
            Some(_) => continue,
            // A side of no length (a circle: the corners meet) is no move.
            None if (end.0 - here.0).hypot(end.1 - here.1) < 1e-9 => continue,
            None => m.push(f.line(end, z, feed)),
        }
        here = end;
    }
    m
}
