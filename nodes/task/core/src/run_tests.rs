//! The run core without DDS: commands in, effects and state out, motion played by hand.

use super::*;
use cnc_interpreter::setup::ToolOffset;
use cnc_msgs::msg::MotionCommand;

#[path = "run_tests/commands.rs"]
mod commands;
#[path = "run_tests/restart.rs"]
mod restart;

const PART: &str = "G00 X100 Z20\nS500 M03\nG01 Z10 F3000\nG01 Z5\nM05\nM30\n";

fn core() -> RunCore {
    let mut base = Setup::lathe([200.0, 100.0]);
    base.offsets.tools.insert(
        1,
        ToolOffset {
            radius: 0.4,
            tip: 3,
            ..ToolOffset::default()
        },
    );
    let memory = Memory {
        tools: base.offsets.tools.clone(),
        ..Memory::default()
    };
    RunCore::new(Dialect::HuaxingLathe, base, memory, 1000)
}

/// A command the core answers at once (not one it passes on to motion).
fn command(core: &mut RunCore, id: u64, request: TaskRequest) -> CommandResult {
    core.command(id, request).expect("answered at once")
}

fn load(name: &str, text: &str) -> TaskRequest {
    TaskRequest::Load {
        name: name.into(),
        text: text.into(),
    }
}

fn start(name: &str, at: &str) -> TaskRequest {
    TaskRequest::Start {
        name: name.into(),
        at: at.into(),
    }
}

fn status(run_id: u64, done_seq: u64, capacity: u32, state: u8) -> MotionStatus {
    MotionStatus {
        run_id,
        accepted_seq: done_seq,
        done_seq,
        capacity,
        line: 0,
        state,
        ..MotionStatus::default()
    }
}

fn blocks(effects: &[Effect]) -> Vec<&MotionBlock> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::Block(b) => Some(b),
            _ => None,
        })
        .collect()
}

/// A core with the part loaded and the axes' position known, READY.
fn ready() -> RunCore {
    let mut c = core();
    assert_eq!(c.execution(), MachineState::WAIT);
    assert!(command(&mut c, 1, load("part.nc", PART)).accepted);
    c.plc_scanned();
    let refused = command(&mut c, 2, start("part.nc", ""));
    assert!(!refused.accepted && refused.message.contains("no axis position"));
    c.axes(&[200.0, 100.0]);
    assert_eq!(c.execution(), MachineState::READY);
    c
}

#[test]
fn the_machine_is_ready_only_once_the_plc_has_scanned() {
    let mut c = core();
    assert!(command(&mut c, 1, load("part.nc", PART)).accepted);
    c.axes(&[200.0, 100.0]);
    // Motion knows the axes, but the PLC's interface still holds the power-up emergency
    // stop: a start now would be refused by motion (1095) or wait unseen.
    assert_eq!(c.execution(), MachineState::WAIT);
    let refused = command(&mut c, 2, start("part.nc", ""));
    assert!(!refused.accepted && refused.message.contains("PLC has not scanned"));
    assert!(blocks(&c.take_effects()).is_empty());
    let reset = command(&mut c, 3, TaskRequest::Reset);
    assert!(reset.accepted);
    assert_eq!(c.execution(), MachineState::WAIT);
    c.plc_scanned();
    assert_eq!(c.execution(), MachineState::READY);
    assert!(command(&mut c, 4, start("part.nc", "")).accepted);
}

