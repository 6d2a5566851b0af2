//! The program run as a pure core: program memory, the mode switch, cycle start, feed hold,
//! cycle stop and reset, completion, and alarms that stop the run. No clock, no thread, no
//! DDS: the node shell feeds it what arrives and carries out the [`Effect`]s it asks for. The
//! block stream to motion under credit is [`ProgramRun`] (`stream.rs`).
//!
//! The machine's execution state follows MTConnect's names (`MachineState`): WAIT until motion
//! has told where the axes are and the PLC has scanned once (before that its interface holds
//! the emergency stop, and motion would refuse what a cycle start asks), READY, ACTIVE while a
//! run goes, FEED_HOLD, STOPPED after an alarm or a cycle stop, PROGRAM_COMPLETED when motion
//! has finished the program's last block.

use std::collections::{BTreeMap, VecDeque};

use cnc_machine::programs::MDI_PROGRAM;
use cnc_msgs::canon::to_motion_block;
use cnc_msgs::msg::{Alarm, AlarmEvent, CommandResult, MachineState, MotionBlock, MotionStatus};
use cnc_msgs::task::{MotionRequest, TaskRequest};

use crate::offset_page;
use crate::position::{text_hash, ProgramPosition};
use crate::search::{search, Approach, SearchTarget};
use cnc_interpreter::setup::Memory;
use cnc_interpreter::{Dialect, Interpreter, Library, Setup};

mod commands;

pub use crate::stream::ProgramRun;
pub use cnc_machine::programs::MAX_PROGRAM_BYTES;
pub use cnc_machine::programs::{valid_program_name, MAX_PROGRAMS};
use cnc_machine::programs::{InRam, ProgramStorage};
/// The longest MDI entry: a few blocks typed at the panel.
pub const MAX_MDI_BYTES: usize = 4096;
/// Answers remembered so that a repeated command (same id) is answered, not executed again.
const ANSWERS_KEPT: usize = 64;
/// The alarm source of the interpreter's own alarms.
pub const SOURCE: &str = "interpreter";

/// What the run core asks its shell to do.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// Send this block to motion.
    Block(MotionBlock),
    /// Send this command to motion; motion answers it ([`RunCore::motion_result`]).
    ToMotion(cnc_msgs::msg::MotionCommand),
    /// Raise the interpreter's alarm (error severity).
    Raise {
        number: u32,
        text: String,
        program: String,
        line: u32,
    },
    /// Clear the interpreter's alarm of this number.
    Clear(u32),
    /// The machine memory changed: store [`RunCore::memory`], durably, before carrying out
    /// the effects after it.
    StoreMemory,
    /// Send a text through the message service's output (`001` §8.4.4), as its block runs.
    MessageService(cnc_interpreter_core::ServiceOutput, String),
}

/// What `/machine_state` says, without its time stamp.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StateView {
    pub mode: u8,
    pub execution: u8,
    pub program: String,
    pub line: u32,
    pub emergency_stop: bool,
    pub alarm_active: bool,
    /// The program's message to the operator (SINUMERIK `MSG`); empty: none.
    pub message: String,
}

struct Run {
    id: u64,
    program: String,
    stream: ProgramRun,
    /// The program text's fingerprint and the kept variables as the run found them: what a
    /// restart at its interrupted block needs to run it again as it ran (decisions D67).
    text_hash: String,
    kept_at_start: BTreeMap<i64, f64>,
    /// The fingerprint of every program the run has called so far, by name: a restart after
    /// one of them was edited is refused like one after the main program was (issue 45).
    called: BTreeMap<String, String>,
    /// Stopped by an alarm or a cycle stop: nothing more is sent.
    failed: bool,
}

impl Run {
    /// Takes the fingerprints of the programs the run has called since the last time.
    fn note_called(&mut self) {
        let interp = self.stream.interpreter();
        if interp.called_programs().count() == self.called.len() {
            return;
        }
        for (name, text) in interp.called_programs() {
            if !self.called.contains_key(name) {
                self.called.insert(name.to_string(), text_hash(text));
            }
        }
    }
}

