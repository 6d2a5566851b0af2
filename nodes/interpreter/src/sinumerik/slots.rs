//! LONGHOLE and SLOT1, elongated holes and slots on a circle (`001` §10.6.6–§10.6.7;
//! inventory §4.5), as pure functions. Each hole or slot lies with its long axis radial, its
//! middle on the circle of radius RAD about CPA/CPO, at STA1 + k·INDA (INDA 0: spread over
//! the full circle); LENG is its whole length. A long hole is as wide as the cutter and is
//! milled back and forth, the cutter plunging at alternate ends; a slot is a stadium, roughed
//! along its middle and then round it out to the allowance, and finished round its wall.
//! Decision D90.

use super::cutter_path::{cutter, feeds, infeed, round_rect, steps, within_budget, Frame, Move};
use super::drilling::CycleAlarm;
use super::pocket::levels;

/// Where the holes or slots lie, their size and depth; lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pattern {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    pub dp: f64,
    pub num: usize,
    pub leng: f64,
    pub centre: (f64, f64),
    pub rad: f64,
    pub sta1: f64,
    pub inda: f64,
    pub ffd: f64,
    pub ffp1: f64,
    pub mid: f64,
}

/// SLOT1's own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    pub wid: f64,
    pub ccw: bool,
    pub fal: f64,
    /// 0 roughing and finishing, 1 roughing, 2 finishing.
    pub vari: i64,
    /// Finishing infeed (0: the whole depth at once) and feed.
    pub midf: f64,
    pub ffp2: f64,
}

/// VARI of SLOT1 and SLOT2: 0 complete, 1 roughing, 2 finishing; anything else is 61002.
fn machining_kind(vari: i64) -> Result<(), CycleAlarm> {
    if (0..=2).contains(&vari) {
        Ok(())
    } else {
        Err(CycleAlarm::new(
            61002,
            "VARI is 0 complete, 1 roughing or 2 finishing",
        ))
    }
}

impl Pattern {
    fn check(&self) -> Result<f64, CycleAlarm> {
        if self.num == 0 {
            return Err(CycleAlarm::new(61103, "number of holes is zero"));
        }
        feeds(&[self.ffd, self.ffp1], "FFD and FFP1")?;
        infeed(self.rtp, self.rfp, self.dp)
    }

    /// The frame of hole `k`: its middle at the origin, its long axis along x.
    fn frame(&self, k: usize) -> Frame {
        let inda = if self.inda == 0.0 {
            360.0 / self.num as f64
        } else {
            self.inda
        };
        let a = (self.sta1 + inda * k as f64).to_radians();
        Frame {
            centre: (
                self.centre.0 + self.rad * a.cos(),
                self.centre.1 + self.rad * a.sin(),
            ),
            cos: a.cos(),
            sin: a.sin(),
        }
    }

    /// 61104 when two of the holes, `half` their length less `width`/2 either side of their
    /// middle along the radius, come closer than `width`.
    fn apart(&self, half: f64, width: f64) -> Result<(), CycleAlarm> {
        let seg = |k: usize| {
            let f = self.frame(k);
            (f.put((-half, 0.0)), f.put((half, 0.0)))
        };
        for i in 0..self.num {
            for j in i + 1..self.num {
                if segment_distance(seg(i), seg(j)) < width - 1e-9 {
                    return Err(CycleAlarm::new(
                        61104,
                        "contour violation of slots/elongated holes: they overlap",
                    ));
                }
            }
        }
        Ok(())
    }
}

type Pt2 = (f64, f64);

