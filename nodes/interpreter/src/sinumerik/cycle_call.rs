//! Calling the 802D's cycles (`001` §10.1–§10.2, §10.4–§10.5; inventory §4): a cycle's
//! parameters by position with omitted ones (`,,` or a list cut short) left out, too many
//! → 12340; `MCALL` makes a drilling cycle modal, run after every later block that moves,
//! until `MCALL` alone cancels it; HOLES1 and HOLES2 run the modal cycle at each position of
//! their row or circle. The drilling axis is the one normal to the plane; levels and
//! positions are in the work coordinates of the active frame. The milling cycles are not
//! built yet (12140).

use cnc_interpreter_core::{Command, Fault, MoveKind, ProgramError, SpindleDir, Turn};

use super::cutter_path::MAX_MOVES;
use super::drilling::{self, CycleAlarm, DeepHole, Levels, Step};
use super::expr::Expr;
use super::Sinumerik;

/// The cycles built, each with its parameters in the manual's order.
const CYCLES: [(&str, &[&str]); 22] = [
    ("CYCLE81", &["RTP", "RFP", "SDIS", "DP", "DPR"]),
    ("CYCLE82", &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB"]),
    (
        "CYCLE83",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "FDEP", "FDPR", "DAM", "DTB", "DTS", "FRF", "VARI",
        ],
    ),
    (
        "CYCLE84",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDAC", "MPIT", "PIT", "POSS", "SST", "SST1",
        ],
    ),
    (
        "CYCLE840",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDR", "SDAC", "ENC", "MPIT", "PIT", "AXN",
        ],
    ),
    (
        "CYCLE85",
        &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "FFR", "RFF"],
    ),
    (
        "CYCLE86",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDIR", "RPA", "RPO", "RPAP", "POSS",
        ],
    ),
    ("CYCLE87", &["RTP", "RFP", "SDIS", "DP", "DPR", "SDIR"]),
    (
        "CYCLE88",
        &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDIR"],
    ),
    ("CYCLE89", &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB"]),
    (
        "CYCLE90",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DIATH", "KDIAM", "PIT", "FFR", "CDIR", "TYPTH",
            "CPA", "CPO",
        ],
    ),
    (
        "LONGHOLE",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "NUM", "LENG", "CPA", "CPO", "RAD", "STA1", "INDA",
            "FFD", "FFP1", "MID",
        ],
    ),
    (
        "SLOT1",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "NUM", "LENG", "WID", "CPA", "CPO", "RAD", "STA1",
            "INDA", "FFD", "FFP1", "MID", "CDIR", "FAL", "VARI", "MIDF", "FFP2", "SSF",
        ],
    ),
    (
        "SLOT2",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "NUM", "AFSL", "WID", "CPA", "CPO", "RAD", "STA1",
            "INDA", "FFD", "FFP1", "MID", "CDIR", "FAL", "VARI", "MIDF", "FFP2", "SSF",
        ],
    ),
    (
        "CYCLE72",
        &[
            "KNAME", "RTP", "RFP", "SDIS", "DP", "MID", "FAL", "FALD", "FFP1", "FFD", "VARI", "RL",
            "AS1", "LP1", "FF3", "AS2", "LP2",
        ],
    ),
    (
        "CYCLE71",
        &[
            "RTP", "RFP", "SDIS", "DP", "PA", "PO", "LENG", "WID", "STA", "MID", "MIDA", "FDP",
            "FALD", "FFP1", "VARI", "FDP1",
        ],
    ),
    (
        "CYCLE76",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "LENG", "WID", "CRAD", "PA", "PO", "STA", "MID",
            "FAL", "FALD", "FFP1", "FFD", "CDIR", "VARI", "AP1", "AP2",
        ],
    ),
    (
        "CYCLE77",
        &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "PRAD", "PA", "PO", "MID", "FAL", "FALD", "FFP1",
            "FFD", "CDIR", "VARI", "AP1",
        ],
    ),
    (
        "POCKET3",
        &[
            "RTP", "RFP", "SDIS", "DP", "LENG", "WID", "CRAD", "PA", "PO", "STA", "MID", "FAL",
            "FALD", "FFP1", "FFD", "CDIR", "VARI", "MIDA", "AP1", "AP2", "AD", "RAD1", "DP1",
        ],
    ),
    (
        "POCKET4",
        &[
            "RTP", "RFP", "SDIS", "DP", "PRAD", "PA", "PO", "MID", "FAL", "FALD", "FFP1", "FFD",
            "CDIR", "VARI", "MIDA", "AP1", "AD", "RAD1", "DP1",
        ],
    ),
    ("HOLES1", &["SPCA", "SPCO", "STA1", "FDIS", "DBH", "NUM"]),
    ("HOLES2", &["CPA", "CPO", "RAD", "STA1", "INDA", "NUM"]),
];

