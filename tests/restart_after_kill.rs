//! Issue 28, must-show 5: the cell is killed (SIGKILL) in the middle of a part; after the
//! restart, the supervisor restarts the program at the interrupted block through the
//! `RunProgram` action (`start_block: "interrupted"`), and the part completes at the same final
//! position as an uninterrupted run, with the spindle turning at the programmed speed through
//! the restarted cuts, and without running again the blocks before the restart line. The cell
//! runs as its own process (`cnc run`) with its kept files in a temporary folder; this test is
//! the supervisor. Runs in scripts/test.sh's network namespace.

use std::time::{Duration, Instant};

mod common;

use cnc_cell::client::CellClient;
use cnc_msgs::action::RunProgramGoal;
use cnc_msgs::msg::{MachineState, SpindleState};
use cnc_runtime::dds::RosNode;
use cnc_runtime::LaunchConfig;
use cnc_task::position::ProgramPosition;
use ros2_client::action_msgs::GoalStatusEnum;

const DOMAIN: u16 = 77;
/// Three roughing passes at F600 (about 8 s of cutting), spindle and coolant on.
const PART: &str = "O0003\nT0101\nG98 S600 M03\nM08\nG00 X62 Z2\nG01 X58 F600\nZ-20\nX60\n\
G00 Z2\nX54\nG01 Z-20\nX58\nG00 Z2\nX50\nG01 Z-15\nX56\nG00 X100 Z50\nM09\nM05\nM30\n";
/// The kill falls a second after the machine reaches this line (`G01 Z-20` of the second
/// pass, 2.2 s long): in the cut.
const KILL_LINE: u32 = 11;
/// The line of `M05`: from it on, the spindle stops.
const M05_LINE: u32 = 19;

fn actual(c: &CellClient) -> Vec<f64> {
    c.axes
        .as_ref()
        .map(|a| a.axes.iter().map(|x| x.actual_position).collect())
        .unwrap_or_default()
}

fn execution(c: &CellClient) -> u8 {
    c.state.as_ref().map_or(0, |s| s.execution)
}

