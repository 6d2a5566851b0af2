//! interpreter node shell: program memory, program runs, the credit-based block stream to
//! motion, and the machine state.
//!
//! Commands arrive from hmi_bridge on `_internal/program_command`, each answered on
//! `_internal/command_result`. During a run, at most `capacity` unfinished blocks are in flight:
//! motion's `done_seq` returns the credit.

use std::collections::{BTreeMap, VecDeque};
use std::time::Duration;

/// Answers remembered so that a repeated command (same id) is answered, not executed again.
const ANSWERS_KEPT: usize = 64;

use cnc_msgs::msg::{
    Alarm, AlarmEvent, AxisState, CommandResult, MachineState, MotionBlock, MotionStatus,
    ProgramCommand,
};
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::monotonic_ns;
use cnc_runtime::dds::{stamp, RosNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown, MDI_PROGRAM};

use cnc_msgs::canon::to_motion_block;

use crate::offset_page;
use crate::setup::Memory;
use crate::{Command, Dialect, Interpreter, Library, Setup};

pub use cnc_runtime::MAX_PROGRAM_BYTES;
/// Programs kept in memory.
pub const MAX_PROGRAMS: usize = 1000;

/// A program name: what a control's directory shows, e.g. `O0001` or `part7.nc`.
pub fn valid_program_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c))
        && !name.starts_with('.')
}

/// The longest MDI entry: a few blocks typed at the panel.
pub const MAX_MDI_BYTES: usize = 4096;

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

struct Run {
    id: u64,
    program: String,
    interp: Interpreter,
    sent_seq: u64,
    end_seq: Option<u64>,
    failed: bool,
}

