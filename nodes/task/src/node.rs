//! interpreter node shell: binds the run core ([`crate::run::RunCore`]: program memory, program
//! runs, the credit-based block stream to motion, the machine state) to DDS and the memory file.
//!
//! Commands arrive from hmi_bridge on `_internal/task_command`, each answered on
//! `_internal/command_result`; what motion must do (feed hold, resume, cycle stop, reset,
//! reference return, jog, mode) goes to it on `_internal/motion_command`, and motion's answers
//! come back on `_internal/motion_result` (a refusal there is the caller's answer). During a
//! run, at most `capacity` unfinished blocks are in flight: motion's `done_seq` returns the
//! credit.

use std::collections::BTreeMap;
use std::time::Duration;

use cnc_msgs::msg::{
    Alarm, AlarmEvent, AxisState, CommandResult, MachineState, MotionBlock, MotionCommand,
    MotionStatus, TaskCommand,
};
use cnc_msgs::signals::{g, GImage, SignalTable};
use cnc_msgs::task::TaskRequest;
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::monotonic_ns;
use cnc_runtime::dds::{stamp, RosNode};
use cnc_runtime::persist::Keeper;
use cnc_runtime::program_store::{InRam, ProgramDir, ProgramStorage};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::position::{PositionTracker, ProgramPosition};
use crate::run::{self, Effect, RunCore, StateView};
use crate::search::Approach;
use cnc_interpreter::setup::Memory;
use cnc_interpreter::{Dialect, Setup};

pub use crate::run::{valid_program_name, MAX_MDI_BYTES, MAX_PROGRAMS, MAX_PROGRAM_BYTES};

/// A program's text for an output of the message service that is off (a warning: nothing
/// else changes; our number, the manual has a prompt line, not an alarm).
pub const MSG_SERVICE_OFF: u32 = 1096;

/// The interpreter's view of the machine from the launch config (`Setup::of_machine`); the
/// program starts at `start`.
pub fn setup_from_config(cfg: &LaunchConfig, start: &[f64]) -> Setup {
    cnc_interpreter::setup::of_machine(&cfg.machine, start)
}

/// The machine memory at start: the config's offset page, then what the memory file holds.
/// A memory file that cannot be read is reported and left alone (it is not overwritten until
/// a program changes the memory).
pub fn load_memory(cfg: &LaunchConfig) -> (Memory, Option<String>) {
    let offsets = setup_from_config(cfg, &cfg.home()).offsets;
    let base = Memory {
        kept: BTreeMap::new(),
        tools: offsets.tools,
        work: offsets.work,
        spindle_tool: cfg.machine.tool_in_spindle,
    };
    let Some(path) = &cfg.machine.memory_file else {
        return (base, None);
    };
    match std::fs::read_to_string(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => (base, None),
        Err(e) => (base, Some(format!("{}: {e}", path.display()))),
        Ok(text) => match serde_yaml::from_str::<Memory>(&text) {
            Ok(m) => (m.sanitized(), None),
            Err(e) => (base, Some(format!("{}: {e}", path.display()))),
        },
    }
}

/// Writes the machine memory durably (temporary file, fsync, rename, fsync of the folder), so
/// a power cut leaves either the old or the new memory.
pub fn save_memory(path: &std::path::Path, memory: &Memory) -> Result<(), String> {
    let text = serde_yaml::to_string(memory).map_err(|e| e.to_string())?;
    cnc_runtime::persist::write_atomic(path, &text)
}

