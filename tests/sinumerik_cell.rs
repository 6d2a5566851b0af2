//! Issue 23, must-show 4: the 802D mill (`launch_configs/sim_mill_802d.yaml`) in the cell over
//! real DDS and iceoryx2. A supervisor node loads the manual's radius compensation example
//! (`../shared/fixtures/001/061`, as printed, header comments and all) and a subprogram it
//! calls by name, starts it through the ROS 2 services, and reads the machine's topics: the
//! program completes without alarm, the part is counted at its M2 (D82), and the axes stand
//! where the manual's program ends. Issue 24, must-show 4: a job of the 802D's cycles (a
//! bore with an oriented stop, a bore with M5 and M0, a circular pocket, a rigid tap) runs
//! through the PLC; at CYCLE87's M0 the machine holds at the bore's bottom with the spindle
//! stopped, and a cycle start from the supervisor runs it on; SPOS positions the spindle,
//! which the spindle topic shows at the next M0 (D100, D101). Run by `scripts/test.sh`
//! inside a network namespace.

use std::time::Duration;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::{MachineState, SpindleState};
use ros2_client::ServiceMapping;

mod common;

const DOMAIN: u16 = 88;
const CYCLES_DOMAIN: u16 = 89;
const PROBE_DOMAIN: u16 = 97;

fn fixture_061() -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/fixtures/001");
    let path = std::fs::read_dir(dir)
        .expect("fixtures 001")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("061"))
        })
        .expect("fixture 061");
    std::fs::read_to_string(path).expect("fixture text")
}

/// The 802D mill on `domain` (no kept memory: the PLC comes up as at its first power-up,
/// with the builder's keep relays, K1.1, D82), a supervisor node, and T1 D1's length as the
/// launch config sets it: the tests' expectations follow from it.
fn start(domain: u16) -> (Cell, CellClient, f64) {
    start_with(domain, |_| {})
}

/// As [`start`], the config changed by `change` first.
fn start_with(
    domain: u16,
    change: impl FnOnce(&mut cnc_runtime::LaunchConfig),
) -> (Cell, CellClient, f64) {
    let mut cfg = common::machine("sim_mill_802d", domain);
    change(&mut cfg);
    let length = cfg
        .machine
        .tools
        .get(&11)
        .expect("T1 D1 in sim_mill_802d.yaml")
        .z;
    let cell = Cell::start(&cfg).expect("the cell starts");
    let client = CellClient::new(
        &cfg.network,
        "mill2",
        "test_supervisor",
        ServiceMapping::Enhanced,
    )
    .expect("supervisor node");
    (cell, client, length)
}

/// Waits until the program has completed and its part is counted, without an alarm, and the
/// axes stand at `end` (machine coordinates); returns the execution states seen on the way.
fn completes_at(client: &mut CellClient, within: Duration, end: [f64; 3]) -> Vec<String> {
    let (ok, seen) = client.wait_until(within, |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
            && c.part_count.as_ref().is_some_and(|p| p.count == 1)
    });
    let names: Vec<String> = seen.iter().map(|s| s.execution_name.clone()).collect();
    assert!(
        ok,
        "did not complete and count; states {names:?}, alarms {:?}",
        client.alarms
    );
    assert!(
        client.alarms.as_ref().is_some_and(|a| a.alarms.is_empty()),
        "alarms {:?}",
        client.alarms
    );
    let (ok, _) = client.wait_until(Duration::from_secs(10), |c| {
        c.axes
            .as_ref()
            .is_some_and(|a| (0..3).all(|i| (a.axes[i].actual_position - end[i]).abs() < 0.001))
    });
    assert!(ok, "final position {:?}, not {end:?}", client.axes);
    names
}

