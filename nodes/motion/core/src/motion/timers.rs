//! The run-time timers (SINUMERIK `001` §9.12.1, decisions D121), counted in servo periods:
//! the machine's own clock, so that they are what the machine did, the same on a busy host
//! and in a test on the simulated clock. The program reads them at a preprocessing stop
//! ([`Command::Sync`](crate::block::Command::Sync)): motion reports that block done once
//! every block before it has finished, and its status carries the timers.

use super::{Active, BlockResult, Motion};

/// The timers, seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunTimers {
    /// The tool engaged: feed moves (lines, arcs, threads, tapping, measuring lines) of every
    /// program since power-on; not rapids, dwells or auxiliary functions (`$AC_CUTTING_TIME`).
    pub cutting: f64,
    /// The program started last, from its start to its end or reset (`$AC_CYCLE_TIME`).
    pub cycle: f64,
    /// Every program since power-on (`$AC_OPERATING_TIME`).
    pub operating: f64,
    /// Since power-on, always (`$AN_POWERON_TIME` in minutes).
    pub power_on: f64,
}

impl Motion {
    /// The timers as they stand.
    pub fn timers(&self) -> RunTimers {
        self.timers
    }

    /// One servo period of `dt` seconds since power-on, whatever the machine does.
    pub(super) fn count_power_on(&mut self, dt: f64) {
        self.timers.power_on += dt;
    }

    /// One servo period of `dt` seconds in automatic operation. A program's time counts while
    /// it runs: not while it is held (feed hold, M00/M01, single block), stopped by an alarm,
    /// its feed override at 0 (the manual: "interrupted on program stop or feed override 0"),
    /// or run as a test under dry run or machine lock (the machine data's default).
    pub(super) fn count_run_time(&mut self, dt: f64) {
        let held = self.feed_hold || self.block_stop || self.alarm || self.emergency_stop;
        let test = self.panel.dry_run || self.panel.machine_lock;
        if !self.program_running || held || test || self.panel.feed_override <= 0.0 {
            return;
        }
        self.timers.cycle += dt;
        self.timers.operating += dt;
        let cutting = matches!(
            self.active,
            Some((_, Active::Path | Active::Thread { .. } | Active::Tap(_)))
        );
        if cutting {
            self.timers.cutting += dt;
        }
    }

    /// A new program starts: its cycle time from 0.
    pub(super) fn start_program_time(&mut self) {
        self.program_running = true;
        self.timers.cycle = 0.0;
    }

    /// The preprocessing stop `seq` is reached (every block before it done): its result is
    /// where the axes stand; the status that reports it carries the timers.
    pub(super) fn sync_reached(&mut self, seq: u64) {
        let at = self.display_point(&self.commanded);
        self.block_result = Some(BlockResult {
            seq,
            triggered: true,
            position: at,
            rest: at,
        });
    }
}
