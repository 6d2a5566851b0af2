//! The 802D's drilling cycles CYCLE81–CYCLE89 and CYCLE840 (`001` §10.4; inventory §4.2–
//! §4.3) as pure functions: the parameters in, the steps along the drilling axis out (levels
//! in work coordinates of that axis). The executor (`cycle_call.rs`) moves the machine by
//! them at the hole the calling program positioned over. Decision D84 records what the
//! manual leaves open.

/// One step of a drilling cycle.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// The drilling axis to a level at rapid.
    Rapid(f64),
    /// The drilling axis to a level at a feed (mm/min).
    Feed(f64, f64),
    Dwell(f64),
    /// An M function: 3/4/5 the spindle, 0 the program stop.
    M(u32),
    /// The oriented stop at POSS: the spindle positioned the shortest way (SPOS, D100).
    Orient(f64),
    /// Rigid tapping to a level: the lead (signed: + the way M3 turns) and the speed (D101).
    Tap(f64, f64, f64),
    /// A spindle speed.
    Speed(f64),
    /// A rapid move in the plane by (1st, 2nd plane axis) and along the drilling axis by the
    /// third, incremental (CYCLE86's lift-off).
    Lift(f64, f64, f64),
    /// Back over the hole in the plane at rapid, at the drilling axis's level.
    OverHole,
}

/// A cycle alarm: its number (61xxx) and text.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleAlarm {
    pub number: u32,
    pub text: String,
}

impl CycleAlarm {
    pub fn new(number: u32, text: impl Into<String>) -> CycleAlarm {
        CycleAlarm {
            number,
            text: text.into(),
        }
    }
}

fn alarm(number: u32, text: impl Into<String>) -> CycleAlarm {
    CycleAlarm::new(number, text)
}

/// The hole's levels from RTP, RFP, SDIS, DP and DPR (§10.4.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levels {
    pub rtp: f64,
    pub rfp: f64,
    /// RFP plus the safety distance, towards RTP.
    pub safety: f64,
    pub bottom: f64,
    /// +1 when the hole goes towards larger values of the drilling axis, −1 otherwise.
    pub dir: f64,
}

impl Levels {
    /// DPR, when given and not 0, wins over DP (§10.4.3); the drilling direction is away
    /// from RTP. RFP = RTP with a relative depth, or RTP on the drilling side of RFP: 61101.
    pub fn new(
        rtp: f64,
        rfp: f64,
        sdis: f64,
        dp: Option<f64>,
        dpr: Option<f64>,
    ) -> Result<Levels, CycleAlarm> {
        let refused = || alarm(61101, "reference plane defined incorrectly (RTP and RFP)");
        let relative = dpr.filter(|d| *d != 0.0);
        let dir = if rtp != rfp {
            -(rtp - rfp).signum()
        } else if relative.is_some() {
            return Err(refused());
        } else {
            match dp {
                Some(dp) if dp > rfp => 1.0,
                _ => -1.0,
            }
        };
        let bottom = match (relative, dp) {
            (Some(r), _) => rfp + dir * r.abs(),
            (None, Some(dp)) => dp,
            (None, None) => {
                return Err(alarm(61101, "no final drilling depth: DP or DPR"));
            }
        };
        if (bottom - rfp) * dir < 0.0 {
            return Err(refused());
        }
        Ok(Levels {
            rtp,
            rfp,
            safety: rfp - dir * sdis.abs(),
            bottom,
            dir,
        })
    }
}

/// CYCLE81 and CYCLE82: to the bottom at the feed, a dwell (82), out at rapid.
pub fn drill(l: Levels, feed: f64, dwell: f64) -> Vec<Step> {
    let mut s = vec![Step::Rapid(l.safety), Step::Feed(l.bottom, feed)];
    if dwell > 0.0 {
        s.push(Step::Dwell(dwell));
    }
    s.push(Step::Rapid(l.rtp));
    s
}

/// The infeeds of CYCLE83 from RFP, each a positive length (§10.4.5): the first depth, then
/// the one before less DAM while that is more than DAM, else DAM; when what remains is no
/// more than two infeeds, it is split into two equal ones (one when it fits in one).
pub fn infeeds(first: f64, total: f64, dam: f64) -> Vec<f64> {
    const MAX: usize = 100_000;
    let mut out = vec![first.min(total)];
    let mut done = out[0];
    let mut last = out[0];
    while total - done > 1e-9 && out.len() < MAX {
        let left = total - done;
        let next = if dam > 0.0 {
            (last - dam).max(dam)
        } else {
            last
        };
        if left > 2.0 * next {
            out.push(next);
            done += next;
            last = next;
        } else if left > next {
            out.extend([left / 2.0, left / 2.0]);
            break;
        } else {
            out.push(left);
            break;
        }
    }
    out
}