/// The interpreter node's logic.
pub struct RunCore {
    dialect: Dialect,
    /// The program's message to the operator (MSG), shown until the next one or the end
    /// of the run.
    message: String,
    /// The machine as the launch config describes it; each start sets the start position and
    /// the memory.
    base: Setup,
    programs: BTreeMap<String, String>,
    /// The external drives' programs by their EXTCALL names, as read at the last start (D110).
    external: BTreeMap<String, String>,
    /// Where stored programs are kept (a folder on disk in the cell).
    storage: Box<dyn ProgramStorage>,
    /// Program memory's capacity, bytes.
    capacity: u64,
    run: Option<Run>,
    answered: VecDeque<CommandResult>,
    /// The last run id given; ids grow across restarts of the node (the shell starts them
    /// from its clock).
    run_counter: u64,
    status: MotionStatus,
    position: Option<Vec<f64>>,
    /// The PLC has scanned once since power-up.
    plc_scanned: bool,
    /// Active error alarms by (source, number): a start is refused while any is active.
    active_alarms: Vec<(String, u32)>,
    execution: u8,
    mode: u8,
    program_name: String,
    motion_command_id: u64,
    memory: Memory,
    effects: Vec<Effect>,
    /// How a restarted program approaches its restart block.
    approach: Approach,
    /// Where the program in automatic operation is, kept for a restart (decisions D64, D67);
    /// the last one stays until another program runs.
    position_kept: Option<ProgramPosition>,
    /// Axes motion reports not referenced (incremental encoders after power-on, D68).
    unreferenced: Vec<String>,
    /// Callers' commands passed on to motion, by the motion command's id: answered when
    /// motion answers (a jog toward a pressed overtravel switch is motion's to refuse).
    awaiting_motion: BTreeMap<u64, AwaitingMotion>,
}

/// A caller's command waiting for motion's answer.
struct AwaitingMotion {
    caller: u64,
    /// The answer if motion accepts.
    message: String,
}

/// How the core answers a command it accepted.
enum Reply {
    /// Now: the answer (its id is filled in by [`RunCore::command`]).
    Done(CommandResult),
    /// When motion answers the command just sent to it; `String` is the answer if it accepts.
    AfterMotion(String),
}

impl RunCore {
    /// A core for a machine `base` (its start position is replaced at each start), with
    /// `memory` as stored, giving run ids after `first_run_id`.
    pub fn new(dialect: Dialect, base: Setup, memory: Memory, first_run_id: u64) -> Self {
        RunCore {
            dialect,
            programs: BTreeMap::new(),
            external: BTreeMap::new(),
            storage: Box::new(InRam),
            capacity: u64::MAX,
            run: None,
            answered: VecDeque::with_capacity(ANSWERS_KEPT),
            run_counter: first_run_id,
            status: MotionStatus::default(),
            position: None,
            plc_scanned: false,
            active_alarms: Vec::new(),
            // Cycle start needs the axes' position from motion; until then the machine waits.
            execution: MachineState::WAIT,
            // The cell's machine powers up in AUTO (DESIGN: a robot cell runs programs
            // without an operator turning the switch).
            mode: MachineState::MODE_AUTO,
            program_name: String::new(),
            // Motion's command ids continue across restarts of the task, as run ids do.
            motion_command_id: first_run_id,
            message: String::new(),
            memory,
            effects: Vec::new(),
            approach: Approach::default_for(&base),
            base,
            position_kept: None,
            unreferenced: Vec::new(),
            awaiting_motion: BTreeMap::new(),
        }
    }

    /// The axes motion reports without a reference point yet (`AxisState.homed` false): no
    /// program starts until they have returned to it (alarm 224, D68).
    pub fn unreferenced_axes(&mut self, names: Vec<String>) {
        self.unreferenced = names;
    }