fn point_segment(p: Pt2, (a, b): (Pt2, Pt2)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

fn segment_distance(s: (Pt2, Pt2), t: (Pt2, Pt2)) -> f64 {
    let cross = |o: Pt2, a: Pt2, b: Pt2| (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0);
    let d1 = cross(t.0, t.1, s.0);
    let d2 = cross(t.0, t.1, s.1);
    let d3 = cross(s.0, s.1, t.0);
    let d4 = cross(s.0, s.1, t.1);
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    point_segment(s.0, t)
        .min(point_segment(s.1, t))
        .min(point_segment(t.0, s))
        .min(point_segment(t.1, s))
}

/// LONGHOLE: each hole from its end nearer to the tool, plunging at FFD at alternate ends
/// and milling to the other at FFP1, level by level within MID, out at rapid to RTP.
pub fn long_holes(
    p: Pattern,
    tool_radius: Option<f64>,
    from: Pt2,
) -> Result<Vec<Move>, CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let down = p.check()?;
    if p.leng < 2.0 * wr {
        return Err(CycleAlarm::new(
            61105,
            "the hole is shorter than the cutter's diameter",
        ));
    }
    let half = p.leng / 2.0 - wr;
    p.apart(half, 2.0 * wr)?;
    let safety = p.rfp - down * p.sdis.abs();
    let mut m = Vec::new();
    let mut here = from;
    for k in 0..p.num {
        let f = p.frame(k);
        let ends = [f.put((-half, 0.0)), f.put((half, 0.0))];
        let near = |q: Pt2| (q.0 - here.0).hypot(q.1 - here.1);
        let mut at = usize::from(near(ends[1]) < near(ends[0]));
        m.push(Move::Rapid((ends[at].0, ends[at].1, p.rtp)));
        m.push(Move::Rapid((ends[at].0, ends[at].1, safety)));
        for level in levels(p.rfp, p.dp, p.mid)? {
            m.push(Move::Line((ends[at].0, ends[at].1, level), p.ffd));
            at = 1 - at;
            m.push(Move::Line((ends[at].0, ends[at].1, level), p.ffp1));
        }
        m.push(Move::Rapid((ends[at].0, ends[at].1, p.rtp)));
        here = ends[at];
        within_budget(&m)?;
    }
    Ok(m)
}

/// SLOT1: roughing and finishing as two move lists (finishing may turn at its own speed).
pub fn slots(
    p: Pattern,
    s: Slot,
    tool_radius: Option<f64>,
) -> Result<(Vec<Move>, Vec<Move>), CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let down = p.check()?;
    machining_kind(s.vari)?;
    let (a, b) = (p.leng / 2.0, s.wid / 2.0);
    if 2.0 * wr >= s.wid || a < b {
        return Err(CycleAlarm::new(
            61105,
            "cutter radius too large: its diameter must be below the width WID",
        ));
    }
    // The allowance shrinks when the cutter leaves no room for it (§10.6.7).
    let fal = s.fal.abs().min(b - wr - 1e-3).max(0.0);
    p.apart(a - b, s.wid)?;
    let safety = p.rfp - down * p.sdis.abs();
    let step = 1.6 * wr;
    let (mut rough, mut finish) = (Vec::new(), Vec::new());
    for k in 0..p.num {
        let f = p.frame(k);
        let mid_end = |sign: f64| f.put((sign * (a - b), 0.0));
        if s.vari != 2 {
            let m = &mut rough;
            let start = mid_end(-1.0);
            m.push(Move::Rapid((start.0, start.1, p.rtp)));
            m.push(Move::Rapid((start.0, start.1, safety)));
            // Loops from the middle line out to the allowance, at most 80 % of the
            // cutter's diameter apart.
            let last = fal + wr;
            let n = steps((b - last) / step, 1)?;
            let mut end = -1.0;
            for level in levels(p.rfp, p.dp, p.mid)? {
                let q = mid_end(end);
                m.push(Move::Line((q.0, q.1, level), p.ffd));
                end = -end;
                let q = mid_end(end);
                m.push(Move::Line((q.0, q.1, level), p.ffp1));
                for i in 1..=n {
                    let o = b - (b - last) * i as f64 / n as f64;
                    m.push(f.line((a - o, 0.0), level, p.ffp1));
                    m.extend(round_rect(&f, a - o, b - o, b - o, level, s.ccw, p.ffp1));
                }
                let q = mid_end(1.0);
                m.push(Move::Line((q.0, q.1, level), p.ffp1));
                end = 1.0;
                within_budget(m)?;
            }
            let q = mid_end(1.0);
            m.push(Move::Rapid((q.0, q.1, p.rtp)));
        }
        if s.vari != 1 {
            let m = &mut finish;
            let feed = if s.ffp2 > 0.0 { s.ffp2 } else { p.ffp1 };
            let q = mid_end(1.0);
            m.push(Move::Rapid((q.0, q.1, p.rtp)));
            m.push(Move::Rapid((q.0, q.1, safety)));
            for level in levels(p.rfp, p.dp, s.midf)? {
                m.push(Move::Line((q.0, q.1, level), p.ffd));
                m.push(f.line((a - wr, 0.0), level, feed));
                m.extend(round_rect(&f, a - wr, b - wr, b - wr, level, s.ccw, feed));
                m.push(Move::Line((q.0, q.1, level), feed));
                within_budget(m)?;
            }
            m.push(Move::Rapid((q.0, q.1, p.rtp)));
        }
    }
    Ok((rough, finish))
}

