//! The T word and the tool-change macro (§4.1.5, §4.3.1–4.3.3): with S#170 set, a T word
//! calls a program with #1 the current tool, #2 the current offset, #3 the target tool, #4 the
//! target offset; the macro's own M codes read the tool, set the offset, send the tool to the
//! PLC and raise alarms.

use cnc_interpreter_core::{Aux, Fault, ProgramError};

use super::Huaxing;
use crate::fanuc::block::Block;
use crate::fanuc::lathe::MAX_OFFSET;
use crate::fanuc::{Family, Fanuc};

/// The codes a tool-change macro program uses (§4.3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolMacro {
    /// M52 Kn: the current tool number into local variable #n.
    ReadTool,
    /// M53 / M53.1 K: make K the active tool-offset number.
    SetOffset,
    /// M54: wait until execution has caught up with interpretation.
    Sync,
    /// M57 K: the target tool to the PLC with the T strobe.
    ToolToPlc,
    /// M58 Kn: raise alarm number n.
    RaiseAlarm,
    /// M14.n: the spindle into position control, its angle axis n's coordinate (§4.2.7, D138).
    PositionMode(u8),
    /// M29 S: rigid tapping with the tapping spindle in position control (§5.23.4, D142).
    RigidTapping,
    /// M66: the live tool out of speed mode into position control (§4.1.5, D143).
    LiveToolPosition,
}

impl Fanuc<Huaxing> {
    /// T word: `Tmmnn` (tool mm, offset nn; `T1` = tool 1 offset 1, decision D16); with a
    /// tool-change macro set, the T word calls it.
    pub(super) fn huaxing_tool_word(&mut self, t: f64) -> Result<(), ProgramError> {
        let (tool, offset) = self.lathe_tool_numbers(t)?;
        if offset > MAX_OFFSET {
            return Err(self.fault(
                Fault::ToolNumber,
                format!("offset number {offset} out of range"),
            ));
        }
        if let Some(program) = self
            .core
            .setup
            .tool_change_macro
            .filter(|_| self.d.tool_macro_depth.is_none())
        {
            return self.call_tool_macro(program, tool.unwrap_or(0), offset);
        }
        self.select_tool(tool, offset)
    }

    /// Calls the tool-change macro with #1 the current tool, #2 the current offset, #3 the
    /// target tool, #4 the target offset.
    fn call_tool_macro(
        &mut self,
        program: u32,
        tool: u32,
        offset: u32,
    ) -> Result<(), ProgramError> {
        let mut locals = vec![None; Huaxing::LOCALS];
        for (i, v) in [self.tool, self.offset_number, tool, offset]
            .into_iter()
            .enumerate()
        {
            locals[i + 1] = Some(v as f64);
        }
        self.core
            .call_program(program, 1, Some(locals), "tool-change macro")?;
        self.d.tool_macro_depth = Some(self.core.depth());
        Ok(())
    }
}

impl<D: Family<M = ToolMacro>> Fanuc<D> {
    /// M52/M53/M54/M57/M58 of a tool-change macro (§4.3.3).
    pub fn tool_macro_code(&mut self, op: ToolMacro, b: &Block<D>) -> Result<(), ProgramError> {
        let k = || {
            b.get('K')
                .filter(|v| v.fract() == 0.0 && *v >= 0.0 && *v <= 9999.0)
                .map(|v| v as u32)
        };
        let need_k = |me: &Self| {
            k().ok_or_else(|| me.fault(Fault::MissingWord, "the code needs K, a whole number"))
        };
        match op {
            ToolMacro::ReadTool => {
                let n = need_k(self)?;
                if !(1..=40).contains(&n) {
                    return Err(self.fault(Fault::OutOfRange, format!("M52 K{n}: #1–#40")));
                }
                let tool = self.tool as f64;
                D::write_var(self, n as i64, Some(tool))
            }
            ToolMacro::SetOffset => {
                let n = need_k(self)?;
                if n > MAX_OFFSET {
                    return Err(
                        self.fault(Fault::ToolNumber, format!("offset number {n} out of range"))
                    );
                }
                self.apply_offset(n);
                Ok(())
            }
            // Execution follows the program in order here; the tool M52 reads is the one the
            // PLC confirmed (its FIN comes before motion goes on).
            ToolMacro::Sync => Ok(()),
            ToolMacro::ToolToPlc => {
                let n = need_k(self)?;
                if n == 0 || n > 99 {
                    return Err(self.fault(Fault::ToolNumber, format!("M57 K{n}: tool 1–99")));
                }
                self.core.aux(Aux::T(n as i32));
                self.tool = n;
                Ok(())
            }
            ToolMacro::PositionMode(n) => self.position_mode(n),
            // The Huaxing takes M29 itself (`rigid_tap.rs`); no other dialect has it.
            ToolMacro::RigidTapping => Ok(()),
            ToolMacro::LiveToolPosition => self.core.live_tool_speed(0.0),
            ToolMacro::RaiseAlarm => {
                let n = need_k(self)?;
                let mut e = self.fault(
                    Fault::ToolNumber,
                    format!("alarm {n} raised by the tool-change macro (M58 K{n})"),
                );
                e.number = n;
                Err(e)
            }
        }
    }
}
