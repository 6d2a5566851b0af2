//! CYCLE90, thread milling (`001` §10.6.11; inventory §4.5), as a pure function: the
//! parameters and the cutter's radius in, the moves of the cutter's centre out, in the plane
//! (1st, 2nd axis) and along the infeed axis. Decision D86 records what the manual leaves
//! open.

use std::f64::consts::TAU;

use super::cutter_path::{cutter, steps, Move};
use super::drilling::CycleAlarm;

/// CYCLE90's parameters, lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thread {
    pub rtp: f64,
    pub rfp: f64,
    pub sdis: f64,
    /// The thread's far end (DP, or RFP and DPR).
    pub bottom: f64,
    pub diath: f64,
    pub kdiam: f64,
    pub pit: f64,
    pub ffr: f64,
    /// G3 (counter-clockwise) unless CDIR is 2.
    pub ccw: bool,
    pub external: bool,
    pub centre: (f64, f64),
}

/// The cutter's path: to the start at RTP, down, a tangential approach arc, the helix (PIT
/// per turn, half a pitch beyond each end of the thread), a tangential retraction arc, out to
/// RTP. Internal threads are entered from the hole's centre on a semicircle in the milling
/// direction; external ones from outside on a quarter circle against it (§10.6.11).
pub fn thread_milling(t: Thread, tool_radius: Option<f64>) -> Result<Vec<Move>, CycleAlarm> {
    let tool_radius = cutter(tool_radius)?;
    if !(0.001..=2000.0).contains(&t.pit) {
        return Err(CycleAlarm::new(
            61001,
            "thread pitch wrong: PIT is 0.001…2000 mm",
        ));
    }
    if t.ffr <= 0.0 {
        return Err(CycleAlarm::new(
            61003,
            "no feed programmed in the cycle: FFR",
        ));
    }
    let r = if t.external {
        t.diath / 2.0 + tool_radius
    } else {
        if tool_radius >= t.kdiam / 2.0 || t.diath <= t.kdiam {
            return Err(CycleAlarm::new(
                61105,
                "cutter radius too large for the core diameter KDIAM, or DIATH not above KDIAM",
            ));
        }
        t.diath / 2.0 - tool_radius
    };
    if t.rfp == t.bottom {
        return Err(CycleAlarm::new(
            61101,
            "reference plane defined incorrectly: no thread length",
        ));
    }
    // Top-down unless RTP lies beyond the far end (bottom-up, §10.6.11).
    let down = (t.bottom - t.rfp).signum();
    let bottom_up = (t.rtp - t.bottom) * down > 0.0;
    let (from, to) = if bottom_up {
        (t.bottom, t.rfp)
    } else {
        (t.rfp, t.bottom)
    };
    let along = (to - from).signum();
    let half = t.pit / 2.0;
    let (z0, z1) = (from - along * half, to + along * half);
    let safety = if bottom_up {
        z0
    } else {
        t.rfp - down * t.sdis.abs()
    };
    let (cx, cy) = t.centre;
    let at = |a: f64, rad: f64, z: f64| (cx + rad * a.cos(), cy + rad * a.sin(), z);
    let turn = if t.ccw { 1.0 } else { -1.0 };
    let sweep = (z1 - z0).abs() / t.pit * TAU;
    let a1 = turn * sweep;
    let slow = t.ffr / 2.0;
    let mut m = Vec::new();
    if t.external {
        // The approach point outside the path, a quarter circle of the cutter's radius away.
        let q = tool_radius;
        let s = (cx + r + q, cy - turn * q);
        m.push(Move::Rapid((s.0, s.1, t.rtp)));
        m.push(Move::Rapid((s.0, s.1, safety)));
        m.push(Move::Rapid((s.0, s.1, z0)));
        m.push(Move::Arc {
            end: at(0.0, r, z0),
            centre: (cx + r + q, cy),
            ccw: !t.ccw,
            feed: slow,
        });
    } else {
        m.push(Move::Rapid((cx, cy, t.rtp)));
        m.push(Move::Rapid((cx, cy, safety)));
        m.push(Move::Line((cx, cy, z0), slow));
        m.push(Move::Arc {
            end: at(0.0, r, z0),
            centre: (cx + r / 2.0, cy),
            ccw: t.ccw,
            feed: slow,
        });
    }
    // The helix: whole turns, then the rest.
    // Whole turns (the helix's last part follows); refused when there would be too many.
    steps(sweep / TAU, 0)?;
    let turns = (sweep / TAU).floor() as usize;
    let dz = (z1 - z0) / sweep * TAU;
    for k in 1..=turns {
        m.push(Move::Arc {
            end: at(0.0, r, z0 + dz * k as f64),
            centre: (cx, cy),
            ccw: t.ccw,
            feed: t.ffr,
        });
    }
    if sweep - TAU * turns as f64 > 1e-9 {
        m.push(Move::Arc {
            end: at(a1, r, z1),
            centre: (cx, cy),
            ccw: t.ccw,
            feed: t.ffr,
        });
    }
    if t.external {
        // Out on a quarter circle, tangent, away from the thread.
        let q = tool_radius;
        let (ux, uy) = (a1.cos(), a1.sin());
        let c = (cx + (r + q) * ux, cy + (r + q) * uy);
        let tangent = (-uy * turn, ux * turn);
        let end = (c.0 + q * tangent.0, c.1 + q * tangent.1, z1);
        m.push(Move::Arc {
            end,
            centre: c,
            ccw: !t.ccw,
            feed: slow,
        });
        m.push(Move::Rapid((end.0, end.1, t.rtp)));
    } else {
        // Back to the centre on a semicircle, still in the milling direction.
        let c = (cx + r / 2.0 * a1.cos(), cy + r / 2.0 * a1.sin());
        m.push(Move::Arc {
            end: (cx, cy, z1),
            centre: c,
            ccw: t.ccw,
            feed: slow,
        });
        m.push(Move::Rapid((cx, cy, t.rtp)));
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn internal() -> Thread {
        Thread {
            rtp: 48.0,
            rfp: 40.0,
            sdis: 5.0,
            bottom: 0.0,
            diath: 60.0,
            kdiam: 50.0,
            pit: 2.0,
            ffr: 500.0,
            ccw: false,
            external: false,
            centre: (60.0, 50.0),
        }
    }

    #[test]
    fn an_internal_thread_turns_once_per_pitch_from_half_a_pitch_above() {
        let m = thread_milling(internal(), Some(5.0)).unwrap();
        // 40 mm and a pitch beyond: 21 turns of the 25 mm path.
        let helix: Vec<&Move> = m
            .iter()
            .filter(|x| matches!(x, Move::Arc { centre, .. } if *centre == (60.0, 50.0)))
            .collect();
        assert_eq!(helix.len(), 21);
        assert!(
            matches!(helix[0], Move::Arc { end, ccw: false, .. } if (end.2 - 39.0).abs() < 1e-9)
        );
        assert!(matches!(helix[20], Move::Arc { end, .. } if (end.2 + 1.0).abs() < 1e-9));
        assert_eq!(m.last(), Some(&Move::Rapid((60.0, 50.0, 48.0))));
    }

    #[test]
    fn refusals() {
        assert_eq!(thread_milling(internal(), None).unwrap_err().number, 61000);
        assert_eq!(
            thread_milling(internal(), Some(0.0)).unwrap_err().number,
            61117
        );
        assert_eq!(
            thread_milling(internal(), Some(25.0)).unwrap_err().number,
            61105
        );
        let bad = Thread {
            pit: 0.0,
            ..internal()
        };
        assert_eq!(thread_milling(bad, Some(5.0)).unwrap_err().number, 61001);
    }
}