#[test]
fn credit_limits_the_blocks_in_flight_and_completion_follows_motion() {
    let mut c = ready();
    assert!(command(&mut c, 3, start("part.nc", "")).accepted);
    assert_eq!(c.execution(), MachineState::ACTIVE);
    c.motion_status(status(0, 0, 3, MotionStatus::STATE_IDLE));
    assert!(c.step());
    let sent = c.take_effects();
    let b = blocks(&sent);
    // Capacity 3, nothing done: three blocks, numbered from 1, of run 1001.
    assert_eq!(b.len(), 3);
    assert_eq!(b.iter().map(|b| b.seq).collect::<Vec<_>>(), [1, 2, 3]);
    assert!(b.iter().all(|b| b.run_id == 1001 && b.program == "part.nc"));
    assert_eq!(b[0].origin.len(), 2);
    // No credit left: nothing more.
    assert!(!c.step());
    assert!(c.take_effects().is_empty());
    // Motion finishes two: two more.
    c.motion_status(status(1001, 2, 3, MotionStatus::STATE_RUNNING));
    c.step();
    assert_eq!(
        blocks(&c.take_effects())
            .iter()
            .map(|b| b.seq)
            .collect::<Vec<_>>(),
        [4, 5]
    );
    // The rest; the program end is the last block.
    // Motion stays one block behind until all are sent.
    let mut last = 5;
    loop {
        c.motion_status(status(1001, last - 1, 3, MotionStatus::STATE_RUNNING));
        c.step();
        match blocks(&c.take_effects()).last() {
            Some(b) => last = b.seq,
            None => break,
        }
    }
    assert_eq!(
        c.execution(),
        MachineState::ACTIVE,
        "motion has not finished"
    );
    c.motion_status(status(1001, last, 3, MotionStatus::STATE_IDLE));
    c.step();
    assert_eq!(c.execution(), MachineState::PROGRAM_COMPLETED);
    assert_eq!(c.state().program, "part.nc");
    // A new start is a new run id.
    assert!(command(&mut c, 4, start("part.nc", "")).accepted);
    c.motion_status(status(1001, last, 3, MotionStatus::STATE_IDLE));
    c.step();
    assert!(blocks(&c.take_effects()).iter().all(|b| b.run_id == 1002));
}

#[test]
fn feed_hold_follows_motion_and_resumes_on_cycle_start() {
    let mut c = ready();
    command(&mut c, 3, start("part.nc", ""));
    c.motion_status(status(1001, 0, 2, MotionStatus::STATE_RUNNING));
    c.step();
    assert!(command(&mut c, 4, TaskRequest::FeedHold).accepted);
    assert_eq!(c.execution(), MachineState::FEED_HOLD);
    // A start while held with no program named resumes.
    let r = command(&mut c, 5, start("", ""));
    assert!(r.accepted && r.message == "resumed", "{r:?}");
    assert_eq!(c.execution(), MachineState::ACTIVE);
    // Motion holding (panel feed hold) shows as FEED_HOLD, running again as ACTIVE.
    c.motion_status(status(1001, 0, 2, MotionStatus::STATE_HOLD));
    c.step();
    assert_eq!(c.execution(), MachineState::FEED_HOLD);
    c.motion_status(status(1001, 0, 2, MotionStatus::STATE_RUNNING));
    c.step();
    assert_eq!(c.execution(), MachineState::ACTIVE);
    assert!(command(&mut c, 6, TaskRequest::FeedHold).accepted);
}

#[test]
fn cycle_stop_ends_the_stream_and_reset_makes_the_machine_ready() {
    let mut c = ready();
    command(&mut c, 3, start("part.nc", ""));
    c.motion_status(status(1001, 0, 2, MotionStatus::STATE_RUNNING));
    c.step();
    c.take_effects();
    assert!(command(&mut c, 4, TaskRequest::CycleStop).accepted);
    assert_eq!(c.execution(), MachineState::STOPPED);
    c.motion_status(status(1001, 2, 2, MotionStatus::STATE_IDLE));
    c.step();
    assert!(
        blocks(&c.take_effects()).is_empty(),
        "a stopped run sends nothing"
    );
    // Offsets and mode may change once stopped.
    assert!(command(&mut c, 5, TaskRequest::Mode(1)).accepted);
    assert!(command(&mut c, 6, TaskRequest::Reset).accepted);
    assert_eq!(c.execution(), MachineState::READY);
    assert_eq!(c.state().line, 0);
}

