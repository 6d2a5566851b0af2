//! Threads and single cycles: G32 (constant lead, with run-out), G33 (tapping), G34 (variable
//! lead), G90/G94 turning and facing cycles and the G92 thread cycle (§5.21, §5.23), and the
//! G05 three-point arc (§5.5), and the cut G99.1 starts on the encoder's Z pulse (§5.25).

use cnc_interpreter_core::geometry::{self, Pt};
use cnc_interpreter_core::{show, Fault, MoveKind, ProgramError, SpindleDir};

use super::{Huaxing, HuaxingG};
use crate::fanuc::block::{whole, Block};
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

impl Fanuc<Huaxing> {
    pub(super) fn three_point_arc(
        &mut self,
        b: &Block<Huaxing>,
        absolute: bool,
    ) -> Result<(), ProgramError> {
        if !b.has('I') && !b.has('K') {
            return Err(self.fault(Fault::ThreePointArc, "G05 needs the intermediate point I/K"));
        }
        let end = self.end_point(b)?;
        let here = self.core.work_position();
        let (a, e) = (self.core.plane_point(&here)?, self.core.plane_point(&end)?);
        // I is the mid point's X in radius (G05: relative to the start), or its absolute
        // X diameter (G05.1), K its Z (`000` §5.5; decision D22).
        let (i, k) = (b.get('I').unwrap_or(0.0), b.get('K').unwrap_or(0.0));
        let m = if absolute {
            Pt::new(k, i * self.core.x_scale())
        } else {
            Pt::new(a.z + k, a.r + i)
        };
        let (c, ccw) = geometry::three_point(a, m, e).map_err(|e| self.arc_error(e))?;
        let f = self.core.feed;
        self.core.emit(
            &end,
            MoveKind::Arc {
                center: c,
                ccw,
                feed: f,
            },
        )
    }

