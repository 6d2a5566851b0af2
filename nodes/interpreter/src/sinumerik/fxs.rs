//! Travel to a fixed stop, `FXS[axis]=1/0`, `FXST[axis]=…`, `FXSW[axis]=…` and `$AA_FXS`
//! (`001` §9.3.23, fixtures 044/045, decisions D118). The selection and the travel stand in
//! one block: the axis's drive runs torque-limited into the stop, the move ends there (its
//! rest dropped) and the program reads on from where the machine says the axes stopped. The
//! torque and the window are setting data: a programmed value holds from its block on, for
//! this program's run; unprogrammed, the machine data's defaults hold. The deselection block
//! carries the move away from the stop.

use cnc_interpreter_core::measure::FixedStop;
use cnc_interpreter_core::{Fault, ProgramError};

use super::exec::Words;
use super::expr::Expr;
use super::{Motion, Sinumerik};

/// The clamping torque without FXST, percent of the drive's maximum (the machine data's
/// default, MD37010).
pub const DEFAULT_TORQUE: f64 = 5.0;
/// The monitoring window without FXSW, mm or degrees (MD37020).
pub const DEFAULT_WINDOW: f64 = 1.0;

impl Sinumerik {
    /// `FXS[axis]=…`, `FXST[axis]=…`, `FXSW[axis]=…`: a selection into the block's words, a
    /// torque or window into the setting data at once (they act before the block's move).
    pub(super) fn fixed_stop_word(
        &mut self,
        w: &mut Words,
        name: &str,
        index: &[Expr],
        value: &Expr,
    ) -> Result<(), ProgramError> {
        let axis = match index {
            [e] => self.axis_argument(name, &Some(e.clone()))?,
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    format!("{name}[axis]: the machine axis it acts on (Z1, X1, …)"),
                ))
            }
        };
        let v = self.number(value)?;
        match name {
            "FXS" => {
                let on = match v {
                    1.0 => true,
                    0.0 => false,
                    _ => {
                        return Err(self.fault(
                            Fault::OutOfRange,
                            "FXS[axis]=1 selects travel to a fixed stop, =0 deselects it",
                        ))
                    }
                };
                if w.fxs.is_some() {
                    return Err(self.fault(
                        Fault::SameGroup,
                        "one FXS selection or deselection per block",
                    ));
                }
                w.fxs = Some((axis, on));
            }
            "FXST" => {
                if !(v > 0.0 && v <= 100.0) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        "FXST: the clamping torque is > 0 … 100 % of the drive's maximum",
                    ));
                }
                self.fxs_torque[axis] = v;
            }
            _ => {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        "FXSW: the monitoring window is above 0 (mm or degrees)",
                    ));
                }
                self.fxs_window[axis] = v;
            }
        }
        Ok(())
    }

    /// The block's axes may move: one at its stop moves only with its deselection.
    pub(super) fn check_clamped_axes(&self, w: &Words) -> Result<(), ProgramError> {
        if !self.core.fixed_stops.contains(&FixedStop::AtStop) {
            return Ok(());
        }
        for (&i, _) in w.axes.iter() {
            let leaving = w.fxs == Some((i, false));
            if self.core.fixed_stops.get(i) == Some(&FixedStop::AtStop) && !leaving {
                return Err(self.fault(
                    Fault::IllegalWord,
                    format!(
                        "{} stands at its fixed stop: FXS[{}]=0 in the block that moves it",
                        self.core.setup.axes[i], self.core.setup.axes[i]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The block's FXS around its move to `end`: a selection makes the move (true: the move
    /// is done); a deselection lifts the stop before the move that follows.
    pub(super) fn fixed_stop_move(&mut self, w: &Words, end: &[f64]) -> Result<bool, ProgramError> {
        let Some((axis, on)) = w.fxs else {
            return Ok(false);
        };
        if !on {
            self.core.leave_fixed_stop(axis)?;
            return Ok(false);
        }
        if !w.axes.iter().any(|(i, _)| *i == axis) {
            return Err(self.fault(
                Fault::MissingWord,
                format!(
                    "FXS[{0}]=1: {0} travels to its stop in this block (program {0})",
                    self.core.setup.axes[axis]
                ),
            ));
        }
        if self.core.fixed_stops[axis] == FixedStop::AtStop {
            return Err(self.fault(
                Fault::IllegalWord,
                format!(
                    "{} is at its fixed stop already: FXS[…]=0 first",
                    self.core.setup.axes[axis]
                ),
            ));
        }
        // The move goes out at once and the program waits for it: nothing may hold it back
        // (a chamfer or rounding at its end waits for the next block, which is not read).
        if self.corner.is_some() || self.core.holding() {
            return Err(self.fault(
                Fault::NotSupported,
                "a travel to a fixed stop takes no chamfer or rounding, before or after it",
            ));
        }
        if self.motion != Motion::Line || self.core.cylinder.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "travel to a fixed stop is a G1 line here (not G0, circles or under TRACYL)",
            ));
        }
        self.no_wait_in_fifo("FXS")?;
        let (torque, window) = (self.fxs_torque[axis], self.fxs_window[axis]);
        let feed = self.core.feed;
        self.core.to_fixed_stop(end, feed, axis, torque, window)?;
        self.tangent = None;
        Ok(true)
    }
}