#[test]
fn the_manuals_compensated_contour_runs_in_the_cell_and_counts_its_part_at_m2() {
    let (cell, mut client, length) = start(DOMAIN);
    let (ok, _) = client.wait_until(Duration::from_secs(30), |c| {
        c.part_count.is_some() && c.state.is_some() && c.axes.is_some()
    });
    assert!(ok, "state topics never arrived");
    client.wait_ready(Duration::from_secs(30)).expect("ready");
    assert_eq!(client.part_count.as_ref().map(|p| p.count), Some(0));

    // The manual's program, and a main program that calls it as a subprogram by name
    // (`RAHMEN.SPF`, 802D naming; its last block's M2 made M17, the subprogram's return).
    let text = fixture_061();
    assert!(text.contains("N130 G0 Z50 M2"), "061's last block");
    let contour = text.replace("N130 G0 Z50 M2", "N130 G0 Z50 M17");
    assert!(
        client
            .load_program("RAHMEN.SPF", &contour)
            .unwrap()
            .accepted
    );
    let main = "; the cell's job: the manual's contour as a subprogram\n\
                N10 G17 G90 G500\n\
                N20 RAHMEN\n\
                N30 G0 X5 Y60 Z50\n\
                N40 M2\n";
    assert!(client.load_program("JOB.MPF", main).unwrap().accepted);
    let r = client.start_program("JOB.MPF").unwrap();
    assert!(r.accepted, "{}", r.message);
    // The manual's end: X5 Y60 Z50 with T1 D1's length along Z (G17), machine coordinates.
    let names = completes_at(
        &mut client,
        Duration::from_secs(120),
        [5.0, 60.0, 50.0 + length],
    );
    assert!(names.iter().any(|n| n == "ACTIVE"), "{names:?}");
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn the_cycles_run_in_the_cell_hold_at_the_m0_of_cycle87_and_go_on_at_cycle_start() {
    let (cell, mut client, length) = start(CYCLES_DOMAIN);
    client.wait_ready(Duration::from_secs(30)).expect("ready");
    let job = "N10 G17 G90 G500 T1 D1 S1000 M3 F300\n\
               N20 G0 X50 Y50 Z60\n\
               N30 CYCLE86(10, 0, 2, -6, , 0.5, 3, -1, -1, 1, 45)\n\
               N40 G0 X100 Y50\n\
               N45 MSG(\"BORE AT X\"<<100<<\": RETRACT THE BAR, THEN START\")\n\
               N50 CYCLE87(10, 0, 2, -6, , 3)\n\
               N60 POCKET4(10, 0, 1, -4, 14, 150, 50, 2, 0, 0, 600, 200, 0, 11, 0)\n\
               N62 G0 X100 Y100\n\
               N64 CYCLE84(10, 0, 2, -6, , 0, 3, 5, , 90, 200, 500)\n\
               N70 G0 X0 Y0 Z100\n\
               N72 SPOS=ACN(300)\n\
               N74 M0\n\
               N80 M2\n";
    assert!(client.load_program("CYCLES.MPF", job).unwrap().accepted);
    let r = client.start_program("CYCLES.MPF").unwrap();
    assert!(r.accepted, "{}", r.message);
    // CYCLE87: M5 and M0 at the bore's bottom, X100 Y50 Z−6 (+ T1 D1's length).
    let (ok, seen) = client.wait_until(Duration::from_secs(120), |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::FEED_HOLD)
            && c.axes.as_ref().is_some_and(|a| {
                (a.axes[0].actual_position - 100.0).abs() < 0.001
                    && (a.axes[2].actual_position - (-6.0 + length)).abs() < 0.001
            })
    });
    let names: Vec<&str> = seen.iter().map(|s| s.execution_name.as_str()).collect();
    assert!(
        ok,
        "no hold at the bottom; states {names:?}, alarms {:?}",
        client.alarms
    );
    let (ok, _) = client.wait_until(Duration::from_secs(10), |c| {
        c.spindle.as_ref().is_some_and(|s| {
            s.direction == SpindleState::DIRECTION_STOP && s.actual_rpm.abs() < 1.0
        })
    });
    assert!(ok, "the spindle stands at the M0: {:?}", client.spindle);
    // The program's message to the operator stands on the machine state (D97).
    let message = client.state.as_ref().map(|s| s.message.clone());
    assert_eq!(
        message.as_deref(),
        Some("BORE AT X100: RETRACT THE BAR, THEN START")
    );
    // Cycle start goes on: out of the bore, the pocket, then SPOS: the drive positions the
    // spindle at 300° and holds it there through the M0 (D100).
    let r = client.start_program("").unwrap();
    assert!(r.accepted, "{}", r.message);
    let (ok, _) = client.wait_until(Duration::from_secs(180), |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::FEED_HOLD)
            && c.spindle
                .as_ref()
                .is_some_and(|s| s.positioned && (s.position_deg - 300.0).abs() < 0.001)
    });
    assert!(
        ok,
        "the spindle positioned at the second M0: {:?}, alarms {:?}",
        client.spindle, client.alarms
    );
    let r = client.start_program("").unwrap();
    assert!(r.accepted, "{}", r.message);
    completes_at(
        &mut client,
        Duration::from_secs(180),
        [0.0, 0.0, 100.0 + length],
    );
    // The end of the run ends the message.
    assert_eq!(client.state.as_ref().map(|s| s.message.as_str()), Some(""));
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}

/// MEAS through the cell's nodes (D116): the io node's simulated probe finds a wall at
/// machine X200, motion brakes there and reports the edge in its status over the machine
/// bus, and the interpreter node, which waited for it, reads on: the program moves to
/// X=R5−10, so the axes end at X190 only if the measured value came through; and the
/// interpreter node writes the MSG service's text with it to the machine's file (D120), and
/// with the cutting time motion's status carried to it (D121).
#[test]
fn a_measuring_block_runs_in_the_cell_and_the_program_goes_on_with_its_value() {
    let dir = common::fresh_dir("sinumerik_cell_msg");
    let msg_file = dir.join("msg.txt");
    let (cell, mut client, _) = start_with(PROBE_DOMAIN, |cfg| {
        cfg.sim.probe = vec![cnc_runtime::config::ProbeTarget {
            min: vec![200.0, -100.0, -100.0],
            max: vec![400.0, 100.0, 200.0],
        }];
        cfg.machine.msg_file = Some(msg_file.clone());
    });
    client.wait_ready(Duration::from_secs(30)).expect("ready");
    let job = "N10 G17 G90 G500 G0 X0 Y0 Z100\n\
               N20 MEAS=1 G1 X300 F2000\n\
               N30 IF $AC_MEA[1]==0 GOTOF MISSED\n\
               N40 G0 X=$AA_MW[X]-10 Y20\n\
               N45 MSG(\"File: wall at X\"<<$AA_MW[X])\n\
               N46 MSG(\"File: cut \"<<TRUNC($AC_CUTTING_TIME))\n\
               N50 M2\n\
               N60 MISSED: M0\n\
               N70 M2\n";
    assert!(client.load_program("PROBE.MPF", job).unwrap().accepted);
    let r = client.start_program("PROBE.MPF").unwrap();
    assert!(r.accepted, "{}", r.message);
    completes_at(&mut client, Duration::from_secs(120), [190.0, 20.0, 100.0]);
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    // The MSG service's file output (§8.4.4, D120) has the measured value, and the cutting
    // time motion counted and reported in its status (D121): the measuring line's 200 mm at
    // F2000 to the wall, 6 s and its ramps.
    let written = std::fs::read_to_string(&msg_file).expect("the MSG service's file");
    assert_eq!(written, "wall at X200\ncut 6\n");
    let _ = std::fs::remove_dir_all(&dir);
}
