//! The order of execution inside a block, for every dialect of the family (decision D6). A
//! decoded block runs in these steps, each in the order its words were written:
//!
//! 1. **Modal codes**: G90/G91, G61/G64, G94/G95 (G98/G99 on a lathe), work system G54–G59,
//!    plane G17–G19, G21, G41/G42/G40 (compensation starts or ends with the block's move),
//!    and the dialect's own modal codes (GTC2E turret mode and offset groups, the mill's
//!    G43/G44/G49 and G98/G99).
//! 2. **The dialect's words before F** (the mill's H without G43/G44, and D).
//! 3. **F**: the feed (in thread blocks of the Huaxing lathe F is the lead, taken there).
//! 4. **S and G96/G97**: the spindle speed; G50 S is the speed clamp instead.
//! 5. **T**: tool and offset (the offset takes effect with the next move); the Huaxing
//!    tool-change macro is called here.
//! 6. **M codes that start something** (M03, M04, M08, clamp, …) go to the PLC, and the
//!    dialect's own M codes act (GTC2E M52/M53/M65 return order, Huaxing tool-macro codes).
//!    In a Huaxing G83/G87 block the M code is the cycle's clamp code instead.
//! 7. **The body** (`body.rs`): one one-shot code (G04, G28, G50, G10, the lathe cycles and
//!    block ranges, GTC2E loops and returns, …) is the whole body; else the mill's modal
//!    canned cycle; else the block's motion in the modal motion code.
//! 8. **M codes that stop something** (M05, M09, M00, M01) go to the PLC after the motion.
//! 9. **G09**: the block's first motion is preceded by an exact stop and the block followed
//!    by continuous mode again.
//! 10. **Program flow**: M02/M30 end the program; M98/M99 call and return; GTC2E M20
//!     restarts, M97 jumps. In a G70 block they wait for the cycle.

use cnc_interpreter_core::{show, Aux, Fault, ProgramError, SpindleDir};

use super::block::Block;
use super::codes::{G, M};
use super::{Family, Fanuc};

impl<D: Family> Fanuc<D> {
    /// Queues a decoded block's commands in the order of the module's list.
    pub(super) fn execute(&mut self, b: Block<D>) -> Result<(), ProgramError> {
        let produced = self.core.queued();
        let start = D::WANTS_BLOCK_START.then(|| self.core.work_position());
        // 1. Modal settings.
        for &(_, g, _) in &b.g {
            match g {
                G::Absolute => self.incremental = false,
                G::Incremental => self.incremental = true,
                G::ExactStopMode => {
                    self.core.set_path_mode(true);
                }
                G::ContinuousMode => {
                    self.core.set_path_mode(false);
                }
                G::FeedPerMinute | G::FeedPerRevolution => {
                    let per_rev = g == G::FeedPerRevolution;
                    if per_rev != self.core.feed_per_rev() {
                        self.core.set_feed_mode(per_rev);
                    }
                }
                // Keep the machine position; the work coordinates change.
                G::WorkSystem(n) => self.core.work_system = n,
                G::PlaneXy | G::PlaneZx | G::PlaneYz => D::plane(self, g)?,
                G::MetricInput => self.inch = false,
                G::InchInput => self.inch = true,
                G::NoseLeft | G::NoseRight => D::start_comp(self, &b, g)?,
                G::NoseCancel if self.core.comp.is_some() => {
                    D::cancel_comp(self, &b)?;
                    self.core.comp_cancel = true;
                }
                G::Own(o) => D::modal(self, o, &b)?,
                _ => {}
            }
        }
        // 2. The dialect's words before F.
        D::words(self, &b)?;
        // 3. F.
        if let Some(f) = b.get('F') {
            if !D::f_is_lead(self, &b) {
                if f < 0.0 {
                    return Err(
                        self.fault(Fault::FeedRange, format!("feed F{} is negative", show(f)))
                    );
                }
                self.core.feed = f;
            }
        }
        // 4. S.
        self.spindle_words(&b)?;
        // 5. T.
        if let Some(t) = b.get('T') {
            D::tool_word(self, t)?;
        }
        // 6. M codes before the motion.
        let m_in_cycle = D::m_in_cycle(self, &b);
        for &(m, code) in &b.m {
            match m {
                M::AuxBefore | M::AuxAfter if m_in_cycle => {}
                M::AuxBefore if D::m_to_nc(self, code)? => {}
                M::AuxBefore => {
                    D::m_before(self, code)?;
                    self.track_spindle(code);
                    self.core.aux(Aux::M((code / 10) as i32));
                }
                M::Own(o) => D::own_m_before(self, o, &b)?,
                _ => {}
            }
        }
        // 7. The body.
        self.block_body(&b)?;
        // 8. M codes after the motion.
        for &(m, code) in &b.m {
            match m {
                M::AuxBefore | M::AuxAfter if m_in_cycle => {}
                M::AuxAfter if D::m_to_nc(self, code)? => {}
                M::AuxAfter | M::Stop => {
                    self.track_spindle(code);
                    self.core.aux(Aux::M((code / 10) as i32));
                }
                // Motion stops on M01 if the optional-stop switch is on when it gets there.
                M::OptionalStop => self.core.aux(Aux::M(1)),
                _ => {}
            }
        }
        // 9. G09: this block ends at rest; the next blends again.
        if b.has_g(G::ExactStopBlock)
            && self.core.queued() > produced
            && !self.core.exact_stop_mode()
        {
            self.core.exact_stop_block(produced);
        }
        // 10. Program flow; in a finishing-cycle block after the cycle.
        if !D::flow_waits(self, &b) {
            self.flow_m_codes(&b)?;
        }
        if let Some(start) = start {
            if self.has_axis_words(&b) || self.core.queued() > produced {
                D::block_ran(self, start);
            }
        }
        D::after_block(self, &b)
    }

