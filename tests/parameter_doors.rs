//! Issue 45, items 2–4 (D124): every parameter the launch config has is in one table with its
//! writer and bounds (`cnc_runtime::parameter_rules`). Through the cell's own door
//! (`set_parameter` over DDS, in MDI mode, as the bridge and the web panel take it), this test
//! walks the machine's parameters as `get_parameters` lists them and tries, for each one the
//! cell may write, non-finite, extreme, out-of-range and loosening values, and for each one
//! that is the builder's a write of any value (its own value included): all are refused with
//! the rule named and no long number printed back. The parameter file holds only the one
//! legitimate write made as a control, the position and message files are untouched, and the
//! cell starts again with its old values.

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_msgs::srv::*;
use cnc_runtime::parameter_rules::{rule, Writer};

fn read_all(c: &mut CellClient) -> BTreeMap<String, String> {
    let get = c
        .service::<GetParameters>("get_parameters")
        .expect("client");
    let page = get
        .query(GetParametersRequest::default())
        .expect("get_parameters answered");
    assert!(page.accepted, "{}", page.message);
    page.names.into_iter().zip(page.values).collect()
}

/// The values an attacker or a careless client tries on `name` (current value `now`).
fn attacks(cfg: &cnc_runtime::LaunchConfig, name: &str, now: &str) -> Vec<String> {
    let r = rule(name);
    if r.writer == Writer::Builder {
        return vec![
            now.to_string(),
            "/tmp/cnc_parameter_doors_target".into(),
            "1".into(),
        ];
    }
    let mut v: Vec<String> = [".nan", ".inf", "-.inf", "1e308", "-1e308"]
        .map(String::from)
        .to_vec();
    if let Some(range) = r.range {
        let (lo, hi) = range.bounds(cfg);
        v.push(format!("{}", hi * 2.0 + 1.0));
        if lo > 0.0 {
            v.push(format!("{}", lo / 2.0));
            v.push("1e-300".into());
        }
    }
    if r.monitor {
        // Loosening: beyond the builder's value.
        let builder = cfg.limits.monitors[name];
        v.push(format!("{}", builder * 1.5 + 1.0));
    }
    if let Some(axis) = name
        .strip_prefix("machine.axes.")
        .and_then(|n| n.split('.').next())
    {
        let rated = &cfg.limits.axes[axis];
        match name.rsplit('.').next() {
            Some("max_velocity") => v.push(format!("{}", rated.max_velocity * 2.0)),
            Some("max_acceleration") => v.push(format!("{}", rated.max_acceleration * 2.0)),
            Some("max") => v.push(format!("{}", rated.max + 1.0)),
            Some("min") => v.push(format!("{}", rated.min - 1.0)),
            _ => {}
        }
    }
    v
}

fn digest(path: &std::path::Path) -> Option<Vec<u8>> {
    std::fs::read(path).ok()
}