    /// This core with the machine's restart approach (`machine.restart` of the config).
    pub fn with_approach(mut self, approach: Approach) -> Self {
        self.approach = approach;
        self
    }

    /// This core with the program position kept before the node started (the position
    /// file): the interrupted program it names can be restarted at its block.
    pub fn with_kept_position(mut self, position: Option<ProgramPosition>) -> Self {
        self.position_kept = position;
        self
    }

    /// Where the program in automatic operation is (or was last), to keep.
    pub fn position(&self) -> Option<&ProgramPosition> {
        self.position_kept.as_ref()
    }

    /// This core with program memory: the programs it holds, where it keeps what is stored
    /// in it, and its capacity in bytes.
    pub fn with_program_memory(
        mut self,
        programs: BTreeMap<String, String>,
        storage: Box<dyn ProgramStorage>,
        capacity: u64,
    ) -> Self {
        self.programs = programs;
        self.storage = storage;
        self.capacity = capacity;
        self
    }

    /// The external drives' programs (EXTCALL), read by the shell before a start (D110).
    pub fn set_external_programs(&mut self, programs: BTreeMap<String, String>) {
        self.external = programs;
    }

    /// The effects asked for since the last call, in order.
    pub fn take_effects(&mut self) -> Vec<Effect> {
        std::mem::take(&mut self.effects)
    }

    pub fn memory(&self) -> &Memory {
        &self.memory
    }

    pub fn execution(&self) -> u8 {
        self.execution
    }

    fn running(&self) -> bool {
        matches!(
            self.execution,
            MachineState::ACTIVE | MachineState::FEED_HOLD
        )
    }

    fn stop_execution(&mut self) {
        if self.running() {
            self.execution = MachineState::STOPPED;
        }
    }

    /// Motion's latest status.
    pub fn motion_status(&mut self, status: MotionStatus) {
        self.status = status;
    }

    /// The axes' commanded positions as motion reports them; a report that is not of this
    /// machine's axes, or not finite, is not a start position.
    pub fn axes(&mut self, commanded: &[f64]) {
        // The machine's axes come first; a turn-mill's spindle as C follows them (D138).
        let n = self.base.axes.len();
        let Some(commanded) = commanded.get(..n) else {
            return;
        };
        if commanded.iter().all(|x| x.is_finite()) {
            self.position = Some(commanded.to_vec());
            self.ready_when_known();
        }
    }

    /// The PLC has scanned once (its first state report): its interface no longer holds the
    /// power-up emergency stop.
    pub fn plc_scanned(&mut self) {
        self.plc_scanned = true;
        self.ready_when_known();
    }

    fn ready_when_known(&mut self) {
        if self.execution == MachineState::WAIT && self.position.is_some() && self.plc_scanned {
            self.execution = MachineState::READY;
        }
    }

    /// An alarm event of any node. Messages and warnings (a refused request, a refused PLC
    /// file) inform; errors and fatal alarms stop the run and block the next start until they
    /// clear.
    pub fn alarm_event(&mut self, e: &AlarmEvent) {
        if e.kind == AlarmEvent::RAISED && e.alarm.severity < Alarm::SEVERITY_ERROR {
            return;
        }
        let key = (e.alarm.source.clone(), e.alarm.number);
        if e.kind != AlarmEvent::RAISED {
            self.active_alarms.retain(|k| k != &key);
            return;
        }
        if !self.active_alarms.contains(&key) {
            self.active_alarms.push(key);
        }
        // Any alarm stops the run: nothing more is sent; motion stops on its own or by the
        // cycle stop.
        if let Some(r) = self.run.as_mut() {
            if !r.failed {
                r.failed = true;
                self.send_motion(MotionRequest::CycleStop);
            }
        }
        self.stop_execution();
    }