    /// The spindle direction an M code leaves.
    pub fn track_spindle(&mut self, code: u32) {
        let dir = match code {
            30 => SpindleDir::Cw,
            40 => SpindleDir::Ccw,
            50 | 200 | 300 => SpindleDir::Stopped,
            _ => return,
        };
        self.core.spindle_left_by_code(dir);
    }

    fn spindle_words(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        if D::speed_word(self, b)? {
            return Ok(());
        }
        let s = b.get('S');
        // G50 S is the clamp, not a speed.
        if b.has_g(G::SetCoordinate) {
            if let Some(s) = s {
                if s <= 0.0 {
                    return Err(self.fault(
                        Fault::SpindleClamp,
                        format!("G50 S{} must be positive", show(s)),
                    ));
                }
                self.core.max_rpm = Some(s);
                // Decision D37: a G50 block that starts the spindle under G97 with no speed
                // yet commanded also runs it at S (a threading example does so).
                let starts = b.m.iter().any(|&(_, code)| code == 30 || code == 40);
                if starts && self.core.css.is_none() && self.core.rpm == 0.0 {
                    self.core.set_rpm(s);
                }
            }
            return Ok(());
        }
        if let Some(s) = s {
            if !(0.0..=99999.0).contains(&s) {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("spindle speed S{} out of range", show(s)),
                ));
            }
        }
        match b.group(D::CSS_GROUP) {
            Some(G::ConstantSurfaceSpeed) => {
                let v = s.or(if self.core.css_speed > 0.0 {
                    Some(self.core.css_speed)
                } else {
                    None
                });
                let v = v.ok_or_else(|| self.fault(Fault::CssWithoutS, "G96 without S"))?;
                self.core.css = Some(D::css_rule(self));
                self.core.css_speed = v;
                let here = self.core.work_position();
                self.core.spindle_for(&here);
                return Ok(());
            }
            Some(G::ConstantRpm) => {
                self.core.css = None;
                // G96 → G97 without S: the last rpm under G96 becomes the G97 speed.
                let rpm = s.or(self.core.sent_rpm).unwrap_or(self.core.rpm);
                self.core.set_rpm(rpm);
                return Ok(());
            }
            _ => {}
        }
        if let Some(s) = s {
            if self.core.css.is_some() {
                self.core.css_speed = s;
                let here = self.core.work_position();
                self.core.spindle_for(&here);
            } else {
                self.core.set_rpm(s);
            }
        }
        Ok(())
    }

    fn flow_m_codes(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        for &(m, code) in &b.m {
            match m {
                M::ProgramEnd => {
                    self.core.saw_end = true;
                    self.track_spindle(code);
                    self.core.aux(Aux::M((code / 10) as i32));
                    D::on_program_end(self);
                    self.core.finish();
                    return Ok(());
                }
                M::SubprogramCall => return D::call(self, b),
                M::SubprogramReturn => return D::ret(self),
                M::Own(o) => {
                    if let Some(r) = D::own_m_flow(self, o, b) {
                        return r;
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
}