/// Parameters that are lengths (converted under G70/G700).
const LENGTHS: [&str; 39] = [
    "RTP", "RFP", "SDIS", "DP", "DPR", "FDEP", "FDPR", "DAM", "PIT", "RPA", "RPO", "RPAP", "SPCA",
    "SPCO", "FDIS", "DBH", "RAD", "DIATH", "KDIAM", "CPA", "CPO", "PRAD", "PA", "PO", "MID", "FAL",
    "FALD", "MIDA", "AP1", "AD", "RAD1", "DP1", "LENG", "WID", "CRAD", "AP2", "FDP", "FDP1",
    "MIDF",
];

/// The names of every cycle of chapter 10.
pub fn is_cycle(name: &str) -> bool {
    name.starts_with("CYCLE")
        || [
            "HOLES1", "HOLES2", "LONGHOLE", "SLOT1", "SLOT2", "POCKET3", "POCKET4",
        ]
        .contains(&name)
}

/// A cycle call with its parameters evaluated (None: omitted).
#[derive(Debug, Clone, PartialEq)]
pub struct CycleCall {
    pub name: &'static str,
    params: &'static [&'static str],
    values: Vec<Option<f64>>,
    /// A text parameter (CYCLE72's KNAME).
    pub text: Option<String>,
}

impl CycleCall {
    pub(super) fn get(&self, p: &str) -> Option<f64> {
        let i = self.params.iter().position(|n| *n == p)?;
        self.values.get(i).copied().flatten()
    }
    pub(super) fn or(&self, p: &str, default: f64) -> f64 {
        self.get(p).unwrap_or(default)
    }
    fn is_drilling(&self) -> bool {
        self.name.starts_with("CYCLE8")
    }
}

/// Cycles that run at the positions of a pattern.
fn pattern(name: &str) -> bool {
    name.starts_with("HOLES")
}

impl Sinumerik {
    pub(super) fn cycle_alarm(&self, a: CycleAlarm, name: &str) -> ProgramError {
        let mut e = self.fault(Fault::NotSupported, format!("{name}: {}", a.text));
        e.number = a.number;
        e
    }

    /// Evaluates a cycle call's parameters: 12340 when there are more than the cycle has.
    pub(super) fn cycle_call(
        &self,
        name: &str,
        args: &[Option<Expr>],
    ) -> Result<CycleCall, ProgramError> {
        let Some(&(name, params)) = CYCLES.iter().find(|(n, _)| *n == name) else {
            return Err(self.fault(
                Fault::NoSuchAddress,
                format!("{name}(…) is no cycle of chapter 10"),
            ));
        };
        if args.len() > params.len() {
            let mut e = self.fault(
                Fault::MacroArgument,
                format!(
                    "{name}: {} parameters, the cycle has {}",
                    args.len(),
                    params.len()
                ),
            );
            e.number = 12340;
            return Err(e);
        }
        let unit = if self.inch { 25.4 } else { 1.0 };
        let mut values = Vec::with_capacity(args.len());
        let mut text = None;
        for (a, p) in args.iter().zip(params) {
            if *p == "KNAME" {
                // The contour's name or label section, a string.
                text = match a {
                    Some(e) => Some(self.value(e)?.text()),
                    None => None,
                };
                values.push(None);
                continue;
            }
            let v = match a {
                Some(e) => Some(self.number(e)?),
                None => None,
            };
            values.push(v.map(|v| if LENGTHS.contains(p) { v * unit } else { v }));
        }
        Ok(CycleCall {
            name,
            params,
            values,
            text,
        })
    }