#[test]
fn no_door_writes_a_builders_parameter_or_a_value_out_of_its_bounds() {
    let dir = common::fresh_dir("parameter_doors");
    let mut cfg = common::sim_lathe(96);
    cfg.machine.parameter_file = Some(dir.join("parameters.yaml"));
    cfg.machine.position_file = Some(dir.join("position.yaml"));
    cfg.machine.msg_file = Some(dir.join("msg.txt"));
    std::fs::write(dir.join("msg.txt"), "a line of before\n").expect("msg file");
    let cell = Cell::start(&cfg).expect("cell");
    let mut c = common::ready_client(&cfg, "setter", Duration::from_secs(30));
    common::set_mode(&mut c, MachineState::MODE_MDI);
    let set = c.service::<SetParameter>("set_parameter").expect("client");
    let write = |name: &str, value: &str| {
        set.call(SetParameterRequest {
            name: name.into(),
            value: value.into(),
        })
        .expect("set_parameter answered")
    };

    // A legitimate write, as a control: the door is open to what the table allows.
    let r = write("servo.dry_run_feed", "800");
    assert!(r.accepted, "{}", r.message);
    let files = |d: &std::path::Path| {
        ["parameters.yaml", "position.yaml", "msg.txt"].map(|f| digest(&d.join(f)))
    };
    let before_files = files(&dir);
    assert!(before_files[0].is_some(), "the control write is stored");
    let before = read_all(&mut c);
    assert!(before.len() > 40, "{} parameters listed", before.len());

    let (mut builders, mut cells, mut tries) = (0, 0, 0);
    for (name, now) in &before {
        match rule(name).writer {
            Writer::Builder => builders += 1,
            Writer::Cell => cells += 1,
        }
        for value in attacks(&cfg, name, now) {
            tries += 1;
            let r = write(name, &value);
            assert!(!r.accepted, "{name} = {value} was accepted: {}", r.message);
            assert!(
                r.message.len() < 300 && !r.message.contains("0000000000"),
                "{name} = {value}: {}",
                r.message
            );
            if rule(name).writer == Writer::Builder {
                assert!(
                    r.message.contains("the machine builder's"),
                    "{name}: {}",
                    r.message
                );
            }
        }
    }
    println!("{builders} builder-only and {cells} cell parameters, {tries} writes refused");
    assert!(builders > 20 && cells > 10);
    // The sections every builder-only kind comes from are there: paths, dialect, geometry,
    // the simulated machine's switches.
    for name in [
        "machine.position_file",
        "machine.msg_file",
        "machine.dialect",
        "machine.axes.X.diameter",
        "machine.axes.X.drive_lag",
        "machine.tool_post",
        "machine.arc_plane.0",
        "sim.client_inputs",
    ] {
        assert!(before.contains_key(name), "{name} is listed");
        assert_eq!(rule(name).writer, Writer::Builder, "{name}");
    }
    assert_eq!(files(&dir), before_files, "no file was touched");
    assert_eq!(read_all(&mut c), before, "nothing pending changed");
    drop(c);
    cell.stop();

    // The next start takes the parameter file: the old values and the one control write.
    let again = cfg
        .clone()
        .with_parameter_file()
        .expect("the parameter file applies");
    assert_eq!(again.servo.dry_run_feed, 800.0);
    let cell = Cell::start(&again).expect("cell again");
    let mut c = common::ready_client(&again, "setter2", Duration::from_secs(30));
    let mut after = read_all(&mut c);
    assert_eq!(
        after
            .insert("servo.dry_run_feed".into(), "1000.0".into())
            .as_deref(),
        Some("800.0"),
        "the control write is taken"
    );
    assert_eq!(after, before, "the cell started with its old values");
    drop(c);
    cell.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 45 item 9: the nodes serve no ROS 2 parameter services (ros2-client's
/// `list/get/set_parameters`), which answered any participant outside `allowed_clients` and
/// made no command event: the machine's parameters have one door, `get/set_parameter`.
#[test]
fn the_nodes_serve_no_ros2_parameter_services() {
    let cfg = common::sim_lathe(97);
    let cell = Cell::start(&cfg).expect("cell");
    let c = common::ready_client(&cfg, "observer", Duration::from_secs(30));
    let participant = c.node().participant();
    // Long enough for every node's readers to be discovered: the bridge's own service
    // readers are the control.
    let mut names = Vec::new();
    for _ in 0..40 {
        names = participant
            .discovered_readers()
            .iter()
            .map(|r| r.subscription_topic_data.topic_name().clone())
            .collect::<Vec<_>>();
        if names.iter().any(|n| n == "rq/lathe1/set_parameterRequest") {
            break;
        }
        std::thread::sleep(Duration::from_millis(250));
    }
    assert!(
        names.iter().any(|n| n == "rq/lathe1/set_parameterRequest"),
        "the bridge's parameter door is discovered: {names:?}"
    );
    // ros2-client's services are per node, `rq/lathe1/<node>/get_parametersRequest`; the
    // bridge's door is `rq/lathe1/get_parametersRequest`.
    let served: Vec<&String> = names
        .iter()
        .filter(|n| n.matches('/').count() >= 3 && n.contains("_parameters"))
        .collect();
    assert!(
        served.is_empty(),
        "ROS 2 parameter services served: {served:?}"
    );
    drop(c);
    cell.stop();
}