/// The keeper of `machine.position_file` and what the file held at start; that is logged,
/// since it says where an interrupted program can be restarted (decisions D67).
fn kept_position(cfg: &LaunchConfig) -> (Option<Keeper>, Option<ProgramPosition>) {
    let Some(path) = cfg.machine.position_file.clone() else {
        return (None, None);
    };
    let kept = match std::fs::read_to_string(&path).map(|t| ProgramPosition::from_yaml(&t)) {
        Ok(Ok(p)) => {
            if p.interrupted() {
                log::warn!(
                    "interpreter: program {} was left at line {} (block {}, {}); kept in {}: \
                     start it with `interrupted` to restart there",
                    p.program,
                    p.line,
                    p.block,
                    p.state,
                    path.display()
                );
            } else {
                log::info!("interpreter: program {} last ran to its end", p.program);
            }
            Some(p)
        }
        Ok(Err(e)) => {
            log::error!("interpreter: {}: {e}", path.display());
            None
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => {
            log::error!("interpreter: {}: {e}", path.display());
            None
        }
    };
    (Some(Keeper::new(path, "program position")), kept)
}

/// The restart approach the config gives (`machine.restart`), over the machine's usual one.
fn approach_from_config(cfg: &LaunchConfig, machine: &Setup) -> Approach {
    let mut a = Approach::default_for(machine);
    if let Ok(Some((axis, positive))) = cfg.machine.restart.retract_axis(&cfg.machine.axes) {
        if a.tool_change_at.is_some() {
            a.tool_change_at = machine.second_reference.get(axis).copied();
        }
        a.retract_axis = axis;
        a.retract_positive = positive;
    }
    if let Some(f) = cfg.machine.restart.approach_feed {
        a.feed = f;
    }
    if let Some(c) = cfg.machine.restart.clearance {
        a.clearance = c;
    }
    a
}

/// What the task sends out: blocks and commands to motion, alarms, the message service, the
/// machine memory file. Carries out the core's effects in order.
struct Outputs {
    blocks: cnc_runtime::dds::Publisher<MotionBlock>,
    to_motion: cnc_runtime::dds::Publisher<MotionCommand>,
    alarms: AlarmReporter,
    msg_file: Option<std::path::PathBuf>,
    msg_file_kib: u32,
    memory_path: Option<std::path::PathBuf>,
}

impl Outputs {
    fn carry_out(&self, core: &mut RunCore) {
        for effect in core.take_effects() {
            match effect {
                Effect::Block(msg) => {
                    if let Err(e) = self.blocks.publish(msg) {
                        log::error!("interpreter: block not sent: {e:?}");
                    }
                }
                Effect::ToMotion(c) => {
                    let _ = self.to_motion.publish(c);
                }
                Effect::Raise {
                    number,
                    text,
                    program,
                    line,
                } => self.alarms.raise(self.alarms.alarm(
                    number,
                    Alarm::SEVERITY_ERROR,
                    &text,
                    &program,
                    line,
                )),
                Effect::Clear(number) => self.alarms.clear(number),
                Effect::MessageService(output, text) => self.message_service(output, &text),
                Effect::StoreMemory => {
                    // Durable before the blocks that follow are published (write ahead).
                    if let Some(p) = self.memory_path.as_deref() {
                        if let Err(e) = save_memory(p, core.memory()) {
                            log::error!("interpreter: machine memory not stored: {e}");
                        }
                    }
                }
            }
        }
    }

    fn message_service(&self, output: cnc_interpreter_core::ServiceOutput, text: &str) {
        use cnc_interpreter_core::ServiceOutput;
        if let (ServiceOutput::File, Some(path)) = (output, &self.msg_file) {
            if let Err(e) = crate::msg_service::append(path, text, self.msg_file_kib) {
                log::error!("interpreter: MSG service file: {e}");
            }
            return;
        }
        // An interface that is off: nothing goes out, and the operator is told ("发生 MSG
        // 指令处理故障", `001` §8.4.4).
        let interface = match output {
            ServiceOutput::File => "File (machine.msg_file)",
            ServiceOutput::Serial => "V24 (RS232)",
        };
        self.alarms.raise(self.alarms.alarm(
            MSG_SERVICE_OFF,
            Alarm::SEVERITY_WARNING,
            &format!(
                "MSG instruction processing fault: the {interface} output is off on this machine \
                 ({text:?} not sent)"
            ),
            "",
            0,
        ));
    }
}

/// Program memory as the config keeps it: a folder on disk, or RAM only.
fn program_memory(cfg: &LaunchConfig) -> (BTreeMap<String, String>, Box<dyn ProgramStorage>) {
    let Some(dir) = &cfg.machine.program_directory else {
        return (BTreeMap::new(), Box::new(InRam));
    };
    let dir = ProgramDir::new(dir);
    let (programs, problems) = dir.read_all();
    for p in problems {
        log::error!("interpreter: program memory: {p}");
    }
    log::info!(
        "interpreter: program memory {}: {} programs",
        dir.root.display(),
        programs.len()
    );
    (programs, Box::new(dir))
}

/// What the task hears of the machine: motion's status and axes, alarms, the PLC's G image.
struct Machine {
    status: cnc_runtime::bus::Subscription<MotionStatus>,
    axes: cnc_runtime::bus::Subscription<AxisState>,
    alarms: cnc_runtime::bus::Subscription<AlarmEvent>,
    /// The PLC's G image, for the block-skip switch (G44.0): its first arrival says the PLC
    /// has scanned (READY waits for it).
    g_in: cnc_runtime::shm::Receiver<GImage>,
    /// A failing G image channel is logged once, not every turn of the loop.
    g_failing: std::cell::Cell<bool>,
}

impl Machine {
    fn feed(&self, core: &mut RunCore) {
        while let Ok(Some(s)) = self.status.take() {
            core.motion_status(s);
        }
        while let Ok(Some(a)) = self.axes.take() {
            let commanded: Vec<f64> = a.axes.iter().map(|x| x.commanded_position).collect();
            core.axes(&commanded);
            core.unreferenced_axes(
                a.axes
                    .iter()
                    .filter(|x| !x.homed)
                    .map(|x| x.name.clone())
                    .collect(),
            );
        }
        while let Ok(Some(e)) = self.alarms.take() {
            core.alarm_event(&e);
        }
        match self.g_in.latest() {
            Ok(Some(g)) => {
                // The PLC writes its G image only after a scan: the machine can be ready.
                core.plc_scanned();
                core.block_skip_switch(g.get(g::BDT1));
                self.g_failing.set(false);
            }
            Ok(None) => {}
            // Until it reads, the machine stays WAIT; the log says why.
            Err(e) if !self.g_failing.replace(true) => {
                log::error!("interpreter: the PLC's G image cannot be read: {e}");
            }
            Err(_) => {}
        }
    }
}

/// The command path: the bridge's commands in, answers out (motion's too, for what the task
/// passed on to it).
struct Commands {
    commands: cnc_runtime::bus::Subscription<TaskCommand>,
    results: cnc_runtime::dds::Publisher<CommandResult>,
    motion_results: cnc_runtime::bus::Subscription<CommandResult>,
}

impl Commands {
    /// Serves what arrived; returns whether anything did.
    fn serve(&self, core: &mut RunCore, out: &Outputs, cfg: &LaunchConfig) -> bool {
        while let Ok(Some(r)) = self.motion_results.take() {
            if let Some(answer) = core.motion_result(&r) {
                let _ = self.results.publish(answer);
            }
        }
        let mut busy = false;
        while let Ok(Some(c)) = self.commands.take() {
            busy = true;
            let request = match TaskRequest::from_command(&c) {
                Ok(r) => r,
                Err(message) => {
                    let _ = self.results.publish(CommandResult {
                        id: c.id,
                        accepted: false,
                        message,
                        ..CommandResult::default()
                    });
                    continue;
                }
            };
            if matches!(&request, TaskRequest::Start { name, .. } if !name.is_empty())
                && !cfg.machine.external_drives.is_empty()
            {
                // The external drives as they are at this start (D110).
                let (programs, problems) =
                    crate::external::read_drives(&cfg.machine.external_drives);
                for p in problems {
                    log::warn!("interpreter: external drive: {p}");
                }
                core.set_external_programs(programs);
            }
            let result = core.command(c.id, request);
            out.carry_out(core);
            if let Some(result) = result {
                let _ = self.results.publish(result);
            }
        }
        busy
    }
}

/// Runs the interpreter node of the machine `instance` ([`cnc_runtime::shm::instance`]) until
/// `shutdown`.
pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<(), String> {
    let dialect = Dialect::from_name(&cfg.machine.dialect)
        .ok_or_else(|| format!("unknown dialect {}", cfg.machine.dialect))?;
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "interpreter")?;
    let commands = Commands {
        commands: ros.subscription(&topics::TASK_COMMAND)?,
        results: ros.publisher(&topics::COMMAND_RESULT)?,
        motion_results: ros.subscription(&topics::MOTION_RESULT)?,
    };
    let out = Outputs {
        blocks: ros.publisher(&topics::MOTION_BLOCKS)?,
        to_motion: ros.publisher(&topics::MOTION_COMMAND)?,
        alarms: AlarmReporter::new(&mut ros, run::SOURCE)?,
        msg_file: cfg.machine.msg_file.clone(),
        msg_file_kib: cfg.machine.msg_file_kib,
        memory_path: cfg.machine.memory_file.clone(),
    };
    let shm = ShmNode::new(&instance, "interpreter")?;
    let machine = Machine {
        status: ros.subscription(&topics::MOTION_STATUS)?,
        axes: ros.subscription(&topics::AXES)?,
        alarms: ros.subscription(&topics::ALARM_EVENTS)?,
        g_in: shm.receiver::<GImage>(channel::G_IMAGE, false)?,
        g_failing: std::cell::Cell::new(false),
    };
    let (memory, memory_error) = load_memory(&cfg);
    if let Some(e) = memory_error {
        log::error!("interpreter: machine memory not read, using the config's offsets: {e}");
    }
    let base = setup_from_config(&cfg, &cfg.home());
    let capacity = cfg.machine.program_capacity_kib.saturating_mul(1024);
    let (programs, storage) = program_memory(&cfg);
    let (keeper, kept) = kept_position(&cfg);
    let approach = approach_from_config(&cfg, &base);
    // Run ids grow across restarts of this node.
    let mut core = RunCore::new(dialect, base, memory, monotonic_ns() / 1000)
        .with_program_memory(programs, storage, capacity)
        .with_approach(approach)
        .with_kept_position(kept);
    let mut state = StateReporter {
        publisher: ros.publisher(&topics::MACHINE_STATE)?,
        last: None,
        last_ns: 0,
        position: keeper,
        tracker: PositionTracker::default(),
    };
    while !shutdown.requested() {
        ros.refresh();
        machine.feed(&mut core);
        out.carry_out(&mut core);
        let mut busy = commands.serve(&mut core, &out, &cfg);
        // A start is reported before any block of it runs: a program that fails in its first
        // blocks still shows ACTIVE, then STOPPED, in that order.
        report_state(&mut state, core.state(), core.position());
        busy |= core.step();
        out.carry_out(&mut core);
        report_state(&mut state, core.state(), core.position());
        if !busy {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    core.shutdown();
    out.carry_out(&mut core);
    Ok(())
}

/// Publishes `/machine_state` on every change, so readers see each transition in order, and
/// twice a second otherwise.
struct StateReporter {
    publisher: cnc_runtime::dds::Publisher<MachineState>,
    last: Option<StateView>,
    /// Keeps the program position on the disk (`machine.position_file`), if configured.
    position: Option<Keeper>,
    tracker: PositionTracker,
    last_ns: u64,
}

fn report_state(state: &mut StateReporter, view: StateView, latest: Option<&ProgramPosition>) {
    // The position goes to its keeper (when due) before the state is published.
    let now = monotonic_ns();
    if let Some(keeper) = state.position.as_mut() {
        if let Some(position) = state.tracker.update(latest, now) {
            keeper.keep(position.to_yaml().into_bytes());
        }
    }
    if state.last.as_ref() != Some(&view) || now - state.last_ns > 500_000_000 {
        state.last_ns = now;
        let _ = state.publisher.publish(MachineState {
            stamp: stamp(),
            mode: view.mode,
            execution: view.execution,
            execution_name: MachineState::execution_name_of(view.execution).into(),
            program: view.program.clone(),
            line: view.line,
            emergency_stop: view.emergency_stop,
            alarm_active: view.alarm_active,
            message: view.message.clone(),
        });
        state.last = Some(view);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cnc_interpreter::Interpreter;

    fn config(memory_file: &std::path::Path) -> LaunchConfig {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../launch_configs/sim_lathe.yaml"
        );
        let mut cfg = LaunchConfig::load(std::path::Path::new(path)).unwrap();
        cfg.machine.memory_file = Some(memory_file.to_path_buf());
        cfg
    }

    #[test]
    fn machine_memory_survives_a_restart_and_a_bad_file_is_reported() {
        let dir = std::env::temp_dir().join(format!("cnc_memory_{}", std::process::id()));
        let file = dir.join("memory.yaml");
        let _ = std::fs::remove_file(&file);
        let cfg = config(&file);
        // No file yet: the config's offset page, no kept variables.
        let (first, err) = load_memory(&cfg);
        assert!(err.is_none() && first.kept.is_empty());
        assert_eq!(first.tools.get(&1).map(|t| t.tip), Some(3));
        // A program sets #200 and an offset; the shell stores what it left.
        let text = "#200=5\n#201=[#200*2]\n#150=7\n#4001=1.5\n#5242=-80\nM30\n";
        let mut setup = setup_from_config(&cfg, &cfg.home());
        setup.kept = first.kept.clone();
        setup.offsets.tools = first.tools.clone();
        let mut interp = Interpreter::new(Dialect::HuaxingLathe, text, setup);
        while let Ok(Some(_)) = interp.next_command() {}
        let left = interp.memory();
        assert_eq!(left.kept, [(200, 5.0), (201, 10.0)].into_iter().collect());
        save_memory(&file, &left).unwrap();
        // After a restart the same memory is there, and a program sees it.
        let (again, err) = load_memory(&cfg);
        assert!(err.is_none());
        assert_eq!(again, left);
        assert_eq!(again.tools.get(&1).map(|t| t.x), Some(1.5));
        // #5242 is G55's Z zero offset.
        assert_eq!(again.work.get(&1).and_then(|w| w.get(&'Z')), Some(&-80.0));
        // A damaged file is reported; the config's values are used.
        std::fs::write(&file, "kept: [not a map").unwrap();
        let (fallback, err) = load_memory(&cfg);
        assert!(err.is_some() && fallback.kept.is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
