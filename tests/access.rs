//! Who may command the machine: a client the launch config does not allow is refused a program
//! start, one it allows is not; malformed requests get clear refusals; every decision is
//! published on `/lathe1/command_events` with who sent it. Runs in scripts/test.sh's netns.

mod common;

use std::time::{Duration, Instant};

use cnc::cell::Cell;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::{CommandEvent, MachineState};
use cnc_msgs::srv::StartProgramResponse;
use cnc_runtime::dds::RosNode;
use cnc_runtime::raw::{Raw, RawAdapter};
use ros2_client::ServiceMapping;

const PROGRAM: &str = "O0001\nG00 X60 Z5\nG01 X50 Z0 F900\nM30\n";

#[test]
fn only_allowed_clients_move_the_machine_and_every_command_is_an_event() {
    let mut cfg = common::sim_lathe(52);
    cfg.hmi.allowed_clients = Some(vec!["/lathe1/supervisor_ok".into()]);
    let cell = Cell::start(&cfg).unwrap();
    let mut auditor = common::Auditor::new(&cfg);
    let mut good = CellClient::new(
        &cfg.network,
        "lathe1",
        "supervisor_ok",
        ServiceMapping::Enhanced,
    )
    .unwrap();
    let mut bad =
        CellClient::new(&cfg.network, "lathe1", "intruder", ServiceMapping::Enhanced).unwrap();
    good.wait_ready(Duration::from_secs(20)).unwrap();
    // Both clients' participants announce their nodes on ros_discovery_info.
    std::thread::sleep(Duration::from_secs(2));

    let r = good.load_program("p.nc", PROGRAM).unwrap();
    assert!(r.accepted, "{}", r.message);
    let r = bad.start_program("p.nc").unwrap();
    assert!(!r.accepted);
    assert!(
        r.message.contains("/lathe1/intruder") && r.message.contains("may not move"),
        "{}",
        r.message
    );
    // Refused means nothing moved.
    std::thread::sleep(Duration::from_millis(300));
    good.poll();
    assert_eq!(good.state.as_ref().unwrap().execution, MachineState::READY);

    // Program memory is guarded: an intruder cannot overwrite or delete what the robot starts
    // next; reading stays open.
    let r = bad.load_program("p.nc", "O0001\nG00 X-500\nM30\n").unwrap();
    assert!(
        !r.accepted && r.message.contains("may not move"),
        "{}",
        r.message
    );
    let r = bad.delete_program("p.nc").unwrap();
    assert!(
        !r.accepted && r.message.contains("may not move"),
        "{}",
        r.message
    );
    let listed = bad.list_programs().unwrap();
    assert!(listed.names.iter().any(|n| n == "p.nc"), "{listed:?}");

    // Malformed requests: clear errors, nothing changed.
    let huge = "G01 X1\n".repeat(cnc_runtime::MAX_PROGRAM_BYTES / 7 + 1);
    let r = good.load_program("huge.nc", &huge).unwrap();
    assert!(
        !r.accepted && r.message.contains("too large"),
        "{}",
        r.message
    );
    let r = good.start_program("missing.nc").unwrap();
    assert!(
        !r.accepted && r.message.contains("not found"),
        "{}",
        r.message
    );
    let r = good.stop(9).unwrap();
    assert!(
        !r.accepted && r.message.contains("unknown stop mode"),
        "{}",
        r.message
    );
    let r = good.load_program("../etc/passwd", "M30\n").unwrap();
    assert!(
        !r.accepted && r.message.contains("invalid program name"),
        "{}",
        r.message
    );
    let r = start_with_raw_bytes(&mut auditor.node, &[4, 0, 0, 0, 0xff, 0xfe, b'A', 0]);
    assert!(
        !r.accepted && r.message.contains("malformed"),
        "{}",
        r.message
    );
    good.poll();
    assert_eq!(good.state.as_ref().unwrap().execution, MachineState::READY);

    // The allowed client runs the program; anyone may stop.
    let r = good.start_program("p.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let t0 = Instant::now();
    loop {
        good.poll();
        if good
            .state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
        {
            break;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "program did not finish"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let r = bad.reset().unwrap();
    assert!(r.accepted, "{}", r.message);

    // Overrides: only the switch steps, only from an allowed client, and they reach the PLC.
    let r = good.set_overrides(200, 100, 100).unwrap();
    assert!(
        !r.accepted && r.message.contains("feed override 200 %"),
        "{}",
        r.message
    );
    let r = bad.set_overrides(100, 80, 100).unwrap();
    assert!(
        !r.accepted && r.message.contains("may not move"),
        "{}",
        r.message
    );
    let r = good.set_overrides(100, 80, 50).unwrap();
    assert!(r.accepted, "{}", r.message);
    let t0 = Instant::now();
    while good
        .spindle
        .as_ref()
        .is_none_or(|s| s.override_percent != 80.0)
    {
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "spindle override never 80 %"
        );
        good.poll();
        std::thread::sleep(Duration::from_millis(10));
    }

    // Program memory: list and delete.
    let r = good.load_program("second.nc", "M30\n").unwrap();
    assert!(r.accepted, "{}", r.message);
    let l = good.list_programs().unwrap();
    assert_eq!(l.names, vec!["p.nc".to_string(), "second.nc".to_string()]);
    assert_eq!(l.sizes, vec![PROGRAM.len() as u64, 4]);
    let r = good.delete_program("second.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let r = good.delete_program("second.nc").unwrap();
    assert!(
        !r.accepted && r.message.contains("not found"),
        "{}",
        r.message
    );
    assert_eq!(
        good.list_programs().unwrap().names,
        vec!["p.nc".to_string()]
    );

    std::thread::sleep(Duration::from_millis(300));
    let seen: Vec<CommandEvent> = auditor.events();
    let find = |command: &str, client: &str, accepted: bool| {
        seen.iter()
            .any(|e| e.command == command && e.client == client && e.accepted == accepted)
    };
    assert!(
        find("start_program", "/lathe1/intruder", false),
        "{seen:#?}"
    );
    assert!(
        find("start_program", "/lathe1/supervisor_ok", true),
        "{seen:#?}"
    );
    assert!(find("load_program", "/lathe1/intruder", false));
    assert!(find("stop", "/lathe1/supervisor_ok", false));
    assert!(find("reset", "/lathe1/intruder", true));
    assert!(seen
        .iter()
        .any(|e| e.command == "start_program" && e.detail == "malformed" && !e.accepted));
    assert!(find("delete_program", "/lathe1/supervisor_ok", false));
    assert!(find("set_overrides", "/lathe1/intruder", false));
    assert!(find("delete_program", "/lathe1/intruder", false));
    assert_eq!(seen.len(), 20, "one event per request: {seen:#?}");
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}

/// A start_program request whose payload is `payload` (CDR, no header: the enhanced mapping),
/// written with plain DDS as a broken client would; returns the decoded reply.
fn start_with_raw_bytes(node: &mut RosNode, payload: &[u8]) -> StartProgramResponse {
    use ros2_client::dds::rustdds::{QosPolicies, TopicKind};
    let participant = node.participant();
    let qos: QosPolicies = (&cnc_runtime::dds::qos::services()).into();
    let rq = participant
        .create_topic(
            "rq/lathe1/start_programRequest".into(),
            "cnc_msgs::srv::dds_::StartProgram_Request_".into(),
            &qos,
            TopicKind::NoKey,
        )
        .unwrap();
    let rr = participant
        .create_topic(
            "rr/lathe1/start_programReply".into(),
            "cnc_msgs::srv::dds_::StartProgram_Response_".into(),
            &qos,
            TopicKind::NoKey,
        )
        .unwrap();
    let writer = participant
        .create_publisher(&qos)
        .unwrap()
        .create_datawriter_no_key::<Raw, RawAdapter>(&rq, None)
        .unwrap();
    let reader = participant
        .create_subscriber(&qos)
        .unwrap()
        .create_simple_datareader_no_key::<Raw, RawAdapter>(&rr, None)
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500)); // discovery both ways
    writer
        .write(
            Raw {
                bytes: payload.to_vec(),
                little_endian: true,
            },
            None,
        )
        .unwrap();
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(10) {
        if let Ok(Some(sample)) = reader.try_take_one() {
            let raw = sample.into_value();
            let (r, _) = cdr_encoding::from_bytes::<StartProgramResponse, byteorder::LittleEndian>(
                &raw.bytes,
            )
            .unwrap();
            return r;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("no reply to the malformed request");
}
