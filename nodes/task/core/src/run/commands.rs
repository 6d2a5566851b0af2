//! The command path of the run core: each [`TaskRequest`] judged against the mode, the run and
//! program memory, carried out or refused with why, answered once per id; what needs motion's
//! judgement (a jog, a reference return) waits for its answer (D128).

use super::*;

impl RunCore {
    /// A command from hmi_bridge (`id` is the caller's), answered now, or `None` while motion
    /// has yet to answer what the task passed on to it ([`RunCore::motion_result`] answers
    /// then). hmi_bridge repeats a command until it is answered: a repeat gets the same answer
    /// again and is not acted on twice.
    pub fn command(&mut self, id: u64, request: TaskRequest) -> Option<CommandResult> {
        if let Some(done) = self.answered.iter().find(|r| r.id == id) {
            return Some(done.clone());
        }
        if self.awaiting_motion.values().any(|w| w.caller == id) {
            return None;
        }
        let result = match self.carry_out(request) {
            Ok(Reply::Done(mut r)) => {
                r.id = id;
                r
            }
            Ok(Reply::AfterMotion(message)) => {
                // Motion not answering (not running) leaves the caller to time out; the oldest
                // waiting are let go so the map stays small.
                if self.awaiting_motion.len() == ANSWERS_KEPT {
                    self.awaiting_motion.pop_first();
                }
                let w = AwaitingMotion {
                    caller: id,
                    message,
                };
                self.awaiting_motion.insert(self.motion_command_id, w);
                return None;
            }
            Err(message) => CommandResult {
                id,
                accepted: false,
                message,
                ..CommandResult::default()
            },
        };
        self.keep_answer(result.clone());
        Some(result)
    }

    /// Motion's answer to one of the task's commands: the answer to the caller whose command
    /// it was, if any (motion's refusal, with its reason, is the caller's answer).
    pub fn motion_result(&mut self, r: &CommandResult) -> Option<CommandResult> {
        let waiting = self.awaiting_motion.remove(&r.id)?;
        let result = CommandResult {
            id: waiting.caller,
            accepted: r.accepted,
            message: if r.accepted {
                waiting.message
            } else {
                r.message.clone()
            },
            ..CommandResult::default()
        };
        self.keep_answer(result.clone());
        Some(result)
    }

    fn keep_answer(&mut self, result: CommandResult) {
        if self.answered.len() == ANSWERS_KEPT {
            self.answered.pop_front();
        }
        self.answered.push_back(result);
    }

