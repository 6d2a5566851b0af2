//! The GTC2E's own cycles, loops and returns (`002` §4.3.2).
//!
//! A GTC2E cycle block defines a shape relative to the start point and runs it once; a
//! following block with only X/U or Z/W moves the start point and runs the same shape again
//! (`002` §4.3.2-5..10, inventory §12). The move to the new start point goes at rapid for G77,
//! G76 and G74, whose first move is a rapid or an infeed, and at the cycle's feed for G24,
//! G75 and G83, where the manual gives feed (decision D24).

use cnc_interpreter_core::{show, Command, Fault, MoveKind, ProgramError, Repeat, SpindleDir};

use super::{Gtc2e, GtcCycle, GtcG, ReturnOrder};
use crate::fanuc::block::{whole, Block};
use crate::fanuc::Fanuc;

/// GTC2E E word: threads per inch, where `.2` means ½ (`E10.2` = 10½; `002` §4.3.2-4).
fn tpi(e: f64) -> Option<f64> {
    let whole = e.trunc();
    let frac = ((e - whole) * 10.0).round();
    if !(2.0..=99.0).contains(&whole) || (e - whole - frac / 10.0).abs() > 1e-6 {
        return None;
    }
    match frac as i64 {
        0 => Some(whole),
        2 => Some(whole + 0.5),
        _ => None,
    }
}

impl Fanuc<Gtc2e> {
    /// K (metric lead, 0.25–24 mm) or E (threads per inch, 2–99½).
    pub(super) fn gtc_lead(&self, b: &Block<Gtc2e>) -> Result<f64, ProgramError> {
        match (b.get('K'), b.get('E')) {
            (Some(_), Some(_)) => Err(self.fault(Fault::RepeatedWord, "K and E in one block")),
            (Some(k), None) if (0.25..=24.0).contains(&k) => Ok(k),
            (Some(k), None) => {
                Err(self.fault(Fault::OutOfRange, format!("K{}: lead 0.25–24 mm", show(k))))
            }
            (None, Some(e)) => tpi(e).map(|t| 25.4 / t).ok_or_else(|| {
                self.fault(
                    Fault::OutOfRange,
                    format!("E{}: 2–99.2 threads per inch", show(e)),
                )
            }),
            (None, None) => Err(self.fault(
                Fault::MissingWord,
                "K (lead) or E (threads per inch) missing",
            )),
        }
    }

    pub(super) fn gtc_starts(&self, b: &Block<Gtc2e>) -> Result<u32, ProgramError> {
        match b.get('L') {
            None => Ok(1),
            Some(l) => {
                let n = whole(l);
                if (1..=12).contains(&n) && (l - n as f64).abs() < 1e-9 {
                    Ok(n)
                } else {
                    Err(self.fault(Fault::OutOfRange, format!("L{}: 1–12 starts", show(l))))
                }
            }
        }
    }

    /// A cycle block: remember the shape, then run it from the current point.
    pub(super) fn gtc_cycle_define(
        &mut self,
        b: &Block<Gtc2e>,
        g: GtcG,
    ) -> Result<(), ProgramError> {
        let here = self.core.work_position();
        let (xi, zi) = self.core.xz()?;
        let end = self.end_point(b)?;
        let needs_z = !(b.has('Z') || b.has('W'));
        if needs_z {
            return Err(self.fault(Fault::MissingWord, "the cycle needs Z or W"));
        }
        let (lead, starts, dwell) = match g {
            GtcG::ThreadCycle | GtcG::Tapping => (self.gtc_lead(b)?, self.gtc_starts(b)?, 0.0),
            GtcG::DrillCycle => {
                let d = b.get('D').unwrap_or(0.0);
                if !(0.0..=5.0).contains(&d) {
                    return Err(self.fault(Fault::OutOfRange, format!("D{}: 0.01–5 s", show(d))));
                }
                (0.0, 1, d)
            }
            _ => (0.0, 1, 0.0),
        };
        if matches!(
            g,
            GtcG::TaperCycle | GtcG::CylinderCycle | GtcG::GroovingCycle
        ) && !(b.has('X') || b.has('U'))
        {
            return Err(self.fault(Fault::MissingWord, "the cycle needs X or U"));
        }
        let cycle = GtcCycle {
            kind: g,
            dx: end[xi] - here[xi],
            dz: end[zi] - here[zi],
            lead,
            starts,
            dwell,
        };
        self.d.gtc_cycle = Some(cycle);
        self.gtc_run(cycle)
    }

