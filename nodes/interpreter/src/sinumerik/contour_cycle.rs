//! CYCLE72, contour milling (`001` §10.6.3; inventory §4.5). The contour is a subprogram
//! (KNAME a name) or a section of the calling program (`"START:END"` labels): its blocks run
//! through a front end of their own, on a machine with no offsets, to give the contour's
//! start point and elements in the plane. At each level the cutter comes down beside the
//! start, the core's radius compensation (G41/G42 by RL, the radius plus FAL when roughing)
//! takes it on a perpendicular line onto the approach (a tangential line, quarter or half
//! circle of LP1), along the contour, off on the departure (AS2/LP2) and back off
//! perpendicularly; then it retracts as VARI's hundreds say. A spatial approach or
//! departure (AS1/AS2 tens 1) takes the last SDIS of the infeed, or the first of the
//! retraction, along the approach or departure path itself. Decision D92.

use std::sync::Arc;

use cnc_interpreter_core::comp::{Side, Startup};
use cnc_interpreter_core::geometry::Pt;
use cnc_interpreter_core::{next_command, Command, Fault, Library, MoveKind, ProgramError, Setup};

use super::cycle_call::CycleCall;
use super::drilling::CycleAlarm;
use super::pocket::levels;
use super::vars::{R_BASE, R_COUNT};
use super::Sinumerik;

/// A contour element in the plane: a line, or an arc about `c`.
#[derive(Debug, Clone, Copy)]
enum Piece {
    Line(Pt),
    Arc { end: Pt, c: Pt, ccw: bool },
}

impl Piece {
    fn end(&self) -> Pt {
        match *self {
            Piece::Line(e) | Piece::Arc { end: e, .. } => e,
        }
    }
    /// The direction of travel at the piece's start (`from`) or end.
    fn tangent(&self, from: Pt, at_end: bool) -> (f64, f64) {
        let unit = |x: f64, y: f64| {
            let l = x.hypot(y).max(1e-12);
            (x / l, y / l)
        };
        match *self {
            Piece::Line(e) => unit(e.z - from.z, e.r - from.r),
            Piece::Arc { end, c, ccw } => {
                let p = if at_end { end } else { from };
                let (dx, dy) = (p.z - c.z, p.r - c.r);
                if ccw {
                    unit(-dy, dx)
                } else {
                    unit(dy, -dx)
                }
            }
        }
    }
}

fn wrong(number: u32, text: impl Into<String>) -> CycleAlarm {
    CycleAlarm::new(number, text)
}

/// The left normal of a direction.
fn left((x, y): (f64, f64)) -> (f64, f64) {
    (-y, x)
}

fn add(p: Pt, (x, y): (f64, f64), k: f64) -> Pt {
    Pt::new(p.z + k * x, p.r + k * y)
}

