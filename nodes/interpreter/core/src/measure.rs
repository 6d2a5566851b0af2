//! Blocks whose end the machine decides: a measuring move (a straight line during which the
//! touch probe's edge latches every axis: MEAS/MEAW, a skip move) and a travel to a fixed
//! stop (the move ends where the axis meets the stop). With delete distance to go the axes
//! stop short of the programmed end, so the program reads on only once the machine's result
//! has come ([`Core::machine_result`]); until then [`crate::next_command`] has nothing to
//! give. Without a machine (a check, a simulation, a block search) the event is taken as
//! coming at the move's end, so the rest of the program is read as on a part that is where
//! the program expects it (decisions D116, D118). A preprocessing stop that reads the
//! machine's run-time timers (`Sync`, D121) waits the same way; nothing moves in it.

use crate::canon::Command;
use crate::emit::MoveKind;
use crate::error::{Fault, ProgramError};
use crate::state::Core;

/// A block's result from the machine, in machine coordinates (X as diameter on a diameter
/// axis).
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The event came: the probe switched, the fixed stop was reached.
    pub triggered: bool,
    /// Every axis at the event (where the axes came to rest if none came).
    pub position: Vec<f64>,
    /// Where the axes came to rest.
    pub rest: Vec<f64>,
    /// The machine's run-time timers when it reported the block (`None` without a machine).
    pub timers: Option<MachineTimers>,
}

/// The machine's run-time timers, seconds (decisions D121): what a preprocessing stop that
/// reads the machine ([`Core::sync_with_machine`]) found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MachineTimers {
    /// Tool-engaged feed time of every program since power-on.
    pub cutting: f64,
    /// Run time of the program started last.
    pub cycle: f64,
    /// Run time of every program since power-on.
    pub operating: f64,
    /// Time since power-on.
    pub power_on: f64,
}

/// An axis's travel to a fixed stop as the program sees it; the values are the ones a
/// control's status variable reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FixedStop {
    #[default]
    Off = 0,
    AtStop = 1,
    NotReached = 2,
    Selected = 3,
}

/// What the program waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Awaited {
    Measurement,
    /// The travel of this axis to its fixed stop.
    FixedStop(usize),
    /// A preprocessing stop that reads the machine (its timers).
    Sync,
}

