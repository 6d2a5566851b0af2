//! The NC's state signals to the PLC (`000` App.2, inventory §9.4): the F image motion keeps
//! from its run state, and the strobes it drops.

use super::*;

impl Motion {
    pub(super) fn clear_strobe(&mut self) {
        for b in [
            f::MF,
            f::SF,
            f::TF,
            f::HF,
            f::DM00,
            f::DM01,
            f::DM02,
            f::DM30,
        ] {
            self.f.set(b, false);
        }
    }

    /// The NC's state signals (`000` App.2, inventory §9.4).
    pub(super) fn update_f(&mut self) {
        let running = self.active.is_some() || !self.queue.is_empty();
        let distributing = matches!(
            self.active,
            Some((
                _,
                Active::Path | Active::Thread { .. } | Active::Rapid { .. }
            ))
        );
        let hold = self.state() == RunState::Hold;
        for (k, r) in self.signal_axis.iter().zip(&self.referenced) {
            if let Some(k) = *k {
                self.f.set(f::zp(k), *r);
            }
        }
        self.f.set(f::MREF, self.reference.is_some());
        let all_locked = self.machine_locked();
        let fi = &mut self.f;
        fi.set(f::OP, running);
        fi.set(f::STL, running && !hold);
        fi.set(f::SPL, hold);
        fi.set(f::SA, !self.servo_off);
        fi.set(f::MA, !self.alarm && !self.servo_off);
        fi.set(f::AL, self.alarm);
        fi.set(f::DEN, !distributing);
        fi.set(
            f::CUT,
            matches!(self.active, Some((_, Active::Path | Active::Thread { .. }))),
        );
        fi.set(
            f::THRD,
            matches!(self.active, Some((_, Active::Thread { .. }))),
        );
        fi.set(f::MCYC, true);
        fi.set(f::MJ, self.mode == MachineState::MODE_JOG);
        fi.set(f::MH, self.mode == MachineState::MODE_HANDWHEEL);
        fi.set(f::MSBK, self.panel.single_block);
        fi.set(f::DRUR, self.panel.dry_run);
        fi.set(f::MMLK, all_locked);
        fi.set(f::MAFL, self.panel.aux_lock);
        fi.set(f::MBDT, self.panel.block_skip);
        fi.set(f::RST, self.reset_ticks > 0);
        self.reset_ticks = self.reset_ticks.saturating_sub(1);
    }
}
