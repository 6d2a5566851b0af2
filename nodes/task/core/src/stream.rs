//! One program run's block stream to motion, under credit: at most the motion queue's
//! capacity of commands unfinished, a restart's preamble first, operator messages filed by
//! the command they follow, complete when motion has finished the program end. Used by the
//! run core ([`crate::run::RunCore`]), `cnc simulate` and the in-process cell tests.

use std::collections::VecDeque;

use cnc_interpreter_core::{Measurement, ServiceOutput};

use cnc_interpreter::{Canon, Command, Interpreter, ProgramError};

/// One program run's block stream: commands go to motion while fewer than the queue's
/// capacity are unfinished; the run is complete when motion has finished the program end.
pub struct ProgramRun {
    interp: Interpreter,
    /// Commands sent before the interpreter's next: a restart's preamble and its first block.
    queued: VecDeque<Canon>,
    /// The program's commands a block search ran without motion (decisions D67).
    skipped: u64,
    /// Commands of the restart's preamble, sent first.
    preamble: u64,
    /// Sequence number of the last command sent (the first is 1).
    sent: u64,
    /// Sequence number of the program end, once sent.
    end: Option<u64>,
    /// Operator messages read, each with the sequence number after which it shows.
    messages: VecDeque<(u64, String)>,
    /// The message service's texts, each with the sequence number after which it goes out.
    service: VecDeque<(u64, ServiceOutput, String)>,
}

impl ProgramRun {
    pub fn new(interp: Interpreter) -> Self {
        ProgramRun {
            interp,
            queued: VecDeque::new(),
            skipped: 0,
            preamble: 0,
            sent: 0,
            end: None,
            messages: VecDeque::new(),
            service: VecDeque::new(),
        }
    }

    /// A run restarted at a block found by [`crate::search::search`] in `interp`: its
    /// preamble first, then the program from the restart block on.
    pub fn restarted(interp: Interpreter, restart: crate::search::Restart) -> Self {
        let preamble = restart.preamble.len() as u64;
        let mut queued: VecDeque<Canon> = restart.preamble.into();
        queued.push_back(restart.first);
        ProgramRun {
            interp,
            queued,
            skipped: restart.skipped,
            preamble,
            sent: 0,
            end: None,
            messages: VecDeque::new(),
            service: VecDeque::new(),
        }
    }

    /// The newest operator message due once motion has finished block `done`, if one is:
    /// a message shows when the commands before it are done, as the block it stands in runs.
    pub fn message_due(&mut self, done: u64) -> Option<String> {
        let mut due = None;
        while self.messages.front().is_some_and(|(seq, _)| *seq <= done) {
            due = self.messages.pop_front().map(|(_, text)| text);
        }
        due
    }

    /// Files the interpreter's new messages by sequence number: the interpreter's `n`th
    /// command is this run's `n + preamble − skipped`th (a restart's search ran the skipped
    /// ones without motion and the preamble came first).
    fn file_messages(&mut self) {
        for (before, text) in self.interp.take_messages() {
            let seq = self.run_seq(before);
            self.messages.push_back((seq, text));
        }
        for (before, output, text) in self.interp.take_service_messages() {
            let seq = self.run_seq(before);
            self.service.push_back((seq, output, text));
        }
    }

    /// This run's sequence number of the interpreter's `n`th command: shifted by the
    /// preamble, less what a restart's search skipped.
    fn run_seq(&self, n: u64) -> u64 {
        (n as i64 + self.preamble as i64 - self.skipped as i64).max(0) as u64
    }

    /// The message service's texts due once motion has finished block `done`, every one in
    /// order (each goes out, where the display shows only the newest message).
    pub fn service_due(&mut self, done: u64) -> Vec<(ServiceOutput, String)> {
        let mut due = Vec::new();
        while self.service.front().is_some_and(|(seq, _, _)| *seq <= done) {
            if let Some((_, output, text)) = self.service.pop_front() {
                due.push((output, text));
            }
        }
        due
    }

    /// The program's own block number (from 1, as in an uninterrupted run) of this run's
    /// command `seq`; a preamble command counts as the restart block.
    pub fn program_block(&self, seq: u64) -> u64 {
        self.skipped + seq.saturating_sub(self.preamble).max(1)
    }

    /// Sends commands to `send(seq, command, interpreter)` while fewer than `capacity` (at
    /// least 2) are unfinished, motion having finished every block up to `done`. Returns how
    /// many it sent; an interpreter alarm ends the stream (nothing of the bad block is sent).
    pub fn feed(
        &mut self,
        done: u64,
        capacity: u64,
        mut send: impl FnMut(u64, Canon, &Interpreter),
    ) -> Result<u64, ProgramError> {
        let credit = capacity
            .max(2)
            .saturating_sub(self.sent.saturating_sub(done));
        let mut count = 0;
        for _ in 0..credit {
            if self.end.is_some() {
                break;
            }
            let next = match self.queued.pop_front() {
                Some(c) => Some(c),
                None => self.interp.next_command()?,
            };
            match next {
                Some(canon) => {
                    self.sent += 1;
                    count += 1;
                    if canon.command == Command::ProgramEnd {
                        self.end = Some(self.sent);
                    }
                    send(self.sent, canon, &self.interp);
                }
                None => break,
            }
        }
        self.file_messages();
        Ok(count)
    }

    /// Blocks whose end the machine decides wait for motion's result before the program
    /// reads on (the stream of a machine; a simulation takes the event as coming at the
    /// move's end: D116, D118).
    pub fn on_machine(&mut self) {
        self.interp.on_machine(true);
    }

    /// The block whose result from the machine the program waits for.
    pub fn awaiting_machine(&self) -> Option<u64> {
        self.interp.awaited_command().map(|n| self.run_seq(n))
    }

    /// Motion's result of block `seq`; one of another block is not this program's to take.
    pub fn machine_result(&mut self, seq: u64, m: Measurement) -> Result<(), ProgramError> {
        if self.awaiting_machine() != Some(seq) {
            return Ok(());
        }
        self.interp.machine_result(m)
    }

    /// Every command of the program has been sent.
    pub fn all_sent(&self) -> bool {
        self.end.is_some()
    }

    /// Motion has finished the program end (`done` its last finished block).
    pub fn completed(&self, done: u64) -> bool {
        self.end == Some(done)
    }

    pub fn sent(&self) -> u64 {
        self.sent
    }

    pub fn interpreter(&self) -> &Interpreter {
        &self.interp
    }

    /// The block-skip switch for the blocks still to be read ([`Interpreter::set_block_skip`]).
    pub fn set_block_skip(&mut self, on: bool) {
        self.interp.set_block_skip(on);
    }
}
