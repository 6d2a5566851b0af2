//! The interpreter as the rest of the cell sees it: a program in a dialect, run by that
//! dialect's front end over the core, yielding canonical commands one at a time.
//!
//! Pure and streaming: it holds the program text and a cursor, and produces commands only as
//! they are asked for, so the motion queue's credit decides how far ahead it reads. An error
//! stops it for good: nothing after the bad line is produced, and nothing of the bad block.

use cnc_interpreter_core::{
    next_command, Canon, Fault, Library, Measurement, ProgramError, ServiceOutput, Setup,
};

use crate::dialect::{Dialect, Engine};
use crate::setup::Memory;

/// Most commands a check collects: a program that jumps back forever must end a check with an
/// alarm, not hang it.
pub const MAX_CHECK_COMMANDS: usize = 5_000_000;

/// Streaming interpreter for one program run.
pub struct Interpreter {
    front: Box<dyn Engine>,
}

impl Interpreter {
    pub fn new(dialect: Dialect, text: &str, setup: Setup) -> Self {
        Interpreter::with_library(dialect, text, setup, Library::new())
    }

    pub fn with_library(dialect: Dialect, text: &str, setup: Setup, library: Library) -> Self {
        Interpreter {
            front: dialect.front_end(text, setup, library),
        }
    }

    /// The block-skip switch: blocks read from now on that begin with `/` are skipped (on) or
    /// run (off). Blocks already read stay as they were read, as on the control.
    pub fn set_block_skip(&mut self, on: bool) {
        self.front.core_mut().setup.block_skip = on;
    }

    /// The next canonical command; `Ok(None)` once the program has ended.
    pub fn next_command(&mut self) -> Result<Option<Canon>, ProgramError> {
        next_command(&mut *self.front)
    }

    /// Measuring moves wait for the machine's result (`on`), or take the probe as switching
    /// at the line's end (a check or simulation: decisions D116).
    pub fn on_machine(&mut self, on: bool) {
        self.front.core_mut().on_machine = on;
    }

    /// The number (from 1, among the program's commands) of the move whose result from the
    /// machine the program waits for.
    pub fn awaited_command(&self) -> Option<u64> {
        self.front.core().awaited_command()
    }

    /// The machine's result of the measuring move the program waits for; an alarm (which
    /// ends the run) when it does not fit the machine.
    pub fn machine_result(&mut self, m: Measurement) -> Result<(), ProgramError> {
        self.front.core_mut().machine_result(m)
    }

    /// A block search starts or ends (what the program counts does not count during one).
    pub fn set_searching(&mut self, on: bool) {
        self.front.core_mut().searching = on;
    }

    /// The operator messages read since the last call, each with the number of commands
    /// before it ([`cnc_interpreter_core::Core::operator_message`]).
    pub fn take_messages(&mut self) -> Vec<(u64, String)> {
        std::mem::take(&mut self.front.core_mut().operator_messages)
    }

    /// The message service's texts read since the last call, each with the number of
    /// commands before it ([`cnc_interpreter_core::Core::service_message`]).
    pub fn take_service_messages(&mut self) -> Vec<(u64, ServiceOutput, String)> {
        std::mem::take(&mut self.front.core_mut().service_messages)
    }

    /// The kept variables and the offset page as the program has left them, for the shell to
    /// store.
    pub fn memory(&self) -> Memory {
        let core = self.front.core();
        Memory {
            kept: core
                .common
                .iter()
                .filter(|(n, _)| Memory::is_kept(**n))
                .map(|(&n, &v)| (n, v))
                .collect(),
            tools: core.setup.offsets.tools.clone(),
            work: core.setup.offsets.work.clone(),
            spindle_tool: core.setup.active_tool,
        }
    }

    /// Program zero per axis in machine coordinates (work offset, shifts, tool offset) as it
    /// stands after the blocks read so far: the HMI's work position is measured from it.
    pub fn program_origin(&self) -> Vec<f64> {
        self.front.core().program_origin()
    }

    /// Every program the run has called so far (its name in the library) and the text it ran.
    pub fn called_programs(&self) -> impl Iterator<Item = (&str, &str)> {
        self.front
            .core()
            .called
            .iter()
            .map(|(n, t)| (n.as_str(), t.as_ref()))
    }

    /// See [`cnc_interpreter_core::Core::work_frame`].
    pub fn work_frame(&self) -> Vec<f64> {
        self.front.core().work_frame()
    }
}

/// Interprets a whole program without running it: every command, or the first error.
pub fn check(dialect: Dialect, text: &str, setup: Setup) -> Result<Vec<Canon>, ProgramError> {
    check_with_library(dialect, text, setup, Library::new())
}

pub fn check_with_library(
    dialect: Dialect,
    text: &str,
    setup: Setup,
    library: Library,
) -> Result<Vec<Canon>, ProgramError> {
    check_limited(dialect, text, setup, library, MAX_CHECK_COMMANDS)
}

/// As [`check_with_library`], ending with an alarm after `limit` commands.
pub fn check_limited(
    dialect: Dialect,
    text: &str,
    setup: Setup,
    library: Library,
    limit: usize,
) -> Result<Vec<Canon>, ProgramError> {
    let mut interp = Interpreter::with_library(dialect, text, setup, library);
    let mut out = Vec::new();
    while let Some(c) = interp.next_command()? {
        if out.len() >= limit {
            return Err(ProgramError::new(
                dialect.alarm(Fault::Macro),
                c.line,
                format!("program does not end within {limit} commands (endless loop?)"),
            ));
        }
        out.push(c);
    }
    Ok(out)
}

/// Every error of a program without running it: each line's syntax and codes are checked on
/// their own, then the program is interpreted up to its first error (after which the state
/// is undefined). Sorted by line, one per line.
pub fn diagnose(dialect: Dialect, text: &str, setup: Setup, library: Library) -> Vec<ProgramError> {
    let mut errors = dialect.line_errors(text);
    if let Err(e) = check_with_library(dialect, text, setup, library) {
        errors.push(e);
    }
    errors.sort_by_key(|e| e.line);
    errors.dedup_by_key(|e| e.line);
    errors
}