/// SLOT2's own parameters: the slot's angular length and width, as SLOT1's otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcSlot {
    /// Angular length, degrees (the middle line's, end centre to end centre).
    pub afsl: f64,
    pub slot: Slot,
}

/// A slot bent along the circle: the loop at `d` either side of its middle arc, starting
/// where its far end (`b`, degrees) meets the outer arc; around the slot counter-clockwise
/// when `ccw`, every end a half circle.
fn arc_loop(
    c: (f64, f64),
    rad: f64,
    (a, b): (f64, f64),
    d: f64,
    z: f64,
    ccw: bool,
    feed: f64,
) -> Vec<Move> {
    let at = |ang: f64, r: f64| {
        let (s, co) = ang.to_radians().sin_cos();
        (c.0 + r * co, c.1 + r * s, z)
    };
    let end = |ang: f64| {
        let q = at(ang, rad);
        (q.0, q.1)
    };
    let arc = |to: (f64, f64, f64), centre: (f64, f64), ccw: bool| Move::Arc {
        end: to,
        centre,
        ccw,
        feed,
    };
    if ccw {
        vec![
            arc(at(b, rad - d), end(b), true),
            arc(at(a, rad - d), c, false),
            arc(at(a, rad + d), end(a), true),
            arc(at(b, rad + d), c, true),
        ]
    } else {
        vec![
            arc(at(a, rad + d), c, false),
            arc(at(a, rad - d), end(a), false),
            arc(at(b, rad - d), c, true),
            arc(at(b, rad + d), end(b), false),
        ]
    }
}