#[test]
fn a_program_alarm_stops_the_run_and_blocks_starts_until_reset() {
    let mut c = ready();
    let bad = "G00 X100 Z20\nG01 Z10 F3000\nG02 X120 Z-20 R5\nM30\n";
    command(&mut c, 3, load("bad.nc", bad));
    command(&mut c, 4, start("bad.nc", ""));
    c.motion_status(status(0, 0, 16, MotionStatus::STATE_IDLE));
    c.step();
    let effects = c.take_effects();
    // The two good blocks went out, then the alarm with the run's program and the line.
    assert_eq!(blocks(&effects).len(), 2);
    let raised = effects.iter().find_map(|e| match e {
        Effect::Raise {
            number,
            program,
            line,
            ..
        } => Some((*number, program.clone(), *line)),
        _ => None,
    });
    assert_eq!(raised, Some((11, "bad.nc".to_string(), 3)));
    assert_eq!(c.execution(), MachineState::STOPPED);
    assert!(c.state().alarm_active);
    let r = command(&mut c, 5, start("part.nc", ""));
    assert!(!r.accepted && r.message.contains("reset first"), "{r:?}");
    // Reset clears the interpreter's own alarm.
    command(&mut c, 6, TaskRequest::Reset);
    assert!(c.take_effects().contains(&Effect::Clear(11)));
    assert!(!c.state().alarm_active);
    assert!(command(&mut c, 7, start("part.nc", "")).accepted);
}

#[test]
fn another_nodes_alarm_stops_the_run_with_a_cycle_stop_and_needs_its_source_to_clear() {
    let mut c = ready();
    command(&mut c, 3, start("part.nc", ""));
    let mut event = AlarmEvent {
        kind: AlarmEvent::RAISED,
        alarm: Alarm {
            number: 65,
            severity: Alarm::SEVERITY_FATAL,
            source: "plc".into(),
            ..Alarm::default()
        },
    };
    c.alarm_event(&event);
    let effects = c.take_effects();
    assert!(matches!(&effects[..], [Effect::ToMotion(p)] if p.kind == MotionCommand::CYCLE_STOP));
    assert_eq!(c.execution(), MachineState::STOPPED);
    assert!(c.state().emergency_stop);
    // Reset does not clear another node's alarm; its CLEARED does.
    command(&mut c, 4, TaskRequest::Reset);
    assert!(c.state().alarm_active);
    assert!(!command(&mut c, 5, start("part.nc", "")).accepted);
    event.kind = AlarmEvent::CLEARED;
    c.alarm_event(&event);
    assert!(!c.state().alarm_active && !c.state().emergency_stop);
    // A warning informs and stops nothing.
    assert!(command(&mut c, 6, start("part.nc", "")).accepted);
    // (The reset's command to motion went before.)
    c.take_effects();
    c.alarm_event(&AlarmEvent {
        kind: AlarmEvent::RAISED,
        alarm: Alarm {
            number: 1,
            severity: Alarm::SEVERITY_WARNING,
            source: "hmi_bridge".into(),
            ..Alarm::default()
        },
    });
    assert_eq!(c.execution(), MachineState::ACTIVE);
    assert!(c.take_effects().is_empty());
}

/// Program memory in a folder as the core sees it: what it was asked to keep, or a disk
/// that refuses.
#[derive(Clone, Default)]
struct Disk {
    files: std::sync::Arc<std::sync::Mutex<BTreeMap<String, String>>>,
    broken: bool,
}

impl cnc_machine::programs::ProgramStorage for Disk {
    fn store(&mut self, name: &str, text: &str) -> Result<(), String> {
        if self.broken {
            return Err("No space left on device".into());
        }
        if let Ok(mut f) = self.files.lock() {
            f.insert(name.into(), text.into());
        }
        Ok(())
    }
    fn remove(&mut self, name: &str) -> Result<(), String> {
        if self.broken {
            return Err("Read-only file system".into());
        }
        if let Ok(mut f) = self.files.lock() {
            f.remove(name);
        }
        Ok(())
    }
}