    /// Runs a cycle called in its own block, or refuses a pattern without a modal cycle.
    pub(super) fn run_cycle(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        if pattern(c.name) {
            return self.run_pattern(c);
        }
        match c.name {
            "CYCLE90" => return self.mill_thread(c),
            "POCKET3" => return self.rectangular_pocket(c),
            "CYCLE76" | "CYCLE77" => return self.spigot(c),
            "CYCLE71" => return self.face(c),
            "LONGHOLE" | "SLOT1" | "SLOT2" => return self.slots(c),
            "CYCLE72" => {
                let kname = c.text.clone().unwrap_or_default();
                return self.contour_milling(c, &kname);
            }
            "POCKET4" => return self.circular_pocket(c),
            _ => {}
        }
        self.drill_hole(c)
    }

    /// MCALL with a cycle: it becomes modal (only drilling cycles); MCALL alone cancels.
    pub(super) fn set_modal_cycle(&mut self, c: Option<CycleCall>) -> Result<(), ProgramError> {
        if let Some(c) = &c {
            if !c.is_drilling() {
                return Err(self.fault(
                    Fault::Call,
                    format!("MCALL {}: only a drilling cycle is called modally", c.name),
                ));
            }
        }
        self.modal_cycle = c;
        Ok(())
    }

    /// After a block that moved: the modal cycle at the new position.
    pub(super) fn run_modal_cycle(&mut self) -> Result<(), ProgramError> {
        match self.modal_cycle.clone() {
            Some(c) => self.drill_hole(&c),
            None => Ok(()),
        }
    }

    /// 12140 when a call would make more than [`MAX_MOVES`] moves.
    fn within_budget(&self, moves: usize, name: &str) -> Result<(), ProgramError> {
        if moves > MAX_MOVES {
            return Err(self.cycle_alarm(
                CycleAlarm {
                    number: 12140,
                    text: format!("the call would make more than {MAX_MOVES} moves"),
                },
                name,
            ));
        }
        Ok(())
    }

    /// The drilling axis: the plane's normal.
    fn drill_axis(&self) -> Result<usize, ProgramError> {
        self.core.plane_normal().ok_or_else(|| {
            self.fault(
                Fault::PlaneAxis,
                "the drilling axis (the plane's normal) is not on this machine",
            )
        })
    }

    /// One hole at the position the program is at.
    fn drill_hole(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let name = c.name;
        let d = self.drill_axis()?;
        let steps = self.drill_steps(c).map_err(|a| self.cycle_alarm(a, name))?;
        self.within_budget(steps.len(), name)?;
        let hole = self.core.work_position();
        for s in steps {
            self.do_step(d, &hole, s)?;
        }
        Ok(())
    }

    fn drill_steps(&self, c: &CycleCall) -> Result<Vec<Step>, CycleAlarm> {
        let levels = Levels::new(
            c.or("RTP", 0.0),
            c.or("RFP", 0.0),
            c.or("SDIS", 0.0),
            c.get("DP"),
            c.get("DPR"),
        )?;
        let feed = self.core.feed;
        let dtb = c.or("DTB", 0.0);
        // POSS is an angle: taken modulo 360° (D100).
        let poss = c.or("POSS", 0.0).rem_euclid(360.0);
        let poss = if poss < 360.0 { poss } else { 0.0 };
        let int = |p: &str| c.get(p).map(|v| v.round());
        Ok(match c.name {
            "CYCLE81" => drilling::drill(levels, feed, 0.0),
            "CYCLE82" => drilling::drill(levels, feed, dtb),
            "CYCLE83" => drilling::deep_hole(
                levels,
                feed,
                DeepHole {
                    fdep: c.get("FDEP"),
                    fdpr: c.get("FDPR"),
                    dam: c.or("DAM", 0.0).abs(),
                    dtb,
                    dts: c.or("DTS", 0.0),
                    frf: c.or("FRF", 1.0).abs(),
                    vari: int("VARI").unwrap_or(0.0).max(0.0) as u32,
                },
            )?,
            "CYCLE84" => {
                let pitch = drilling::pitch(c.get("MPIT"), c.get("PIT"))?.ok_or(CycleAlarm {
                    number: 61001,
                    text: "thread pitch wrong: MPIT or PIT is needed".into(),
                })?;
                drilling::rigid_tap(
                    levels,
                    poss,
                    pitch,
                    dtb,
                    int("SDAC").unwrap_or(0.0).max(0.0) as u32,
                    c.or("SST", 0.0),
                    c.or("SST1", 0.0),
                    self.core.rpm,
                )?
            }
            "CYCLE840" => self.chuck_tap_steps(c, levels, dtb)?,
            "CYCLE85" => {
                drilling::bore_out_at_feed(levels, c.or("FFR", 0.0), dtb, c.or("RFF", 0.0))
            }
            "CYCLE86" => drilling::bore_oriented(
                levels,
                poss,
                feed,
                dtb,
                drilling::spindle_dir(int("SDIR"))?,
                (c.or("RPA", 0.0), c.or("RPO", 0.0), c.or("RPAP", 0.0)),
            ),
            "CYCLE87" => {
                drilling::bore_with_stop(levels, feed, 0.0, drilling::spindle_dir(int("SDIR"))?)
            }
            "CYCLE88" => {
                drilling::bore_with_stop(levels, feed, dtb, drilling::spindle_dir(int("SDIR"))?)
            }
            _ => drilling::bore_out_at_feed(levels, feed, dtb, feed),
        })
    }

