//! The `RunProgram` action end to end: a separate ros2-client node (its own participant, as a
//! cell supervisor would be) sends goals to the cell's hmi_bridge over DDS, gets feedback per
//! block and results, and cancels a goal mid-program. Runs in scripts/test.sh's network
//! namespace.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

mod common;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::action::{RunProgramFeedback, RunProgramGoal, RunProgramResult};
use cnc_msgs::msg::{MachineState, ProgramEvent};
use cnc_runtime::dds::RosNode;
use cnc_runtime::topics;
use ros2_client::action_msgs::{CancelGoalResponseEnum, GoalStatusEnum};
use ros2_client::ServiceMapping;

use common::RunProgramClient as Client;

const SHORT: &str =
    "O0001\nG00 X60 Z5\nS600 M03\nG01 X40 Z0 F900\nZ-20\nG02 X50 Z-25 R5\nG01 X56 Z-30\nM05\nM30\n";
/// One slow cut: a minute at F300.
const LONG: &str = "O0002\nG00 X60 Z5\nS500 M03\nG01 X50 F300\nZ-300\nM05\nM30\n";

/// Sends a goal and waits for its acceptance.
fn send(client: &Client, goal: RunProgramGoal) -> (ros2_client::action::GoalId, bool) {
    let (req, id) = client.send_goal(goal).unwrap();
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(15) {
        if let Ok(Some(r)) = client.receive_goal_response(req) {
            return (id, r.accepted);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("no answer to the goal");
}

/// Feedback and result of a goal, until the result or `timeout`; `on_feedback` may act.
fn follow(
    client: &Client,
    id: ros2_client::action::GoalId,
    timeout: Duration,
    mut on_feedback: impl FnMut(&RunProgramFeedback),
) -> (Vec<RunProgramFeedback>, GoalStatusEnum, RunProgramResult) {
    let req = client.request_result(id).unwrap();
    let mut feedback = Vec::new();
    let t0 = Instant::now();
    while t0.elapsed() < timeout {
        while let Ok(Some(f)) = client.receive_feedback(id) {
            on_feedback(&f);
            feedback.push(f);
        }
        if let Ok(Some((status, result))) = client.receive_result(req) {
            while let Ok(Some(f)) = client.receive_feedback(id) {
                feedback.push(f);
            }
            return (feedback, status, result);
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    panic!(
        "no result within {timeout:?}; feedback so far: {}",
        feedback.len()
    );
}

fn goal(program: &str, cycles: u32) -> RunProgramGoal {
    RunProgramGoal {
        program: program.into(),
        cycles,
        start_line: 0,
        start_block: String::new(),
    }
}

#[test]
fn run_program_reports_every_block_and_a_cancel_stops_the_machine_ready_for_the_next_goal() {
    let cfg = common::sim_lathe(51);
    let cell = Cell::start(&cfg).unwrap();
    let mut cell_client =
        CellClient::new(&cfg.network, "lathe1", "loader", ServiceMapping::Enhanced).unwrap();
    cell_client.wait_ready(Duration::from_secs(20)).unwrap();
    for (name, text) in [("short.nc", SHORT), ("long.nc", LONG)] {
        let r = cell_client.load_program(name, text).unwrap();
        assert!(r.accepted, "{}", r.message);
    }
    let mut supervisor = RosNode::new(&cfg.network, "cell", "supervisor").unwrap();
    // The program events a line-side display would follow.
    let mut watcher = RosNode::new(&cfg.network, "lathe1", "event_watch").unwrap();
    let program_events = watcher
        .dds_subscription_with_qos::<ProgramEvent>(
            &topics::PROGRAM_EVENTS,
            topics::PROGRAM_EVENTS
                .qos()
                .history(ros2_client::qos::History::KeepLast { depth: 10_000 }),
        )
        .unwrap();
    let client = common::run_program_client(&mut supervisor);
    std::thread::sleep(Duration::from_secs(2)); // discovery of the action's services

    // Refused goals change nothing, and each says why through GetResult (issue 26: the
    // reason was only in the log, and GetResult for it never came back).
    for (program, cycles, why) in [("missing.nc", 1, "missing.nc"), ("short.nc", 0, "cycles")] {
        let (id, accepted) = send(&client, goal(program, cycles));
        assert!(!accepted, "{program} × {cycles} accepted");
        let (feedback, status, result) = follow(&client, id, Duration::from_secs(15), |_| {});
        assert!(feedback.is_empty());
        assert_eq!(status, GoalStatusEnum::Aborted, "{}", result.message);
        assert!(
            result.message.starts_with("goal rejected: ") && result.message.contains(why),
            "{program} × {cycles}: {}",
            result.message
        );
        assert_eq!(result.parts_made, 0);
    }
    // A result asked for a goal never sent is answered at once, not left waiting.
    let (_, status, result) = follow(
        &client,
        ros2_client::action::GoalId::new_random(),
        Duration::from_secs(15),
        |_| {},
    );
    assert_eq!(status, GoalStatusEnum::Unknown, "{}", result.message);
    assert!(
        result.message.contains("unknown goal"),
        "{}",
        result.message
    );

    // Two cycles with feedback per block.
    let (id, accepted) = send(&client, goal("short.nc", 2));
    assert!(accepted);
    let (feedback, status, result) = follow(&client, id, Duration::from_secs(120), |_| {});
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.message);
    assert_eq!(result.parts_made, 2);
    assert_eq!(result.cycle_times.len(), 2);
    assert!(
        result.cycle_times.iter().all(|&t| t > 1.0),
        "{:?}",
        result.cycle_times
    );
    for cycle in 1..=2 {
        let this: Vec<&RunProgramFeedback> = feedback.iter().filter(|f| f.cycle == cycle).collect();
        let lines: BTreeSet<u32> = this.iter().map(|f| f.line).collect();
        for line in [2, 4, 5, 6, 7] {
            assert!(
                lines.contains(&line),
                "cycle {cycle}: no feedback at line {line}: {lines:?}"
            );
        }
        let blocks: Vec<u64> = this.iter().map(|f| f.block).collect();
        assert!(blocks.windows(2).all(|w| w[0] <= w[1]), "{blocks:?}");
        let distinct: BTreeSet<u64> = blocks.iter().copied().collect();
        assert!(distinct.len() >= 5, "cycle {cycle}: blocks {distinct:?}");
        assert!(this.iter().all(|f| (0.0..=100.0).contains(&f.percent)));
    }

    // A long cut, canceled while it cuts.
    let (id, accepted) = send(&client, goal("long.nc", 1));
    assert!(accepted);
    let mut cancel_sent = None;
    let (_, status, result) = follow(&client, id, Duration::from_secs(60), |f| {
        if f.line == 5 && cancel_sent.is_none() {
            std::thread::sleep(Duration::from_millis(500)); // well into the cut
            cancel_sent = Some(client.cancel_goal(id).unwrap());
        }
    });
    assert_eq!(status, GoalStatusEnum::Canceled, "{}", result.message);
    assert_eq!(result.parts_made, 0);
    let cancel = cancel_sent.expect("cancel sent");
    let t0 = Instant::now();
    let code = loop {
        if let Ok(Some(r)) = client.receive_cancel_response(cancel) {
            break r.return_code;
        }
        assert!(t0.elapsed() < Duration::from_secs(10), "no cancel response");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert_eq!(code, CancelGoalResponseEnum::None);
    // The axes come to rest and stay there, and the machine is ready.
    std::thread::sleep(Duration::from_millis(500));
    cell_client.poll();
    let z_at = |c: &CellClient| c.axes.as_ref().unwrap().axes[1].commanded_position;
    let z0 = z_at(&cell_client);
    std::thread::sleep(Duration::from_secs(1));
    cell_client.poll();
    let z1 = z_at(&cell_client);
    assert!(
        (z1 - z0).abs() < 1e-6,
        "Z still moving after cancel: {z0} → {z1}"
    );
    assert!(z0 > -290.0, "the cut was not interrupted: Z {z0}");
    assert_eq!(
        cell_client.state.as_ref().unwrap().execution,
        MachineState::READY
    );

    // And the next goal runs.
    let (id, accepted) = send(&client, goal("short.nc", 1));
    assert!(accepted);
    let (_, status, result) = follow(&client, id, Duration::from_secs(60), |_| {});
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.message);
    assert_eq!(result.parts_made, 1);
    std::thread::sleep(Duration::from_millis(300));
    let mut events = Vec::new();
    loop {
        match program_events.take() {
            Ok(Some((e, _))) => events.push(e),
            Ok(None) => break,
            Err(e) => panic!("{e:?}"),
        }
    }
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");

    // The same story on `program_events`: three runs of short.nc completed with a block event
    // at each motion line, and the canceled cut started then aborted.
    let story: Vec<(String, &str)> = events
        .iter()
        .filter(|e| e.kind != ProgramEvent::BLOCK)
        .map(|e| (e.program.clone(), e.kind_name.as_str()))
        .collect();
    let expected: Vec<(String, &str)> = [
        ("short.nc", "STARTED"),
        ("short.nc", "COMPLETED"),
        ("short.nc", "STARTED"),
        ("short.nc", "COMPLETED"),
        ("long.nc", "STARTED"),
        ("long.nc", "ABORTED"),
        ("short.nc", "STARTED"),
        ("short.nc", "COMPLETED"),
    ]
    .iter()
    .map(|(p, k)| (p.to_string(), *k))
    .collect();
    assert_eq!(story, expected, "{events:#?}");
    let runs: Vec<&[ProgramEvent]> = events
        .split_inclusive(|e| matches!(e.kind, ProgramEvent::COMPLETED | ProgramEvent::ABORTED))
        .collect();
    for run in &runs {
        let end = &run[run.len() - 1];
        let blocks: Vec<u32> = run.iter().map(|e| e.blocks).collect();
        assert!(blocks.windows(2).all(|w| w[0] <= w[1]), "{blocks:?}");
        if end.program == "short.nc" {
            let lines: BTreeSet<u32> = run
                .iter()
                .filter(|e| e.kind == ProgramEvent::BLOCK)
                .map(|e| e.line)
                .collect();
            for line in [2, 4, 5, 6, 7] {
                assert!(
                    lines.contains(&line),
                    "no block event at line {line}: {lines:?}"
                );
            }
            assert!(end.elapsed > 1.0, "cycle of {} s", end.elapsed);
        } else {
            assert_eq!(end.line, 5, "the cut was aborted in line 5");
            assert!(!end.reason.is_empty());
        }
    }
}
