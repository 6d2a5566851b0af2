//! The run core without DDS: commands in, effects and state out, motion played by hand.

use super::*;
use cnc_interpreter::setup::ToolOffset;
use cnc_msgs::msg::MotionCommand;

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

#[test]
fn mdi_runs_in_mdi_mode_only_and_programs_in_auto_only() {
    let mut c = ready();
    let r = command(
        &mut c,
        3,
        TaskRequest::Mdi {
            text: "G00 X80 Z20".into(),
        },
    );
    assert!(!r.accepted && r.message.contains("not MDI"), "{r:?}");
    assert!(command(&mut c, 4, TaskRequest::Mode(1)).accepted);
    let r = command(&mut c, 5, start("part.nc", ""));
    assert!(!r.accepted && r.message.contains("not AUTO"), "{r:?}");
    assert!(!command(&mut c, 6, TaskRequest::Mdi { text: "  ".into() }).accepted);
    assert!(
        command(
            &mut c,
            7,
            TaskRequest::Mdi {
                text: "G00 X80 Z20".into()
            }
        )
        .accepted
    );
    assert_eq!(c.state().program, MDI_PROGRAM);
    // No mode change while it runs.
    let r = command(&mut c, 8, TaskRequest::Mode(0));
    assert!(!r.accepted && r.message.contains("running"), "{r:?}");
    assert!(!command(&mut c, 9, TaskRequest::Mode(9)).accepted);
}

#[test]
fn a_repeated_command_is_answered_again_not_done_twice() {
    let mut c = ready();
    let first = command(&mut c, 3, start("part.nc", ""));
    let again = command(&mut c, 3, start("part.nc", ""));
    assert_eq!(first, again);
    assert!(first.accepted);
    // A new id is a new start, refused while one runs.
    assert!(!command(&mut c, 4, start("part.nc", "")).accepted);
}

#[test]
fn program_memory_refuses_bad_names_and_keeps_a_running_program() {
    let mut c = ready();
    assert!(!command(&mut c, 3, load("../etc", "M30")).accepted);
    assert!(!command(&mut c, 4, load(".hidden", "M30")).accepted);
    let big = "G00 X1\n".repeat(MAX_PROGRAM_BYTES / 7 + 1);
    assert!(!command(&mut c, 5, load("big.nc", &big)).accepted);
    command(&mut c, 6, start("part.nc", ""));
    assert!(!command(&mut c, 7, load("part.nc", "M30")).accepted);
    assert!(
        !command(
            &mut c,
            8,
            TaskRequest::Delete {
                name: "part.nc".into()
            }
        )
        .accepted
    );
    let list = command(&mut c, 9, TaskRequest::List);
    assert_eq!(
        (list.programs, list.program_sizes),
        (vec!["part.nc".to_string()], vec![PART.len() as u64])
    );
    let read = command(
        &mut c,
        10,
        TaskRequest::Read {
            name: "part.nc".into(),
        },
    );
    assert_eq!(read.message, PART);
    assert!(
        !command(
            &mut c,
            11,
            TaskRequest::Read {
                name: "none.nc".into()
            }
        )
        .accepted
    );
}