/// The distance CYCLE83's chip removal stops short of the last depth (§10.4.5): 0.6 mm up to
/// 30 mm of depth, else a fiftieth of the depth, at most 7 mm.
pub fn anticipation(depth: f64) -> f64 {
    if depth <= 30.0 {
        0.6
    } else {
        (depth / 50.0).min(7.0)
    }
}

/// CYCLE83's own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeepHole {
    /// First depth: absolute (FDEP) or relative to RFP (FDPR, wins when given and not 0).
    pub fdep: Option<f64>,
    pub fdpr: Option<f64>,
    pub dam: f64,
    pub dtb: f64,
    pub dts: f64,
    pub frf: f64,
    /// 0 chip breaking, 1 chip removal.
    pub vari: u32,
}

/// CYCLE83, deep-hole drilling (§10.4.5): the first depth at F·FRF, then the infeeds; chip
/// breaking backs off 1 mm at F after each, chip removal leaves the hole to RFP+SDIS and
/// comes back at rapid to the anticipation distance above the last depth.
pub fn deep_hole(l: Levels, feed: f64, d: DeepHole) -> Result<Vec<Step>, CycleAlarm> {
    let total = (l.bottom - l.rfp).abs();
    let first = match (d.fdpr.filter(|f| *f != 0.0), d.fdep) {
        (Some(r), _) => r.abs(),
        (None, Some(f)) => (f - l.rfp) * l.dir,
        (None, None) => total,
    };
    if first <= 0.0 {
        return Err(alarm(
            61107,
            "first drilling depth defined incorrectly: it lies before the reference plane",
        ));
    }
    if d.vari > 1 {
        return Err(alarm(
            61002,
            "VARI is 0 (chip breaking) or 1 (chip removal)",
        ));
    }
    let frf = if d.frf > 0.0 { d.frf.min(1.0) } else { 1.0 };
    let ahead = anticipation(total);
    let mut s = vec![Step::Rapid(l.safety)];
    let mut depth = 0.0;
    for (k, step) in infeeds(first, total, d.dam).into_iter().enumerate() {
        let level = |depth: f64| l.rfp + l.dir * depth;
        if k > 0 {
            if d.vari == 1 {
                s.push(Step::Rapid(l.safety));
                if d.dts > 0.0 {
                    s.push(Step::Dwell(d.dts));
                }
                s.push(Step::Rapid(
                    level(depth - ahead).max_toward(l.safety, l.dir),
                ));
            } else {
                s.push(Step::Feed(level(depth - 1.0), feed));
            }
        }
        depth += step;
        let f = if k == 0 { feed * frf } else { feed };
        s.push(Step::Feed(level(depth), f));
        if d.dtb > 0.0 {
            s.push(Step::Dwell(d.dtb));
        }
    }
    s.push(Step::Rapid(l.rtp));
    Ok(s)
}

trait Toward {
    /// `self`, but not beyond `limit` against the drilling direction `dir`.
    fn max_toward(self, limit: f64, dir: f64) -> f64;
}

impl Toward for f64 {
    fn max_toward(self, limit: f64, dir: f64) -> f64 {
        if (self - limit) * dir < 0.0 {
            limit
        } else {
            self
        }
    }
}

/// The pitch of ISO metric coarse threads M3…M48 (ISO 261), mm: the manual gives MPIT as a
/// thread size without a table.
pub fn iso_coarse_pitch(size: f64) -> Option<f64> {
    const TABLE: [(f64, f64); 21] = [
        (3.0, 0.5),
        (3.5, 0.6),
        (4.0, 0.7),
        (5.0, 0.8),
        (6.0, 1.0),
        (8.0, 1.25),
        (10.0, 1.5),
        (12.0, 1.75),
        (14.0, 2.0),
        (16.0, 2.0),
        (18.0, 2.5),
        (20.0, 2.5),
        (22.0, 2.5),
        (24.0, 3.0),
        (27.0, 3.0),
        (30.0, 3.5),
        (33.0, 3.5),
        (36.0, 4.0),
        (39.0, 4.0),
        (42.0, 4.5),
        (48.0, 5.0),
    ];
    TABLE
        .iter()
        .find(|(s, _)| (s - size).abs() < 1e-9)
        .map(|(_, p)| *p)
}

