//! Bag folders: files cut by size and age with the audit chain running across them,
//! `metadata.yaml` that says what the files hold, rotation of old bags.

use std::path::PathBuf;

use cnc_recorder::audit::{verify, Verdict};
use cnc_recorder::bag::{offered_qos, rotate, Bag, BagOptions, BagTopic};
use cnc_recorder::mcap::Compression;
use cnc_runtime::topics::Delivery;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cnc_bag_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn topics() -> Vec<BagTopic> {
    vec![
        BagTopic {
            name: "/m/spindle".into(),
            type_name: "cnc_msgs/msg/SpindleState".into(),
            qos: offered_qos(Delivery::State),
        },
        BagTopic {
            name: "/m/alarm_events".into(),
            type_name: "cnc_msgs/msg/AlarmEvent".into(),
            qos: offered_qos(Delivery::Events(100)),
        },
    ]
}

const S: u64 = 1_000_000_000;

/// Records 60 messages over 6 s into a bag that splits every 2 s.
fn record(root: &std::path::Path) -> PathBuf {
    let options = BagOptions {
        compression: Compression::Zstd,
        flush_ns: S / 2,
        split_bytes: 1 << 30,
        split_ns: 2 * S,
    };
    let t0 = 1_800_000_000 * S;
    let mut bag = Bag::create(root, "m_test", topics(), options, t0).unwrap();
    for i in 0..60u64 {
        let t = t0 + i * S / 10;
        let topic = (i % 3 == 0) as usize;
        bag.record(topic, t, t, &[0, 1, 0, 0, i as u8, 0, 0, 0])
            .unwrap();
        bag.tick(t).unwrap();
    }
    let path = bag.dir().to_path_buf();
    let info = bag.close().unwrap();
    assert_eq!(info.files.len(), 3);
    path
}

#[test]
fn files_split_by_age_and_metadata_yaml_counts_every_message() {
    let root = dir("split");
    let bag = record(&root);
    let text = std::fs::read_to_string(bag.join("metadata.yaml")).unwrap();
    let y: serde_yaml::Value = serde_yaml::from_str(&text).unwrap();
    let info = &y["rosbag2_bagfile_information"];
    assert_eq!(info["message_count"].as_u64(), Some(60));
    assert_eq!(info["relative_file_paths"].as_sequence().unwrap().len(), 3);
    let counts: Vec<u64> = info["topics_with_message_count"]
        .as_sequence()
        .unwrap()
        .iter()
        .map(|t| t["message_count"].as_u64().unwrap())
        .collect();
    assert_eq!(counts, vec![40, 20]);
    let files: u64 = info["files"]
        .as_sequence()
        .unwrap()
        .iter()
        .map(|f| f["message_count"].as_u64().unwrap())
        .sum();
    assert_eq!(files, 60);
    // The QoS text survives the quoting as YAML that parses to the profile.
    let qos = info["topics_with_message_count"][1]["topic_metadata"]["offered_qos_profiles"]
        .as_str()
        .unwrap();
    let q: serde_yaml::Value = serde_yaml::from_str(qos).unwrap();
    assert_eq!(q[0]["depth"].as_u64(), Some(100));
    assert_eq!(q[0]["durability"].as_u64(), Some(2));
    // The recovery tool, which rebuilds metadata.yaml from the files alone, agrees (topics in
    // the order they first appear in the files).
    let rebuilt = cnc_recorder::recover::bag_info(&bag).unwrap().to_yaml();
    let r: serde_yaml::Value = serde_yaml::from_str(&rebuilt).unwrap();
    let by_name = |v: &serde_yaml::Value| -> std::collections::BTreeMap<String, u64> {
        v["rosbag2_bagfile_information"]["topics_with_message_count"]
            .as_sequence()
            .unwrap()
            .iter()
            .map(|t| {
                (
                    t["topic_metadata"]["name"].as_str().unwrap().to_string(),
                    t["message_count"].as_u64().unwrap(),
                )
            })
            .collect()
    };
    assert_eq!(by_name(&r), by_name(&y));
    let info_r = &r["rosbag2_bagfile_information"];
    for key in ["files", "duration", "starting_time", "message_count"] {
        assert_eq!(info_r[key], info[key], "{key}");
    }
}

#[test]
fn the_chain_runs_across_files_and_a_missing_file_breaks_it() {
    let root = dir("chain");
    let bag = record(&root);
    assert!(matches!(
        verify(&bag).unwrap(),
        Verdict::Intact { files: 3, .. }
    ));
    std::fs::remove_file(bag.join("m_test_1.mcap")).unwrap();
    match verify(&bag).unwrap() {
        Verdict::Altered(why) => {
            assert!(
                why.contains("m_test_2.mcap") && why.contains("chain"),
                "{why}"
            )
        }
        v => panic!("{v:?}"),
    }
}

#[test]
fn rotation_deletes_the_oldest_bags_but_never_the_current_one() {
    let root = dir("rotate");
    for name in ["a_1", "a_2", "a_3"] {
        let d = root.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("metadata.yaml"), "x").unwrap();
        std::fs::write(d.join("f.mcap"), vec![0u8; 1000]).unwrap();
    }
    // Not a bag: left alone.
    std::fs::create_dir_all(root.join("other")).unwrap();
    let deleted = rotate(&root, 2100, &root.join("a_3")).unwrap();
    assert_eq!(deleted, vec![root.join("a_1")]);
    // The current bag alone over the cap stays.
    let deleted = rotate(&root, 10, &root.join("a_3")).unwrap();
    assert_eq!(deleted, vec![root.join("a_2")]);
    assert!(root.join("a_3").exists() && root.join("other").exists());
}