#[test]
fn a_part_killed_mid_run_is_restarted_at_its_block_and_completes_at_the_same_position() {
    let dir = common::fresh_dir("cnc_restart");
    let config = common::sim_lathe_file(&dir, "restart_lathe.yaml", DOMAIN, |_| {});
    let cfg = LaunchConfig::load(&config).expect("config");
    let position_file = cfg.machine.position_file.clone().expect("position file");
    let log = dir.join("cell.log");

    // The uninterrupted part: where it ends.
    let mut cell = common::KillOnDrop(common::cnc_run(&config, &log));
    let mut c = common::ready_client(&cfg, "supervisor", Duration::from_secs(60));
    assert!(c.load_program("restart.nc", PART).expect("load").accepted);
    assert!(c.start_program("restart.nc").expect("start").accepted);
    common::wait(&mut c, Duration::from_secs(60), "the whole part", |c| {
        execution(c) == MachineState::PROGRAM_COMPLETED
    });
    std::thread::sleep(Duration::from_millis(200));
    c.poll();
    let whole_end = actual(&c);
    println!("uninterrupted part ends at {whole_end:?}");

    // The same part again, killed on its second or third pass.
    assert!(c.start_program("restart.nc").expect("start").accepted);
    // The state shows the last run's line until motion takes the new run's first block.
    common::wait(&mut c, Duration::from_secs(60), "the new run", |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::ACTIVE && s.line < KILL_LINE)
    });
    common::wait(&mut c, Duration::from_secs(60), "the second pass", |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::ACTIVE && s.line >= KILL_LINE)
    });
    let t_cut = Instant::now();
    common::wait(&mut c, Duration::from_secs(5), "in the cut", |_| {
        t_cut.elapsed() >= Duration::from_secs(1)
    });
    let seen = c.state.as_ref().map_or(0, |s| s.line);
    let at_kill = actual(&c);
    drop(c);
    // SAFETY: kill(2) with the pid of the child this test spawned and has not waited for.
    unsafe { libc::kill(cell.0.id() as i32, libc::SIGKILL) };
    let _ = cell.0.wait();
    let kept = ProgramPosition::from_yaml(
        &std::fs::read_to_string(&position_file).expect("a kept position"),
    )
    .expect("a whole position");
    println!(
        "killed on line {seen} at {at_kill:?}; kept: line {}, block {}, {}",
        kept.line, kept.block, kept.state
    );
    assert!(kept.interrupted() && kept.program == "restart.nc" && kept.block > 1);
    assert!(
        kept.line <= seen && kept.line >= 2,
        "kept {kept:?}, seen {seen}"
    );

    // The restart: the machine comes up where the simulator starts, not where the tool was.
    let mut cell = common::KillOnDrop(common::cnc_run(&config, &log));
    let mut c = common::ready_client(&cfg, "supervisor", Duration::from_secs(60));
    println!("after the restart the axes stand at {:?}", actual(&c));
    let mut supervisor = RosNode::new(&cfg.network, "cell", "restart_supervisor").expect("node");
    let action = common::run_program_client(&mut supervisor);
    std::thread::sleep(Duration::from_secs(2)); // discovery of the action's services
    let (req, id) = action
        .send_goal(RunProgramGoal {
            program: "restart.nc".into(),
            cycles: 1,
            start_line: 0,
            start_block: "interrupted".into(),
        })
        .expect("goal sent");
    let t0 = Instant::now();
    let accepted = loop {
        if let Ok(Some(r)) = action.receive_goal_response(req) {
            break r.accepted;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(15),
            "no answer to the goal"
        );
        std::thread::sleep(Duration::from_millis(5));
    };
    assert!(accepted, "restart goal refused: see {}", log.display());
    let result_req = action.request_result(id).expect("result request");
    let mut lines = Vec::new();
    // (line, spindle) while the restarted run is on a line before M05.
    let mut spindle_seen: Vec<(u32, SpindleState)> = Vec::new();
    let (status, result) = loop {
        c.poll();
        if let (Some(s), Some(sp)) = (c.state.as_ref(), c.spindle.as_ref()) {
            if s.execution == MachineState::ACTIVE && s.line > 0 && s.line < M05_LINE {
                spindle_seen.push((s.line, sp.clone()));
            }
        }
        while let Ok(Some(f)) = action.receive_feedback(id) {
            lines.push(f.line);
        }
        if let Ok(Some(r)) = action.receive_result(result_req) {
            break r;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(90),
            "the restarted part did not end: {:?}",
            c.state
        );
        std::thread::sleep(Duration::from_millis(5));
    };
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.message);
    assert_eq!(result.parts_made, 1);
    // Nothing before the restart block ran again.
    let first = lines.iter().copied().filter(|&l| l > 0).min();
    println!(
        "restarted run's feedback lines {first:?}..{:?}",
        lines.iter().max()
    );
    assert!(first.is_some_and(|l| l >= kept.line), "lines {lines:?}");
    // The spindle turned at its speed through the cuts after the restart block (the preamble,
    // which starts it, is on the restart block's line).
    let restart_line = first.unwrap_or(0);
    let in_cut: Vec<&SpindleState> = spindle_seen
        .iter()
        .filter(|(l, _)| *l > restart_line)
        .map(|(_, s)| s)
        .collect();
    assert!(!in_cut.is_empty(), "no sample in the restarted cuts");
    for s in in_cut {
        assert!(
            s.direction == SpindleState::DIRECTION_CW && (s.actual_rpm - 600.0).abs() < 30.0,
            "spindle in a restarted cut: {s:?}"
        );
    }
    std::thread::sleep(Duration::from_millis(200));
    c.poll();
    let end = actual(&c);
    println!("restarted part ends at {end:?}");
    assert_eq!(end.len(), whole_end.len());
    for (a, b) in end.iter().zip(&whole_end) {
        assert!(
            (a - b).abs() < 0.005,
            "ends at {end:?}, uninterrupted {whole_end:?}"
        );
    }
    // The position now says the part was finished: nothing to restart.
    let after = ProgramPosition::from_yaml(&std::fs::read_to_string(&position_file).unwrap())
        .expect("position");
    assert!(!after.interrupted(), "{after:?}");
    drop(c);
    let _ = cell.0.kill();
    let _ = cell.0.wait();
    let _ = std::fs::remove_dir_all(&dir);
}
