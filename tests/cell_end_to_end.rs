//! End to end over real DDS and iceoryx2: the cell in this process, a separate ros2-client node
//! as the supervisor. Run by `scripts/test.sh` inside a network namespace with only loopback.
//! Each test uses its own DDS domain and so its own iceoryx2 instance.

use std::time::Duration;

mod common;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_runtime::LaunchConfig;
use ros2_client::ServiceMapping;

fn config(domain: u16) -> LaunchConfig {
    common::sim_lathe(domain)
}

/// A supervisor node of the cell's machine `lathe1`, calling services with `mapping`.
fn supervisor(cfg: &LaunchConfig, mapping: ServiceMapping) -> CellClient {
    CellClient::new(&cfg.network, "lathe1", "test_supervisor", mapping).unwrap()
}

const PROGRAM: &str = "O0001\nG00 X60 Z5\nS600 M03\nG01 X40 Z0 F600\nZ-20\nG02 X50 Z-25 R5\nG01 X56.789 Z-30.123\nM05\nM30\n";

#[test]
fn program_runs_through_ros2_services_and_the_part_is_counted() {
    let cfg = config(41);
    let cell = Cell::start(&cfg).unwrap();
    let mut client = supervisor(&cfg, ServiceMapping::Enhanced);
    let (ok, _) = client.wait_until(Duration::from_secs(20), |c| {
        c.part_count.is_some() && c.state.is_some() && c.axes.is_some()
    });
    assert!(ok, "state topics never arrived");
    client.wait_ready(Duration::from_secs(20)).unwrap();
    assert_eq!(client.part_count.as_ref().unwrap().count, 0);
    let r = client.load_program("part1.nc", PROGRAM).unwrap();
    assert!(r.accepted, "{}", r.message);
    let r = client.start_program("part1.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let mut max_rpm_while_cutting: f64 = 0.0;
    let (ok, seen) = client.wait_until(Duration::from_secs(60), |c| {
        if let (Some(s), Some(sp)) = (&c.state, &c.spindle) {
            if s.execution == MachineState::ACTIVE && (4..=6).contains(&s.line) {
                max_rpm_while_cutting = max_rpm_while_cutting.max(sp.actual_rpm);
            }
        }
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
            && c.part_count.as_ref().is_some_and(|p| p.count == 1)
    });
    let names: Vec<&str> = seen.iter().map(|s| s.execution_name.as_str()).collect();
    assert!(
        ok,
        "program did not complete; states seen {names:?}, alarms {:?}",
        client.alarms
    );
    let active = names
        .iter()
        .position(|n| *n == "ACTIVE")
        .expect("ACTIVE seen");
    let done = names
        .iter()
        .rposition(|n| *n == "PROGRAM_COMPLETED")
        .unwrap();
    assert!(active < done);
    // The spindle turned at the programmed 600 rpm while cutting (at-speed window 2 %).
    assert!(
        (max_rpm_while_cutting - 600.0).abs() <= 12.0,
        "spindle {max_rpm_while_cutting} rpm while cutting"
    );
    // Final position: X56.789 Z-30.123 within 1 µm, after the drives settle.
    let (ok, _) = client.wait_until(Duration::from_secs(5), |c| {
        c.axes.as_ref().is_some_and(|a| {
            (a.axes[0].actual_position - 56.789).abs() < 0.001
                && (a.axes[1].actual_position + 30.123).abs() < 0.001
        })
    });
    assert!(ok, "final position {:?}", client.axes);
    assert!(
        client
            .servo_stats
            .as_ref()
            .is_some_and(|s| s.ticks > 0 && s.interval_p50_us > 0.0),
        "no servo statistics"
    );
    let (summary, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(summary.contains("round trip"), "{summary}");
}

#[test]
fn bad_program_raises_an_alarm_with_its_line_and_reset_recovers() {
    let cfg = config(42);
    let cell = Cell::start(&cfg).unwrap();
    let mut client = supervisor(&cfg, ServiceMapping::Cyclone);
    let (ok, _) = client.wait_until(Duration::from_secs(20), |c| {
        c.axes.is_some() && c.alarms.is_some()
    });
    assert!(ok);
    client.wait_ready(Duration::from_secs(20)).unwrap();
    // Line 3 has an unknown G code; lines 1-2 stay near the start.
    let bad = "G00 X150 Z50\nG01 Z40 F3000\nG77 X10\nG01 X0 Z-100\nM30\n";
    assert!(client.load_program("bad.nc", bad).unwrap().accepted);
    assert!(client.start_program("bad.nc").unwrap().accepted);
    let (ok, _) = client.wait_until(Duration::from_secs(30), |c| {
        c.alarms.as_ref().is_some_and(|a| !a.alarms.is_empty())
    });
    assert!(ok, "no alarm");
    let alarm = client.alarms.as_ref().unwrap().alarms[0].clone();
    assert_eq!(
        (
            alarm.number,
            alarm.line,
            alarm.source.as_str(),
            alarm.program.as_str()
        ),
        (7, 3, "interpreter", "bad.nc")
    );
    assert!(alarm.text.contains("G77"), "{}", alarm.text);
    let (ok, _) = client.wait_until(Duration::from_secs(10), |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::STOPPED && s.alarm_active)
    });
    assert!(ok, "state {:?}", client.state);
    std::thread::sleep(Duration::from_millis(500));
    client.poll();
    for a in &client.axes.as_ref().unwrap().axes {
        let (lo, hi) = if a.name == "X" {
            (149.999, 200.001)
        } else {
            (39.999, 100.001)
        };
        assert!(
            (lo..=hi).contains(&a.actual_position),
            "{} moved past line 2: {}",
            a.name,
            a.actual_position
        );
    }
    // Start is refused while the alarm is active; after reset a good program runs.
    assert!(!client.start_program("bad.nc").unwrap().accepted);
    assert!(client.reset().unwrap().accepted);
    let (ok, _) = client.wait_until(Duration::from_secs(10), |c| {
        c.alarms.as_ref().is_some_and(|a| a.alarms.is_empty())
    });
    assert!(ok, "alarm not cleared by reset");
    // An arc with an impossible radius: alarm 11 on its line.
    assert!(
        client
            .load_program("arc.nc", "G00 X100 Z20\nG02 X120 Z-20 R5 F100\nM30\n")
            .unwrap()
            .accepted
    );
    assert!(client.start_program("arc.nc").unwrap().accepted);
    let (ok, _) = client.wait_until(Duration::from_secs(30), |c| {
        c.alarms
            .as_ref()
            .is_some_and(|a| a.alarms.iter().any(|x| x.number == 11 && x.line == 2))
    });
    assert!(ok, "alarms {:?}", client.alarms);
    assert!(client.reset().unwrap().accepted);
    assert!(
        client
            .load_program("good.nc", "G00 X100 Z20\nG01 Z10 F2000\nM30\n")
            .unwrap()
            .accepted
    );
    assert!(client.start_program("good.nc").unwrap().accepted);
    let (ok, _) = client.wait_until(Duration::from_secs(30), |c| {
        c.part_count.as_ref().is_some_and(|p| p.count == 1)
    });
    assert!(
        ok,
        "good program after reset did not complete: {:?} {:?}",
        client.state, client.alarms
    );
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn a_malformed_plc_program_is_refused_and_the_running_one_keeps_the_machine() {
    let dir = std::env::temp_dir().join(format!("cnc_plc_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("machine.plc");
    std::fs::write(&file, cnc_plc::LATHE_STANDARD).unwrap();
    let mut cfg = config(48);
    cfg.plc.program = Some(file.clone());
    let cell = Cell::start(&cfg).unwrap();
    let mut client = supervisor(&cfg, ServiceMapping::Enhanced);
    client.wait_ready(Duration::from_secs(20)).unwrap();
    // The machine builder saves a program with a write to an input on line 4.
    std::fs::write(&file, "RD X1.0\nWRT G8.4\nRD X0.0\nWRT X0.1\nEND1\nEND2\n").unwrap();
    let (ok, _) = client.wait_until(Duration::from_secs(10), |c| {
        c.alarms
            .as_ref()
            .is_some_and(|a| a.alarms.iter().any(|x| x.number == 1091))
    });
    assert!(ok, "no refusal alarm: {:?}", client.alarms);
    let alarm = client
        .alarms
        .as_ref()
        .and_then(|a| a.alarms.iter().find(|x| x.number == 1091).cloned())
        .unwrap();
    assert!(
        alarm.text.contains("line 4") && alarm.text.contains("X0.1 cannot be written"),
        "{}",
        alarm.text
    );
    // The standard program still runs the machine: spindle to speed, part counted.
    let program = "G00 X100 Z20\nS900 M03\nG01 Z10 F2000\nM05\nM30\n";
    assert!(client.load_program("p.nc", program).unwrap().accepted);
    assert!(client.start_program("p.nc").unwrap().accepted);
    let mut max_rpm: f64 = 0.0;
    let (ok, _) = client.wait_until(Duration::from_secs(30), |c| {
        if let Some(sp) = &c.spindle {
            max_rpm = max_rpm.max(sp.actual_rpm);
        }
        c.part_count.as_ref().is_some_and(|p| p.count == 1)
    });
    assert!(
        ok,
        "program did not complete: {:?} {:?}",
        client.state, client.alarms
    );
    assert!((max_rpm - 900.0).abs() <= 18.0, "spindle {max_rpm} rpm");
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
