//! The family's macro statements that move through the program: `GOTO n`, and the loops
//! `WHILE [cond] DO m` … `END m` (decision D49).

use cnc_interpreter_core::{read_line, Fault, Pos, ProgramError};

use super::expr::{truth, variable_number, Expr};
use super::syntax::{parse_line, Stmt};
use super::{Family, Fanuc};

/// Loop numbers DO and END may carry; three loops can nest.
const LOOP_IDS: std::ops::RangeInclusive<u32> = 1..=3;

impl<D: Family> Fanuc<D> {
    /// The variable number an expression names.
    pub fn var_number(&self, var: &Expr) -> Result<i64, ProgramError> {
        let v = var
            .eval(self)
            .map_err(|e| self.eval_err(e))?
            .ok_or_else(|| self.fault(Fault::MacroVariable, "variable number is null"))?;
        variable_number(v).map_err(|e| self.eval_err(e))
    }

    /// `GOTO n`: on at the block numbered n.
    pub(super) fn goto(&mut self, target: &Expr) -> Result<(), ProgramError> {
        let v = target
            .eval(self)
            .map_err(|e| self.eval_err(e))?
            .ok_or_else(|| self.fault(Fault::Macro, "GOTO to a null value"))?;
        let n = variable_number(v).map_err(|e| self.eval_err(e))?;
        if !(0..=99999).contains(&n) {
            return Err(self.fault(Fault::TargetNotFound, format!("GOTO {n}: no such block")));
        }
        self.core.jump_to_number(n as u32)
    }

    fn loop_id(&self, id: u32, word: &str) -> Result<(), ProgramError> {
        if LOOP_IDS.contains(&id) {
            Ok(())
        } else {
            Err(self.fault(
                Fault::MacroLoop,
                format!("{word}{id}: loop numbers are 1–3"),
            ))
        }
    }

    /// `WHILE [cond] DO m` (or `DO m`): while the condition holds the loop runs on; else the
    /// program goes on after `END m` (an alarm when there is none).
    pub(super) fn while_loop(&mut self, cond: Option<&Expr>, id: u32) -> Result<(), ProgramError> {
        self.loop_id(id, "DO")?;
        let go_on = match cond {
            Some(c) => truth(c.eval(self).map_err(|e| self.eval_err(e))?),
            None => true,
        };
        let start = self.core.block_start;
        let again = self.core.current().loops.contains(&(id, start));
        // Entering the loop: its END must be there, as when leaving it.
        let after_end = if again && go_on {
            None
        } else {
            Some(self.after_end(id)?)
        };
        let level = self.core.level();
        // Coming round again (or after a GOTO out of the loop): the loop starts afresh.
        if let Some(k) = level.loops.iter().position(|&(m, _)| m == id) {
            level.loops.truncate(k);
        }
        match after_end {
            Some(pos) if !go_on => level.pos = pos,
            _ => level.loops.push((id, start)),
        }
        Ok(())
    }

    /// Where the program goes on after the `END m` that closes the loop being read.
    fn after_end(&self, id: u32) -> Result<Pos, ProgramError> {
        let level = self.core.current();
        let mut pos = level.pos;
        while let Some((raw, next)) = read_line(&level.text, pos) {
            if parse_line(raw, true).map(|l| l.stmt) == Ok(Stmt::End(id)) {
                return Ok(next);
            }
            pos = next;
        }
        Err(self.fault(Fault::MacroEnd, format!("WHILE … DO{id} has no END{id}")))
    }

    /// `END m`: back to the `WHILE … DO m` that opened the loop.
    pub(super) fn end_loop(&mut self, id: u32) -> Result<(), ProgramError> {
        self.loop_id(id, "END")?;
        let level = self.core.level();
        let Some(k) = level.loops.iter().rposition(|&(m, _)| m == id) else {
            return Err(self.fault(Fault::MacroLoop, format!("END{id} without DO{id}")));
        };
        // Inner loops end here; this one stays open for its WHILE to test again.
        let (_, start) = level.loops[k];
        level.loops.truncate(k + 1);
        level.pos = start;
        Ok(())
    }
}
