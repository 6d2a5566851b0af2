//! Program flow: the call levels (the main program and the programs it calls), block-range
//! repeats, calls of a line range, counted loops and jumps. A front end decides which of its
//! words do what; the bookkeeping lives here once.

use std::ops::Range;
use std::sync::Arc;

use crate::canon::{Aux, Command};
use crate::error::{Fault, ProgramError};
use crate::state::Core;
use crate::text::{find_number, read_line, Pos};
use crate::variables::Value;

/// A loop or block-range repetition inside one program text.
#[derive(Debug, Clone)]
pub enum Repeat {
    /// Run lines up to and including the one numbered `last`, `remaining` more times (None:
    /// forever), then continue at `then` (None: after `last`), optionally returning to `home`.
    Range {
        first: Pos,
        last: u32,
        remaining: Option<u32>,
        then: Option<Pos>,
        home: Option<Vec<f64>>,
        /// Program end code of the block that started the range, run after it.
        end_code: Option<i32>,
    },
    /// A call of a line range by its first line, ended by a return.
    LineCall {
        first: Pos,
        remaining: u32,
        ret: Pos,
    },
    /// A counted loop from `first` to its loop end.
    Loop { first: Pos, remaining: u32 },
}

/// One call level: the main program or a called program.
#[derive(Debug, Clone)]
pub struct CallLevel {
    pub text: Arc<str>,
    /// What alarms call the program (empty for the main program).
    pub name: String,
    pub pos: Pos,
    /// Times the program still runs after this pass (a repeat count of the call).
    pub remaining: u32,
    pub repeats: Vec<Repeat>,
    /// The level's local variables; `None`: it works with its caller's (a subprogram on
    /// controls where only a macro call opens a level of locals).
    pub locals: Option<Vec<Value>>,
    /// Open condition loops: loop number and where the line that opened it starts.
    pub loops: Vec<(u32, Pos)>,
}

impl CallLevel {
    pub(crate) fn main(text: Arc<str>, locals: usize) -> CallLevel {
        CallLevel {
            text,
            name: String::new(),
            pos: Pos::default(),
            remaining: 0,
            repeats: Vec::new(),
            locals: Some(vec![None; locals]),
            loops: Vec::new(),
        }
    }
}

impl Core {
    /// The innermost call level.
    pub fn level(&mut self) -> &mut CallLevel {
        // There is always a main level: the last one is never popped.
        let last = self.levels.len() - 1;
        &mut self.levels[last]
    }

    /// The main program's line being run (the calling line while a called program runs).
    pub fn main_line(&self) -> u32 {
        self.levels[0].pos.line
    }

    /// The innermost call level, to read.
    pub fn current(&self) -> &CallLevel {
        &self.levels[self.levels.len() - 1]
    }

    /// Call levels in use (1: the main program).
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// The local variables the innermost level works with: its own, or those of the nearest
    /// caller that has its own.
    pub fn locals(&self) -> &[Value] {
        self.levels
            .iter()
            .rev()
            .find_map(|l| l.locals.as_deref())
            .unwrap_or(&[])
    }

    /// The local variables the innermost level works with, to write.
    pub fn locals_mut(&mut self) -> &mut [Value] {
        self.levels
            .iter_mut()
            .rev()
            .find_map(|l| l.locals.as_deref_mut())
            .unwrap_or(&mut [])
    }

    /// Reads the next line of the innermost level: its text and the line's byte range in it.
    /// The line becomes the one being run. `None` at the end of the text.
    pub fn next_line(&mut self) -> Option<(Arc<str>, Range<usize>)> {
        let level = self.level();
        let text = level.text.clone();
        let pos = level.pos;
        let (raw, next) = read_line(&text, pos)?;
        let start = raw.as_ptr() as usize - text.as_ptr() as usize;
        let range = start..start + raw.len();
        self.level().pos = next;
        self.block_start = pos;
        self.line = next.line;
        Some((text, range))
    }

    /// The line being run is read again next: a block that must wait for the machine before
    /// it runs (a preprocessing stop) runs once the machine has answered.
    pub fn read_line_again(&mut self) {
        let start = self.block_start;
        self.level().pos = start;
    }

    /// Any block has been read (a `%` opening a tape is only recognised before one).
    pub fn saw_any_block(&self) -> bool {
        self.line > 1 || self.levels.len() > 1
    }

    /// The main program's text ended without a program end.
    pub fn end_of_main(&mut self) -> Result<(), ProgramError> {
        if let (Some(text), false) = (self.rules.needs_end, self.saw_end) {
            return Err(self.fault(Fault::NoProgramEnd, text));
        }
        self.finish();
        Ok(())
    }

