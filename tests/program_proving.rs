//! Issue 28, program-proving switches end to end: the machine-lock and aux-lock keys of the
//! simulated panel pressed through `sim/input` over DDS (as an operator's panel or a cell
//! integrator's test would), through the standard ladder to motion. A whole program runs:
//! the commanded positions on `axes` follow it, the actual ones never change, the spindle
//! never turns, and `axes.machine_lock` says why. Released, the machine is where it was.

use std::time::{Duration, Instant};

mod common;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::{MachineState, SimInput};
use cnc_runtime::dds::RosNode;
use cnc_runtime::topics;
use ros2_client::ServiceMapping;

const PROGRAM: &str =
    "O0001\nG98 G00 X60 Z5\nS600 M03\nM08\nG01 X40 Z0 F900\nZ-20\nG02 X50 Z-25 R5\nG00 X150 Z50\nM09\nM05\nM30\n";

/// Polls until `done` holds; fails after 30 s.
fn wait(client: &mut CellClient, what: &str, done: impl FnMut(&CellClient) -> bool) {
    common::wait(client, Duration::from_secs(30), what, done);
}

fn locked(c: &CellClient) -> Option<bool> {
    c.axes.as_ref().map(|a| a.machine_lock)
}

#[test]
fn a_program_runs_under_machine_and_aux_lock_and_nothing_moves() {
    let cfg = common::sim_lathe(76);
    let cell = Cell::start(&cfg).unwrap();
    let mut client = CellClient::new(
        &cfg.network,
        "lathe1",
        "supervisor",
        ServiceMapping::Enhanced,
    )
    .unwrap();
    client.wait_ready(Duration::from_secs(30)).unwrap();
    let r = client.load_program("prove.nc", PROGRAM).unwrap();
    assert!(r.accepted, "{}", r.message);
    let mut panel = RosNode::new(&cfg.network, "lathe1", "panel").unwrap();
    let keys = panel.dds_publisher::<SimInput>(&topics::SIM_INPUT).unwrap();
    wait(&mut client, "axes", |c| locked(c) == Some(false));

    // Both keys held until the machine-lock lamp shows, then let go (each toggles on its
    // rising edge). The aux-lock key goes down first, so the PLC has seen it by then.
    // A press lost before the panel's writer was discovered is pressed again.
    let toggle = |client: &mut CellClient, want: bool| {
        for _ in 0..5 {
            for input in [SimInput::AUX_LOCK_KEY, SimInput::MACHINE_LOCK_KEY] {
                keys.publish(SimInput { input, value: true }).unwrap();
            }
            let t0 = Instant::now();
            while locked(client) != Some(want) && t0.elapsed() < Duration::from_secs(10) {
                client.poll();
                std::thread::sleep(Duration::from_millis(5));
            }
            for input in [SimInput::AUX_LOCK_KEY, SimInput::MACHINE_LOCK_KEY] {
                keys.publish(SimInput {
                    input,
                    value: false,
                })
                .unwrap();
            }
            if locked(client) == Some(want) {
                return;
            }
        }
        panic!("machine lock never became {want}");
    };
    toggle(&mut client, true);
    let at_start = client.axes.clone().unwrap();
    let actual: Vec<f64> = at_start.axes.iter().map(|a| a.actual_position).collect();

    let r = client.start_program("prove.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let mut top_rpm: f64 = 0.0;
    let mut displayed = vec![];
    wait(&mut client, "the program's end", |c| {
        if let Some(a) = &c.axes {
            let now: Vec<f64> = a.axes.iter().map(|x| x.actual_position).collect();
            assert_eq!(now, actual, "a slide moved under machine lock");
            displayed.push(a.axes[0].commanded_position);
        }
        top_rpm = top_rpm.max(c.spindle.as_ref().map_or(0.0, |s| s.actual_rpm.abs()));
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
    });
    assert_eq!(top_rpm, 0.0, "the spindle turned under aux lock");
    // `axes` comes 25 times a second, apart from `machine_state`: the display reaches the
    // program's end point in a sample at or after the completion.
    let at_end = |a: &cnc_msgs::msg::AxisState| {
        (a.axes[0].commanded_position - 150.0).abs() < 1e-6
            && (a.axes[1].commanded_position - 50.0).abs() < 1e-6
    };
    wait(&mut client, "the display at the program's end point", |c| {
        c.axes.as_ref().is_some_and(at_end)
    });
    let a = client.axes.clone().unwrap();
    assert!(a.machine_lock);
    let now: Vec<f64> = a.axes.iter().map(|x| x.actual_position).collect();
    assert_eq!(now, actual, "a slide moved under machine lock");
    assert!(
        displayed.iter().any(|x| (x - 40.0).abs() < 1.0),
        "the display passed through the cut: {displayed:?}"
    );
    assert!(client.alarms.as_ref().is_none_or(|a| a.alarms.is_empty()));

    // Released: the program's position is the slides' again.
    toggle(&mut client, false);
    wait(&mut client, "commanded back at the slides", |c| {
        c.axes.as_ref().is_some_and(|a| {
            a.axes
                .iter()
                .zip(&actual)
                .all(|(x, p)| (x.commanded_position - p).abs() < 1e-6)
        })
    });
    drop(panel);
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}