/// SLOT2: slots along the circle (§10.6.8), each from STA1 + k·INDA over AFSL degrees;
/// roughing along the middle arc and round bent slots out to FAL, finishing round the wall.
pub fn arc_slots(
    p: Pattern,
    s: ArcSlot,
    tool_radius: Option<f64>,
) -> Result<(Vec<Move>, Vec<Move>), CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let down = p.check()?;
    let slot = s.slot;
    machining_kind(slot.vari)?;
    let half = slot.wid / 2.0;
    if 2.0 * wr >= slot.wid {
        return Err(CycleAlarm::new(
            61105,
            "cutter radius too large: its diameter must be below the width WID",
        ));
    }
    let afsl = s.afsl.abs();
    let inda = if p.inda == 0.0 {
        360.0 / p.num as f64
    } else {
        p.inda
    };
    // The slots' middle arcs apart by their width, and off the centre.
    if p.rad <= half || afsl <= 0.0 {
        return Err(CycleAlarm::new(
            61104,
            "contour violation: the slot reaches the circle's centre or has no length",
        ));
    }
    let spans: Vec<(f64, f64)> = (0..p.num)
        .map(|k| {
            let a = p.sta1 + inda * k as f64;
            (a, a + afsl)
        })
        .collect();
    for i in 0..p.num {
        for j in i + 1..p.num {
            let gap = arc_gap(spans[i], spans[j]);
            if 2.0 * p.rad * (gap.to_radians().min(std::f64::consts::PI) / 2.0).sin()
                < slot.wid - 1e-9
            {
                return Err(CycleAlarm::new(
                    61104,
                    "contour violation of slots: they overlap",
                ));
            }
        }
    }
    let fal = slot.fal.abs().min(half - wr - 1e-3).max(0.0);
    let safety = p.rfp - down * p.sdis.abs();
    let step = 1.6 * wr;
    let c = p.centre;
    let at = |ang: f64, r: f64, z: f64| {
        let (s, co) = ang.to_radians().sin_cos();
        (c.0 + r * co, c.1 + r * s, z)
    };
    let (mut rough, mut finish) = (Vec::new(), Vec::new());
    for &(a, b) in &spans {
        if slot.vari != 2 {
            let m = &mut rough;
            let last = half - fal - wr;
            let n = steps(last / step, 1)?;
            let start = at(a, p.rad, p.rtp);
            m.push(Move::Rapid(start));
            m.push(Move::Rapid((start.0, start.1, safety)));
            for level in levels(p.rfp, p.dp, p.mid)? {
                m.push(Move::Line(at(a, p.rad, level), p.ffd));
                m.push(Move::Arc {
                    end: at(b, p.rad, level),
                    centre: c,
                    ccw: true,
                    feed: p.ffp1,
                });
                for i in 1..=n {
                    let d = last * i as f64 / n as f64;
                    m.push(Move::Line(at(b, p.rad + d, level), p.ffp1));
                    m.extend(arc_loop(c, p.rad, (a, b), d, level, slot.ccw, p.ffp1));
                }
                m.push(Move::Line(at(b, p.rad, level), p.ffp1));
                m.push(Move::Arc {
                    end: at(a, p.rad, level),
                    centre: c,
                    ccw: false,
                    feed: p.ffp1,
                });
                within_budget(m)?;
            }
            m.push(Move::Rapid(at(a, p.rad, p.rtp)));
        }
        if slot.vari != 1 {
            let m = &mut finish;
            let feed = if slot.ffp2 > 0.0 { slot.ffp2 } else { p.ffp1 };
            let top = at(b, p.rad, p.rtp);
            m.push(Move::Rapid(top));
            m.push(Move::Rapid((top.0, top.1, safety)));
            for level in levels(p.rfp, p.dp, slot.midf)? {
                m.push(Move::Line(at(b, p.rad, level), p.ffd));
                m.push(Move::Line(at(b, p.rad + half - wr, level), feed));
                m.extend(arc_loop(c, p.rad, (a, b), half - wr, level, slot.ccw, feed));
                m.push(Move::Line(at(b, p.rad, level), feed));
                within_budget(m)?;
            }
            m.push(Move::Rapid(top));
        }
    }
    Ok((rough, finish))
}

/// The smallest angle between two spans of degrees (0 when they overlap).
fn arc_gap(x: (f64, f64), y: (f64, f64)) -> f64 {
    let norm = |a: f64| a.rem_euclid(360.0);
    let inside = |a: f64, (s, e): (f64, f64)| norm(a - s) <= e - s + 1e-9;
    if inside(x.0, y) || inside(x.1, y) || inside(y.0, x) || inside(y.1, x) {
        return 0.0;
    }
    let d = |a: f64, b: f64| {
        let t = norm(a - b);
        t.min(360.0 - t)
    };
    d(x.0, y.1)
        .min(d(x.1, y.0))
        .min(d(x.0, y.0))
        .min(d(x.1, y.1))
}