impl Sinumerik {
    /// The contour KNAME names: its start point and its elements, in the plane.
    fn contour(&self, kname: &str) -> Result<(Pt, Vec<Piece>), ProgramError> {
        let text: Arc<str> = match kname.split_once(':') {
            Some((start, end)) => {
                let program = self.program_text.clone().unwrap_or_else(|| Arc::from(""));
                section(&program, start.trim(), end.trim()).ok_or_else(|| {
                    self.fault(
                        Fault::TargetNotFound,
                        format!(
                            "CYCLE72: the labels {start}: and {end}: are not both in this program"
                        ),
                    )
                })?
            }
            None => self
                .core
                .library
                .get_named(kname.trim())
                .map(|(_, t)| t)
                .ok_or_else(|| {
                    self.fault(
                        Fault::ProgramNotFound,
                        format!("CYCLE72: the contour program {kname} does not exist"),
                    )
                })?,
        };
        // On a machine of the same axes with no offsets and no tool, in this plane, with the
        // R parameters as they stand.
        let axes = self.core.setup.axes.clone();
        let n = axes.len();
        let mut setup = Setup::new(&axes, &vec![false; n], &self.core.work_position());
        for k in 0..R_COUNT {
            if let Some(v) = self.core.common.get(&(R_BASE + k)) {
                setup.kept.insert(R_BASE + k, *v);
            }
        }
        // Called as a subprogram (its M17, RET or M2 returns), with a feed of its own: only
        // the geometry is taken.
        let mut library = Library::new();
        library.insert_named("CONTOUR_OF_72", "CONTOUR_OF_72.SPF", &text);
        let body = format!("G{} F1000\nCONTOUR_OF_72\nM30\n", self.plane_code);
        let mut front = Sinumerik::new(&body, setup, library);
        let (h, v) = self.core.plane_axes()?;
        let mut moves = Vec::new();
        loop {
            match next_command(&mut front) {
                Ok(Some(c)) => {
                    let piece = match &c.command {
                        Command::Rapid { end } | Command::Linear { end, .. } => {
                            Piece::Line(Pt::new(end[h], end[v]))
                        }
                        Command::Arc {
                            end,
                            center,
                            clockwise,
                            ..
                        } => Piece::Arc {
                            end: Pt::new(end[h], end[v]),
                            c: Pt::new(center[h], center[v]),
                            ccw: !clockwise,
                        },
                        _ => continue,
                    };
                    moves.push(piece);
                    if moves.len() > super::cutter_path::MAX_MOVES {
                        return Err(
                            self.fault(Fault::NotSupported, "CYCLE72: the contour is too long")
                        );
                    }
                }
                Ok(None) => break,
                Err(e) => {
                    let mut err = self.fault(
                        Fault::DataFormat,
                        format!("CYCLE72: in the contour, line {}: {}", e.line, e.text),
                    );
                    err.number = e.number;
                    return Err(err);
                }
            }
        }
        let mut pieces = moves.into_iter();
        let start = pieces.next().map(|p| p.end()).ok_or_else(|| {
            self.fault(
                Fault::DataFormat,
                "CYCLE72: the contour needs its start point and at least one element",
            )
        })?;
        let rest: Vec<Piece> = pieces.collect();
        if rest.is_empty() {
            return Err(self.fault(
                Fault::DataFormat,
                "CYCLE72: the contour needs its start point and at least one element",
            ));
        }
        Ok((start, rest))
    }