    /// Feeds motion while credit lasts, notes completion and feed hold. Returns whether it
    /// sent anything.
    pub fn step(&mut self) -> bool {
        let mut busy = false;
        if let Some(r) = self.run.as_mut() {
            let done = if self.status.run_id == r.id {
                self.status.done_seq
            } else {
                0
            };
            let batch_start = self.effects.len();
            if !r.failed {
                let (id, program) = (r.id, r.program.clone());
                let measured = match r.stream.awaiting_machine() {
                    Some(seq) if self.status.run_id == id && self.status.result_seq == seq => {
                        r.stream.machine_result(seq, measurement(&self.status))
                    }
                    _ => Ok(()),
                };
                let effects = &mut self.effects;
                let sent = measured.and_then(|_| {
                    r.stream.feed(
                        done,
                        u64::from(self.status.capacity),
                        |seq, canon, interp| {
                            let mut msg =
                                to_motion_block(id, seq, &program, canon.line, &canon.command);
                            msg.origin = interp.program_origin();
                            msg.work_frame = interp.work_frame();
                            effects.push(Effect::Block(msg));
                        },
                    )
                });
                if let Some(m) = r.stream.message_due(done) {
                    self.message = m;
                }
                for (output, text) in r.stream.service_due(done) {
                    self.effects.push(Effect::MessageService(output, text));
                }
                match sent {
                    Ok(n) => busy = n > 0,
                    Err(e) => {
                        busy = true;
                        r.failed = true;
                        self.effects.push(Effect::Raise {
                            number: e.number,
                            text: e.text.clone(),
                            program: program.clone(),
                            line: e.line,
                        });
                        // The interpreter knows its own alarm at once: it does not wait for the
                        // event to come back over DDS to stop the program.
                        let key = (SOURCE.to_string(), e.number);
                        if !self.active_alarms.contains(&key) {
                            self.active_alarms.push(key);
                        }
                        if matches!(
                            self.execution,
                            MachineState::ACTIVE | MachineState::FEED_HOLD
                        ) {
                            self.execution = MachineState::STOPPED;
                        }
                    }
                }
            }
            if busy {
                // Kept variables and offsets these blocks set are stored before the blocks go
                // to motion (write ahead): nothing a block did is seen, a counted part
                // included, before what it wrote is kept (decisions D59).
                let now = r.stream.interpreter().memory();
                if now != self.memory {
                    self.memory = now;
                    self.effects.insert(batch_start, Effect::StoreMemory);
                }
            }
            let complete = self.status.run_id == r.id && r.stream.completed(self.status.done_seq);
            if complete && self.execution == MachineState::ACTIVE {
                self.execution = MachineState::PROGRAM_COMPLETED;
                self.message.clear();
                self.remember();
                self.run = None;
            }
        }
        if let Some(r) = self.run.as_ref() {
            if self.status.run_id == r.id {
                if self.status.state == MotionStatus::STATE_HOLD
                    && self.execution == MachineState::ACTIVE
                {
                    self.execution = MachineState::FEED_HOLD;
                } else if self.status.state == MotionStatus::STATE_RUNNING
                    && self.execution == MachineState::FEED_HOLD
                {
                    self.execution = MachineState::ACTIVE;
                }
            }
        }
        self.keep_position();
        busy
    }

    /// Sends motion `request` (numbered in the task's own series).
    fn send_motion(&mut self, request: MotionRequest) {
        self.motion_command_id += 1;
        let command = request.to_command(self.motion_command_id);
        self.effects.push(Effect::ToMotion(command));
    }