    fn carry_out(&mut self, request: TaskRequest) -> Result<Reply, String> {
        let running = self.running();
        let starts = matches!(request, TaskRequest::Start { .. } | TaskRequest::Mdi { .. });
        // An MDI entry is stored as the program `MDI` and started as a program is (decisions
        // D43); cycle start runs programs in AUTO only.
        if starts {
            // At power-up the PLC's interface holds the emergency stop until its first scan: a
            // start then would be refused by motion, or wait unseen.
            if !self.plc_scanned {
                return Err(
                    "the machine is not ready: the PLC has not scanned its inputs yet".into(),
                );
            }
            if self.mode == MachineState::MODE_HOME {
                return self.reference_return();
            }
            if !self.unreferenced.is_empty() && self.execution != MachineState::FEED_HOLD {
                return Err(format!(
                    "alarm 224: reference return not done ({}): select HOME and press cycle \
                     start",
                    self.unreferenced.join(", ")
                ));
            }
        }
        match request {
            TaskRequest::Mdi { text } => {
                if let Some(why) = mdi_refusal(self.mode, running, &text) {
                    return Err(why);
                }
                self.programs.insert(MDI_PROGRAM.into(), text);
                done(self.start(MDI_PROGRAM, "")?)
            }
            TaskRequest::Start { .. }
                if self.mode != MachineState::MODE_AUTO
                    && self.execution != MachineState::FEED_HOLD =>
            {
                Err(format!(
                    "cycle start refused: mode {}, not AUTO",
                    MachineState::mode_name_of(self.mode)
                ))
            }
            TaskRequest::Start { name, at } => done(self.start(&name, &at)?),
            TaskRequest::Mode(m) => done(self.set_mode(m)?),
            TaskRequest::Jog(j) => self.jog(&j),
            TaskRequest::Read { name } => done(
                self.programs
                    .get(&name)
                    .cloned()
                    .ok_or_else(|| not_found(&name))?,
            ),
            TaskRequest::Offsets => {
                let (tools, work) = offset_page::page(&self.memory, &self.base.axes);
                Ok(Reply::Done(CommandResult {
                    accepted: true,
                    message: format!("{} tool offsets, {} work offsets", tools.len(), work.len()),
                    tool_offsets: tools,
                    work_offsets: work,
                    ..CommandResult::default()
                }))
            }
            TaskRequest::SetToolOffset(row) => {
                let dialect = self.dialect;
                done(self.edit_offsets(|m, _| offset_page::set_tool(m, dialect, &row))?)
            }
            TaskRequest::SetWorkOffset(row) => {
                done(self.edit_offsets(|m, axes| offset_page::set_work(m, &row, axes))?)
            }
            TaskRequest::Load { name, text } => done(self.load(&name, &text)?),
            TaskRequest::FeedHold => {
                if self.execution != MachineState::ACTIVE {
                    return Err("no program running".into());
                }
                self.execution = MachineState::FEED_HOLD;
                self.send_motion(MotionRequest::FeedHold);
                done("feed hold")
            }
            TaskRequest::CycleStop => {
                if let Some(r) = self.run.as_mut() {
                    r.failed = true;
                }
                self.stop_execution();
                self.send_motion(MotionRequest::CycleStop);
                done("cycle stop")
            }
            TaskRequest::Reset => {
                self.reset();
                done("reset")
            }
            TaskRequest::List => {
                let (programs, program_sizes) = self
                    .programs
                    .iter()
                    .map(|(name, text)| (name.clone(), text.len() as u64))
                    .unzip();
                Ok(Reply::Done(CommandResult {
                    accepted: true,
                    message: format!("{} programs", self.programs.len()),
                    programs,
                    program_sizes,
                    ..CommandResult::default()
                }))
            }
            TaskRequest::Delete { name } => done(self.delete(&name, running)?),
        }
    }

    /// Reset: the run is dropped, the interpreter's alarms cleared, motion reset.
    fn reset(&mut self) {
        self.remember();
        self.run = None;
        self.message.clear();
        // Program alarms are cleared by reset; alarms whose cause persists (emergency stop)
        // stay until their source clears them.
        for (source, number) in self.active_alarms.clone() {
            if source == SOURCE {
                self.effects.push(Effect::Clear(number));
                self.active_alarms
                    .retain(|k| k != &(source.clone(), number));
            }
        }
        self.execution = if self.position.is_some() && self.plc_scanned {
            MachineState::READY
        } else {
            MachineState::WAIT
        };
        self.send_motion(MotionRequest::Reset);
    }

    fn delete(&mut self, name: &str, running: bool) -> Result<String, String> {
        let this_runs = self.run.as_ref().is_some_and(|r| r.program == name);
        if this_runs && running {
            return Err(format!("{name} is running: stop it first"));
        }
        if !self.programs.contains_key(name) {
            return Err(not_found(name));
        }
        if name != MDI_PROGRAM {
            self.storage
                .remove(name)
                .map_err(|e| format!("{name} not deleted: {e}"))?;
        }
        self.programs.remove(name);
        Ok(format!("{name} deleted"))
    }

    /// An edit of the offset pages, refused while a program runs; `edit` changes a copy, so a
    /// refused value leaves the pages as they were.
    fn edit_offsets(
        &mut self,
        edit: impl FnOnce(&mut Memory, &[char]) -> Result<String, String>,
    ) -> Result<String, String> {
        if self.running() {
            return Err("offsets cannot change while a program runs (stop it first)".into());
        }
        // A stopped run's offsets are taken first, so the edit is not overwritten by them
        // later.
        self.remember();
        self.run = None;
        let mut edited = self.memory.clone();
        let message = edit(&mut edited, &self.base.axes)?;
        self.memory = edited;
        self.effects.push(Effect::StoreMemory);
        Ok(message)
    }

    /// Cycle start in HOME mode: motion returns the axes with incremental encoders to their
    /// reference point, in the config's order (D68); motion's refusal is the answer.
    fn reference_return(&mut self) -> Result<Reply, String> {
        if !self.active_alarms.is_empty() {
            return Err(format!(
                "alarm active ({} alarms): reset first",
                self.active_alarms.len()
            ));
        }
        if self.running() {
            return Err("a program is running".into());
        }
        self.send_motion(MotionRequest::ReferenceReturn);
        Ok(Reply::AfterMotion("reference return started".into()))
    }