    /// CYCLE840: with an encoder (ENC 0) the feed is speed × pitch; without (ENC 1) it is
    /// the feed programmed before. SDR 0 reverses the spindle turning now.
    fn chuck_tap_steps(
        &self,
        c: &CycleCall,
        levels: Levels,
        dtb: f64,
    ) -> Result<Vec<Step>, CycleAlarm> {
        let alarm = |number: u32, text: &str| CycleAlarm {
            number,
            text: text.into(),
        };
        let axn = c.or("AXN", 0.0).round();
        if axn != 0.0 && axn != 3.0 {
            return Err(alarm(
                61102,
                "AXN 1 or 2 (tapping along a plane axis) is not built: the tool axis is the plane's normal",
            ));
        }
        let reverse = match c.or("SDR", 0.0).round() as i64 {
            0 => match self.core.spindle() {
                SpindleDir::Cw => 4,
                SpindleDir::Ccw => 3,
                SpindleDir::Stopped => {
                    return Err(alarm(
                        61102,
                        "no spindle direction programmed: M3 or M4 before the call",
                    ))
                }
            },
            d @ (3 | 4) => d as u32,
            _ => return Err(alarm(61102, "SDR is 0, 3 or 4")),
        };
        let after = match c.get("SDAC").map(|v| v.round() as i64) {
            None => None,
            Some(m @ (3..=5)) => Some(m as u32),
            Some(_) => return Err(alarm(61102, "SDAC is 3, 4 or 5")),
        };
        let with_encoder = c.or("ENC", 0.0).round() == 0.0;
        let feed = if with_encoder {
            match drilling::pitch(c.get("MPIT"), c.get("PIT"))? {
                Some(p) => self.core.rpm * p.abs(),
                None => self.core.feed,
            }
        } else {
            self.core.feed
        };
        Ok(drilling::chuck_tap(levels, feed, dtb, reverse, after))
    }

    fn do_step(&mut self, d: usize, hole: &[f64], s: Step) -> Result<(), ProgramError> {
        let along = |me: &Self, level: f64| {
            let mut end = me.core.work_position();
            end[d] = level;
            end
        };
        // A level the tool is already at is no move (RTP on RFP+SDIS, a hole begun there).
        let here = self.core.work_position()[d];
        match s {
            Step::Rapid(level) | Step::Feed(level, _) if (level - here).abs() < 1e-9 => Ok(()),
            Step::Rapid(level) => {
                let end = along(self, level);
                self.core.emit(&end, MoveKind::Rapid)
            }
            Step::Feed(level, feed) => {
                let end = along(self, level);
                self.core.emit(&end, MoveKind::Feed(feed))
            }
            Step::Dwell(seconds) => {
                self.core.push(Command::Dwell { seconds });
                Ok(())
            }
            Step::M(m) => {
                if matches!(m, 3..=5) {
                    self.positioned = false;
                }
                self.core.spindle_code(m as i32);
                Ok(())
            }
            Step::Tap(level, lead, rpm) => {
                let end = along(self, level);
                self.core.emit(&end, MoveKind::Tap { lead, rpm })
            }
            Step::Orient(degrees) => {
                self.positioned = true;
                self.core.orient_spindle(degrees, Turn::Shortest);
                Ok(())
            }
            Step::Speed(rpm) => {
                self.core.set_rpm(rpm);
                Ok(())
            }
            Step::Lift(a, b, c) => {
                let (h, v) = self.core.plane_axes()?;
                let mut end = self.core.work_position();
                end[h] += a;
                end[v] += b;
                end[d] += c;
                self.core.emit(&end, MoveKind::Rapid)
            }
            Step::OverHole => {
                let (h, v) = self.core.plane_axes()?;
                let mut end = self.core.work_position();
                end[h] = hole[h];
                end[v] = hole[v];
                self.core.emit(&end, MoveKind::Rapid)
            }
        }
    }

