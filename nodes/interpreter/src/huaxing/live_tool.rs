//! The live tool on the Huaxing turn-mill (`000` §5.9; decision D142): G14.n taps with the
//! live tool, axis n (1…6 for X…C) the machine's live tool, R its speed, D the dwell at the
//! bottom, F the metric pitch (I threads per inch); the slides move to the block's point
//! while the tool turns (any two slides: a slanted thread), dwell, and come back turning the
//! other way. G14 is modal: each following block with a position taps again. No program
//! word moves the live tool's axis itself.
//!
//! Speed mode (§4.1.5's M65/M66, decision D143): on a machine with a live tool, `M65 S…`
//! turns it at S r/min for drilling and milling, and while it turns every S word is its
//! speed; M66 stops it into position control, and so does M05 (B12.7 = 0: it stops with the
//! spindle). A machine without one keeps M65 as the second spindle's stop.

use cnc_interpreter_core::{show, Command, Fault, ProgramError};

use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

/// G14's modal words.
#[derive(Debug, Clone, Copy, Default)]
pub struct LiveTapWords {
    /// R: the live tool's speed, r/min.
    rpm: Option<f64>,
    /// D: the dwell at the bottom, s.
    dwell: f64,
    /// F (mm) or I (threads per inch): the pitch, signed (− a left-hand thread).
    lead: Option<f64>,
}

impl Fanuc<Huaxing> {
    /// Takes G14's modal words R, D and F/I.
    pub(super) fn live_tap_words(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        if let Some(r) = b.get('R') {
            self.d.live_tap.rpm = Some(r);
        }
        if let Some(d) = b.get('D') {
            if !(0.0..=9999.999).contains(&d) {
                return Err(self.fault(
                    Fault::DwellTime,
                    format!("G14 D{}: the dwell at the bottom, 0–9999.999 s", show(d)),
                ));
            }
            self.d.live_tap.dwell = d;
        }
        match (b.get('F'), b.get('I')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::ThreadLead, "G14 with both F and I"));
            }
            (Some(f), None) => self.d.live_tap.lead = Some(f),
            (None, Some(i)) if i != 0.0 => self.d.live_tap.lead = Some(25.4 / i),
            (None, Some(_)) => {
                return Err(self.fault(Fault::ThreadLead, "G14 I0: no threads per inch"));
            }
            (None, None) => {}
        }
        Ok(())
    }

    /// G14.n to the block's point and back.
    pub(super) fn live_tap(&mut self, b: &Block<Huaxing>, n: u8) -> Result<(), ProgramError> {
        match self.core.setup.live_tool {
            Some(t) if t.number == n => {}
            _ => {
                return Err(self.fault(
                    Fault::RotaryAxis,
                    format!("G14.{n}: axis {n} is not a live tool of this machine"),
                ))
            }
        }
        let words = self.d.live_tap;
        let rpm = words
            .rpm
            .ok_or_else(|| self.fault(Fault::MissingWord, "G14 needs R, the live tool's speed"))?;
        let lead = words
            .lead
            .ok_or_else(|| self.fault(Fault::ThreadLead, "G14 needs the pitch F (or I)"))?;
        let here = self.core.work_position();
        let end = self.end_point(b)?;
        self.core.live_tool_tap(&end, lead, rpm)?;
        if words.dwell > 0.0 {
            self.core.push(Command::Dwell {
                seconds: words.dwell,
            });
        }
        self.core.live_tool_tap(&here, -lead, rpm)?;
        Ok(())
    }

    /// The live tool's axis is turned by taps only: its address is no word of a program.
    pub(super) fn live_tool_words(&self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        match self.core.setup.live_tool {
            Some(t) if b.has(t.letter) => Err(self.fault(
                Fault::RotaryAxis,
                format!(
                    "address {}: the live tool turns in a tap (G14.{}), not by a word",
                    t.letter, t.number
                ),
            )),
            _ => Ok(()),
        }
    }

    /// The S word of an `M65` block, or any S while the live tool turns: its speed (D143).
    /// True when the S was the live tool's.
    pub(super) fn live_tool_speed_word(
        &mut self,
        b: &Block<Huaxing>,
    ) -> Result<bool, ProgramError> {
        if self.core.setup.live_tool.is_none() {
            return Ok(false);
        }
        let m65 = b.m.iter().any(|&(_, code)| code == 650);
        // M29's S is the tap's speed, and a tap needs the tool in position control.
        if b.m.iter().any(|&(_, code)| code == 290) && self.core.live_tool_rpm > 0.0 {
            return Err(self.fault(
                Fault::LiveToolSpeed,
                "M29: a tap needs the live tool in position control; it turns in speed mode \
                 (M66 first)",
            ));
        }
        // G50's S is the spindle's clamp, G96/G97's its surface speed or r/min: never the
        // live tool's.
        let spindles = b.has_g(G::SetCoordinate) || b.group(2).is_some();
        match b.get('S').filter(|_| !spindles) {
            Some(s) if s > 0.0 && (m65 || self.core.live_tool_rpm > 0.0) => {
                self.core.live_tool_speed(s)?;
                Ok(true)
            }
            Some(_) | None if m65 => Err(self.fault(
                Fault::LiveToolSpeed,
                "M65 turns the live tool at the block's S: a speed above 0 r/min",
            )),
            Some(s) if self.core.live_tool_rpm > 0.0 => Err(self.fault(
                Fault::LiveToolSpeed,
                format!(
                    "S{}: the live tool turns in speed mode; M66 stops it",
                    show(s)
                ),
            )),
            _ => Ok(false),
        }
    }

    /// An M code of the table the live tool takes (D143): M65 is its speed mode (its S was
    /// taken with the block's S), M05 stops it with the spindle (B12.7 = 0). True when the
    /// PLC does not get the code.
    pub(super) fn live_tool_m(&mut self, code: u32) -> Result<bool, ProgramError> {
        if self.core.setup.live_tool.is_none() {
            return Ok(false);
        }
        match code {
            650 => Ok(true),
            50 => self.core.live_tool_speed(0.0).map(|()| false),
            _ => Ok(false),
        }
    }
}