    /// Lead from F (mm) or I (threads per inch); `000` alarm 2 for both, none or zero.
    pub(super) fn lead(&mut self, b: &Block<Huaxing>, modal: bool) -> Result<f64, ProgramError> {
        let lead = match (b.get('F'), b.get('I')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::ThreadLead, "thread with both F and I"))
            }
            (Some(f), None) => f,
            (None, Some(i)) if i > 0.0 => 25.4 / i,
            (None, Some(i)) => {
                return Err(self.fault(Fault::ThreadLead, format!("I{} threads per inch", show(i))))
            }
            (None, None) if modal && self.d.thread.lead > 0.0 => self.d.thread.lead,
            (None, None) => return Err(self.fault(Fault::ThreadLead, "thread lead F or I missing")),
        };
        if !(lead > 0.0 && lead <= 500.0) {
            return Err(self.fault(
                Fault::ThreadLead,
                format!("thread lead {lead} out of 0.0001–500 mm"),
            ));
        }
        self.d.thread.lead = lead;
        Ok(lead)
    }

    /// A thread from the current point to `end` (work), with run-out: within `k` of the end
    /// along the long axis the short axis moves `j` (radius, signed) (`000` §5.23.1).
    pub(super) fn thread_to(
        &mut self,
        end: &[f64],
        lead: f64,
        angle: f64,
        j: f64,
        k: f64,
    ) -> Result<(), ProgramError> {
        let here = self.core.work_position();
        let (a, e) = (self.core.plane_point(&here)?, self.core.plane_point(end)?);
        let long_is_z = (e.z - a.z).abs() >= (e.r - a.r).abs();
        let len = if long_is_z {
            (e.z - a.z).abs()
        } else {
            (e.r - a.r).abs()
        };
        if j != 0.0 && k > 0.0 && k < len {
            let s = 1.0 - k / len;
            let mid = a.lerp(e, s);
            let out = if long_is_z {
                Pt::new(e.z, e.r + j)
            } else {
                Pt::new(e.z + j, e.r)
            };
            self.core.emit(
                &self.core.with_point(&here, mid),
                MoveKind::Thread { lead, angle },
            )?;
            // The thread's long axis keeps its lead through the run-out (D36; `000` §5.23.5: "the
            // long axis continues"); motion reads a lead along the piece's own long axis, which
            // is the short axis when the retract J is longer than K.
            let runout_lead = if j.abs() > k {
                lead * j.abs() / k
            } else {
                lead
            };
            self.core.emit(
                &self.core.with_point(&here, out),
                MoveKind::Thread {
                    lead: runout_lead,
                    angle,
                },
            )?;
        } else {
            self.core.emit(end, MoveKind::Thread { lead, angle })?;
        }
        Ok(())
    }

    /// Run-out words J/K with the G32 rules (`000` §5.23.1).
    pub(super) fn runout(&mut self, b: &Block<Huaxing>, g92: bool) -> (f64, f64) {
        if let Some(j) = b.get('J') {
            self.d.thread.j = Some(j);
        }
        if let Some(k) = b.get('K') {
            self.d.thread.k = Some(k.abs());
        }
        let (j, k) = (self.d.thread.j, self.d.thread.k);
        let j = if g92 { j.map(f64::abs) } else { j };
        match (j, k) {
            (None, _) | (Some(_), None) if !g92 && j.is_none() => (0.0, 0.0),
            (Some(j), None) => (j, j.abs()),
            (Some(j), Some(k)) if j != 0.0 => (j, if k == 0.0 { j.abs() } else { k }),
            _ => (0.0, 0.0),
        }
    }

    pub(super) fn g32(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let lead = self.lead(b, true)?;
        let (j, k) = self.runout(b, false);
        // Q: start angle in 0.001° (a decimal point is ignored, `000` §5.23.1).
        let angle = b.get('Q').map(|q| q / 1000.0).unwrap_or(0.0);
        if !(0.0..=360.0).contains(&angle) {
            return Err(self.fault(Fault::OutOfRange, "Q start angle out of 0–360000"));
        }
        let end = self.end_point(b)?;
        self.thread_to(&end, lead, angle, j, k)
    }

    pub(super) fn g34(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let lead = self.lead(b, true)?;
        let dl = b.get('R').ok_or_else(|| {
            self.fault(
                Fault::ThreadLead,
                "G34 needs R (lead change per revolution)",
            )
        })?;
        let end = self.end_point(b)?;
        let here = self.core.work_position();
        let (a, e) = (self.core.plane_point(&here)?, self.core.plane_point(&end)?);
        let len = (e.z - a.z).abs().max((e.r - a.r).abs());
        // Variable lead as one-revolution pieces of constant lead (the average of each turn).
        let mut s = 0.0;
        let mut l = lead;
        let mut pieces = 0;
        while s < len - 1e-9 {
            pieces += 1;
            if l <= 0.0 || l > 500.0 || pieces > 100_000 {
                return Err(self.fault(Fault::ThreadLead, format!("G34 lead becomes {l:.4} mm")));
            }
            let step = (l + dl / 2.0).max(1e-6).min(len - s);
            s += step;
            let p = a.lerp(e, s / len);
            self.core.emit(
                &self.core.with_point(&here, p),
                MoveKind::Thread {
                    lead: l + dl / 2.0,
                    angle: 0.0,
                },
            )?;
            l += dl;
        }
        Ok(())
    }

    pub(super) fn g33(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        // Z tapping cycle (`000` §5.23.3): feed in synchronised, M05, reverse, back, M05.
        let lead = self.lead(b, true)?;
        let reverse = match self.core.spindle() {
            SpindleDir::Cw => 4,
            SpindleDir::Ccw => 3,
            SpindleDir::Stopped => {
                return Err(self.fault(
                    Fault::MissingWord,
                    "G33 tapping needs the spindle running (M03/M04)",
                ))
            }
        };
        let forward = if reverse == 4 { 3 } else { 4 };
        let starts = b.get('L').map(whole).unwrap_or(1).clamp(1, 99);
        let start = self.core.work_position();
        let (_, zi) = self.core.xz()?;
        let mut bottom = start.clone();
        bottom[zi] = match (b.get('Z'), b.get('W')) {
            (Some(z), None) => z,
            (None, Some(w)) => start[zi] + w,
            _ => return Err(self.fault(Fault::MissingWord, "G33 needs Z or W")),
        };
        for n in 0..starts {
            if n > 0 {
                self.core.spindle_code(forward);
            }
            let angle = 360.0 * n as f64 / starts as f64;
            self.core.emit(&bottom, MoveKind::Thread { lead, angle })?;
            self.core.spindle_code(5);
            self.core.spindle_code(reverse);
            self.core.emit(&start, MoveKind::Thread { lead, angle })?;
            self.core.spindle_code(5);
        }
        Ok(())
    }

    pub(super) fn single_cycle(
        &mut self,
        b: &Block<Huaxing>,
        g: HuaxingG,
    ) -> Result<(), ProgramError> {
        let here = self.core.work_position();
        let (xi, zi) = self.core.xz()?;
        // Retained X, Z, R (`000` §5.21.3).
        let end = self.end_point(b)?;
        if b.has('X') || b.has('U') {
            self.d.cycle.x = Some(end[xi]);
        }
        if b.has('Z') || b.has('W') {
            self.d.cycle.z = Some(end[zi]);
        }
        if let Some(r) = b.get('R') {
            self.d.cycle.r = r;
        }
        let (Some(x), Some(z)) = (self.d.cycle.x, self.d.cycle.z) else {
            return Err(self.fault(Fault::MissingWord, "cycle needs X(U) and Z(W)"));
        };
        let r = self.d.cycle.r;
        let (x0, z0) = (here[xi], here[zi]);
        let at = |x: f64, z: f64| {
            let mut w = here.clone();
            w[xi] = x;
            w[zi] = z;
            w
        };
        let f = self.core.feed;
        let u = x - x0;
        match g {
            HuaxingG::TurningCycle => {
                // R: cut start X minus cut end X, radius (`000` §5.21.1); alarm 3.
                if r != 0.0
                    && u.abs() > 1e-9
                    && r.signum() != u.signum()
                    && r.abs() > (u / 2.0).abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "R and U of opposite sign with |R| > |U/2|",
                    ));
                }
                let xs = x + 2.0 * r;
                self.core.emit(&at(xs, z0), MoveKind::Rapid)?;
                self.core.emit(&at(x, z), MoveKind::Feed(f))?;
                self.core.emit(&at(x0, z), MoveKind::Feed(f))?;
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            HuaxingG::FacingCycle => {
                let w = z - z0;
                if r != 0.0
                    && w.abs() > 1e-9
                    && r.signum() != w.signum()
                    && r.abs() > w.abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "R and W of opposite sign with |R| > |W|",
                    ));
                }
                let zs = z + r;
                self.core.emit(&at(x0, zs), MoveKind::Rapid)?;
                self.core.emit(&at(x, z), MoveKind::Feed(f))?;
                self.core.emit(&at(x, z0), MoveKind::Feed(f))?;
                self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            _ => {
                // G92 thread cycle (`000` §5.23.5).
                let lead = self.lead(b, true)?;
                if r != 0.0
                    && u.abs() > 1e-9
                    && r.signum() != u.signum()
                    && r.abs() > (u / 2.0).abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "G92: R and U of opposite sign with |R| > |U/2|",
                    ));
                }
                if let Some(l) = b.get('L') {
                    let l = whole(l);
                    if !(1..=99).contains(&l) {
                        return Err(self.fault(Fault::OutOfRange, format!("G92 L{l}: 1–99 starts")));
                    }
                    self.d.cycle_starts = l;
                }
                let (j, k) = self.runout(b, true);
                // Run-out goes away from the part: toward the start X.
                let away = if x0 >= x { 1.0 } else { -1.0 };
                let starts = self.d.cycle_starts.max(1);
                for n in 0..starts {
                    let angle = 360.0 * n as f64 / starts as f64;
                    self.core.emit(&at(x + 2.0 * r, z0), MoveKind::Rapid)?;
                    self.thread_to(&at(x, z), lead, angle, away * j, k)?;
                    let cur = self.core.work_position();
                    self.core.emit(&at(x0, cur[zi]), MoveKind::Rapid)?;
                    self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
                }
            }
        }
        Ok(())
    }
}