/// The interpreter's view of the machine from the launch config: axes, reference point, tool
/// post, the offset page and the work offsets; the program starts at `start`.
pub fn setup_from_config(cfg: &LaunchConfig, start: &[f64]) -> Setup {
    let letters = cfg.axis_letters();
    let mut setup = Setup::new(&letters, &cfg.diameter_axes(), start);
    setup.reference = cfg.home();
    setup.second_reference = cfg.second_reference();
    setup.front_tool_post = cfg.machine.tool_post == cnc_runtime::config::ToolPost::Front;
    setup.tool_change_macro = cfg.machine.tool_change_macro;
    for (&n, t) in &cfg.machine.tools {
        setup.offsets.tools.insert(
            n,
            crate::setup::ToolOffset {
                x: t.x,
                z: t.z,
                wear_x: t.wear_x,
                wear_z: t.wear_z,
                radius: t.radius,
                tip: t.tip,
            },
        );
    }
    for (code, axes) in &cfg.machine.work_offsets {
        if let Some(i) = cnc_runtime::config::work_offset_index(code) {
            let row = setup.offsets.work.entry(i).or_default();
            for (axis, &v) in axes {
                if let Some(c) = axis.chars().next() {
                    row.insert(c, v);
                }
            }
        }
    }
    setup
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

/// Writes the machine memory: to a temporary file, then renamed over the old one, so a
/// power cut leaves either the old or the new memory.
pub fn save_memory(path: &std::path::Path, memory: &Memory) -> Result<(), String> {
    let text = serde_yaml::to_string(memory).map_err(|e| e.to_string())?;
    cnc_runtime::persist::write_atomic(path, &text)
}

/// Takes what a run left in memory (kept variables, offsets) and stores it if it changed.
fn remember(run: Option<&Run>, memory: &mut Memory, path: Option<&std::path::Path>) {
    let Some(r) = run else { return };
    let now = r.interp.memory();
    if now != *memory {
        *memory = now;
        if let Some(p) = path {
            if let Err(e) = save_memory(p, memory) {
                log::error!("interpreter: machine memory not stored: {e}");
            }
        }
    }
}

pub fn run(cfg: LaunchConfig, shutdown: Shutdown) -> Result<(), String> {
    let dialect = Dialect::from_name(&cfg.machine.dialect)
        .ok_or_else(|| format!("unknown dialect {}", cfg.machine.dialect))?;
    let axes = cfg.axis_letters();
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "interpreter")?;
    let commands = ros.subscription::<ProgramCommand>(&topics::PROGRAM_COMMAND)?;
    let results = ros.publisher::<CommandResult>(&topics::COMMAND_RESULT)?;
    let to_motion_cmd = ros.publisher::<ProgramCommand>(&topics::PROGRAM_COMMAND)?;
    let blocks = ros.publisher::<MotionBlock>(&topics::MOTION_BLOCKS)?;
    let status_sub = ros.subscription::<MotionStatus>(&topics::MOTION_STATUS)?;
    let axes_sub = ros.subscription::<AxisState>(&topics::AXES)?;
    let alarm_sub = ros.subscription::<AlarmEvent>(&topics::ALARM_EVENTS)?;
    let state_pub = ros.publisher::<MachineState>(&topics::MACHINE_STATE)?;
    let alarms = AlarmReporter::new(&mut ros, "interpreter")?;

    let (mut memory, memory_error) = load_memory(&cfg);
    if let Some(e) = memory_error {
        log::error!("interpreter: machine memory not read, using the config's offsets: {e}");
    }
    let memory_path = cfg.machine.memory_file.clone();
    let mut programs: BTreeMap<String, String> = BTreeMap::new();
    let mut run: Option<Run> = None;
    let mut answered: VecDeque<CommandResult> = VecDeque::with_capacity(ANSWERS_KEPT);
    let mut run_counter = monotonic_ns() / 1000; // run ids grow across restarts of this node
    let mut status = MotionStatus::default();
    let mut position: Option<Vec<f64>> = None;
    let mut active_alarms: Vec<(String, u32)> = Vec::new();
    // Cycle start needs the axes' position from motion; until then the machine waits.
    let mut execution = MachineState::WAIT;
    let mut program_name = String::new();
    let mut state = StateReporter {
        publisher: state_pub,
        last: None,
        last_ns: 0,
    };
    let mut stop_command_id = 0u64;
    // The mode switch: the cell's machine powers up in AUTO (DESIGN: a robot cell runs
    // programs without an operator turning the switch).
    let mut mode = MachineState::MODE_AUTO;

    while !shutdown.requested() {
        let mut busy = false;
        while let Ok(Some((s, _))) = status_sub.take() {
            status = s;
        }
        while let Ok(Some((a, _))) = axes_sub.take() {
            // Only a report of this machine's axes is a start position.
            if a.axes.len() == axes.len() && a.axes.iter().all(|x| x.commanded_position.is_finite())
            {
                position = Some(a.axes.iter().map(|x| x.commanded_position).collect());
                if execution == MachineState::WAIT {
                    execution = MachineState::READY;
                }
            }
        }
        while let Ok(Some((e, _))) = alarm_sub.take() {
            // Messages and warnings (a refused request, a refused PLC file) inform; errors
            // and fatal alarms stop the run and block the next start until they clear.
            if e.kind == AlarmEvent::RAISED && e.alarm.severity < Alarm::SEVERITY_ERROR {
                continue;
            }
            let key = (e.alarm.source.clone(), e.alarm.number);
            if e.kind == AlarmEvent::RAISED {
                if !active_alarms.contains(&key) {
                    active_alarms.push(key);
                }
                // Any alarm stops the run: nothing more is sent; motion stops on its own or by
                // the cycle stop below.
                if let Some(r) = run.as_mut() {
                    if !r.failed {
                        r.failed = true;
                        stop_command_id += 1;
                        let _ = to_motion_cmd.publish(ProgramCommand {
                            id: stop_command_id,
                            command: ProgramCommand::CYCLE_STOP,
                            program: String::new(),
                            text: String::new(),
                        });
                    }
                }
                if execution == MachineState::ACTIVE || execution == MachineState::FEED_HOLD {
                    execution = MachineState::STOPPED;
                }
            } else {
                active_alarms.retain(|k| k != &key);
            }
        }
        while let Ok(Some((c, _))) = commands.take() {
            busy = true;
            // hmi_bridge repeats a command until it is answered: a repeat gets the same answer
            // again and is not acted on twice.
            if let Some(done) = answered.iter().find(|r| r.id == c.id) {
                let _ = results.publish(done.clone());
                continue;
            }
            let running = matches!(execution, MachineState::ACTIVE | MachineState::FEED_HOLD);
            // An MDI entry is stored as the program `MDI` and started as a program is
            // (decisions D43); cycle start runs programs in AUTO only.
            let mut refusal = None;
            let c = match c.command {
                ProgramCommand::MDI => match mdi_refusal(mode, running, &c.text) {
                    Some(why) => {
                        refusal = Some(why);
                        c
                    }
                    None => {
                        programs.insert(MDI_PROGRAM.into(), c.text.clone());
                        ProgramCommand {
                            command: ProgramCommand::START,
                            program: MDI_PROGRAM.into(),
                            ..c
                        }
                    }
                },
                ProgramCommand::START
                    if mode != MachineState::MODE_AUTO && execution != MachineState::FEED_HOLD =>
                {
                    refusal = Some(format!(
                        "cycle start refused: mode {}, not AUTO",
                        MachineState::mode_name_of(mode)
                    ));
                    c
                }
                _ => c,
            };
            let (accepted, message) = if let Some(why) = refusal {
                (false, why)
            } else {
                match c.command {
                ProgramCommand::MODE => match c.text.trim().parse::<u8>() {
                    Ok(m) if m <= MachineState::MODE_HANDWHEEL => {
                        if running && m != mode {
                            (false, "mode change refused: a program is running (stop it first)".into())
                        } else {
                            mode = m;
                            (true, format!("mode {}", MachineState::mode_name_of(m)))
                        }
                    }
                    _ => (false, format!("unknown mode {:?}: 0 AUTO, 1 MDI, 2 JOG, 3 HOME, 4 EDIT, 5 HANDWHEEL", c.text)),
                },
                ProgramCommand::READ => match programs.get(&c.program) {
                    Some(text) => (true, text.clone()),
                    None => (false, format!("program {:?} not found (alarm 22)", c.program)),
                },
                ProgramCommand::OFFSETS => (true, offset_page::format(&memory, &axes)),
                ProgramCommand::SET_TOOL_OFFSET | ProgramCommand::SET_WORK_OFFSET => {
                    if running {
                        (false, "offsets cannot change while a program runs (stop it first)".into())
                    } else {
                        // A stopped run's offsets are taken first, so the edit is not
                        // overwritten by them later.
                        remember(run.as_ref(), &mut memory, memory_path.as_deref());
                        run = None;
                        let mut edited = memory.clone();
                        let outcome = if c.command == ProgramCommand::SET_TOOL_OFFSET {
                            offset_page::set_tool(&mut edited, &c.program, &c.text)
                        } else {
                            offset_page::set_work(&mut edited, &c.program, &c.text, &axes)
                        };
                        match outcome {
                            Ok(message) => {
                                memory = edited;
                                if let Some(p) = memory_path.as_deref() {
                                    if let Err(e) = save_memory(p, &memory) {
                                        log::error!("interpreter: machine memory not stored: {e}");
                                    }
                                }
                                (true, message)
                            }
                            Err(why) => (false, why),
                        }
                    }
                }
                ProgramCommand::LOAD => {
                    if !valid_program_name(&c.program) {
                        (false, format!("invalid program name {:?}: letters, digits, '.', '_', '-', at most 64", c.program))
                    } else if c.text.len() > MAX_PROGRAM_BYTES {
                        (
                            false,
                            format!(
                                "program too large: {} bytes, limit {MAX_PROGRAM_BYTES}",
                                c.text.len()
                            ),
                        )
                    } else if programs.len() >= MAX_PROGRAMS && !programs.contains_key(&c.program) {
                        (
                            false,
                            format!("program memory full ({MAX_PROGRAMS} programs)"),
                        )
                    } else if run.as_ref().is_some_and(|r| r.program == c.program)
                        && execution == MachineState::ACTIVE
                    {
                        (false, format!("{} is running", c.program))
                    } else {
                        let lines = c.text.lines().count();
                        programs.insert(c.program.clone(), c.text.clone());
                        (true, format!("{} stored ({lines} lines)", c.program))
                    }
                }
                ProgramCommand::START => {
                    if !active_alarms.is_empty() {
                        (
                            false,
                            format!("alarm active ({} alarms): reset first", active_alarms.len()),
                        )
                    } else if matches!(execution, MachineState::ACTIVE) {
                        (false, "a program is running".into())
                    } else if execution == MachineState::FEED_HOLD && c.program.is_empty() {
                        execution = MachineState::ACTIVE;
                        (true, "resumed".into())
                    } else if let Some(text) = programs.get(&c.program) {
                        match position.clone() {
                            None => (false, "no axis position from motion yet".into()),
                            Some(start) => {
                                run_counter += 1;
                                remember(run.as_ref(), &mut memory, memory_path.as_deref());
                                let mut setup = setup_from_config(&cfg, &start);
                                setup.kept = memory.kept.clone();
                                setup.offsets.tools = memory.tools.clone();
                                setup.offsets.work = memory.work.clone();
                                // The cell runs programs as the operator would: M99 or G27
                                // loops go on until stop.
                                setup.single_pass = false;
                                let interp = Interpreter::with_library(
                                    dialect,
                                    text,
                                    setup,
                                    library(&programs),
                                );
                                run = Some(Run {
                                    id: run_counter,
                                    program: c.program.clone(),
                                    interp,
                                    sent_seq: 0,
                                    end_seq: None,
                                    failed: false,
                                });
                                program_name = c.program.clone();
                                execution = MachineState::ACTIVE;
                                (true, format!("{} started", c.program))
                            }
                        }
                    } else {
                        (
                            false,
                            format!("program {:?} not found (alarm 22)", c.program),
                        )
                    }
                }
                ProgramCommand::FEED_HOLD => {
                    if execution == MachineState::ACTIVE {
                        execution = MachineState::FEED_HOLD;
                        (true, "feed hold".into())
                    } else {
                        (false, "no program running".into())
                    }
                }
                ProgramCommand::CYCLE_STOP => {
                    if let Some(r) = run.as_mut() {
                        r.failed = true;
                    }
                    if matches!(execution, MachineState::ACTIVE | MachineState::FEED_HOLD) {
                        execution = MachineState::STOPPED;
                    }
                    (true, "cycle stop".into())
                }
                ProgramCommand::RESET => {
                    remember(run.as_ref(), &mut memory, memory_path.as_deref());
                    run = None;
                    // Program alarms are cleared by reset; alarms whose cause persists (emergency
                    // stop) stay until their source clears them.
                    for (source, number) in active_alarms.clone() {
                        if source == "interpreter" {
                            alarms.clear(number);
                            active_alarms.retain(|k| k != &(source.clone(), number));
                        }
                    }
                    execution = if position.is_some() {
                        MachineState::READY
                    } else {
                        MachineState::WAIT
                    };
                    (true, "reset".into())
                }
                ProgramCommand::LIST => {
                    let lines: Vec<String> = programs
                        .iter()
                        .map(|(name, text)| format!("{name}\t{}", text.len()))
                        .collect();
                    (true, lines.join("\n"))
                }
                ProgramCommand::DELETE => {
                    let running = run.as_ref().is_some_and(|r| r.program == c.program)
                        && matches!(execution, MachineState::ACTIVE | MachineState::FEED_HOLD);
                    if running {
                        (false, format!("{} is running: stop it first", c.program))
                    } else if programs.remove(&c.program).is_some() {
                        (true, format!("{} deleted", c.program))
                    } else {
                        (
                            false,
                            format!("program {:?} not found (alarm 22)", c.program),
                        )
                    }
                }
                other => (false, format!("unknown command {other}")),
                }
            };
            let result = CommandResult {
                id: c.id,
                accepted,
                message,
            };
            let _ = results.publish(result.clone());
            if answered.len() == ANSWERS_KEPT {
                answered.pop_front();
            }
            answered.push_back(result);
        }
        // A start is reported before any block of it runs: a program that fails in its first
        // blocks still shows ACTIVE, then STOPPED, in that order.
        report_state(
            &mut state,
            mode,
            execution,
            run.as_ref(),
            &status,
            &active_alarms,
            &program_name,
        );
        // Feed the motion queue while credit lasts.
        if let Some(r) = run.as_mut() {
            let in_flight = if status.run_id == r.id {
                r.sent_seq.saturating_sub(status.done_seq)
            } else {
                r.sent_seq
            };
            let credit = (status.capacity.max(2) as u64).saturating_sub(in_flight);
            for _ in 0..credit {
                if r.failed || r.end_seq.is_some() {
                    break;
                }
                match r.interp.next_command() {
                    Ok(Some(canon)) => {
                        busy = true;
                        r.sent_seq += 1;
                        let mut msg = to_motion_block(
                            r.id,
                            r.sent_seq,
                            &r.program,
                            canon.line,
                            &canon.command,
                        );
                        msg.origin = r.interp.program_origin();
                        if canon.command == Command::ProgramEnd {
                            r.end_seq = Some(r.sent_seq);
                        }
                        if let Err(e) = blocks.publish(msg) {
                            log::error!("interpreter: block not sent: {e:?}");
                        }
                    }
                    Ok(None) => break,
                    Err(e) => {
                        r.failed = true;
                        alarms.raise(alarms.alarm(
                            e.number,
                            Alarm::SEVERITY_ERROR,
                            &e.text,
                            &r.program,
                            e.line,
                        ));
                        // The interpreter knows its own alarm at once: it does not wait for the
                        // event to come back over DDS to stop the program.
                        let key = ("interpreter".to_string(), e.number);
                        if !active_alarms.contains(&key) {
                            active_alarms.push(key);
                        }
                        if matches!(execution, MachineState::ACTIVE | MachineState::FEED_HOLD) {
                            execution = MachineState::STOPPED;
                        }
                    }
                }
            }
            if status.run_id == r.id
                && Some(status.done_seq) == r.end_seq
                && r.end_seq.is_some()
                && execution == MachineState::ACTIVE
            {
                execution = MachineState::PROGRAM_COMPLETED;
                remember(Some(r), &mut memory, memory_path.as_deref());
                run = None;
            }
        }
        if let Some(r) = run.as_ref() {
            if status.run_id == r.id
                && status.state == MotionStatus::STATE_HOLD
                && execution == MachineState::ACTIVE
            {
                execution = MachineState::FEED_HOLD;
            }
            if status.run_id == r.id
                && status.state == MotionStatus::STATE_RUNNING
                && execution == MachineState::FEED_HOLD
            {
                execution = MachineState::ACTIVE;
            }
        }
        report_state(
            &mut state,
            mode,
            execution,
            run.as_ref(),
            &status,
            &active_alarms,
            &program_name,
        );
        if !busy {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    // A program stopped by shutdown keeps what it had stored so far.
    remember(run.as_ref(), &mut memory, memory_path.as_deref());
    Ok(())
}

/// Publishes `/machine_state` on every change, so readers see each transition in order, and
/// twice a second otherwise.
struct StateReporter {
    publisher: cnc_runtime::dds::Publisher<MachineState>,
    last: Option<(u8, u8, u32, bool, bool, String)>,
    last_ns: u64,
}

fn report_state(
    state: &mut StateReporter,
    mode: u8,
    execution: u8,
    run: Option<&Run>,
    status: &MotionStatus,
    active_alarms: &[(String, u32)],
    program_name: &str,
) {
    let line = if run.is_some_and(|r| r.id == status.run_id)
        || !matches!(execution, MachineState::READY | MachineState::WAIT)
    {
        status.line
    } else {
        0
    };
    let estop = active_alarms.iter().any(|(s, n)| s == "plc" && *n == 65);
    let key = (
        mode,
        execution,
        line,
        estop,
        !active_alarms.is_empty(),
        program_name.to_string(),
    );
    let now = monotonic_ns();
    if state.last.as_ref() != Some(&key) || now - state.last_ns > 500_000_000 {
        state.last_ns = now;
        state.last = Some(key);
        let _ = state.publisher.publish(MachineState {
            stamp: stamp(),
            mode,
            execution,
            execution_name: MachineState::execution_name_of(execution).into(),
            program: program_name.into(),
            line,
            emergency_stop: estop,
            alarm_active: !active_alarms.is_empty(),
        });
    }
}

/// Program memory as a subprogram library: every stored program with an O number on its first
/// line or in its name (`O0010`, `O0010.nc`).
fn library(programs: &BTreeMap<String, String>) -> Library {
    let mut lib = Library::new();
    for (name, text) in programs {
        let number = Library::declared_number(text)
            .or_else(|| Library::file_number(std::path::Path::new(name)));
        if let Some(n) = number {
            if lib.get(n).is_none() {
                lib.insert(n, name, text);
            }
        }
    }
    lib
}

#[cfg(test)]
mod tests {
    use super::*;

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