#[test]
fn the_block_skip_switch_applies_to_the_blocks_read_after_it() {
    const SKIPPY: &str = "G00 X100 Z20\n/G00 X150\nG01 Z10 F3000\n/G00 X160\nM30\n";
    let lines_sent = |c: &mut RunCore, credit: u32| {
        c.step();
        // The lines the blocks came from (M30 is two blocks: its strobe and the end).
        let mut sent: Vec<u32> = blocks(&c.take_effects()).iter().map(|b| b.line).collect();
        sent.dedup();
        c.motion_status(status(
            c.run_counter,
            0,
            credit,
            MotionStatus::STATE_RUNNING,
        ));
        sent
    };
    for (on, expected) in [(true, vec![1, 3, 5]), (false, vec![1, 2, 3, 4, 5])] {
        let mut c = ready();
        assert!(command(&mut c, 3, load("skip.nc", SKIPPY)).accepted);
        c.block_skip_switch(on);
        assert!(command(&mut c, 4, start("skip.nc", "")).accepted);
        c.motion_status(status(0, 0, 100, MotionStatus::STATE_IDLE));
        assert_eq!(lines_sent(&mut c, 100), expected, "switch {on}");
    }
    // Turned off during the run: the first skip block was read with it on, the second after.
    let mut c = ready();
    assert!(command(&mut c, 3, load("skip.nc", SKIPPY)).accepted);
    assert!(command(&mut c, 4, start("skip.nc", "")).accepted);
    c.motion_status(status(0, 0, 2, MotionStatus::STATE_IDLE));
    let first = lines_sent(&mut c, 2);
    assert_eq!(first, vec![1, 3]);
    c.block_skip_switch(false);
    c.motion_status(status(c.run_counter, 2, 2, MotionStatus::STATE_RUNNING));
    assert_eq!(lines_sent(&mut c, 2), vec![4, 5]);
}

#[test]
fn an_802d_message_shows_as_its_block_runs_until_the_next_one_or_the_end() {
    let base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, Memory::default(), 1000);
    let part = "MSG(\"ROUGHING\")\nG0 X10\nG1 X20 F100\nMSG(\"FINISHING \"<<2)\nG1 X30\n\
                MSG()\nG1 X40\nM2\n";
    assert!(command(&mut c, 1, load("PART.MPF", part)).accepted);
    c.plc_scanned();
    c.axes(&[0.0; 3]);
    assert!(command(&mut c, 2, start("PART.MPF", "")).accepted);
    // Every block goes to motion at once; the messages wait for motion.
    c.motion_status(status(1001, 0, 100, MotionStatus::STATE_RUNNING));
    c.step();
    let sent = c.take_effects();
    let seq_of_line = |line: u32| {
        blocks(&sent)
            .iter()
            .find(|b| b.line == line)
            .map(|b| b.seq)
            .unwrap()
    };
    let (x10, x20, x30, end) = (
        seq_of_line(2),
        seq_of_line(3),
        seq_of_line(5),
        blocks(&sent).last().map(|b| b.seq).unwrap(),
    );
    let mut shown = Vec::new();
    for done in 0..end {
        c.motion_status(status(1001, done, 100, MotionStatus::STATE_RUNNING));
        c.step();
        shown.push(c.state().message);
    }
    // Before the first move is done, its message shows; the second once X20 is reached, as
    // its block follows; `MSG()` clears it once X30 is reached.
    assert_eq!(shown[x10 as usize - 1], "ROUGHING");
    assert_eq!(shown[x20 as usize - 1], "ROUGHING");
    assert_eq!(shown[x20 as usize], "FINISHING 2");
    assert_eq!(shown[x30 as usize - 1], "FINISHING 2");
    assert_eq!(shown[x30 as usize], "");
    // A message at the end is gone with the run.
    let part = "G0 X10\nMSG(\"CHECK THE PART\")\nM2\n";
    assert!(command(&mut c, 3, load("B.MPF", part)).accepted);
    c.motion_status(status(1001, end, 100, MotionStatus::STATE_IDLE));
    c.step();
    assert_eq!(c.execution(), MachineState::PROGRAM_COMPLETED);
    assert!(command(&mut c, 4, start("B.MPF", "")).accepted);
    c.step();
    let last = blocks(&c.take_effects()).last().map(|b| b.seq).unwrap();
    c.motion_status(status(1002, last - 1, 100, MotionStatus::STATE_RUNNING));
    c.step();
    assert_eq!(c.state().message, "CHECK THE PART");
    c.motion_status(status(1002, last, 100, MotionStatus::STATE_IDLE));
    c.step();
    assert_eq!(c.execution(), MachineState::PROGRAM_COMPLETED);
    assert_eq!(c.state().message, "");
}