/// The signed pitch from MPIT and PIT (a sign for the hand: + right, − left); 61001 when both
/// are given and differ, or MPIT is no thread size.
pub fn pitch(mpit: Option<f64>, pit: Option<f64>) -> Result<Option<f64>, CycleAlarm> {
    let wrong = |why: &str| alarm(61001, format!("thread pitch wrong: {why}"));
    let from_size = match mpit.filter(|m| *m != 0.0) {
        Some(m) => Some(
            iso_coarse_pitch(m.abs())
                .map(|p| p * m.signum())
                .ok_or_else(|| wrong("MPIT is no thread size M3…M48"))?,
        ),
        None => None,
    };
    let value = pit.filter(|p| *p != 0.0);
    if let Some(p) = value {
        if !(0.001..=2000.0).contains(&p.abs()) {
            return Err(wrong("PIT is 0.001…2000 mm"));
        }
    }
    match (from_size, value) {
        (Some(a), Some(b)) if (a - b).abs() > 1e-9 => Err(wrong("MPIT and PIT differ")),
        (Some(a), _) => Ok(Some(a)),
        (None, b) => Ok(b),
    }
}

/// CYCLE84, rigid tapping (§10.4.6), as the manual describes it (D101): the oriented stop
/// at POSS (SPOS), the tap in at SST with the pitch's hand (G331), the dwell, out to
/// RFP+SDIS at SST1 turning the other way (G332), RTP at rapid, then the speed before the
/// call and SDAC's direction.
#[allow(clippy::too_many_arguments)]
pub fn rigid_tap(
    l: Levels,
    poss: f64,
    pitch: f64,
    dtb: f64,
    sdac: u32,
    sst: f64,
    sst1: f64,
    rpm_before: f64,
) -> Result<Vec<Step>, CycleAlarm> {
    if ![3, 4, 5].contains(&sdac) {
        return Err(alarm(
            61102,
            "SDAC, the spindle after the cycle, is 3, 4 or 5",
        ));
    }
    if sst <= 0.0 {
        return Err(alarm(61102, "SST, the tapping speed, is missing"));
    }
    let sst1 = if sst1 > 0.0 { sst1 } else { sst };
    let mut s = vec![
        Step::Rapid(l.safety),
        Step::Orient(poss),
        Step::Tap(l.bottom, pitch, sst),
    ];
    if dtb > 0.0 {
        s.push(Step::Dwell(dtb));
    }
    s.extend([
        Step::Tap(l.safety, -pitch, sst1),
        Step::Rapid(l.rtp),
        Step::Speed(rpm_before),
        Step::M(sdac),
    ]);
    Ok(s)
}

/// CYCLE840, tapping with a compensating chuck (§10.4.7): in at the feed given (without
/// encoder) or at speed × pitch (with), the dwell, the spindle reversed (SDR 0: the other way
/// of the one turning) and out to RFP+SDIS, G0 to RTP, then SDAC.
pub fn chuck_tap(l: Levels, feed: f64, dtb: f64, reverse: u32, after: Option<u32>) -> Vec<Step> {
    let mut s = vec![Step::Rapid(l.safety), Step::Feed(l.bottom, feed)];
    if dtb > 0.0 {
        s.push(Step::Dwell(dtb));
    }
    s.extend([
        Step::M(reverse),
        Step::Feed(l.safety, feed),
        Step::Rapid(l.rtp),
    ]);
    if let Some(m) = after {
        s.push(Step::M(m));
    }
    s
}

/// CYCLE85 (in at FFR, out at RFF) and CYCLE89 (in and out at the feed before the call):
/// a dwell at the bottom, out to RFP+SDIS at the feed, G0 to RTP.
pub fn bore_out_at_feed(l: Levels, feed_in: f64, dwell: f64, feed_out: f64) -> Vec<Step> {
    let mut s = vec![Step::Rapid(l.safety), Step::Feed(l.bottom, feed_in)];
    if dwell > 0.0 {
        s.push(Step::Dwell(dwell));
    }
    s.extend([Step::Feed(l.safety, feed_out), Step::Rapid(l.rtp)]);
    s
}

/// SDIR, the spindle's direction in boring cycles: 3 or 4, else 61102.
pub fn spindle_dir(sdir: Option<f64>) -> Result<u32, CycleAlarm> {
    match sdir {
        Some(d) if d == 3.0 || d == 4.0 => Ok(d as u32),
        _ => Err(alarm(
            61102,
            "no spindle direction programmed: SDIR is 3 or 4",
        )),
    }
}

