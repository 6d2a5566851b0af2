//! The services an integrator sets a machine up with, from a separate ROS 2 node: the mode
//! switch, MDI, the tool and work offset pages, parameters, and alarm acknowledgement; and a
//! motion alarm that reset clears. Runs in scripts/test.sh's network namespace, domain 55.

mod common;

use std::time::Duration;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::{MachineState, ToolOffset, WorkOffset};
use cnc_msgs::srv::*;
use ros2_client::ServiceMapping;

/// Polls until `done` holds, or fails with `what` after 30 s.
fn wait(client: &mut CellClient, what: &str, done: impl Fn(&CellClient) -> bool) {
    common::wait(client, Duration::from_secs(30), what, done);
}

fn execution(c: &CellClient) -> u8 {
    c.state.as_ref().map_or(MachineState::WAIT, |s| s.execution)
}

/// Commanded machine position of axis `i` (0 X as diameter, 1 Z).
fn axis(c: &CellClient, i: usize) -> f64 {
    c.axes
        .as_ref()
        .map_or(f64::NAN, |a| a.axes[i].commanded_position)
}

#[test]
fn mode_mdi_offsets_parameters_and_alarms_are_served_to_the_cell() {
    let dir = std::env::temp_dir().join(format!("cnc_machine_services_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let parameter_file = dir.join("parameters.yaml");
    let mut cfg = common::sim_lathe(55);
    cfg.machine.parameter_file = Some(parameter_file.clone());
    cfg.hmi.allowed_clients = Some(vec!["/lathe1/setter".into()]);
    let cell = Cell::start(&cfg).unwrap();
    let mut c =
        CellClient::new(&cfg.network, "lathe1", "setter", ServiceMapping::Enhanced).unwrap();
    let mut intruder =
        CellClient::new(&cfg.network, "lathe1", "intruder", ServiceMapping::Enhanced).unwrap();
    let mode = c.service::<SetMode>("set_mode").unwrap();
    let mdi = c.service::<Mdi>("mdi").unwrap();
    let offsets = c.service::<GetOffsets>("get_offsets").unwrap();
    let tool = c.service::<SetToolOffset>("set_tool_offset").unwrap();
    let work = c.service::<SetWorkOffset>("set_work_offset").unwrap();
    let get_parameters = c.service::<GetParameters>("get_parameters").unwrap();
    let set_parameter = c.service::<SetParameter>("set_parameter").unwrap();
    let acknowledge = c.service::<AcknowledgeAlarm>("acknowledge_alarm").unwrap();
    let intruder_parameter = intruder.service::<SetParameter>("set_parameter").unwrap();
    c.wait_ready(Duration::from_secs(20)).unwrap();
    std::thread::sleep(Duration::from_secs(2)); // the clients' nodes are announced
    let set_mode = |m: u8| mode.call(SetModeRequest { mode: m }).unwrap();
    let run_mdi = |text: &str| mdi.call(MdiRequest { text: text.into() }).unwrap();

    // The mode switch and MDI.
    let r = run_mdi("G00 X80 Z20");
    assert!(
        !r.accepted && r.message.contains("not MDI"),
        "{}",
        r.message
    );
    let r = set_mode(9);
    assert!(
        !r.accepted && r.message.contains("unknown mode"),
        "{}",
        r.message
    );
    let r = set_mode(MachineState::MODE_MDI);
    assert!(r.accepted, "{}", r.message);
    let r = run_mdi("G00 X80 Z20");
    assert!(r.accepted, "{}", r.message);
    wait(&mut c, "the MDI move", |c| {
        execution(c) == MachineState::PROGRAM_COMPLETED && (axis(c, 1) - 20.0).abs() < 1e-6
    });
    assert!((axis(&c, 0) - 80.0).abs() < 1e-6, "X {}", axis(&c, 0));
    assert_eq!(c.state.as_ref().unwrap().mode, MachineState::MODE_MDI);

    // The offset pages.
    let page = offsets.query(GetOffsetsRequest::default()).unwrap();
    assert!(page.accepted, "{}", page.message);
    let t1 = page.tools.iter().find(|t| t.number == 1).expect("tool 1");
    assert_eq!((t1.radius, t1.tip), (0.4, 3));
    let codes: Vec<&str> = page.work.iter().map(|w| w.code.as_str()).collect();
    assert_eq!(codes, ["G54", "G55", "G56", "G57", "G58", "G59"]);
    let row = ToolOffset {
        number: 5,
        x: 1.25,
        z: -2.5,
        wear_x: 0.01,
        wear_z: -0.02,
        radius: 0.8,
        tip: 3,
    };
    let r = tool
        .call(SetToolOffsetRequest {
            offset: row.clone(),
        })
        .unwrap();
    assert!(r.accepted, "{}", r.message);
    for (bad, why) in [
        (
            ToolOffset {
                tip: 12,
                ..row.clone()
            },
            "tip direction",
        ),
        (
            ToolOffset {
                x: f64::NAN,
                ..row.clone()
            },
            "out of range",
        ),
        (
            ToolOffset {
                number: 0,
                ..row.clone()
            },
            "out of range 1-99",
        ),
    ] {
        let r = tool.call(SetToolOffsetRequest { offset: bad }).unwrap();
        assert!(!r.accepted && r.message.contains(why), "{}", r.message);
    }
    let r = work
        .call(SetWorkOffsetRequest {
            offset: WorkOffset {
                code: "G54".into(),
                axes: vec!["Z".into()],
                values: vec![-100.0],
            },
        })
        .unwrap();
    assert!(r.accepted, "{}", r.message);
    for (code, axes, values, why) in [
        ("G60", vec!["Z"], vec![1.0], "not G54-G59"),
        ("G54", vec!["Y"], vec![1.0], "not an axis"),
        ("G54", vec!["Z"], vec![], "1 axes but 0 values"),
    ] {
        let offset = WorkOffset {
            code: code.into(),
            axes: axes.into_iter().map(String::from).collect(),
            values,
        };
        let r = work.call(SetWorkOffsetRequest { offset }).unwrap();
        assert!(!r.accepted && r.message.contains(why), "{}", r.message);
    }
    let page = offsets.query(GetOffsetsRequest::default()).unwrap();
    assert_eq!(page.tools.iter().find(|t| t.number == 5), Some(&row));
    assert_eq!(page.work[0].values, [0.0, -100.0], "G54 X kept, Z set");
    // The written G54 moves the next cut: Z0 of the program is machine Z -100.
    let r = run_mdi("G54 G00 X60 Z0");
    assert!(r.accepted, "{}", r.message);
    wait(&mut c, "the move in G54", |c| {
        execution(c) == MachineState::PROGRAM_COMPLETED && (axis(c, 1) + 100.0).abs() < 1e-6
    });

    // Parameters: read, refused writes, a write that waits for the next start.
    let name = "machine.axes.X.max_velocity";
    let read = |prefix: &str| {
        get_parameters
            .query(GetParametersRequest {
                prefix: prefix.into(),
            })
            .unwrap()
    };
    let all = read("");
    assert!(all.names.len() > 20, "{:?}", all.names);
    assert!(all
        .names
        .iter()
        .all(|n| !n.starts_with("hmi.") && !n.starts_with("network.")));
    let x = read("machine.axes.X.");
    let at = x.names.iter().position(|n| n == name).expect(name);
    assert_eq!(
        (x.values[at].as_str(), x.pending[at].as_str()),
        ("6000.0", "")
    );
    let write = |value: &str| {
        set_parameter
            .call(SetParameterRequest {
                name: name.into(),
                value: value.into(),
            })
            .unwrap()
    };
    let r = intruder_parameter
        .call(SetParameterRequest {
            name: name.into(),
            value: "5000".into(),
        })
        .unwrap();
    assert!(
        !r.accepted && r.message.contains("may not move"),
        "{}",
        r.message
    );
    for (value, why) in [("fast", "invalid type"), ("-5", "positive velocity")] {
        let r = write(value);
        assert!(!r.accepted && r.message.contains(why), "{}", r.message);
    }
    assert!(!parameter_file.exists(), "refused writes store nothing");
    let r = write("5000");
    assert!(r.accepted, "{}", r.message);
    let x = read(name);
    assert_eq!(
        (x.values[0].as_str(), x.pending[0].as_str()),
        ("6000.0", "5000.0")
    );
    let next = cfg.clone().with_parameter_file().unwrap();
    assert_eq!(next.machine.axes[0].max_velocity, 5000.0);
    // In AUTO, parameters are not written.
    assert!(set_mode(MachineState::MODE_AUTO).accepted);
    let r = write("4000");
    assert!(
        !r.accepted && r.message.contains("not MDI"),
        "{}",
        r.message
    );

    // The write's alarm asks for a restart; it is acknowledged, and stays until then.
    wait(&mut c, "the parameter alarm", |c| {
        c.alarms.as_ref().is_some_and(|a| {
            a.alarms
                .iter()
                .any(|a| a.source == "hmi_bridge" && a.number == 0)
        })
    });
    let r = acknowledge
        .call(AcknowledgeAlarmRequest {
            source: "hmi_bridge".into(),
            number: 0,
        })
        .unwrap();
    assert!(r.accepted, "{}", r.message);
    wait(&mut c, "the acknowledged alarm", |c| {
        c.alarms.as_ref().is_some_and(|a| {
            a.alarms
                .iter()
                .any(|a| a.source == "hmi_bridge" && a.number == 0 && a.acknowledged)
        })
    });
    let r = acknowledge
        .call(AcknowledgeAlarmRequest {
            source: "motion".into(),
            number: 38,
        })
        .unwrap();
    assert!(
        !r.accepted && r.message.contains("no active alarm"),
        "{}",
        r.message
    );

    // A motion alarm (soft limit) blocks the next start until reset clears it.
    assert!(set_mode(MachineState::MODE_MDI).accepted);
    let r = run_mdi("G00 Z500");
    assert!(r.accepted, "{}", r.message);
    wait(&mut c, "the soft-limit alarm", |c| {
        c.alarms.as_ref().is_some_and(|a| {
            a.alarms
                .iter()
                .any(|a| a.source == "motion" && a.number == 38)
        })
    });
    wait(&mut c, "the stop", |c| {
        execution(c) == MachineState::STOPPED
    });
    let r = run_mdi("G00 Z10");
    assert!(
        !r.accepted && r.message.contains("reset first"),
        "{}",
        r.message
    );
    assert!(c.reset().unwrap().accepted);
    wait(&mut c, "the alarm cleared by reset", |c| {
        c.alarms
            .as_ref()
            .is_some_and(|a| !a.alarms.iter().any(|a| a.source == "motion"))
    });
    let r = run_mdi("G00 Z10");
    assert!(r.accepted, "{}", r.message);
    wait(&mut c, "the move after reset", |c| {
        execution(c) == MachineState::PROGRAM_COMPLETED && (axis(c, 1) + 90.0).abs() < 1e-6
    });

    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
