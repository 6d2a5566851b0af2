//! POCKET3, the rectangular pocket (`001` §10.6.9; inventory §4.5), as a pure function, the
//! way `pocket.rs` makes POCKET4: level by level within MID, entered at the centre straight
//! down or on a helix, then cleared from a slot along the long axis outwards by rounded
//! rectangles at most MIDA apart; finishing takes the wall once per level (entered and left on
//! quarter circles) and the floor. Decision D87.

use super::cutter_path::{
    cutter, feeds, infeed, round_rect, steps, width_step, within_budget, Frame, Move,
};
use super::drilling::CycleAlarm;
use super::pocket::{levels, Insertion};

/// POCKET3's parameters, lengths in mm, the direction already resolved from CDIR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectPocket {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    pub dp: f64,
    pub leng: f64,
    pub wid: f64,
    pub crad: f64,
    pub centre: (f64, f64),
    /// The long axis's angle to the 1st plane axis, degrees.
    pub sta: f64,
    pub mid: f64,
    pub fal: f64,
    pub fald: f64,
    pub ffp1: f64,
    pub ffd: f64,
    pub ccw: bool,
    pub roughing: bool,
    pub insertion: Insertion,
    pub mida: f64,
}

/// The cutter centre's moves for POCKET3 with a cutter of `tool_radius` (`None`: no cutting
/// edge active).
pub fn rectangular_pocket(
    p: RectPocket,
    tool_radius: Option<f64>,
) -> Result<Vec<Move>, CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let down = infeed(p.rtp, p.rfp, p.dp)?;
    let (la, lb) = (p.leng.abs() / 2.0, p.wid.abs() / 2.0);
    if wr >= la.min(lb) - p.fal {
        return Err(CycleAlarm::new(
            61105,
            "cutter radius too large for the pocket",
        ));
    }
    if p.crad > la.min(lb) {
        return Err(CycleAlarm::new(61113, "corner radius CRAD too large"));
    }
    let mida = width_step(p.mida, wr)?;
    if p.mid > 0.0 && p.fald > p.mid {
        return Err(CycleAlarm::new(
            61110,
            "base allowance FALD > depth infeed MID",
        ));
    }
    feeds(&[p.ffp1, p.ffd], "FFP1 and FFD")?;
    // Along the long side.
    let (long, short, sta) = if la >= lb {
        (la, lb, p.sta)
    } else {
        (lb, la, p.sta + 90.0)
    };
    let (sin, cos) = sta.to_radians().sin_cos();
    let f = Frame {
        centre: p.centre,
        cos,
        sin,
    };
    let (cx, cy) = p.centre;
    let safety = p.rfp - down * p.sdis.abs();
    let floor = p.dp - down * p.fald.abs();
    let mut m = vec![Move::Rapid((cx, cy, p.rtp)), Move::Rapid((cx, cy, safety))];
    // Clearing out to the centre path of half sizes a × b, corner radius r.
    let clear = |m: &mut Vec<Move>, a: f64, b: f64, r: f64, z: f64| -> Result<(), CycleAlarm> {
        let n = steps(b / mida, 1)?;
        // The slot along the long axis, then rectangles out to the wall's path.
        if a - b > 1e-9 {
            m.push(f.line((-(a - b), 0.0), z, p.ffp1));
            m.push(f.line((a - b, 0.0), z, p.ffp1));
        }
        for k in 1..=n {
            let d = b * (1.0 - k as f64 / n as f64);
            m.push(f.line((a - d, 0.0), z, p.ffp1));
            m.extend(round_rect(&f, a - d, b - d, r - d, z, p.ccw, p.ffp1));
        }
        m.push(f.line((0.0, 0.0), z, p.ffp1));
        within_budget(m)
    };
    if p.roughing {
        let (a, b) = (long - p.fal - wr, short - p.fal - wr);
        let r = (p.crad - p.fal - wr).max(0.0);
        match p.insertion {
            Insertion::Helix { radius, per_turn }
                if radius <= 0.0 || per_turn <= 0.0 || radius > b =>
            {
                return Err(CycleAlarm::new(61108, "illegal values for RAD1 and DP1"));
            }
            Insertion::Reciprocating { angle } if !(angle > 0.0 && angle <= 90.0) => {
                return Err(CycleAlarm::new(
                    61108,
                    "RAD1, the insertion angle, must be over 0° and at most 90°",
                ));
            }
            _ => {}
        }
        let mut z = safety;
        for level in levels(p.rfp, floor, p.mid)? {
            match p.insertion {
                Insertion::Vertical => m.push(Move::Line((cx, cy, level), p.ffd)),
                Insertion::Helix { radius, per_turn } => {
                    // Started on the positive long axis (§10.6.9).
                    let start = f.put((radius, 0.0));
                    m.push(Move::Line((start.0, start.1, z), p.ffp1));
                    let turns = steps((level - z).abs() / per_turn, 1)?;
                    for k in 1..=turns {
                        let at = z + (level - z) * k as f64 / turns as f64;
                        m.push(Move::Arc {
                            end: (start.0, start.1, at),
                            centre: (cx, cy),
                            ccw: p.ccw,
                            feed: p.ffd,
                        });
                    }
                    m.push(Move::Arc {
                        end: (start.0, start.1, level),
                        centre: (cx, cy),
                        ccw: p.ccw,
                        feed: p.ffd,
                    });
                    m.push(Move::Line((cx, cy, level), p.ffp1));
                }
                Insertion::Reciprocating { angle } => {
                    reciprocate(&mut m, &f, &p, angle, a, (z, level))?;
                }
            }
            clear(&mut m, a, b, r, level)?;
            z = level;
        }
    } else {
        let (a, b) = (long - wr, short - wr);
        let r = (p.crad - wr).max(0.0);
        if p.fal > 0.0 {
            let ra = p.fal.max(2.0).min(b / 2.0);
            let turn = if p.ccw { 1.0 } else { -1.0 };
            let roughed = (long - p.fal - wr, short - p.fal - wr);
            for level in levels(p.rfp, floor, p.mid)? {
                let entry = (a - ra, -turn * ra);
                m.push(Move::Rapid((cx, cy, level)));
                // The entry point was cleared by roughing when it lies inside its path.
                let inside = entry.0 <= roughed.0 && entry.1.abs() <= roughed.1;
                if inside {
                    m.push(Move::Rapid(f.point(entry, level)));
                } else {
                    m.push(f.line(entry, level, p.ffp1));
                }
                m.push(f.arc((a, 0.0), (a - ra, 0.0), level, p.ccw, p.ffp1));
                m.extend(round_rect(&f, a, b, r, level, p.ccw, p.ffp1));
                m.push(f.arc((a - ra, turn * ra), (a - ra, 0.0), level, p.ccw, p.ffp1));
                m.push(Move::Line((cx, cy, level), p.ffp1));
            }
        }
        if p.fald > 0.0 {
            m.push(Move::Rapid((cx, cy, floor - down * p.sdis.abs())));
            m.push(Move::Line((cx, cy, p.dp), p.ffd));
            clear(&mut m, a, b, r, p.dp)?;
        }
    }
    m.push(Move::Rapid((cx, cy, p.rtp)));
    Ok(m)
}