    /// The program ends: held elements are let go, then the program end.
    pub fn finish(&mut self) {
        // A chamfer with no move after it: the line runs to its corner (decision D31).
        let _ = self.resolve_corner(None);
        // Program end cancels compensation: the held element ends at its offset end.
        if let Some(mut comp) = self.comp.take() {
            let held = comp.held_line();
            let outs = comp.flush();
            let here = self.work_position();
            let _ = self.emit_outs(outs, &here, held);
        }
        self.hold_at = None;
        self.corner_slot = None;
        self.reserved = None;
        self.push(Command::ProgramEnd);
        self.done = true;
    }

    /// The program is over (nothing more is read).
    pub fn finished(&self) -> bool {
        self.done
    }

    /// Range repeats end after the line numbered `number` has run.
    pub fn after_line(&mut self, number: Option<u32>) -> Result<(), ProgramError> {
        let Some(n) = number else { return Ok(()) };
        loop {
            let level = self.level();
            let Some(Repeat::Range {
                first,
                last,
                remaining,
                then,
                home,
                end_code,
            }) = level.repeats.last().cloned()
            else {
                return Ok(());
            };
            if last != n {
                return Ok(());
            }
            match remaining {
                Some(r) if r <= 1 => {
                    level.repeats.pop();
                    if let Some(t) = then {
                        level.pos = t;
                    }
                    if let Some(home) = home {
                        self.rapid_to(&home);
                    }
                    if let Some(code) = end_code {
                        self.saw_end = true;
                        self.aux(Aux::M(code));
                        self.finish();
                        return Ok(());
                    }
                    // An enclosing range may end on the same line.
                    continue;
                }
                Some(r) => {
                    if let Some(Repeat::Range { remaining, .. }) = level.repeats.last_mut() {
                        *remaining = Some(r - 1);
                    }
                    level.pos = first;
                }
                None => {
                    if self.setup.single_pass {
                        self.finish();
                    } else {
                        self.level().pos = first;
                    }
                }
            }
            return Ok(());
        }
    }

    /// Goes on at the line numbered `n` of the innermost level.
    pub fn jump_to_number(&mut self, n: u32) -> Result<(), ProgramError> {
        let level = self.current();
        let pos = find_number(&level.text, level.pos, n)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("block N{n} not found")))?;
        self.level().pos = pos;
        Ok(())
    }

    /// Runs library program `number` `count` times as a called program with the given
    /// locals (`None`: the caller's); `what` names the caller in the alarm when the program
    /// is missing.
    pub fn call_program(
        &mut self,
        number: u32,
        count: u32,
        locals: Option<Vec<Value>>,
        what: &str,
    ) -> Result<(), ProgramError> {
        self.check_call_depth()?;
        let (name, text) = self.library.get(number).ok_or_else(|| {
            self.fault(
                Fault::UndefinedSubprogram,
                format!("{what} O{number:04} not in the library"),
            )
        })?;
        let name = name.to_string();
        self.push_level(name, text, count, locals);
        Ok(())
    }

    /// Runs the library program called `name` `count` times as a called program with the
    /// given locals (`None`: the caller's).
    pub fn call_named(
        &mut self,
        name: &str,
        count: u32,
        locals: Option<Vec<Value>>,
    ) -> Result<(), ProgramError> {
        self.check_call_depth()?;
        let (file, text) = self.library.get_named(name).ok_or_else(|| {
            self.fault(
                Fault::UndefinedSubprogram,
                format!("program {name} does not exist"),
            )
        })?;
        let file = file.to_string();
        self.push_level(file, text, count, locals);
        Ok(())
    }

    /// One more call level would nest deeper than the control allows.
    fn check_call_depth(&self) -> Result<(), ProgramError> {
        if self.levels.len() > self.rules.max_call_depth {
            return Err(self.fault(
                Fault::CallDepth,
                format!(
                    "subprograms nested deeper than {} levels",
                    self.rules.max_call_depth
                ),
            ));
        }
        Ok(())
    }

    fn push_level(&mut self, name: String, text: Arc<str>, count: u32, locals: Option<Vec<Value>>) {
        self.called
            .entry(name.clone())
            .or_insert_with(|| text.clone());
        self.levels.push(CallLevel {
            text,
            name,
            pos: Pos::default(),
            remaining: count.saturating_sub(1),
            repeats: Vec::new(),
            locals,
            loops: Vec::new(),
        });
    }

    /// A return: from a called program to its caller (or to its top for a further repeat);
    /// in the main program it starts over, or ends where the program must end.
    pub fn return_from_call(&mut self) {
        if self.levels.len() == 1 {
            if self.setup.single_pass {
                self.finish();
            } else {
                self.restart();
            }
            return;
        }
        let level = self.level();
        if level.remaining > 0 {
            level.remaining -= 1;
            level.pos = Pos::default();
            level.repeats.clear();
            level.loops.clear();
        } else {
            self.levels.pop();
        }
    }

    /// The innermost level starts over from its top.
    pub fn restart(&mut self) {
        let level = self.level();
        level.pos = Pos::default();
        level.repeats.clear();
    }
}
