//! The command path: modes, MDI, program memory, repeated commands, and what goes to motion
//! or comes back from it (D128).

use super::*;

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