#[test]
fn an_802d_part_is_counted_in_memory_before_its_m30_goes_to_motion() {
    // D82 with D59: $AC_TOTAL_PARTS (kept entry 11000) goes up at M30 and is stored (write
    // ahead) before the blocks of the run go to motion.
    let base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, Memory::default(), 1000);
    assert!(command(&mut c, 1, load("PART.MPF", "G0 X10\nM30\n")).accepted);
    c.plc_scanned();
    c.axes(&[0.0; 3]);
    let mut done = 0;
    for (k, run_id) in [(1.0, 1001), (2.0, 1002)] {
        let id = 2 + run_id - 1001;
        assert!(command(&mut c, id, start("PART.MPF", "")).accepted);
        c.motion_status(status(run_id, 0, 100, MotionStatus::STATE_RUNNING));
        c.step();
        let effects = c.take_effects();
        let store = effects
            .iter()
            .position(|e| matches!(e, Effect::StoreMemory))
            .expect("the count is stored");
        let first_block = effects
            .iter()
            .position(|e| matches!(e, Effect::Block(_)))
            .expect("blocks go to motion");
        assert!(store < first_block, "{effects:?}");
        assert_eq!(c.memory().kept.get(&11_000), Some(&k));
        done = blocks(&effects).last().map(|b| b.seq).unwrap();
        c.motion_status(status(run_id, done, 100, MotionStatus::STATE_IDLE));
        c.step();
        assert_eq!(c.execution(), MachineState::PROGRAM_COMPLETED);
    }
    assert!(done > 0);
}

#[test]
fn extcall_runs_a_program_of_the_external_drives_read_at_the_start() {
    // D110: the shell hands the drives' programs over before a start; EXTCALL finds them by
    // their drive path, and a program not on a drive stops the run with 14011.
    let base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, Memory::default(), 1000);
    let main = "N10 G0 X1\nN20 EXTCALL (\"D:\\EXTERNE_UP\\BOHRUNG\")\nN30 G0 X3\nN40 M30\n";
    assert!(command(&mut c, 1, load("MAIN.MPF", main)).accepted);
    c.plc_scanned();
    c.axes(&[0.0; 3]);
    c.set_external_programs(
        [(
            r"D:\EXTERNE_UP\BOHRUNG".to_string(),
            "G1 X2 F100\nM17\n".to_string(),
        )]
        .into_iter()
        .collect(),
    );
    assert!(command(&mut c, 2, start("MAIN.MPF", "")).accepted);
    c.motion_status(status(1001, 0, 100, MotionStatus::STATE_RUNNING));
    c.step();
    let xs: Vec<f64> = blocks(&c.take_effects())
        .iter()
        .filter(|b| !b.end.is_empty())
        .map(|b| b.end[0])
        .collect();
    assert_eq!(xs, [1.0, 2.0, 3.0]);
    // Without the drive (unplugged before the start) the call stops with 14011.
    let base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, Memory::default(), 1000);
    assert!(command(&mut c, 1, load("MAIN.MPF", main)).accepted);
    c.plc_scanned();
    c.axes(&[0.0; 3]);
    assert!(command(&mut c, 2, start("MAIN.MPF", "")).accepted);
    c.motion_status(status(1001, 0, 100, MotionStatus::STATE_RUNNING));
    c.step();
    let raised: Vec<u32> = c
        .take_effects()
        .iter()
        .filter_map(|e| match e {
            Effect::Raise { number, .. } => Some(*number),
            _ => None,
        })
        .collect();
    assert_eq!(raised, [14011]);
}

/// An 802D mill at X0 Y0 Z100 running `program`, its run numbered 11.
fn mill_running(program: &str) -> RunCore {
    let base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0, 0.0, 100.0]);
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, Memory::default(), 10);
    assert!(command(&mut c, 1, load("PROBE.MPF", program)).accepted);
    c.plc_scanned();
    c.axes(&[0.0, 0.0, 100.0]);
    assert!(command(&mut c, 2, start("PROBE.MPF", "")).accepted);
    c.motion_status(status(0, 0, 64, MotionStatus::STATE_IDLE));
    c
}

