//! CYCLE76 and CYCLE77, the rectangular and the circular spigot (`001` §10.6.4–§10.6.5;
//! inventory §4.5), as one pure function: a circle is a rounded rectangle whose corner
//! radius is half its size. Level by level within MID the cutter comes down outside, enters
//! on a semicircle, goes round the spigot from the blank's edge inwards (one turn when no
//! blank is given, as the manual's cycle does), leaves on a semicircle. Decision D88.

use super::cutter_path::{feeds, infeed, round_rect, steps, within_budget, Frame, Move};
use super::drilling::CycleAlarm;
use super::pocket::levels;

/// A spigot's parameters, lengths in mm, the direction resolved from CDIR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spigot {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    pub dp: f64,
    /// Half length and half width (a circle: its radius twice).
    pub half: (f64, f64),
    /// Corner radius (a circle: its radius).
    pub crad: f64,
    pub centre: (f64, f64),
    pub sta: f64,
    pub mid: f64,
    pub fal: f64,
    pub fald: f64,
    pub ffp1: f64,
    pub ffd: f64,
    pub ccw: bool,
    pub roughing: bool,
    /// The blank's half length and width (a round blank: its radius twice), if given.
    pub blank: Option<(f64, f64)>,
}

/// How far a point of the spigot's frame lies outside its rounded rectangle.
fn outside(p: (f64, f64), half: (f64, f64), r: f64) -> f64 {
    let (qx, qy) = (p.0.abs() - (half.0 - r), p.1.abs() - (half.1 - r));
    qx.max(0.0).hypot(qy.max(0.0)) + qx.max(qy).min(0.0) - r
}

/// The cutter centre's moves round the spigot with a cutter of `tool_radius` (`None`: no
/// cutting edge active: 61009).
pub fn spigot(p: Spigot, tool_radius: Option<f64>) -> Result<Vec<Move>, CycleAlarm> {
    let wr = tool_radius
        .filter(|r| *r > 0.0)
        .ok_or_else(|| CycleAlarm::new(61009, "no tool compensation active (T and D)"))?;
    let down = infeed(p.rtp, p.rfp, p.dp)?;
    feeds(&[p.ffp1, p.ffd], "FFP1 and FFD")?;
    let (a, b) = p.half;
    let r = p.crad.min(a).min(b).max(0.0);
    let (sin, cos) = p.sta.to_radians().sin_cos();
    let f = Frame {
        centre: p.centre,
        cos,
        sin,
    };
    let step = 1.6 * wr;
    // Offsets of the cutter's centre from the spigot's wall, outermost first: out to where
    // the cutter's edge reaches the blank's farthest corner, at most 80 % of its diameter
    // apart, in to `last`.
    let offsets = |last: f64| -> Result<Vec<f64>, CycleAlarm> {
        let far = p.blank.map_or(last, |(bx, by)| {
            (outside((bx, by), (a, b), r) - wr + 1e-3).max(last)
        });
        let n = steps((far - last) / step, 0)?;
        Ok((0..=n)
            .map(|k| {
                if n == 0 {
                    last
                } else {
                    far - (far - last) * k as f64 / n as f64
                }
            })
            .collect())
    };
    let safety = p.rfp - down * p.sdis.abs();
    let ra = wr;
    let turn_round =
        |m: &mut Vec<Move>, offs: &[f64], z: f64, feed_in: f64| -> Result<(), CycleAlarm> {
            let o0 = offs[0];
            let start = (a + o0 + 2.0 * ra, 0.0);
            m.push(f.line(start, z, feed_in));
            // In on a semicircle against the milling direction, tangent to the first turn.
            m.push(f.arc((a + o0, 0.0), (a + o0 + ra, 0.0), z, !p.ccw, p.ffp1));
            for (k, o) in offs.iter().enumerate() {
                if k > 0 {
                    m.push(f.line((a + o, 0.0), z, p.ffp1));
                }
                m.extend(round_rect(&f, a + o, b + o, r + o, z, p.ccw, p.ffp1));
            }
            if offs.len() > 1 {
                m.push(f.line((a + o0, 0.0), z, p.ffp1));
            }
            m.push(f.arc(start, (a + o0 + ra, 0.0), z, !p.ccw, p.ffp1));
            within_budget(m)
        };
    let start = f.put((a + offsets(p.fal + wr)?[0] + 2.0 * ra, 0.0));
    let mut m = vec![
        Move::Rapid((start.0, start.1, p.rtp)),
        Move::Rapid((start.0, start.1, safety)),
    ];
    if p.roughing {
        let offs = offsets(p.fal + wr)?;
        let floor = p.dp - down * p.fald.abs();
        for level in levels(p.rfp, floor, p.mid)? {
            turn_round(&mut m, &offs, level, p.ffd)?;
        }
    } else {
        // Finishing takes the spigot to size (§10.6.4: the allowances 0): one turn at each
        // level down to DP, then the floor at DP out to the blank.
        let first = f.put((a + wr + 2.0 * ra, 0.0));
        m.push(Move::Rapid((first.0, first.1, safety)));
        for level in levels(p.rfp, p.dp, p.mid)? {
            turn_round(&mut m, &[wr], level, p.ffd)?;
        }
        let offs = offsets(wr)?;
        if offs.len() > 1 {
            m.push(Move::Rapid((first.0, first.1, safety)));
            let s = f.put((a + offs[0] + 2.0 * ra, 0.0));
            m.push(Move::Rapid((s.0, s.1, safety)));
            turn_round(&mut m, &offs, p.dp, p.ffd)?;
        }
    }
    let end = m.last().map_or(start, |x| match x {
        Move::Rapid(q) | Move::Line(q, _) => (q.0, q.1),
        Move::Arc { end, .. } => (end.0, end.1),
    });
    m.push(Move::Rapid((end.0, end.1, p.rtp)));
    Ok(m)
}
