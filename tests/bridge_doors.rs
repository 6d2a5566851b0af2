//! Every door of the bridge refuses a malformed request with a command event (issue 47). The
//! doors are not listed here: the test finds them as any DDS peer would, by the request
//! readers the bridge's participant offers (`rq/lathe1/…Request`), and writes each an empty
//! payload, which no request type decodes from. A door added without the table's malformed
//! handling — or a service whose refusals pile up unrecorded, as `list_programs`' once did —
//! makes no event and fails this test. Runs in scripts/test.sh's network namespace.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::time::{Duration, Instant};

use cnc::cell::Cell;
use cnc_runtime::raw::{Raw, RawAdapter};
use ros2_client::dds::rustdds::{QosPolicies, TopicKind};

#[test]
fn every_door_the_bridge_offers_records_a_malformed_request() {
    let cfg = common::sim_lathe(161);
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut auditor = common::Auditor::new(&cfg);
    let participant = auditor.node.participant();
    // The bridge's doors as discovery shows them, once their number stops growing.
    let doors = |p: &ros2_client::dds::rustdds::DomainParticipant| -> BTreeSet<(String, String)> {
        p.discovered_readers()
            .iter()
            .map(|r| &r.subscription_topic_data)
            .filter_map(|t| {
                let door = t
                    .topic_name()
                    .strip_prefix("rq/lathe1/")?
                    .strip_suffix("Request")?;
                Some((door.to_string(), t.type_name().clone()))
            })
            .collect()
    };
    let t0 = Instant::now();
    let mut found = BTreeSet::new();
    let mut steady = 0;
    while steady < 20 {
        let now = doors(&participant);
        steady = if now.len() == found.len() {
            steady + 1
        } else {
            0
        };
        found = now;
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "discovery: {found:?}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let names: Vec<&str> = found.iter().map(|(n, _)| n.as_str()).collect();
    println!("{} doors: {names:?}", names.len());
    // The 16 services of the table, the robot's, and the action's three.
    assert_eq!(found.len(), 20, "{names:?}");
    for expected in ["jog", "set_tool_offset", "list_programs", "robot_request"] {
        assert!(names.contains(&expected), "{expected} missing: {names:?}");
    }

    let qos: QosPolicies = (&cnc_runtime::dds::qos::services()).into();
    let publisher = participant.create_publisher(&qos).unwrap();
    let writers: Vec<_> = found
        .iter()
        .map(|(door, ty)| {
            let topic = participant
                .create_topic(
                    format!("rq/lathe1/{door}Request"),
                    ty.clone(),
                    &qos,
                    TopicKind::NoKey,
                )
                .unwrap();
            publisher
                .create_datawriter_no_key::<Raw, RawAdapter>(&topic, None)
                .unwrap()
        })
        .collect();
    std::thread::sleep(Duration::from_millis(1500)); // the bridge's readers match ours
    let empty = || Raw {
        bytes: Vec::new(),
        little_endian: true,
    };
    for w in &writers {
        w.write(empty(), None).unwrap();
    }

    // Each door records its malformed request once: a door listed twice in the table (two
    // readers of one topic) would record it twice, and carry out a good request twice.
    let mut recorded: BTreeMap<String, usize> = BTreeMap::new();
    let t0 = Instant::now();
    let take = |recorded: &mut BTreeMap<String, usize>| {
        for e in auditor.events() {
            assert!(!e.accepted, "{e:?}");
            if e.detail == "malformed" {
                println!("{}: {}", e.command, e.message);
                *recorded.entry(e.command).or_default() += 1;
            }
        }
    };
    while recorded.len() < found.len() && t0.elapsed() < Duration::from_secs(20) {
        take(&mut recorded);
        std::thread::sleep(Duration::from_millis(50));
    }
    // A second answer of a door listed twice would come within this second.
    std::thread::sleep(Duration::from_secs(1));
    take(&mut recorded);
    let missing: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| !recorded.contains_key(*n))
        .collect();
    assert!(
        missing.is_empty(),
        "no event for a malformed request: {missing:?}"
    );
    let twice: Vec<_> = recorded.iter().filter(|(_, n)| **n != 1).collect();
    assert!(
        twice.is_empty(),
        "doors that answered more than once: {twice:?}"
    );
    let _ = &mut auditor;
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}
