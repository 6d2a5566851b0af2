//! POCKET4, the circular pocket (`001` §10.6.10; inventory §4.5), as a pure function: the
//! parameters and the cutter's radius in, the moves of its centre out. Roughing clears the
//! pocket level by level (at most MID deep, evenly) to the allowances, inserting vertically
//! or on a helix, then widening in rings at most MIDA apart; finishing takes the wall in one
//! turn per level, entered and left on quarter circles, then the floor. Decision D87.

use super::cutter_path::{cutter, feeds, infeed, steps, width_step, within_budget, Move, P3};
use super::drilling::CycleAlarm;

/// How roughing enters each level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Insertion {
    /// Straight down at the centre (VARI tens 0 and 1).
    Vertical,
    /// On a helix of radius `radius` (the centre's path), `per_turn` deeper each turn.
    Helix { radius: f64, per_turn: f64 },
    /// POCKET3 only: back and forth along the long axis, sloping down at most `angle`
    /// degrees to the level, then once more along it on the level (§10.6.9).
    Reciprocating { angle: f64 },
}

/// POCKET4's parameters, lengths in mm, the direction already resolved from CDIR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CirclePocket {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    pub dp: f64,
    pub prad: f64,
    pub centre: (f64, f64),
    pub mid: f64,
    pub fal: f64,
    pub fald: f64,
    pub ffp1: f64,
    pub ffd: f64,
    /// G3 (counter-clockwise) for the rings and the wall.
    pub ccw: bool,
    /// VARI units: true roughing, false finishing.
    pub roughing: bool,
    pub insertion: Insertion,
    /// The widest step between rings; 0: 80 % of the cutter's diameter.
    pub mida: f64,
}

/// The levels from `top` to `bottom`, at most `mid` apart and evenly spread (the fewest);
/// `mid` 0: one.
pub fn levels(top: f64, bottom: f64, mid: f64) -> Result<Vec<f64>, CycleAlarm> {
    let depth = (bottom - top).abs();
    let n = if mid > 0.0 { steps(depth / mid, 1)? } else { 1 };
    Ok((1..=n)
        .map(|k| top + (bottom - top) * k as f64 / n as f64)
        .collect())
}