/// Reciprocating insertion (VARI tens 3): from the centre at `z` out to one end of the long
/// axis, `reach` from the centre, then end to end, each pass sloping down evenly and no
/// steeper than `angle`, until `level`; one pass more on the level takes the slope away,
/// and the cutter comes back to the centre. The pass length is the long axis's whole
/// cleared length, which makes the fewest passes (D87).
fn reciprocate(
    m: &mut Vec<Move>,
    f: &Frame,
    p: &RectPocket,
    angle: f64,
    reach: f64,
    (z, level): (f64, f64),
) -> Result<(), CycleAlarm> {
    let (ffd, ffp1) = (p.ffd, p.ffp1);
    let depth = (level - z).abs();
    // Angle 90°: straight down, tan is huge and one pass does.
    let run = depth / angle.to_radians().tan().max(1e-12);
    let passes = steps(run / (2.0 * reach), 1)?;
    let mut end = -reach;
    m.push(f.line((end, 0.0), z, ffp1));
    for k in 1..=passes {
        end = -end;
        let at = z + (level - z) * k as f64 / passes as f64;
        m.push(f.line((end, 0.0), at, ffd));
    }
    m.push(f.line((-end, 0.0), level, ffd));
    m.push(f.line((0.0, 0.0), level, ffp1));
    within_budget(m)
}