#[test]
fn what_a_run_leaves_in_memory_is_stored_and_offsets_wait_for_a_stop() {
    let mut c = ready();
    command(&mut c, 3, load("kept.nc", "#200=7\nG00 X100\nM30\n"));
    command(&mut c, 4, start("kept.nc", ""));
    let r = command(
        &mut c,
        5,
        TaskRequest::SetToolOffset(cnc_msgs::msg::ToolOffset {
            number: 1,
            x: 0.5,
            ..Default::default()
        }),
    );
    assert!(
        !r.accepted && r.message.contains("while a program runs"),
        "{r:?}"
    );
    c.motion_status(status(0, 0, 16, MotionStatus::STATE_IDLE));
    c.step();
    // Stored as soon as the block that sets it is interpreted, not at the end of the run:
    // a crash before the end keeps what the program wrote (issue 26).
    let effects = c.take_effects();
    assert!(effects.contains(&Effect::StoreMemory), "{effects:?}");
    assert_eq!(c.memory().kept.get(&200), Some(&7.0));
    let last = blocks(&effects).last().map(|b| b.seq).unwrap_or(0);
    c.motion_status(status(1001, last, 16, MotionStatus::STATE_IDLE));
    c.step();
    assert_eq!(c.execution(), MachineState::PROGRAM_COMPLETED);
    assert_eq!(c.memory().kept.get(&200), Some(&7.0));
    // The next run starts from it.
    command(&mut c, 6, load("use.nc", "G00 X[#200*10]\nM30\n"));
    command(&mut c, 7, start("use.nc", ""));
    c.motion_status(status(1001, last, 16, MotionStatus::STATE_IDLE));
    c.step();
    let b = c.take_effects();
    assert_eq!(blocks(&b)[0].end.first(), Some(&70.0), "{b:?}");
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

/// Issue 26: programs lived in RAM only, and 120 loads of 4 MiB were all taken. Program
/// memory keeps what it stores, refuses what exceeds its capacity with alarm 70, and a
/// program the disk did not take is not reported stored.
#[test]
fn program_memory_is_kept_bounded_by_its_capacity_and_a_failed_write_is_no_load() {
    let disk = Disk::default();
    let held: BTreeMap<String, String> = [("O0001".to_string(), "M30\n".to_string())].into();
    let mut c = core().with_program_memory(held, Box::new(disk.clone()), 1000);
    let r = command(&mut c, 1, TaskRequest::List);
    assert!(r.programs.contains(&"O0001".to_string()), "{r:?}");
    let r = command(&mut c, 2, load("shafts/O0010.nc", &"G0X1\n".repeat(100)));
    assert!(r.accepted, "{r:?}");
    assert!(disk.files.lock().unwrap().contains_key("shafts/O0010.nc"));
    let r = command(&mut c, 3, load("big.nc", &"G0X1\n".repeat(100)));
    assert!(!r.accepted && r.message.contains("alarm 70"), "{r:?}");
    assert!(r.message.contains("of 1000 bytes free"), "{r:?}");
    let r = command(&mut c, 4, load("../escape.nc", "M30\n"));
    assert!(
        !r.accepted && r.message.contains("invalid program name"),
        "{r:?}"
    );
    let r = command(
        &mut c,
        5,
        TaskRequest::Delete {
            name: "shafts/O0010.nc".into(),
        },
    );
    assert!(r.accepted, "{r:?}");
    assert!(disk.files.lock().unwrap().is_empty());
    // Deleting made room.
    assert!(command(&mut c, 6, load("big.nc", &"G0X1\n".repeat(100))).accepted);

    let broken = Disk {
        broken: true,
        ..Disk::default()
    };
    let mut c = core().with_program_memory(BTreeMap::new(), Box::new(broken), 1 << 20);
    let r = command(&mut c, 1, load("part.nc", "M30\n"));
    assert!(!r.accepted && r.message.contains("No space left"), "{r:?}");
    let r = command(&mut c, 2, TaskRequest::List);
    assert!(
        !r.programs.contains(&"part.nc".to_string()),
        "not in memory either: {r:?}"
    );
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

/// The program counts its runs in kept #200 and moves by the count: a restart that read #200
/// as the interrupted run left it would cut 1 mm further out.
const COUNTED: &str =
    "#200=#200+1\nG00 X[100+#200] Z20\nS500 M03\nG01 Z10 F3000\nG01 Z5\nG01 X120\nM05\nM30\n";

fn counted_core() -> RunCore {
    let mut c = core();
    assert!(command(&mut c, 1, load("count.nc", COUNTED)).accepted);
    c.plc_scanned();
    c.axes(&[200.0, 100.0]);
    c
}

#[test]
fn a_program_starts_at_a_line_with_its_preamble_then_the_rest_of_it() {
    let mut c = counted_core();
    let r = command(&mut c, 2, start("count.nc", "line 5"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("at line 5"), "{}", r.message);
    let sent = run_to_end(&mut c, 1001);
    // S500 M03, then the approach: X stays out at 200, Z over to 10, X to 102 and onto 101.
    let ends: Vec<&Vec<f64>> = sent
        .iter()
        .filter(|b| b.0 != MotionBlock::KIND_AUX && !b.1.is_empty())
        .map(|b| &b.1)
        .collect();
    assert_eq!(
        ends,
        [
            &vec![200.0, 10.0],
            &vec![102.0, 10.0],
            &vec![101.0, 10.0],
            &vec![101.0, 5.0],
            &vec![120.0, 5.0]
        ]
    );
    assert!(sent.iter().all(|b| b.2 >= 5), "{sent:?}");
    let refused = command(&mut c, 3, start("count.nc", "N999"));
    assert!(!refused.accepted && refused.message.contains("not found"));
    let refused = command(&mut c, 4, start("count.nc", "goto 3"));
    assert!(!refused.accepted);
}

#[test]
fn an_interrupted_run_restarts_at_its_block_with_the_variables_it_started_with() {
    // The uninterrupted run, for comparison.
    let mut whole = counted_core();
    assert!(command(&mut whole, 2, start("count.nc", "")).accepted);
    let full = run_to_end(&mut whole, 1001);
    assert_eq!(whole.memory().kept.get(&200), Some(&1.0));

    // The run that is interrupted: motion has finished 4 blocks, at line 4, when the power
    // goes (an emergency stop here; a kill leaves the same kept position).
    let mut first = counted_core();
    assert!(command(&mut first, 2, start("count.nc", "")).accepted);
    first.motion_status(status_at(1001, 0, 1, MotionStatus::STATE_RUNNING));
    first.step();
    assert!(blocks(&first.take_effects()).len() > 5);
    first.motion_status(status_at(1001, 4, 4, MotionStatus::STATE_RUNNING));
    first.step();
    let kept = first.position().cloned().expect("a kept position");
    assert_eq!(
        (kept.program.as_str(), kept.line, kept.block),
        ("count.nc", 4, 5)
    );
    assert!(kept.interrupted());
    assert_eq!(kept.kept_at_start.get(&200), None, "#200 before the run");
    let memory_after = first.memory().clone();
    assert_eq!(memory_after.kept.get(&200), Some(&1.0));

    // The cell restarts: memory and position as kept, the axes elsewhere.
    let fresh = || {
        let c = RunCore::new(
            Dialect::HuaxingLathe,
            Setup::lathe([200.0, 100.0]),
            memory_after.clone(),
            2000,
        );
        let mut c = c.with_kept_position(Some(kept.clone()));
        assert!(command(&mut c, 1, load("count.nc", COUNTED)).accepted);
        c.plc_scanned();
        c.axes(&[250.0, 150.0]);
        c
    };
    let mut again = fresh();
    let r = command(&mut again, 2, start("", "interrupted"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("block 5"), "{}", r.message);
    let rest = run_to_end(&mut again, 2001);
    // After the preamble, exactly the uninterrupted run's blocks from block 5 on: X101, not
    // X102 (the search ran with #200 as the interrupted run found it).
    assert!(rest.len() > full.len() - 4);
    assert_eq!(rest[rest.len() - (full.len() - 4)..], full[4..]);
    assert_eq!(again.memory().kept.get(&200), Some(&1.0));
    // Completed: nothing is left to restart.
    let r = command(&mut again, 3, start("", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("no interrupted program"),
        "{}",
        r.message
    );

    // Another program's name, or an edited program, is refused.
    let mut other = fresh();
    let r = command(&mut other, 2, start("part.nc", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("not part.nc"),
        "{}",
        r.message
    );
    assert!(command(&mut other, 3, load("count.nc", PART)).accepted);
    let r = command(&mut other, 4, start("count.nc", "interrupted"));
    assert!(!r.accepted && r.message.contains("edited"), "{}", r.message);
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

fn calling_core() -> RunCore {
    let mut c = core();
    assert!(command(&mut c, 1, load("main.nc", MAIN_CALLING)).accepted);
    assert!(command(&mut c, 2, load("O2000", SUB)).accepted);
    c.plc_scanned();
    c.axes(&[200.0, 100.0]);
    c
}

/// An interruption inside a subprogram restarts at the subprogram's interrupted block (not at
/// the main program's call line), and the rest is the uninterrupted run's; a restart after the
/// subprogram was edited is refused.
#[test]
fn an_interrupted_subprogram_restarts_at_its_block_and_an_edit_of_it_is_refused() {
    let mut whole = calling_core();
    assert!(command(&mut whole, 3, start("main.nc", "")).accepted);
    let full = run_to_end(&mut whole, 1001);

    // Interrupted with 5 blocks done: inside O2000 (its third move).
    let mut first = calling_core();
    assert!(command(&mut first, 3, start("main.nc", "")).accepted);
    first.motion_status(status_at(1001, 0, 1, MotionStatus::STATE_RUNNING));
    first.step();
    assert!(blocks(&first.take_effects()).len() > 6);
    first.motion_status(status_at(1001, 5, 3, MotionStatus::STATE_RUNNING));
    first.step();
    let kept = first.position().cloned().expect("a kept position");
    assert!(kept.interrupted() && kept.block == 6, "{kept:?}");

    let fresh = |sub: &str| {
        let c = RunCore::new(
            Dialect::HuaxingLathe,
            Setup::lathe([200.0, 100.0]),
            first.memory().clone(),
            2000,
        );
        let mut c = c.with_kept_position(Some(kept.clone()));
        assert!(command(&mut c, 1, load("main.nc", MAIN_CALLING)).accepted);
        assert!(command(&mut c, 2, load("O2000", sub)).accepted);
        c.plc_scanned();
        c.axes(&[250.0, 150.0]);
        c
    };
    let mut again = fresh(SUB);
    let r = command(&mut again, 3, start("", "interrupted"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("block 6"), "{}", r.message);
    let rest = run_to_end(&mut again, 2001);
    // After the preamble, the uninterrupted run's blocks from block 6 on: the subprogram is
    // not run again from its top.
    assert!(rest.len() >= full.len() - 5, "{rest:?}");
    assert_eq!(rest[rest.len() - (full.len() - 5)..], full[5..], "{rest:?}");

    // The subprogram edited since: refused, naming it.
    let mut edited = fresh(SUB_EDITED);
    let r = command(&mut edited, 3, start("", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("O2000") && r.message.contains("edited"),
        "{}",
        r.message
    );
}

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

fn to_motion(effects: &[Effect]) -> Vec<MotionCommand> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::ToMotion(m) => Some(m.clone()),
            _ => None,
        })
        .collect()
}

/// Issue 47: the task decides; what it passes on to motion is answered by motion, and a
/// refusal there is the caller's answer, with motion's reason.
#[test]
fn a_jog_motion_refuses_is_refused_to_the_caller_with_motion_s_reason() {
    let mut c = ready();
    let jog =
        |direction| TaskRequest::Jog(cnc_msgs::jog::Jog::new("z", direction, 600.0, 0.0).unwrap());
    let r = command(&mut c, 3, jog(1));
    assert!(!r.accepted && r.message.contains("not JOG"), "{r:?}");
    assert!(command(&mut c, 4, TaskRequest::Mode(MachineState::MODE_JOG)).accepted);
    c.take_effects();
    assert_eq!(c.command(5, jog(1)), None, "waits for motion");
    let sent = to_motion(&c.take_effects());
    let [m] = &sent[..] else { panic!("{sent:?}") };
    assert_eq!(
        (m.kind, m.axis, m.direction, m.feed),
        (MotionCommand::JOG, 1, 1, 600.0)
    );
    // The bridge repeats the command until answered: not sent twice.
    assert_eq!(c.command(5, jog(1)), None);
    assert!(c.take_effects().is_empty());
    let why = "jog refused: Z is on its + overtravel switch: jog it the other way";
    let refusal = CommandResult {
        id: m.id,
        accepted: false,
        message: why.into(),
        ..CommandResult::default()
    };
    let answer = c.motion_result(&refusal).expect("the caller's answer");
    assert_eq!((answer.id, answer.accepted), (5, false));
    assert_eq!(answer.message, why);
    // Answered once: a repeat gets the same answer, a second answer of motion's is no one's.
    assert_eq!(c.command(5, jog(1)), Some(answer));
    assert_eq!(c.motion_result(&refusal), None);
    // Accepted by motion: the task's words.
    assert_eq!(c.command(6, jog(-1)), None);
    let [m] = &to_motion(&c.take_effects())[..] else {
        panic!()
    };
    let accepted = CommandResult {
        id: m.id,
        accepted: true,
        message: "jog".into(),
        ..CommandResult::default()
    };
    let answer = c.motion_result(&accepted).unwrap();
    assert!(
        answer.accepted && answer.message.starts_with("jog Z -"),
        "{answer:?}"
    );
    // Refused by the task: nothing reaches motion.
    let r = command(
        &mut c,
        7,
        TaskRequest::Jog(cnc_msgs::jog::Jog::new("Y", 1, 0.0, 0.0).unwrap()),
    );
    assert!(!r.accepted && r.message.contains("no axis Y"), "{r:?}");
    assert!(to_motion(&c.take_effects()).is_empty());
    // Cycle start in HOME: the reference return is motion's to refuse too.
    assert!(command(&mut c, 8, TaskRequest::Mode(MachineState::MODE_HOME)).accepted);
    c.take_effects();
    assert_eq!(c.command(9, start("", "")), None);
    let [m] = &to_motion(&c.take_effects())[..] else {
        panic!()
    };
    assert_eq!(m.kind, MotionCommand::REFERENCE_RETURN);
    let refusal = CommandResult {
        id: m.id,
        accepted: false,
        message: "reference return refused: a jog is moving an axis".into(),
        ..CommandResult::default()
    };
    let answer = c.motion_result(&refusal).unwrap();
    assert_eq!((answer.id, answer.accepted), (9, false));
}

/// Issue 47: one node judges a cycle start. A refused START reaches motion in no form; feed
/// hold, and the start that resumes it, do.
#[test]
fn a_refused_start_sends_motion_nothing_and_a_resume_sends_it_on() {
    let mut c = ready();
    c.take_effects();
    let r = command(&mut c, 3, start("none.nc", ""));
    assert!(!r.accepted);
    assert!(c.take_effects().is_empty());
    assert!(command(&mut c, 4, start("part.nc", "")).accepted);
    c.take_effects();
    let r = command(&mut c, 5, start("part.nc", ""));
    assert!(!r.accepted && r.message.contains("running"), "{r:?}");
    assert!(to_motion(&c.take_effects()).is_empty());
    assert!(command(&mut c, 6, TaskRequest::FeedHold).accepted);
    let kinds = |c: &mut RunCore| -> Vec<u8> {
        to_motion(&c.take_effects())
            .iter()
            .map(|m| m.kind)
            .collect()
    };
    assert_eq!(kinds(&mut c), [MotionCommand::FEED_HOLD]);
    assert!(command(&mut c, 7, start("", "")).accepted);
    assert_eq!(kinds(&mut c), [MotionCommand::RESUME]);
}