    /// A jog, passed on to motion in JOG and HANDWHEEL modes (D69). Motion judges what
    /// depends on the axes (an alarm, an overtravel switch pressed, D70, an axis moving): its
    /// refusal is the answer.
    fn jog(&mut self, j: &cnc_msgs::jog::Jog) -> Result<Reply, String> {
        if !matches!(
            self.mode,
            MachineState::MODE_JOG | MachineState::MODE_HANDWHEEL
        ) {
            return Err(format!(
                "jog refused: mode {}, not JOG or HANDWHEEL",
                MachineState::mode_name_of(self.mode)
            ));
        }
        if self.running() {
            return Err("jog refused: a program is running".into());
        }
        let Some(axis) = self.base.axes.iter().position(|a| a.to_string() == j.axis) else {
            return Err(format!("jog refused: no axis {}", j.axis));
        };
        self.send_motion(MotionRequest::Jog {
            axis: axis as u8,
            direction: j.direction,
            feed: j.feed,
            increment: j.increment,
        });
        let sign = match j.direction {
            1 => "+",
            -1 => "-",
            _ => "0",
        };
        Ok(Reply::AfterMotion(format!(
            "jog {} {sign} {} {}",
            j.axis, j.feed, j.increment
        )))
    }

    fn set_mode(&mut self, m: u8) -> Result<String, String> {
        if m > MachineState::MODE_HANDWHEEL {
            return Err(format!(
                "unknown mode {m}: 0 AUTO, 1 MDI, 2 JOG, 3 HOME, 4 EDIT, 5 HANDWHEEL"
            ));
        }
        if self.running() && m != self.mode {
            return Err("mode change refused: a program is running (stop it first)".into());
        }
        self.mode = m;
        // Motion acts on the PLC's jog keys in JOG and HANDWHEEL modes (D71).
        self.send_motion(MotionRequest::Mode(m));
        Ok(format!("mode {}", MachineState::mode_name_of(m)))
    }

    fn load(&mut self, name: &str, text: &str) -> Result<String, String> {
        let mut sizes = cnc_machine::programs::sizes(&self.programs);
        // The MDI entry is the panel's, not a stored program: it takes no capacity.
        sizes.remove(MDI_PROGRAM);
        cnc_machine::programs::check_store(&sizes, name, text.len(), self.capacity)?;
        if name == MDI_PROGRAM {
            return Err(format!(
                "{MDI_PROGRAM} is the MDI entry's name (decisions D43)"
            ));
        }
        if self.run.as_ref().is_some_and(|r| r.program == name)
            && self.execution == MachineState::ACTIVE
        {
            return Err(format!("{name} is running"));
        }
        self.storage
            .store(name, text)
            .map_err(|e| format!("{name} not stored: {e}"))?;
        let lines = text.lines().count();
        self.programs.insert(name.to_string(), text.to_string());
        Ok(format!("{name} stored ({lines} lines)"))
    }

