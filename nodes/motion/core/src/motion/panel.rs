//! The operator's switches as motion sees them, from the PLC's G image, and what machine lock
//! does to the drives: the program's position runs on while the drive setpoint is held.

use super::*;

/// The operator's switches as motion sees them (`000` §7.3, §7.4; decision D38).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Feed override, 0–1.5 (the manual's steps 0–150 %). Threads ignore it.
    pub feed_override: f64,
    /// Rapid override, 0–1 (the manual's F0 = 0 %, 25 %, 50 %, 100 %).
    pub rapid_override: f64,
    /// Single block: stop after each program line (a cycle is one line).
    pub single_block: bool,
    /// Dry run: feed moves at `servo.dry_run_feed` instead of F (threads stay locked).
    pub dry_run: bool,
    /// Optional stop: M01 stops like M00.
    pub optional_stop: bool,
    /// Machine lock: the program runs and its positions count, the drives are held where the
    /// slides stand. Taken and released with the machine at rest (decisions D66).
    pub machine_lock: bool,
    /// Each-axis machine lock (G108), a bit per axis index: the mill's Z-axis lock holds Z
    /// alone (decisions D73).
    pub axis_lock: u32,
    /// Auxiliary function lock: M, S and T complete without reaching the PLC, except M00,
    /// M01, M02 and M30.
    pub aux_lock: bool,
    /// Block skip (G44.0): the interpreter acts on it, since it reads the blocks; motion only
    /// answers it on F4.0.
    pub block_skip: bool,
}

impl Default for Panel {
    fn default() -> Self {
        Panel {
            feed_override: 1.0,
            rapid_override: 1.0,
            single_block: false,
            dry_run: false,
            optional_stop: false,
            machine_lock: false,
            axis_lock: 0,
            aux_lock: false,
            block_skip: false,
        }
    }
}

impl Motion {
    /// The operator's switches; overrides take effect on the next tick.
    pub fn set_panel(&mut self, panel: Panel) {
        let clean = |v: f64, max: f64| {
            if v.is_finite() {
                v.clamp(0.0, max)
            } else {
                1.0
            }
        };
        self.panel = Panel {
            feed_override: clean(panel.feed_override, crate::planner::MAX_FEED_OVERRIDE),
            rapid_override: clean(panel.rapid_override, 1.0),
            ..panel
        };
    }

    /// The operator's signals in the PLC's G image, applied every tick: overrides and
    /// switches as levels, feed hold while `*SP` is low, cycle start on the rising edge of ST.
    pub fn plc_signals(&mut self, plc: &GImage) {
        self.set_panel(Panel {
            feed_override: plc.feed_override(),
            rapid_override: plc.rapid_override(),
            single_block: plc.get(g::SBK),
            dry_run: plc.get(g::DRN),
            optional_stop: plc.get(g::MOPS),
            machine_lock: plc.get(g::MLK),
            axis_lock: self.signal_axis.iter().enumerate().fold(0, |bits, (i, k)| {
                bits | u32::from(k.is_some_and(|k| plc.get(g::axis_lock(k)))) << i
            }),
            aux_lock: plc.get(g::AFL),
            block_skip: plc.get(g::BDT1),
        });
        if !plc.get(g::SP_N) && plc.get(g::ESP_N) {
            self.feed_hold();
        }
        let start = plc.get(g::ST);
        if start && !self.plc_start && plc.get(g::SP_N) {
            self.cycle_start();
        }
        self.plc_start = start;
    }

    /// Machine lock is taken and released only with the machine at rest, so a running move
    /// never jumps. Released, the program's position goes back to where the slides stand
    /// (the interpreter takes its next start from there).
    pub(super) fn take_machine_lock(&mut self) {
        let at_rest = self.active.is_none() && self.queue.is_empty();
        let all = if self.panel.machine_lock {
            self.all_axes()
        } else {
            0
        };
        let wanted = (all | self.panel.axis_lock) & self.all_axes();
        if !at_rest || wanted == self.locked {
            return;
        }
        let released = self.locked & !wanted;
        self.locked = wanted;
        if released != 0 {
            for i in 0..self.commanded.len() {
                if released & (1 << i) != 0 {
                    self.commanded[i] = self.drive[i];
                }
            }
            let here = self.commanded_point();
            self.planner.reset(here);
        }
    }

    /// What the drives get this tick: the commanded position, except on axes a lock holds.
    pub(super) fn drive_setpoint(&mut self) -> &[f64] {
        for (i, (d, c)) in self.drive.iter_mut().zip(&self.commanded).enumerate() {
            if self.locked & (1 << i) == 0 {
                *d = *c;
            }
        }
        &self.drive
    }

    /// Whether the slides stand at the setpoint. Under machine lock that is the held one,
    /// not the program's.
    pub(super) fn in_position(&self) -> bool {
        // Under machine lock the slides stand at the held setpoint, not at the program's.
        self.cfg.axes.iter().enumerate().all(|(i, a)| {
            let target = if self.locked & (1 << i) != 0 {
                self.drive[i]
            } else {
                self.commanded[i]
            };
            (self.actual[i] - target).abs() <= a.in_position
        })
    }
}
