//! The GTC2E's own cycles, loops and returns (`002` §4.3.2).
//!
//! A GTC2E cycle block defines a shape relative to the start point and runs it once; a
//! following block with only X/U or Z/W moves the start point and runs the same shape again
//! (`002` §4.3.2-5..10, inventory §12). The move to the new start point goes at rapid for G77,
//! G76 and G74, whose first move is a rapid or an infeed, and at the cycle's feed for G24,
//! G75 and G83, where the manual gives feed (decision D24).

use super::*;

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

impl Interpreter {
    /// K (metric lead, 0.25–24 mm) or E (threads per inch, 2–99½).
    fn gtc_lead(&self, b: &Block) -> Result<f64, ProgramError> {
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

    fn gtc_starts(&self, b: &Block) -> Result<u32, ProgramError> {
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
    pub(super) fn gtc_cycle_define(&mut self, b: &Block, g: G) -> Result<(), ProgramError> {
        let here = self.work_position();
        let (xi, zi) = self.xz()?;
        let end = self.end_point(b)?;
        let needs_z = !(b.has('Z') || b.has('W'));
        if needs_z {
            return Err(self.fault(Fault::MissingWord, "the cycle needs Z or W"));
        }
        let (lead, starts, dwell) = match g {
            G::GtcThreadCycle | G::GtcTapping => (self.gtc_lead(b)?, self.gtc_starts(b)?, 0.0),
            G::GtcDrillCycle => {
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
            G::GtcTaperCycle | G::GtcCylinderCycle | G::GtcGroovingCycle
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
        self.gtc_cycle = Some(cycle);
        self.gtc_run(cycle)
    }

    /// A follow-on block: move the start point, run the shape again.
    pub(super) fn gtc_cycle_follow_on(&mut self, b: &Block) -> Result<(), ProgramError> {
        let Some(cycle) = self.gtc_cycle else {
            return Err(self.fault(Fault::MissingWord, "no cycle defined for this block"));
        };
        let end = self.end_point(b)?;
        let kind = if matches!(
            cycle.kind,
            G::GtcTaperCycle | G::GtcGroovingCycle | G::GtcDrillCycle
        ) {
            MoveKind::Feed(self.feed)
        } else {
            MoveKind::Rapid
        };
        self.emit(&end, kind)?;
        self.gtc_run(cycle)
    }

    fn gtc_run(&mut self, c: GtcCycle) -> Result<(), ProgramError> {
        let a = self.work_position();
        let (xi, zi) = self.xz()?;
        let at = |x: f64, z: f64| {
            let mut v = a.clone();
            v[xi] = x;
            v[zi] = z;
            v
        };
        let (x0, z0) = (a[xi], a[zi]);
        let (x1, z1) = (x0 + c.dx, z0 + c.dz);
        let f = self.feed;
        match c.kind {
            G::GtcCylinderCycle => {
                // A→B rapid (X infeed), B→C feed along Z, C→D rapid (X out), D→A rapid.
                self.emit(&at(x1, z0), MoveKind::Rapid)?;
                self.emit(&at(x1, z1), MoveKind::Feed(f))?;
                self.emit(&at(x0, z1), MoveKind::Rapid)?;
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            G::GtcGroovingCycle => {
                // A→B→C feed (three cutting surfaces), C→D→A rapid.
                self.emit(&at(x1, z0), MoveKind::Feed(f))?;
                self.emit(&at(x1, z1), MoveKind::Feed(f))?;
                self.emit(&at(x0, z1), MoveKind::Rapid)?;
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            G::GtcTaperCycle => {
                // B→C feed; back Z first then X when X grew, else X first then Z.
                self.emit(&at(x1, z1), MoveKind::Feed(f))?;
                if c.dx >= 0.0 {
                    self.emit(&at(x1, z0), MoveKind::Rapid)?;
                } else {
                    self.emit(&at(x0, z1), MoveKind::Rapid)?;
                }
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            G::GtcDrillCycle => {
                self.emit(&at(x0, z1), MoveKind::Feed(f))?;
                if c.dwell > 0.0 {
                    self.push(Command::Dwell { seconds: c.dwell });
                }
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            G::GtcTapping => {
                // Tap in synchronised, stop, reverse, back, stop (`002` §4.3.2-6).
                let reverse = if self.spindle == SpindleDir::Ccw {
                    3
                } else {
                    4
                };
                self.emit(
                    &at(x0, z1),
                    MoveKind::Thread {
                        lead: c.lead,
                        angle: 0.0,
                    },
                )?;
                self.aux(Aux::M(5));
                self.aux(Aux::M(reverse));
                self.emit(
                    &at(x0, z0),
                    MoveKind::Thread {
                        lead: c.lead,
                        angle: 0.0,
                    },
                )?;
                self.aux(Aux::M(5));
                self.spindle = SpindleDir::Stopped;
            }
            _ => {
                // G76: thread toward Z; W (G31) before the end X retracts U (G31) while Z runs
                // on; Z rapid back; X back to the infeed point (`002` §4.3.2-5).
                let retract = self.gtc_retract.u.unwrap_or(c.lead / 2.0);
                let early = self.gtc_retract.w.min(c.dz.abs());
                let away = -self.last_x_direction;
                for n in 0..c.starts {
                    let angle = 360.0 * n as f64 / c.starts as f64;
                    let zdir = c.dz.signum();
                    let zr = z1 - zdir * early;
                    let xr = x0 + c.dx * if c.dz != 0.0 { (zr - z0) / c.dz } else { 1.0 };
                    if early > 0.0 {
                        self.emit(
                            &at(xr, zr),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                        self.emit(
                            &at(x1 + away * retract, z1),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                    } else {
                        self.emit(
                            &at(x1, z1),
                            MoveKind::Thread {
                                lead: c.lead,
                                angle,
                            },
                        )?;
                        self.emit(&at(x1 + away * retract, z1), MoveKind::Rapid)?;
                    }
                    self.emit(&at(x1 + away * retract, z0), MoveKind::Rapid)?;
                    self.emit(&at(x0, z0), MoveKind::Rapid)?;
                }
            }
        }
        Ok(())
    }

    /// G33: one thread pass (`002` §4.3.2-4); with L starts, each further start after a return
    /// by the G31 retract (decision D25).
    pub(super) fn gtc_thread(&mut self, b: &Block) -> Result<(), ProgramError> {
        let lead = self.gtc_lead(b)?;
        let starts = self.gtc_starts(b)?;
        let start = self.work_position();
        let end = self.end_point(b)?;
        let (xi, _) = self.xz()?;
        let retract = self.gtc_retract.u.unwrap_or(lead / 2.0);
        for n in 0..starts {
            let angle = 360.0 * n as f64 / starts as f64;
            if n > 0 {
                let mut out = self.work_position();
                out[xi] -= self.last_x_direction * retract;
                self.emit(&out, MoveKind::Rapid)?;
                let mut back = start.clone();
                back[xi] = out[xi];
                self.emit(&back, MoveKind::Rapid)?;
                self.emit(&start, MoveKind::Rapid)?;
            }
            self.emit(&end, MoveKind::Thread { lead, angle })?;
        }
        Ok(())
    }

    pub(super) fn gtc_g31(&mut self, b: &Block) -> Result<(), ProgramError> {
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
            self.gtc_retract.u = u;
        }
        if let Some(w) = w {
            self.gtc_retract.w = w;
        }
        Ok(())
    }

    pub(super) fn gtc_loop_start(&mut self, b: &Block) -> Result<(), ProgramError> {
        let l = b
            .get('L')
            .ok_or_else(|| self.fault(Fault::MissingWord, "G22 needs L"))?;
        let n = whole(l);
        if !(1..=99).contains(&n) {
            return Err(self.fault(Fault::OutOfRange, "G22 L: 1–99"));
        }
        let f = self.frame();
        let first = f.pos;
        f.repeats.push(Repeat::Loop {
            first,
            remaining: n,
        });
        Ok(())
    }

    pub(super) fn gtc_loop_end(&mut self) -> Result<(), ProgramError> {
        let f = self.frame();
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
        let (xi, zi) = self.xz()?;
        let here = self.work_position();
        let mut goal = here.clone();
        if x {
            goal[xi] = target[xi];
        }
        if z {
            goal[zi] = target[zi];
        }
        let mut via = here.clone();
        match self.return_order {
            ReturnOrder::XThenZ => via[xi] = goal[xi],
            ReturnOrder::ZThenX => via[zi] = goal[zi],
            ReturnOrder::Together => via = goal.clone(),
        }
        if via != here && via != goal {
            self.emit(&via, MoveKind::Rapid)?;
        }
        if goal != self.work_position() {
            self.emit(&goal, MoveKind::Rapid)?;
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