/// CYCLE86, boring with an oriented stop (§10.4.9): in at the feed, dwell, the oriented stop
/// at POSS, the lift-off by RPA/RPO/RPAP at rapid, out to RFP+SDIS and RTP, back over the
/// hole, the spindle on again in SDIR.
pub fn bore_oriented(
    l: Levels,
    poss: f64,
    feed: f64,
    dtb: f64,
    sdir: u32,
    lift: (f64, f64, f64),
) -> Vec<Step> {
    let mut s = vec![
        Step::M(sdir),
        Step::Rapid(l.safety),
        Step::Feed(l.bottom, feed),
    ];
    if dtb > 0.0 {
        s.push(Step::Dwell(dtb));
    }
    s.extend([
        Step::Orient(poss),
        Step::Lift(lift.0, lift.1, lift.2),
        Step::Rapid(l.safety),
        Step::Rapid(l.rtp),
        Step::OverHole,
        Step::M(sdir),
    ]);
    s
}

/// CYCLE87 and CYCLE88, boring with a stop (§10.4.10–§10.4.11): the spindle in SDIR, in at
/// the feed, a dwell (88), M5 and M0; after NC START out at rapid to RTP.
pub fn bore_with_stop(l: Levels, feed: f64, dtb: f64, sdir: u32) -> Vec<Step> {
    let mut s = vec![
        Step::M(sdir),
        Step::Rapid(l.safety),
        Step::Feed(l.bottom, feed),
    ];
    if dtb > 0.0 {
        s.push(Step::Dwell(dtb));
    }
    s.extend([Step::M(5), Step::M(0), Step::Rapid(l.rtp)]);
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_follow_the_manual_rules() {
        let l = Levels::new(110.0, 100.0, 2.0, Some(35.0), None).unwrap();
        assert_eq!((l.safety, l.bottom, l.dir), (102.0, 35.0, -1.0));
        // DPR wins over DP.
        let l = Levels::new(110.0, 100.0, 2.0, Some(35.0), Some(65.0)).unwrap();
        assert_eq!(l.bottom, 35.0);
        let l = Levels::new(110.0, 100.0, 2.0, Some(50.0), Some(20.0)).unwrap();
        assert_eq!(l.bottom, 80.0);
        // Drilling upwards (RTP below RFP).
        let l = Levels::new(-10.0, 0.0, 1.0, None, Some(5.0)).unwrap();
        assert_eq!((l.safety, l.bottom), (-1.0, 5.0));
        assert_eq!(
            Levels::new(100.0, 100.0, 2.0, None, Some(5.0))
                .unwrap_err()
                .number,
            61101
        );
        // RTP on the drilling side of RFP.
        assert_eq!(
            Levels::new(90.0, 100.0, 2.0, Some(50.0), None)
                .unwrap_err()
                .number,
            61101
        );
    }

    #[test]
    fn deep_hole_infeeds_degress_and_split_the_last_two() {
        // 95 mm from RFP: first 50, then 30, 20 ... remaining split equally.
        let f = infeeds(50.0, 145.0, 20.0);
        assert_eq!(f[..2], [50.0, 30.0]);
        assert!((f.iter().sum::<f64>() - 145.0).abs() < 1e-9);
        let n = f.len();
        assert_eq!(f[n - 1], f[n - 2]);
        assert!(f[n - 1] > 10.0, "{f:?}");
        assert!(f.windows(2).take(n - 3).all(|w| w[1] <= w[0]));
        assert_eq!(infeeds(200.0, 45.0, 10.0), [45.0]);
        assert_eq!(anticipation(30.0), 0.6);
        assert_eq!(anticipation(100.0), 2.0);
        assert_eq!(anticipation(1000.0), 7.0);
    }

    #[test]
    fn pitches_from_size_or_value() {
        assert_eq!(pitch(Some(5.0), None).unwrap(), Some(0.8));
        assert_eq!(pitch(Some(-10.0), None).unwrap(), Some(-1.5));
        assert_eq!(pitch(None, Some(3.5)).unwrap(), Some(3.5));
        assert_eq!(pitch(Some(5.0), Some(0.8)).unwrap(), Some(0.8));
        assert_eq!(pitch(Some(5.0), Some(1.0)).unwrap_err().number, 61001);
        assert_eq!(pitch(Some(7.0), None).unwrap_err().number, 61001);
    }
}