    /// CYCLE72 with the active cutting edge.
    pub(super) fn contour_milling(
        &mut self,
        c: &CycleCall,
        kname: &str,
    ) -> Result<(), ProgramError> {
        let alarm = |me: &Self, a: CycleAlarm| me.cycle_alarm(a, c.name);
        let vari = c.or("VARI", 0.0).round() as i64;
        let (units, tens, hundreds) = (vari % 10, vari / 10 % 10, vari / 100);
        if !(1..=2).contains(&units) || tens > 1 || hundreds > 3 {
            return Err(alarm(
                self,
                wrong(61002, "VARI: units 1/2, tens 0/1, hundreds 0–3"),
            ));
        }
        let rl = c.or("RL", 40.0).round() as i64;
        let side = match rl {
            40 => None,
            41 => Some(Side::Left),
            42 => Some(Side::Right),
            _ => return Err(alarm(self, wrong(61114, "RL is 40, 41 or 42"))),
        };
        let as1 = c.or("AS1", 1.0).round() as i64;
        let as2 = c.get("AS2").map_or(as1, |v| v.round() as i64);
        let (lp1, lp2) = (c.or("LP1", 0.0), c.get("LP2").unwrap_or(c.or("LP1", 0.0)));
        for a in [as1, as2] {
            if !(1..=3).contains(&(a % 10)) || a / 10 > 1 || (side.is_none() && a % 10 != 1) {
                return Err(alarm(
                    self,
                    wrong(
                        61115,
                        "approach/retract mode wrong (G40: straight lines only)",
                    ),
                ));
            }
        }
        let (spatial_in, spatial_out) = (as1 / 10 == 1, as2 / 10 == 1);
        if lp1 <= 0.0 || lp2 <= 0.0 {
            return Err(alarm(self, wrong(61116, "approach/retract path = 0")));
        }
        let wr = match self.offset_entry() {
            None => return Err(alarm(self, wrong(61000, "no tool offset active (D)"))),
            Some(e) if e.radius < 0.0 => {
                return Err(alarm(self, wrong(61112, "tool radius negative")))
            }
            Some(e) => e.radius,
        };
        let (rtp, rfp, dp) = (c.or("RTP", 0.0), c.or("RFP", 0.0), c.or("DP", 0.0));
        let down = super::cutter_path::infeed(rtp, rfp, dp).map_err(|a| alarm(self, a))?;
        let (fal, fald) = (c.or("FAL", 0.0).abs(), c.or("FALD", 0.0).abs());
        let (ffp1, ffd) = (c.or("FFP1", 0.0), c.or("FFD", 0.0));
        super::cutter_path::feeds(&[ffp1, ffd], "FFP1 and FFD").map_err(|a| alarm(self, a))?;
        if units == 1 && fald > (dp - rfp).abs() {
            return Err(alarm(
                self,
                wrong(61010, "finishing allowance FALD larger than the depth"),
            ));
        }
        let ff3 = c.get("FF3").filter(|f| *f > 0.0).unwrap_or(ffp1);
        let sdis = c.or("SDIS", 0.0).abs();
        let (p0, pieces) = self.contour(kname)?;
        // The approach and departure in the plane, on the cutter's side.
        let normal = |t: (f64, f64)| match side {
            Some(Side::Right) => (-left(t).0, -left(t).1),
            _ => left(t),
        };
        let ccw = side == Some(Side::Left);
        let t0 = pieces[0].tangent(p0, false);
        let n0 = normal(t0);
        let (s, approach) = match as1 % 10 {
            1 => (add(p0, t0, -lp1), Piece::Line(p0)),
            2 => {
                let m = add(p0, n0, lp1);
                (add(m, t0, -lp1), Piece::Arc { end: p0, c: m, ccw })
            }
            _ => (
                add(p0, n0, 2.0 * lp1),
                Piece::Arc {
                    end: p0,
                    c: add(p0, n0, lp1),
                    ccw,
                },
            ),
        };
        let last_from = if pieces.len() > 1 {
            pieces[pieces.len() - 2].end()
        } else {
            p0
        };
        let pn = pieces[pieces.len() - 1].end();
        let tn = pieces[pieces.len() - 1].tangent(last_from, true);
        let nn = normal(tn);
        let departure = match as2 % 10 {
            1 => Piece::Line(add(pn, tn, lp2)),
            2 => {
                let m = add(pn, nn, lp2);
                Piece::Arc {
                    end: add(m, tn, lp2),
                    c: m,
                    ccw,
                }
            }
            _ => Piece::Arc {
                end: add(pn, nn, 2.0 * lp2),
                c: add(pn, nn, lp2),
                ccw,
            },
        };
        let e = departure.end();
        let de = departure.tangent(pn, true);
        let ds = approach.tangent(s, false);
        let radius = if units == 1 { wr + fal } else { wr };
        // Beside the approach's start (and after the departure's end) on the cutter's side:
        // compensation comes on and goes off on short perpendicular lines.
        let clear = radius + 2.0;
        let a = match side {
            Some(_) => add(s, normal(ds), clear),
            None => s,
        };
        let b = match side {
            Some(_) => add(e, normal(de), clear),
            None => e,
        };
        let floor = if units == 1 { dp - down * fald } else { dp };
        let safety = rfp - down * sdis;
        let (h, v) = self.core.plane_axes()?;
        let d = self.core.plane_normal().ok_or_else(|| {
            self.fault(
                Fault::PlaneAxis,
                "the infeed axis (the plane's normal) is not on this machine",
            )
        })?;
        let at = |me: &Self, p: Pt, z: f64| {
            let mut w = me.core.work_position();
            w[h] = p.z;
            w[v] = p.r;
            w[d] = z;
            w
        };
        let between = |tens: i64| {
            if tens == 1 {
                MoveKind::Feed(ff3)
            } else {
                MoveKind::Rapid
            }
        };
        let steps = levels(rfp, floor, c.or("MID", 0.0).abs()).map_err(|a| alarm(self, a))?;
        // A move that goes somewhere.
        let go = |me: &mut Self, to: Vec<f64>, kind: MoveKind| -> Result<(), ProgramError> {
            let here = me.core.work_position();
            if here.iter().zip(&to).any(|(x, y)| (x - y).abs() > 1e-9) {
                me.core.emit(&to, kind)?;
            }
            Ok(())
        };
        let now = self.core.work_position();
        go(
            self,
            at(self, Pt::new(now[h], now[v]), rtp),
            MoveKind::Rapid,
        )?;
        go(self, at(self, a, rtp), MoveKind::Rapid)?;
        for level in steps {
            let top = self.core.work_position()[d];
            go(self, at(self, a, top), between(tens))?;
            // At rapid only down to RFP+SDIS: beside the contour the blank's extent is not
            // known, so the rest of the infeed is fed (D92).
            if (self.core.work_position()[d] - safety) * down < 0.0 {
                go(self, at(self, a, safety), MoveKind::Rapid)?;
            }
            // A spatial approach (AS1 tens 1) comes down its last SDIS along the approach,
            // a line or a helix, at FFD; a spatial departure rises SDIS along its path at FF3.
            let approach_top = if spatial_in {
                level - down * sdis
            } else {
                level
            };
            let departure_top = if spatial_out {
                level - down * sdis
            } else {
                level
            };
            go(self, at(self, a, approach_top), MoveKind::Feed(ffd))?;
            if let Some(sd) = side {
                self.core
                    .start_comp(sd, radius, 0, Startup::ToNextElement)?;
                self.core
                    .emit(&at(self, s, approach_top), MoveKind::Feed(ffp1))?;
            }
            let path = std::iter::once((approach, level, if spatial_in { ffd } else { ffp1 }))
                .chain(pieces.iter().map(|p| (*p, level, ffp1)))
                .chain(std::iter::once((
                    departure,
                    departure_top,
                    if spatial_out { ff3 } else { ffp1 },
                )));
            for (piece, z, feed) in path {
                let kind = match piece {
                    Piece::Line(_) => MoveKind::Feed(feed),
                    Piece::Arc { c, ccw, .. } => MoveKind::Arc {
                        center: c,
                        ccw,
                        feed,
                    },
                };
                self.core.emit(&at(self, piece.end(), z), kind)?;
            }
            if side.is_some() {
                self.core.comp_cancel = true;
                self.core
                    .emit(&at(self, b, departure_top), MoveKind::Feed(ffp1))?;
            }
            let lift = match hundreds {
                0 => rtp,
                1 => safety,
                2 => level - down * sdis,
                _ => departure_top,
            };
            go(self, at(self, b, lift), between(tens))?;
        }
        let end = self.core.work_position();
        go(
            self,
            at(self, Pt::new(end[h], end[v]), rtp),
            MoveKind::Rapid,
        )?;
        // §10.6.3: after roughing the tool stands above the departure point at RTP; after
        // finishing, at the contour's start point at RTP (issue 46).
        if units == 2 {
            go(self, at(self, p0, rtp), MoveKind::Rapid)?;
        }
        Ok(())
    }
}

/// The lines between `START:` and `END:` of `program` (the labels' own lines left out).
fn section(program: &str, start: &str, end: &str) -> Option<Arc<str>> {
    let label = |line: &str, name: &str| {
        let code = line
            .split(';')
            .next()
            .unwrap_or("")
            .trim()
            .to_ascii_uppercase();
        let code = code
            .trim_start_matches(|c: char| c == 'N' || c.is_ascii_digit())
            .trim();
        code.starts_with(&format!("{}:", name.to_ascii_uppercase()))
    };
    let lines: Vec<&str> = program.lines().collect();
    let i = lines.iter().position(|l| label(l, start))?;
    let j = lines.iter().skip(i + 1).position(|l| label(l, end))? + i + 1;
    // The start label's line may carry a block after the colon.
    let first = lines[i].split_once(':').map_or("", |(_, b)| b);
    let mut text = String::from(first);
    text.push('\n');
    for l in &lines[i + 1..j] {
        text.push_str(l);
        text.push('\n');
    }
    Some(Arc::from(text))
}