    /// A follow-on block: move the start point, run the shape again.
    pub(super) fn gtc_cycle_follow_on(&mut self, b: &Block<Gtc2e>) -> Result<(), ProgramError> {
        let Some(cycle) = self.d.gtc_cycle else {
            return Err(self.fault(Fault::MissingWord, "no cycle defined for this block"));
        };
        let end = self.end_point(b)?;
        let kind = if matches!(
            cycle.kind,
            GtcG::TaperCycle | GtcG::GroovingCycle | GtcG::DrillCycle
        ) {
            MoveKind::Feed(self.core.feed)
        } else {
            MoveKind::Rapid
        };
        self.core.emit(&end, kind)?;
        self.gtc_run(cycle)
    }

    pub(super) fn gtc_run(&mut self, c: GtcCycle) -> Result<(), ProgramError> {
        let a = self.core.work_position();
        let (xi, zi) = self.core.xz()?;
        let at = |x: f64, z: f64| {
            let mut v = a.clone();
            v[xi] = x;
            v[zi] = z;
            v
        };
        let (x0, z0) = (a[xi], a[zi]);
        let (x1, z1) = (x0 + c.dx, z0 + c.dz);
        let f = self.core.feed;
        match c.kind {
            GtcG::CylinderCycle => {
                // A→B rapid (X infeed), B→C feed along Z, C→D rapid (X out), D→A rapid.
                self.core.emit(&at(x1, z0), MoveKind::Rapid)?;
                self.core.emit(&at(x1, z1), MoveKind::Feed(f))?;
                self.core.emit(&at(x0, z1), MoveKind::Rapid)?;
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            GtcG::GroovingCycle => {
                // A→B→C feed (three cutting surfaces), C→D→A rapid.
                self.core.emit(&at(x1, z0), MoveKind::Feed(f))?;
                self.core.emit(&at(x1, z1), MoveKind::Feed(f))?;
                self.core.emit(&at(x0, z1), MoveKind::Rapid)?;
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            GtcG::TaperCycle => {
                // B→C feed; back Z first then X when X grew, else X first then Z.
                self.core.emit(&at(x1, z1), MoveKind::Feed(f))?;
                if c.dx >= 0.0 {
                    self.core.emit(&at(x1, z0), MoveKind::Rapid)?;
                } else {
                    self.core.emit(&at(x0, z1), MoveKind::Rapid)?;
                }
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            GtcG::DrillCycle => {
                self.core.emit(&at(x0, z1), MoveKind::Feed(f))?;
                if c.dwell > 0.0 {
                    self.core.push(Command::Dwell { seconds: c.dwell });
                }
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            GtcG::Tapping => {
                // Tap in synchronised, stop, reverse, back, stop (`002` §4.3.2-6).
                let reverse = if self.core.spindle() == SpindleDir::Ccw {
                    3
                } else {
                    4
                };
                self.core.emit(
                    &at(x0, z1),
                    MoveKind::Thread {
                        lead: c.lead,
                        angle: 0.0,
                    },
                )?;
                self.core.spindle_code(5);
                self.core.spindle_code(reverse);
                self.core.emit(
                    &at(x0, z0),
                    MoveKind::Thread {
                        lead: c.lead,
                        angle: 0.0,
                    },
                )?;
                self.core.spindle_code(5);
            }
            _ => {
                // G76: thread toward Z; W (G31) before the end X retracts U (G31) while Z runs
                // on; Z rapid back; X back to the infeed point (`002` §4.3.2-5).
                let retract = self.d.gtc_retract.u.unwrap_or(c.lead / 2.0);
                let early = self.d.gtc_retract.w.min(c.dz.abs());
                let away = -self.last_x_direction;
                for n in 0..c.starts {
                    let angle = 360.0 * n as f64 / c.starts as f64;
                    let zdir = c.dz.signum();
                    let zr = z1 - zdir * early;
                    let xr = x0 + c.dx * if c.dz != 0.0 { (zr - z0) / c.dz } else { 1.0 };
                    if early > 0.0 {
                        self.core.emit(
                            &at(xr, zr),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                        self.core.emit(
                            &at(x1 + away * retract, z1),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                    } else {
                        self.core.emit(
                            &at(x1, z1),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                        self.core
                            .emit(&at(x1 + away * retract, z1), MoveKind::Rapid)?;
                    }
                    self.core
                        .emit(&at(x1 + away * retract, z0), MoveKind::Rapid)?;
                    self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
                }
            }
        }
        Ok(())
    }

    /// G33: one thread pass (`002` §4.3.2-4); with L starts, each further start after a return
    /// by the G31 retract (decision D25).
    pub(super) fn gtc_thread(&mut self, b: &Block<Gtc2e>) -> Result<(), ProgramError> {
        let lead = self.gtc_lead(b)?;
        let starts = self.gtc_starts(b)?;
        let start = self.core.work_position();
        let end = self.end_point(b)?;
        let (xi, _) = self.core.xz()?;
        let retract = self.d.gtc_retract.u.unwrap_or(lead / 2.0);
        for n in 0..starts {
            let angle = 360.0 * n as f64 / starts as f64;
            if n > 0 {
                let mut out = self.core.work_position();
                out[xi] -= self.last_x_direction * retract;
                self.core.emit(&out, MoveKind::Rapid)?;
                let mut back = start.clone();
                back[xi] = out[xi];
                self.core.emit(&back, MoveKind::Rapid)?;
                self.core.emit(&start, MoveKind::Rapid)?;
            }
            self.core.emit(&end, MoveKind::Thread { lead, angle })?;
        }
        Ok(())
    }

    pub(super) fn gtc_g31(&mut self, b: &Block<Gtc2e>) -> Result<(), ProgramError> {
        let (u, w, l) = (b.get('U'), b.get('W'), b.get('L'));
        for (c, v) in [('U', u), ('W', w), ('L', l)] {
            if v.is_some_and(|v| v < 0.0) {
                return Err(self.fault(Fault::IllegalWord, format!("G31 {c} must be positive")));
            }
        }
        if let Some(l) = l {
            if !(1..=7).contains(&whole(l)) {
                return Err(self.fault(Fault::OutOfRange, "G31 L: speed 1–7"));
            }
            // The retract speed is the planner's business (issue 4); only its range is checked.
        }
        if u.is_some() {
            self.d.gtc_retract.u = u;
        }
        if let Some(w) = w {
            self.d.gtc_retract.w = w;
        }
        Ok(())
    }

    pub(super) fn gtc_loop_start(&mut self, b: &Block<Gtc2e>) -> Result<(), ProgramError> {
        let l = b
            .get('L')
            .ok_or_else(|| self.fault(Fault::MissingWord, "G22 needs L"))?;
        let n = whole(l);
        if !(1..=99).contains(&n) {
            return Err(self.fault(Fault::OutOfRange, "G22 L: 1–99"));
        }
        let f = self.core.level();
        let first = f.pos;
        f.repeats.push(Repeat::Loop {
            first,
            remaining: n,
        });
        Ok(())
    }

    pub(super) fn gtc_loop_end(&mut self) -> Result<(), ProgramError> {
        let f = self.core.level();
        match f.repeats.last_mut() {
            Some(Repeat::Loop { first, remaining }) => {
                if *remaining > 1 {
                    *remaining -= 1;
                    f.pos = *first;
                } else {
                    f.repeats.pop();
                }
                Ok(())
            }
            _ => Err(self.fault(Fault::LoopWithoutStart, "G80 without G22")),
        }
    }

    /// Rapid return with the axis order of M52 (X then Z), M53 (Z then X) or M65 (together
    /// at 45°, then the rest).
    pub(super) fn gtc_return(
        &mut self,
        target: &[f64],
        x: bool,
        z: bool,
    ) -> Result<(), ProgramError> {
        let (xi, zi) = self.core.xz()?;
        let here = self.core.work_position();
        let mut goal = here.clone();
        if x {
            goal[xi] = target[xi];
        }
        if z {
            goal[zi] = target[zi];
        }
        let mut via = here.clone();
        match self.d.return_order {
            ReturnOrder::XThenZ => via[xi] = goal[xi],
            ReturnOrder::ZThenX => via[zi] = goal[zi],
            ReturnOrder::Together => via = goal.clone(),
        }
        if via != here && via != goal {
            self.core.emit(&via, MoveKind::Rapid)?;
        }
        if goal != self.core.work_position() {
            self.core.emit(&goal, MoveKind::Rapid)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn inch_threads_with_half() {
        assert_eq!(super::tpi(10.2), Some(10.5));
        assert_eq!(super::tpi(14.0), Some(14.0));
        assert_eq!(super::tpi(10.3), None);
        assert_eq!(super::tpi(1.0), None);
    }
}