/// A measuring block (MEAS, D116): the run sends it and nothing after it until motion's
/// status carries its result; the program then reads on from where the axes came to rest.
#[test]
fn a_measuring_block_holds_the_program_until_motion_reports_its_result() {
    let mut c = mill_running(
        "G90 G0 X0 Y0 Z10\nMEAS=1 G1 Z-20 F300\nR5=$AA_MW[Z]\n\
         IF $AC_MEA[1]==0 GOTOF MISSED\nG1 X10 F500\nM30\nMISSED: M0\nM30\n",
    );
    c.step();
    let sent = c.take_effects();
    let kinds: Vec<u8> = blocks(&sent).iter().map(|b| b.kind).collect();
    assert_eq!(kinds.last(), Some(&MotionBlock::KIND_PROBE), "{kinds:?}");
    let result_seq = blocks(&sent).last().map_or(0, |b| b.seq);
    // Credit is plenty, but the program waits for the measurement.
    let waiting = status(11, result_seq - 1, 64, MotionStatus::STATE_RUNNING);
    c.motion_status(waiting.clone());
    c.step();
    assert!(blocks(&c.take_effects()).is_empty());
    // Done without its result (another block's): still waiting.
    c.motion_status(MotionStatus {
        result_seq: result_seq - 1,
        ..status(11, result_seq, 64, MotionStatus::STATE_IDLE)
    });
    c.step();
    assert!(blocks(&c.take_effects()).is_empty());
    // The probe switched at Z2.5 and the axes came to rest at Z2.3.
    c.motion_status(MotionStatus {
        result_seq,
        result_triggered: true,
        result_position: vec![0.0, 0.0, 2.5],
        result_rest: vec![0.0, 0.0, 2.3],
        ..status(11, result_seq, 64, MotionStatus::STATE_IDLE)
    });
    c.step();
    let after = c.take_effects();
    let next = blocks(&after);
    let line = next.first().expect("the program reads on");
    // The line after the switch (G1 X10) starts from the rest: it keeps Z2.3.
    assert_eq!(line.kind, MotionBlock::KIND_LINEAR);
    assert_eq!(line.end, vec![10.0, 0.0, 2.3]);
    // R5 (kept as 10 005) holds the Z where the probe switched.
    assert_eq!(c.memory().kept.get(&10_005), Some(&2.5));
}

/// A result that does not fit the machine ends the run with an alarm.
#[test]
fn a_measurement_that_does_not_fit_the_machine_is_an_alarm() {
    let mut c = mill_running("MEAS=-1 G1 Z-20 F300\nG1 X10\nM30\n");
    c.step();
    let seq = blocks(&c.take_effects()).last().map_or(0, |b| b.seq);
    c.motion_status(MotionStatus {
        result_seq: seq,
        result_triggered: true,
        result_position: vec![0.0, 2.5],
        result_rest: vec![0.0, 0.0, f64::NAN],
        ..status(11, seq, 64, MotionStatus::STATE_IDLE)
    });
    c.step();
    let effects = c.take_effects();
    assert!(blocks(&effects).is_empty());
    assert!(effects
        .iter()
        .any(|e| matches!(e, Effect::Raise { line: 1, text, .. }
            if text.contains("machine's result names 2 and 3 axis values"))));
    assert_eq!(c.execution(), MachineState::STOPPED);
}

/// The MSG service's text goes out as its block runs: once motion has finished the commands
/// before it (D120).
#[test]
fn a_msg_service_text_goes_out_when_its_block_runs() {
    let mut c = mill_running("G0 X10\nMSG(\"File: at X10\")\nG0 X20\nM30\n");
    c.step();
    let sent = c.take_effects();
    let first = blocks(&sent)
        .iter()
        .find(|b| b.kind == MotionBlock::KIND_RAPID)
        .map_or(0, |b| b.seq);
    let service = |effects: &[Effect]| {
        effects
            .iter()
            .filter(|e| matches!(e, Effect::MessageService(..)))
            .count()
    };
    assert_eq!(service(&sent), 0, "not before X10 is reached");
    c.motion_status(status(11, first - 1, 64, MotionStatus::STATE_RUNNING));
    c.step();
    assert_eq!(service(&c.take_effects()), 0);
    c.motion_status(status(11, first, 64, MotionStatus::STATE_RUNNING));
    c.step();
    let effects = c.take_effects();
    assert!(effects.iter().any(|e| matches!(e,
        Effect::MessageService(cnc_interpreter_core::ServiceOutput::File, t) if t == "at X10")));
}