/// The cutter centre's moves for POCKET4 with a cutter of `tool_radius` (`None`: no cutting
/// edge active).
pub fn circular_pocket(p: CirclePocket, tool_radius: Option<f64>) -> Result<Vec<Move>, CycleAlarm> {
    let wr = cutter(tool_radius)?;
    let down = infeed(p.rtp, p.rfp, p.dp)?;
    if p.prad - p.fal <= wr {
        return Err(CycleAlarm::new(
            61105,
            "cutter radius too large for the pocket",
        ));
    }
    let mida = width_step(p.mida, wr)?;
    if p.mid > 0.0 && p.fald > p.mid {
        return Err(CycleAlarm::new(
            61110,
            "base allowance FALD > depth infeed MID",
        ));
    }
    feeds(&[p.ffp1, p.ffd], "FFP1 and FFD")?;
    let (cx, cy) = p.centre;
    let safety = p.rfp - down * p.sdis.abs();
    let floor = p.dp - down * p.fald.abs();
    let mut m = vec![Move::Rapid((cx, cy, p.rtp)), Move::Rapid((cx, cy, safety))];
    let ring = |m: &mut Vec<Move>, r: f64, z: f64, feed: f64| {
        m.push(Move::Line((cx + r, cy, z), feed));
        m.push(Move::Arc {
            end: (cx + r, cy, z),
            centre: (cx, cy),
            ccw: p.ccw,
            feed,
        });
    };
    // Rings out to `outer` (the centre's radius), at most `mida` apart.
    let rings = |m: &mut Vec<Move>, outer: f64, z: f64| -> Result<(), CycleAlarm> {
        let n = steps(outer / mida, 1)?;
        for k in 1..=n {
            ring(m, outer * k as f64 / n as f64, z, p.ffp1);
        }
        m.push(Move::Line((cx, cy, z), p.ffp1));
        within_budget(m)
    };
    if p.roughing {
        let outer = p.prad - p.fal - wr;
        if let Insertion::Helix { radius, per_turn } = p.insertion {
            if radius <= 0.0 || per_turn <= 0.0 || radius > outer {
                return Err(CycleAlarm::new(61108, "illegal values for RAD1 and DP1"));
            }
        }
        let mut z = safety;
        for level in levels(p.rfp, floor, p.mid)? {
            match p.insertion {
                // POCKET4 has no reciprocating insertion: its call refuses tens 3.
                Insertion::Vertical | Insertion::Reciprocating { .. } => {
                    m.push(Move::Line((cx, cy, level), p.ffd))
                }
                Insertion::Helix { radius, per_turn } => {
                    m.push(Move::Line((cx + radius, cy, z), p.ffp1));
                    let turns = steps((level - z).abs() / per_turn, 1)?;
                    for k in 1..=turns {
                        let at = z + (level - z) * k as f64 / turns as f64;
                        m.push(Move::Arc {
                            end: (cx + radius, cy, at),
                            centre: (cx, cy),
                            ccw: p.ccw,
                            feed: p.ffd,
                        });
                    }
                    // A full turn on the level takes the ramp away.
                    ring(&mut m, radius, level, p.ffd);
                    m.push(Move::Line((cx, cy, level), p.ffp1));
                }
            }
            rings(&mut m, outer, level)?;
            z = level;
        }
    } else {
        let wall = p.prad - wr;
        if p.fal > 0.0 {
            // Enter and leave on quarter circles of 2 mm (more for a larger allowance).
            let ra = p.fal.max(2.0).min(wall / 2.0);
            let turn = if p.ccw { 1.0 } else { -1.0 };
            let inside = wall - ra;
            let clear = |pt: (f64, f64)| (pt.0 - cx).hypot(pt.1 - cy) <= wall - p.fal;
            for level in levels(p.rfp, floor, p.mid)? {
                let a: P3 = (cx + inside, cy - turn * ra, level);
                m.push(Move::Rapid((cx, cy, level)));
                if clear((a.0, a.1)) {
                    m.push(Move::Rapid(a));
                } else {
                    m.push(Move::Line(a, p.ffp1));
                }
                m.push(Move::Arc {
                    end: (cx + wall, cy, level),
                    centre: (cx + inside, cy),
                    ccw: p.ccw,
                    feed: p.ffp1,
                });
                m.push(Move::Arc {
                    end: (cx + wall, cy, level),
                    centre: (cx, cy),
                    ccw: p.ccw,
                    feed: p.ffp1,
                });
                m.push(Move::Arc {
                    end: (cx + inside, cy + turn * ra, level),
                    centre: (cx + inside, cy),
                    ccw: p.ccw,
                    feed: p.ffp1,
                });
                m.push(Move::Line((cx, cy, level), p.ffp1));
            }
        }
        if p.fald > 0.0 {
            m.push(Move::Rapid((cx, cy, floor - down * p.sdis.abs())));
            m.push(Move::Line((cx, cy, p.dp), p.ffd));
            rings(&mut m, wall, p.dp)?;
        }
    }
    m.push(Move::Rapid((cx, cy, p.rtp)));
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_are_even_and_at_most_mid_apart() {
        assert_eq!(
            levels(0.0, -20.0, 6.0).unwrap(),
            [-5.0, -10.0, -15.0, -20.0]
        );
        assert_eq!(levels(0.0, -20.0, 0.0).unwrap(), [-20.0]);
        assert_eq!(levels(0.0, -12.0, 4.0).unwrap(), [-4.0, -8.0, -12.0]);
        assert_eq!(levels(0.0, -1000.0, 1e-6).unwrap_err().number, 12140);
    }
}