impl Fanuc<Huaxing> {
    /// The cut after G99.1 (§5.25, D132): it waits for the spindle encoder's Z pulse and then
    /// runs at F mm per revolution, so it is cut as a thread from the index (start angle 0)
    /// whose lead along its longer axis gives F along the path; the overrides do not act on
    /// it, as on any cut locked to the encoder. Only that one cut; G99 stays. Rapids before it
    /// wait; an arc cannot start on the pulse (alarm); G98 before the cut cancels it.
    pub(super) fn cut_on_index(&mut self, b: &Block<Huaxing>) -> Option<Result<(), ProgramError>> {
        if !self.d.start_on_index {
            return None;
        }
        if !self.core.feed_per_rev() {
            self.d.start_on_index = false;
            return None;
        }
        if !self.has_axis_words(b) {
            return None;
        }
        match b.group(1).unwrap_or(self.motion) {
            G::Linear => {}
            G::ArcCw | G::ArcCcw => {
                self.d.start_on_index = false;
                return Some(Err(self.fault(
                    Fault::NotSupported,
                    "G99.1: the cut that starts on the encoder's Z pulse is a line (G01)",
                )));
            }
            _ => return None,
        }
        self.d.start_on_index = false;
        if let Some(m) = b.group(1) {
            self.motion = m;
        }
        Some(self.index_cut(b))
    }

    fn index_cut(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let feed = self.core.feed;
        if feed <= 0.0 {
            return Err(self.fault(Fault::FeedRange, "G99.1 needs F (mm per revolution)"));
        }
        let start = self.core.work_position();
        let end = self.end_point(b)?;
        // Slide distances: a diameter axis moves half its programmed change.
        let slide: Vec<f64> = start
            .iter()
            .zip(&end)
            .zip(&self.core.setup.diameter)
            .map(|((a, e), &d)| if d { (e - a) / 2.0 } else { e - a })
            .collect();
        let path = slide.iter().map(|d| d * d).sum::<f64>().sqrt();
        let long = slide.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let lead = if path > 0.0 { feed * long / path } else { feed };
        self.core.emit(&end, MoveKind::Thread { lead, angle: 0.0 })
    }
}