    /// HOLES1/HOLES2: each position at rapid in the plane, the modal cycle there.
    fn run_pattern(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let points = match c.name {
            "HOLES1" => row(c),
            _ => circle(c),
        }
        .map_err(|a| self.cycle_alarm(a, c.name))?;
        let Some(modal) = self.modal_cycle.clone() else {
            let mut e = self.fault(
                Fault::Call,
                format!(
                    "{}: no drilling cycle active (MCALL a drilling cycle first)",
                    c.name
                ),
            );
            e.number = 62100;
            return Err(e);
        };
        let per_hole = self
            .drill_steps(&modal)
            .map_err(|a| self.cycle_alarm(a, modal.name))?
            .len();
        self.within_budget(per_hole.saturating_mul(points.len()), c.name)?;
        let (h, v) = self.core.plane_axes()?;
        let here = self.core.work_position();
        // The row starts at the end nearer to where the tool is (§10.5.2).
        let near_last = points.len() > 1 && c.name == "HOLES1" && {
            let dist = |p: (f64, f64)| (p.0 - here[h]).hypot(p.1 - here[v]);
            dist(points[points.len() - 1]) < dist(points[0])
        };
        let ordered: Vec<(f64, f64)> = if near_last {
            points.into_iter().rev().collect()
        } else {
            points
        };
        for (x, y) in ordered {
            let mut end = self.core.work_position();
            end[h] = x;
            end[v] = y;
            self.core.emit(&end, MoveKind::Rapid)?;
            self.drill_hole(&modal)?;
        }
        Ok(())
    }
}

fn count(c: &CycleCall) -> Result<usize, CycleAlarm> {
    let n = c.or("NUM", 0.0).round();
    if n < 1.0 {
        return Err(CycleAlarm {
            number: 61103,
            text: "number of holes is zero".into(),
        });
    }
    if n > 9_999.0 {
        return Err(CycleAlarm {
            number: 61106,
            text: "more than 9999 holes".into(),
        });
    }
    Ok(n as usize)
}

/// HOLES1's positions (§10.5.2): from the reference point SPCA/SPCO along the angle STA1,
/// the first FDIS away, then every DBH.
pub fn row(c: &CycleCall) -> Result<Vec<(f64, f64)>, CycleAlarm> {
    let n = count(c)?;
    let (s, co) = c.or("STA1", 0.0).to_radians().sin_cos();
    let (fdis, dbh) = (c.or("FDIS", 0.0).abs(), c.or("DBH", 0.0).abs());
    let (x0, y0) = (c.or("SPCA", 0.0), c.or("SPCO", 0.0));
    Ok((0..n)
        .map(|i| {
            let l = fdis + i as f64 * dbh;
            (x0 + l * co, y0 + l * s)
        })
        .collect())
}

/// HOLES2's positions (§10.5.3): on the circle about CPA/CPO of radius RAD, from STA1 every
/// INDA degrees (0: spread over the full circle). 61106 when they would overlap.
pub fn circle(c: &CycleCall) -> Result<Vec<(f64, f64)>, CycleAlarm> {
    let n = count(c)?;
    let rad = c.or("RAD", 0.0);
    let wrong = |t: &str| CycleAlarm {
        number: 61106,
        text: format!("number or spacing of circular elements: {t}"),
    };
    if rad <= 0.0 {
        return Err(wrong("RAD must be positive"));
    }
    let inda = match c.or("INDA", 0.0) {
        0.0 => 360.0 / n as f64,
        a => a,
    };
    if inda.abs() * (n as f64 - 1.0) >= 360.0 + 1e-9 {
        return Err(wrong("the holes overrun the full circle"));
    }
    let (x0, y0, sta) = (c.or("CPA", 0.0), c.or("CPO", 0.0), c.or("STA1", 0.0));
    Ok((0..n)
        .map(|i| {
            let (s, co) = (sta + i as f64 * inda).to_radians().sin_cos();
            (x0 + rad * co, y0 + rad * s)
        })
        .collect())
}