    /// Notes where the program is, if the state shows one worth keeping: with the block in
    /// progress (the first motion has not finished) while the run is there.
    fn keep_position(&mut self) {
        let Some(mut p) = ProgramPosition::of(&self.state()) else {
            return;
        };
        if let Some(r) = self.run.as_mut() {
            r.note_called();
        }
        let run = self.run.as_ref().filter(|r| r.program == p.program);
        let old = self
            .position_kept
            .as_ref()
            .filter(|o| o.program == p.program);
        // The run has ended (completed): the last block and start state stay.
        p.block = match (run, old) {
            (Some(r), _) => {
                let done = if self.status.run_id == r.id {
                    self.status.done_seq
                } else {
                    0
                };
                r.stream.program_block(done + 1)
            }
            (None, Some(o)) => o.block,
            (None, None) => 0,
        };
        if let Some(r) = run {
            p.text_hash.clone_from(&r.text_hash);
            p.kept_at_start.clone_from(&r.kept_at_start);
            p.called.clone_from(&r.called);
        } else if let Some(o) = old {
            p.text_hash.clone_from(&o.text_hash);
            p.kept_at_start.clone_from(&o.kept_at_start);
            p.called.clone_from(&o.called);
        }
        let same = old.is_some_and(|o| {
            (o.line, o.block, &o.state, &o.called) == (p.line, p.block, &p.state, &p.called)
        });
        if same {
            return;
        }
        if self.position_kept.as_ref() != Some(&p) {
            self.position_kept = Some(p);
        }
    }

    /// The machine state as it stands.
    pub fn state(&self) -> StateView {
        let ours = self
            .run
            .as_ref()
            .is_some_and(|r| r.id == self.status.run_id);
        let line = if ours || !matches!(self.execution, MachineState::READY | MachineState::WAIT) {
            self.status.line
        } else {
            0
        };
        StateView {
            mode: self.mode,
            execution: self.execution,
            program: self.program_name.clone(),
            line,
            emergency_stop: self
                .active_alarms
                .iter()
                .any(|(s, n)| s == "plc" && *n == 65),
            alarm_active: !self.active_alarms.is_empty(),
            message: self.message.clone(),
        }
    }

    /// The operator's block-skip switch (the PLC's G44.0): it applies to the blocks the run
    /// reads from now on, and to the runs after it.
    pub fn block_skip_switch(&mut self, on: bool) {
        if self.base.block_skip == on {
            return;
        }
        self.base.block_skip = on;
        if let Some(run) = self.run.as_mut() {
            run.stream.set_block_skip(on);
        }
    }

    /// The node stops: a program stopped by shutdown keeps what it had stored so far.
    pub fn shutdown(&mut self) {
        self.remember();
    }

    /// Takes what the run left in memory (kept variables, offsets); asks to store it if it
    /// changed.
    fn remember(&mut self) {
        let Some(r) = self.run.as_ref() else { return };
        let now = r.stream.interpreter().memory();
        if now != self.memory {
            self.memory = now;
            self.effects.push(Effect::StoreMemory);
        }
    }
}

/// Motion's result of the last block whose end it decided (`MotionStatus::result_*`), with
/// the timers the same report carries.
fn measurement(status: &MotionStatus) -> cnc_interpreter_core::Measurement {
    cnc_interpreter_core::Measurement {
        triggered: status.result_triggered,
        position: status.result_position.clone(),
        rest: status.result_rest.clone(),
        timers: Some(cnc_interpreter_core::MachineTimers {
            cutting: status.cutting_time,
            cycle: status.cycle_time,
            operating: status.operating_time,
            power_on: status.power_on_time,
        }),
    }
}

impl RunCore {
    /// Program memory as a subprogram library: every stored program by its O number (on its
    /// first line or in its name, `O0010`, `O0010.nc`) and by its name (`L10.SPF` as `L10`);
    /// the external drives' programs by their EXTCALL names only (`D:\UP\BOHRUNG`).
    fn library(&self) -> Library {
        let mut lib = Library::new();
        for (name, text) in &self.programs {
            // A second program of a taken number stays callable by name only.
            let _ = cnc_interpreter::library::add_program(&mut lib, name, text);
        }
        for (name, text) in &self.external {
            lib.insert_named(name, name, text);
        }
        lib
    }
}

#[cfg(test)]
#[path = "run_tests.rs"]
mod tests;