impl Core {
    /// A measuring line to work position `end` at `feed`: the probe's rising edge (or
    /// falling) latches the axes; `stop` brakes there and drops the rest of the line.
    pub fn measure(
        &mut self,
        end: &[f64],
        feed: f64,
        rising: bool,
        stop: bool,
    ) -> Result<(), ProgramError> {
        if self.comp.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "a measuring move under radius compensation is not built: cancel it first",
            ));
        }
        self.measurement = None;
        self.emit(end, MoveKind::Probe { feed, rising, stop })?;
        self.await_machine(Awaited::Measurement)
    }

    /// A line to work position `end` at `feed` with `axis` travelling to its fixed stop,
    /// its drive's torque limited to `torque` percent, then watched within `window`.
    pub fn to_fixed_stop(
        &mut self,
        end: &[f64],
        feed: f64,
        axis: usize,
        torque: f64,
        window: f64,
    ) -> Result<(), ProgramError> {
        let axis_code = u8::try_from(axis)
            .map_err(|_| self.fault(Fault::AxisAddress, "no such axis for a fixed stop"))?;
        if self.comp.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "travel to a fixed stop under radius compensation is not built: cancel it first",
            ));
        }
        self.push(Command::FixedStop {
            axis: axis_code,
            on: true,
            torque,
            window,
        });
        self.fixed_stops[axis] = FixedStop::Selected;
        self.emit(end, MoveKind::Feed(feed))?;
        self.await_machine(Awaited::FixedStop(axis))
    }

    /// Lifts `axis`'s fixed stop before the move the caller emits next (which must leave it).
    pub fn leave_fixed_stop(&mut self, axis: usize) -> Result<(), ProgramError> {
        let axis_code = u8::try_from(axis)
            .map_err(|_| self.fault(Fault::AxisAddress, "no such axis for a fixed stop"))?;
        self.push(Command::FixedStop {
            axis: axis_code,
            on: false,
            torque: 100.0,
            window: 1.0,
        });
        self.fixed_stops[axis] = FixedStop::Off;
        Ok(())
    }

    /// A preprocessing stop that reads the machine: every command before it runs to its end,
    /// then the machine reports its timers ([`Core::machine_timers`]); the program reads on
    /// after that. The block that asked is read again then ([`Core::read_line_again`]).
    /// Without a machine the timers stay as they were.
    pub fn sync_with_machine(&mut self) -> Result<(), ProgramError> {
        self.push(Command::Sync);
        self.await_machine(Awaited::Sync)
    }

    /// The timers the last preprocessing stop read, taken once.
    pub fn machine_timers(&mut self) -> Option<MachineTimers> {
        self.timers_read.take()
    }

    /// After a block whose end the machine decides, its move the last command queued: wait
    /// for its result, or without a machine take the event as coming at the move's end.
    fn await_machine(&mut self, what: Awaited) -> Result<(), ProgramError> {
        // The move's number among the program's commands, from 1.
        let number = self.emitted + self.pending.len() as u64;
        self.awaiting = Some((what, number));
        if self.on_machine {
            Ok(())
        } else {
            let at = self.pos.clone();
            self.machine_result(Measurement {
                triggered: true,
                position: at.clone(),
                rest: at,
                timers: None,
            })
        }
    }

    /// Whether the program waits for the machine's result of a block.
    pub fn awaiting_machine(&self) -> bool {
        self.awaiting.is_some()
    }

    /// The number (from 1, among the program's commands) of the move whose result the
    /// program waits for.
    pub fn awaited_command(&self) -> Option<u64> {
        self.awaiting.map(|(_, number)| number)
    }

    /// The machine's result of the block the program waits for: the program goes on from
    /// where the axes came to rest. A result that does not name every axis with a number is
    /// an alarm.
    pub fn machine_result(&mut self, mut m: Measurement) -> Result<(), ProgramError> {
        let n = self.pos.len();
        // A turn-mill's C and live tool (the program's last axes, D141, D142) are spindles,
        // which the machine's result does not name: they stay where the program has them.
        let spindles = usize::from(self.setup.spindle_c_axis && self.axis('C').is_some())
            + usize::from(self.setup.live_tool.is_some());
        for v in [&mut m.position, &mut m.rest] {
            if v.len() + spindles == n {
                let k = v.len();
                v.extend_from_slice(&self.pos[k..]);
            }
        }
        let whole = |v: &[f64]| v.len() == n && v.iter().all(|x| x.is_finite());
        if !whole(&m.rest) || !whole(&m.position) {
            let e = self.fault(
                Fault::OutOfRange,
                format!(
                    "the machine's result names {} and {} axis values, the machine has {n}",
                    m.position.len(),
                    m.rest.len()
                ),
            );
            // An error stops the run for good (`driver.rs`).
            self.error = Some(e.clone());
            self.pending.clear();
            return Err(e);
        }
        let what = self.awaiting.take().map(|(what, _)| what);
        if what == Some(Awaited::Sync) {
            // Nothing moved: the position stays the program's (under TRACYL it is not the
            // machine's).
            self.timers_read = m.timers;
            return Ok(());
        }
        self.pos.clone_from(&m.rest);
        match what {
            Some(Awaited::Measurement) => {
                if m.triggered {
                    self.measured_at = Some(m.position.clone());
                }
                self.measurement = Some(m);
            }
            Some(Awaited::FixedStop(axis)) => {
                if let Some(s) = self.fixed_stops.get_mut(axis) {
                    *s = if m.triggered {
                        FixedStop::AtStop
                    } else {
                        FixedStop::NotReached
                    };
                }
            }
            Some(Awaited::Sync) | None => {}
        }
        Ok(())
    }
}
