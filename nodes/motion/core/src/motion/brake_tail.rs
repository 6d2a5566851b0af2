//! The brake tail (issue 48): what the drives play if their setpoint queue runs dry. With every
//! batch of setpoints motion plans, on a copy of itself, the stop that would follow the batch's
//! last setpoint: a feed hold (deceleration on the programmed path at the machine's limits, as
//! the operator's feed hold), a jog or handwheel move ended as its key's release ends it. The
//! copy at the end of the tail is kept: it is the state the machine is in once the drives have
//! played it, and motion goes on from it.

use super::*;

/// The planned stop: its setpoints (encoder counts, as [`Motion::tick`] returns them) and the
/// state motion is in once they have played.
pub struct PlannedStop {
    pub len: usize,
    pub stopped: Box<Motion>,
}

impl Motion {
    /// Plans the stop after this tick into `out` (one setpoint per tick, at most `out.len()`;
    /// the tail ends when the setpoints stand still for two ticks). `plc` is this tick's G
    /// image: the tail keeps its switches, with feed hold pressed and the jog keys released.
    pub fn brake_tail(&self, plc: &GImage, out: &mut [[f64; MAX_AXES]]) -> PlannedStop {
        let mut m = Box::new(self.clone());
        let mut hold = *plc;
        hold.set(g::SP_N, false);
        hold.set(g::ST, false);
        for k in 0..6 {
            hold.set(g::jog_plus(k), false);
            hold.set(g::jog_minus(k), false);
        }
        m.events.clear();
        // The tail is the core's own stop: the drives play it as it is planned.
        m.at_drives.on = false;
        m.feed_hold();
        m.jog_stop();
        m.handwheel.stop();
        m.plc_signals(&hold);
        let n = self.cfg.axes.len().min(MAX_AXES);
        let mut len = 0;
        let mut still = 0;
        while len < out.len() {
            let ideal = m.ideal_feedback();
            let before = m.encoder_setpoint.clone();
            let sp = m.tick(Some(&ideal[..n]), &hold);
            out[len][..n].copy_from_slice(sp);
            len += 1;
            still = if sp == before.as_slice() {
                still + 1
            } else {
                0
            };
            if still >= 2 {
                break;
            }
        }
        m.events.clear();
        m.at_drives = self.at_drives;
        PlannedStop { len, stopped: m }
    }

    /// The encoder reading of drives that follow every setpoint exactly: what the planned tail
    /// assumes the machine reports.
    fn ideal_feedback(&self) -> [f64; MAX_AXES] {
        let mut out = [0.0; MAX_AXES];
        for (i, o) in out.iter_mut().enumerate().take(self.cfg.axes.len()) {
            *o = self.answered_drive(i) - self.shift[i];
        }
        out
    }
}
