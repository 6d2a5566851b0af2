//! The live tool. A tap with it (decision D142): the slides go to the hole's end while the
//! live tool turns the tap's turns, as one machine line of the slides and the tool's angle,
//! so the interpolation itself gears them (any two slides may move: a slanted thread). Its
//! speed mode (D143): it turns at a speed for drilling and milling while the slides feed,
//! and stands in position control again at speed 0.

use crate::canon::Command;
use crate::error::{Fault, ProgramError};
use crate::show;
use crate::state::Core;

impl Core {
    /// The slides to the work point `end` with the live tool turning `lead` mm a turn (signed,
    /// positive the tool's positive way) at `rpm`; the tool's angle goes on by the tap's
    /// degrees, which it returns.
    pub fn live_tool_tap(&mut self, end: &[f64], lead: f64, rpm: f64) -> Result<f64, ProgramError> {
        let Some(tool) = self.setup.live_tool else {
            return Err(self.fault(Fault::RotaryAxis, "this machine has no live tool"));
        };
        let Some(a) = self.axis(tool.letter) else {
            return Err(self.fault(Fault::RotaryAxis, "this machine has no live tool"));
        };
        if self.live_tool_rpm > 0.0 {
            return Err(self.fault(
                Fault::LiveToolSpeed,
                "a tap needs the live tool in position control: it turns in speed mode (M66 \
                 first)",
            ));
        }
        if self.comp.is_some() || self.polar.is_some() || self.cylinder.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                "a live tool tap runs with no compensation or transformation on",
            ));
        }
        if !(lead.is_finite() && lead != 0.0) {
            return Err(self.fault(
                Fault::ThreadLead,
                format!("tapping pitch {} is not valid", show(lead)),
            ));
        }
        self.check_live_tool_rpm(tool.max_rpm, rpm)?;
        let mut m = self.to_machine(end);
        m[a] = self.pos[a];
        // The slides' travel in mm (a diameter axis counts half), the tool's turns from it.
        let length = (0..m.len())
            .filter(|&i| i != a)
            .map(|i| ((m[i] - self.pos[i]) * self.axis_scale(i)).powi(2))
            .sum::<f64>()
            .sqrt();
        let degrees = 360.0 * length / lead;
        if !(degrees.is_finite() && degrees.abs() <= 2_000_000.0) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("a tap of {}° of the live tool", show(degrees)),
            ));
        }
        m[a] += degrees;
        // The feed along the machine line (slides and degrees) that turns the tool at rpm.
        let minutes = degrees.abs() / 360.0 / rpm;
        let feed = if minutes > 0.0 {
            length.hypot(degrees) / minutes
        } else {
            return Ok(0.0);
        };
        self.pos.copy_from_slice(&m);
        self.push(Command::Linear { end: m, feed });
        Ok(degrees)
    }

    /// The live tool into speed mode at `rpm` (its positive way), or at 0 out of it: it
    /// stands again in position control. Above 0 and at most the tool's top speed.
    pub fn live_tool_speed(&mut self, rpm: f64) -> Result<(), ProgramError> {
        let Some(tool) = self.setup.live_tool else {
            return Err(self.fault(Fault::RotaryAxis, "this machine has no live tool"));
        };
        if rpm != 0.0 {
            self.check_live_tool_rpm(tool.max_rpm, rpm)?;
        }
        if rpm != self.live_tool_rpm {
            self.live_tool_rpm = rpm;
            self.push(Command::LiveTool { rpm });
        }
        Ok(())
    }

    /// A live tool speed must be above 0 and at most the tool's top speed (S#122): alarm 73.
    fn check_live_tool_rpm(&self, max_rpm: f64, rpm: f64) -> Result<(), ProgramError> {
        match rpm > 0.0 && rpm <= max_rpm {
            true => Ok(()),
            false => Err(self.fault(
                Fault::LiveToolSpeed,
                format!(
                    "live tool speed {} r/min: above 0 and at most {}",
                    show(rpm),
                    show(max_rpm)
                ),
            )),
        }
    }
}