/// Issue 45 item 5: a main program and the subprogram it calls.
const MAIN_CALLING: &str = "G00 X100 Z20\nS500 M03\nM98 P2000\nG00 X150 Z50\nM05\nM30\n";
const SUB: &str = "O2000\nG01 X90 Z10 F3000\nG01 Z5\nG01 Z0\nG01 X95\nG01 Z-5\nM99\n";
const SUB_EDITED: &str = "O2000\nG01 X80 Z10 F3000\nG01 Z5\nG01 Z0\nG01 X95\nG01 Z-5\nM99\n";

/// Issue 46 item 4: the tool in the spindle is kept with the machine's memory: a run that
/// changes the tool leaves it there, and the next run starts with it.
#[test]
fn the_tool_in_the_spindle_is_kept_from_run_to_run() {
    let mut base = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0, 0.0, 100.0]);
    base.tool_change_with_m6 = true;
    for (entry, z) in [(11, 50.0), (31, 10.0), (32, 12.0)] {
        base.offsets.tools.insert(
            entry,
            ToolOffset {
                z,
                ..ToolOffset::default()
            },
        );
    }
    let memory = Memory {
        tools: base.offsets.tools.clone(),
        spindle_tool: 1,
        ..Memory::default()
    };
    let mut c = RunCore::new(Dialect::Sinumerik802d, base, memory, 1000);
    for (id, name, text) in [
        (1, "CHANGE.MPF", "T3\nM6\nG0 Z0\nM30\n"),
        (2, "EDGE.MPF", "D2\nG0 Z0\nM30\n"),
    ] {
        assert!(command(&mut c, id, load(name, text)).accepted);
    }
    c.plc_scanned();
    c.axes(&[0.0, 0.0, 100.0]);
    assert!(command(&mut c, 3, start("CHANGE.MPF", "")).accepted);
    let first = run_to_end(&mut c, 1001);
    let last_z = |blocks: &[(u8, Vec<f64>, u32)]| {
        blocks.iter().rev().find(|b| b.1.len() == 3).map(|b| b.1[2])
    };
    assert_eq!(last_z(&first), Some(10.0), "T3 D1 {first:?}");
    assert_eq!(c.memory().spindle_tool, 3);
    assert!(command(&mut c, 4, start("EDGE.MPF", "")).accepted);
    let second = run_to_end(&mut c, 1002);
    assert_eq!(last_z(&second), Some(12.0), "T3 D2 {second:?}");
}

/// Motion's status for run `run_id` with `done_seq` blocks finished, at `line`.
fn status_at(run_id: u64, done_seq: u64, line: u32, state: u8) -> MotionStatus {
    MotionStatus {
        line,
        ..status(run_id, done_seq, 64, state)
    }
}

/// Plays motion for the core's run `run_id` to its end, finishing whatever was sent; the
/// blocks as (kind, end, line).
fn run_to_end(c: &mut RunCore, run_id: u64) -> Vec<(u8, Vec<f64>, u32)> {
    let mut out = Vec::new();
    let mut done = 0;
    c.motion_status(status_at(run_id, 0, 1, MotionStatus::STATE_RUNNING));
    for _ in 0..100 {
        c.step();
        for b in blocks(&c.take_effects()) {
            assert_eq!(b.run_id, run_id);
            out.push((b.kind, b.end.clone(), b.line));
            done = b.seq;
        }
        c.motion_status(status_at(run_id, done, 1, MotionStatus::STATE_RUNNING));
        if c.execution() == MachineState::PROGRAM_COMPLETED {
            return out;
        }
    }
    panic!("the run did not end: {:?}", c.state());
}
