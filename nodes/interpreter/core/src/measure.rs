//! Measuring moves: a straight line during which the touch probe's edge latches every axis
//! (MEAS/MEAW, a skip move). Where the axes end is the machine's to say: with delete
//! distance to go they stop short of the line's end. So after a measuring move the program
//! reads on only once the result has come ([`Core::measured`]); until then
//! [`crate::next_command`] has nothing to give. Without a machine (a check, a simulation, a
//! block search) the probe is taken as switching at the line's end, so the rest of the
//! program is read as on a part that is where the program expects it (decisions D116).

use crate::emit::MoveKind;
use crate::error::{Fault, ProgramError};
use crate::state::Core;

/// A measuring move's result, in machine coordinates (X as diameter on a diameter axis).
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The probe switched during the move.
    pub triggered: bool,
    /// Every axis where the probe switched (where the axes came to rest if it did not).
    pub position: Vec<f64>,
    /// Where the axes came to rest.
    pub rest: Vec<f64>,
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
        if self.measure_on_machine {
            self.awaiting_measurement = true;
        } else {
            self.measured_at = Some(self.pos.clone());
            self.measurement = Some(Measurement {
                triggered: true,
                position: self.pos.clone(),
                rest: self.pos.clone(),
            });
        }
        Ok(())
    }

    /// Whether a measuring move waits for its result.
    pub fn awaiting_measurement(&self) -> bool {
        self.awaiting_measurement
    }

    /// The machine's result of the measuring move: the program goes on from where the axes
    /// came to rest. A result that does not name every axis with a number is an alarm.
    pub fn measured(&mut self, m: Measurement) -> Result<(), ProgramError> {
        let n = self.pos.len();
        let whole = |v: &[f64]| v.len() == n && v.iter().all(|x| x.is_finite());
        if !whole(&m.rest) || !whole(&m.position) {
            let e = self.fault(
                Fault::OutOfRange,
                format!(
                    "the measurement names {} and {} axis values, the machine has {n}",
                    m.position.len(),
                    m.rest.len()
                ),
            );
            // An error stops the run for good (`driver.rs`).
            self.error = Some(e.clone());
            self.pending.clear();
            return Err(e);
        }
        self.pos.clone_from(&m.rest);
        if m.triggered {
            self.measured_at = Some(m.position.clone());
        }
        self.measurement = Some(m);
        self.awaiting_measurement = false;
        Ok(())
    }
}
