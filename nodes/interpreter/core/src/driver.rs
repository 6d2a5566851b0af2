//! The loop a front end plugs into: commands leave the queue as they are asked for, and when
//! the queue is empty (or everything in it waits behind a held element) the front end reads
//! the next block. An error stops the run for good: nothing after the bad line is produced,
//! and nothing of the bad block.

use crate::canon::Canon;
use crate::error::{Fault, ProgramError};
use crate::state::{Core, MAX_SILENT_BLOCKS};

/// A dialect's front end: it reads its language and lowers each block onto the core.
pub trait FrontEnd {
    fn core(&self) -> &Core;
    fn core_mut(&mut self) -> &mut Core;
    /// Reads the next line of the innermost call level ([`Core::next_line`]) and runs it,
    /// queuing its commands; at the end of a text, returns or ends the program.
    fn read_block(&mut self) -> Result<(), ProgramError>;
}

/// The next canonical command of `front`'s program; `Ok(None)` once the program has ended,
/// or while it waits for the machine's result of a block ([`Core::awaiting_machine`]).
pub fn next_command<F: FrontEnd + ?Sized>(front: &mut F) -> Result<Option<Canon>, ProgramError> {
    loop {
        let core = front.core_mut();
        if let Some(e) = &core.error {
            return Err(e.clone());
        }
        if core.gate() != Some(0) {
            if let Some(c) = core.pending.pop_front() {
                for h in core.hold_points() {
                    *h -= 1;
                }
                core.silent_blocks = 0;
                core.silent_reread = false;
                core.emitted += 1;
                return Ok(Some(c));
            }
        }
        // The machine's result of a block decides where the program goes on from (`measure.rs`).
        if core.done || core.awaiting.is_some() {
            return Ok(None);
        }
        core.silent_blocks += 1;
        if core.silent_blocks > MAX_SILENT_BLOCKS && !core.silent_reread {
            // Only new text read since the last command: long, but no loop.
            core.silent_blocks = 1;
        }
        let result = if core.silent_blocks > MAX_SILENT_BLOCKS {
            Err(core.fault(Fault::Macro, "program loops without producing any command"))
        } else {
            front.read_block()
        };
        let core = front.core_mut();
        if let Err(e) = result {
            core.error = Some(e.clone());
            core.pending.clear();
            return Err(e);
        }
        core.note_progress();
    }
}

impl Core {
    /// Notes whether the block just read was text read before (a loop can only be that).
    fn note_progress(&mut self) {
        let Some(level) = self.levels.last() else {
            return;
        };
        let text = std::sync::Arc::as_ptr(&level.text) as *const u8 as usize;
        let far = self.furthest.entry(text).or_insert(0);
        if level.pos.offset > *far {
            *far = level.pos.offset;
        } else {
            self.silent_reread = true;
        }
    }
}
