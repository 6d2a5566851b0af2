//! CYCLE71, face milling (`001` §10.6.2; inventory §4.5), as a pure function: a rectangle
//! from the corner PA/PO, LENG × WID (their signs say which way from the corner), turned by
//! STA, milled level by level within MID in passes along one plane axis, one way or back and
//! forth, each pass at most MIDA from the last, the cutter running out past the edges and
//! coming down outside the face. No radius compensation. Decision D89.

use super::cutter_path::{cutter, feeds, infeed, steps, width_step, within_budget, Frame, Move};
use super::drilling::CycleAlarm;
use super::pocket::levels;

/// CYCLE71's parameters, lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Face {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    pub dp: f64,
    pub corner: (f64, f64),
    pub leng: f64,
    pub wid: f64,
    pub sta: f64,
    pub mid: f64,
    pub mida: f64,
    /// Lift after a finishing pass.
    pub fdp: f64,
    pub fald: f64,
    pub ffp1: f64,
    /// VARI: units 1 roughing, 2 finishing; tens 1–4.
    pub vari: i64,
    /// Overrun past the far edge in the infeed direction.
    pub fdp1: f64,
}

/// The cutter centre's moves for CYCLE71 with a cutter of `tool_radius` (`None`: no cutting
/// edge active).
pub fn face_milling(p: Face, tool_radius: Option<f64>) -> Result<Vec<Move>, CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let (units, tens) = (p.vari % 10, p.vari / 10);
    if !(1..=2).contains(&units) || !(1..=4).contains(&tens) {
        return Err(CycleAlarm::new(
            61002,
            "VARI: units 1 roughing or 2 finishing, tens 1–4 the direction",
        ));
    }
    if p.leng == 0.0 || p.wid == 0.0 {
        return Err(CycleAlarm::new(61118, "length or width = 0"));
    }
    let mida = width_step(p.mida, wr)?;
    feeds(&[p.ffp1], "FFP1")?;
    let down = infeed(p.rtp, p.rfp, p.dp)?;
    let (sin, cos) = p.sta.to_radians().sin_cos();
    let f = Frame {
        centre: p.corner,
        cos,
        sin,
    };
    // Passes run along u and step along w (the frame's x and y, or the other way round).
    let along_x = tens == 1 || tens == 3;
    let back_and_forth = tens >= 3;
    let (u_len, w_len) = if along_x {
        (p.leng, p.wid)
    } else {
        (p.wid, p.leng)
    };
    let (u0, u1) = (u_len.min(0.0), u_len.max(0.0));
    let (w0, w1) = (w_len.min(0.0), w_len.max(0.0));
    let frame = |u: f64, w: f64| if along_x { (u, w) } else { (w, u) };
    // The cutter starts and ends a diameter past the face.
    let (start, end) = (u0 - 2.0 * wr, u1 + 2.0 * wr);
    // The first pass takes exactly MIDA; the rest, evenly at most MIDA apart, end with the
    // centre FDP1 − its radius past the far edge.
    let first = w0 + mida - wr;
    let last = (w1 + p.fdp1 - wr).max(first);
    let n = steps((last - first) / mida, 0)?;
    let passes: Vec<f64> = (0..=n)
        .map(|k| {
            if n == 0 {
                first
            } else {
                first + (last - first) * k as f64 / n as f64
            }
        })
        .collect();
    let safety = p.rfp - down * p.sdis.abs();
    let floor = p.dp - down * p.fald.abs();
    let finishing = units == 2;
    let planes = if finishing {
        vec![p.dp]
    } else {
        levels(p.rfp, floor, p.mid)?
    };
    let put = |u: f64, w: f64, z: f64| {
        let q = f.put(frame(u, w));
        (q.0, q.1, z)
    };
    let mut m = vec![
        Move::Rapid(put(start, passes[0], p.rtp)),
        Move::Rapid(put(start, passes[0], safety)),
    ];
    for level in planes {
        // Lifted between passes: by the infeed and SDIS when roughing, the allowance and
        // SDIS (at least FDP) when finishing.
        let lift = if finishing {
            level - down * (p.fald.abs() + p.sdis.abs()).max(p.fdp.abs())
        } else {
            safety
        };
        let mut from_start = true;
        for (k, w) in passes.iter().enumerate() {
            let (a, b) = if from_start {
                (start, end)
            } else {
                (end, start)
            };
            if k == 0 || !back_and_forth {
                m.push(Move::Rapid(put(a, *w, m_level(&m))));
                m.push(Move::Rapid(put(a, *w, level)));
            } else {
                // Across outside the face to the next pass.
                m.push(Move::Line(put(a, *w, level), p.ffp1));
            }
            m.push(Move::Line(put(b, *w, level), p.ffp1));
            if !back_and_forth {
                m.push(Move::Rapid(put(b, *w, lift)));
            } else {
                from_start = !from_start;
            }
        }
        let here = m_point(&m);
        m.push(Move::Rapid((here.0, here.1, lift)));
        within_budget(&m)?;
    }
    let here = m_point(&m);
    m.push(Move::Rapid((here.0, here.1, p.rtp)));
    Ok(m)
}

/// Where the last move ends.
fn m_point(m: &[Move]) -> (f64, f64, f64) {
    match m.last() {
        Some(Move::Rapid(q) | Move::Line(q, _)) => *q,
        Some(Move::Arc { end, .. }) => *end,
        None => (0.0, 0.0, 0.0),
    }
}

fn m_level(m: &[Move]) -> f64 {
    m_point(m).2
}