    /// Cycle start of the program `name` at the top, or at the block `at` says (block search,
    /// [`SearchTarget::parse`], or `interrupted`: where the kept position says the last run
    /// was left). Empty `name` and `at` in feed hold: the run goes on.
    fn start(&mut self, name: &str, at: &str) -> Result<String, String> {
        if !self.active_alarms.is_empty() {
            return Err(format!(
                "alarm active ({} alarms): reset first",
                self.active_alarms.len()
            ));
        }
        if self.execution == MachineState::ACTIVE {
            return Err("a program is running".into());
        }
        if self.execution == MachineState::FEED_HOLD && name.is_empty() && at.is_empty() {
            self.execution = MachineState::ACTIVE;
            self.send_motion(MotionRequest::Resume);
            return Ok("resumed".into());
        }
        // What the last run left is taken first: this run starts from it.
        self.remember();
        let (name, target, kept) = if at.trim() == "interrupted" {
            let (name, block, kept) = self.interrupted(name)?;
            (name, Some(SearchTarget::Block(block)), kept)
        } else {
            let target = SearchTarget::parse(at)?;
            (name.to_string(), target, self.memory.kept.clone())
        };
        let Some(text) = self.programs.get(&name).cloned() else {
            return Err(not_found(&name));
        };
        let Some(start) = self.position.clone() else {
            return Err("no axis position from motion yet".into());
        };
        let mut setup = self.base.clone();
        setup.start = start.clone();
        setup.kept = kept.clone();
        setup.offsets.tools = self.memory.tools.clone();
        setup.offsets.work = self.memory.work.clone();
        setup.active_tool = self.memory.spindle_tool;
        // The cell runs programs as the operator would: M99 or G27 loops go on until stop.
        setup.single_pass = false;
        let mut interp = Interpreter::with_library(self.dialect, &text, setup, self.library());
        let (mut stream, message) = match &target {
            None => (ProgramRun::new(interp), format!("{name} started")),
            Some(t) => {
                let found = search(self.dialect, &mut interp, &text, t, &start, &self.approach)
                    .map_err(|e| format!("{name}: {e}"))?;
                let message = format!(
                    "{name} started at line {} (block {}, {} blocks searched)",
                    found.first.line,
                    found.skipped + 1,
                    found.skipped
                );
                (ProgramRun::restarted(interp, found), message)
            }
        };
        // The block search read without the machine; the run measures on it.
        stream.on_machine();
        self.run_counter += 1;
        self.message.clear();
        self.run = Some(Run {
            id: self.run_counter,
            program: name.clone(),
            stream,
            failed: false,
            text_hash: text_hash(&text),
            kept_at_start: kept,
            called: BTreeMap::new(),
        });
        self.program_name = name;
        self.execution = MachineState::ACTIVE;
        Ok(message)
    }

    /// The program, block and kept variables of the interrupted run the kept position names
    /// (`name` empty: whichever it names); refused when there is none, when it names another
    /// program, or when the program was edited since.
    fn interrupted(&self, name: &str) -> Result<(String, u64, BTreeMap<i64, f64>), String> {
        let p = self
            .position_kept
            .as_ref()
            .filter(|p| p.interrupted() && p.block > 0)
            .ok_or("no interrupted program is kept: start it by line or from the top")?;
        if !name.is_empty() && name != p.program {
            return Err(format!(
                "{} was interrupted (line {}), not {name}",
                p.program, p.line
            ));
        }
        let text = self
            .programs
            .get(&p.program)
            .ok_or_else(|| not_found(&p.program))?;
        if text_hash(text) != p.text_hash {
            return Err(format!(
                "{} was edited since it was interrupted at line {}: start it by line",
                p.program, p.line
            ));
        }
        // Every program the interrupted run called, as it ran (a subprogram's edit changes
        // the path as much as the main program's).
        let library = self.library();
        for (called, hash) in &p.called {
            let now = library.text_of(called).map(|t| text_hash(&t));
            if now.as_deref() != Some(hash.as_str()) {
                return Err(format!(
                    "{called}, which {} called, was edited or removed since it was interrupted \
                     at line {}: start it by line",
                    p.program, p.line
                ));
            }
        }
        // The file may have been edited by hand: only kept variables, only numbers.
        let kept = p
            .kept_at_start
            .iter()
            .filter(|(n, v)| Memory::is_kept(**n) && v.is_finite())
            .map(|(&n, &v)| (n, v))
            .collect();
        Ok((p.program.clone(), p.block, kept))
    }
}

/// An accepted command's answer: a message only.
fn done(message: impl Into<String>) -> Result<Reply, String> {
    Ok(Reply::Done(CommandResult {
        accepted: true,
        message: message.into(),
        ..CommandResult::default()
    }))
}

fn not_found(name: &str) -> String {
    format!("program {name:?} not found (alarm 22)")
}

/// Why an MDI entry is not run, if it is not.
fn mdi_refusal(mode: u8, running: bool, text: &str) -> Option<String> {
    if mode != MachineState::MODE_MDI {
        Some(format!(
            "MDI refused: mode {}, not MDI",
            MachineState::mode_name_of(mode)
        ))
    } else if running {
        Some("MDI refused: a program is running".into())
    } else if text.trim().is_empty() {
        Some("MDI refused: no block entered".into())
    } else if text.len() > MAX_MDI_BYTES {
        Some(format!(
            "MDI refused: {} bytes, limit {MAX_MDI_BYTES}",
            text.len()
        ))
    } else {
        None
    }
}
