//! Every `.msg`/`.srv` file and its Rust type have the same fields, in the same order, with the
//! same ROS types, and the same constants.

use cnc_msgs::{msg::*, srv::*, RosMessage};
use std::path::Path;

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64", "string", "wstring",
];

#[derive(Debug, Default, PartialEq)]
struct Section {
    fields: Vec<(String, String)>,
    constants: Vec<(String, String, String)>,
}

/// Qualifies a type as it would appear after `rosidl` resolution: `Alarm` → `cnc_msgs/Alarm`.
fn qualify(ty: &str) -> String {
    let (base, array) = match ty.find('[') {
        Some(i) => (&ty[..i], &ty[i..]),
        None => (ty, ""),
    };
    if PRIMITIVES.contains(&base) || base.contains('/') {
        ty.to_string()
    } else {
        format!("cnc_msgs/{base}{array}")
    }
}

fn parse_section(text: &str) -> Section {
    let mut section = Section::default();
    for raw in text.lines() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut parts = line.splitn(2, char::is_whitespace);
        let ty = parts.next().expect("type").trim();
        let rest = parts
            .next()
            .unwrap_or_else(|| panic!("no name in line {raw:?}"))
            .trim();
        if let Some((name, value)) = rest.split_once('=') {
            section
                .constants
                .push((name.trim().into(), ty.into(), value.trim().into()));
        } else {
            let name = rest.split_whitespace().next().expect("name");
            assert!(
                name.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_'),
                "field name {name} is not a valid ROS 2 field name"
            );
            section.fields.push((name.into(), qualify(ty)));
        }
    }
    if section.fields.is_empty() {
        section
            .fields
            .push(("structure_needs_at_least_one_member".into(), "uint8".into()));
    }
    section
}

fn rust_section<T: RosMessage>() -> Section {
    Section {
        fields: T::fields()
            .into_iter()
            .map(|(n, t)| (n.to_string(), t))
            .collect(),
        constants: T::constants()
            .into_iter()
            .map(|(n, t, v)| (n.to_string(), t, v))
            .collect(),
    }
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn check_msg<T: RosMessage>(file: &str) {
    let text = std::fs::read_to_string(root().join("msg").join(file)).expect("msg file");
    assert_eq!(
        parse_section(&text),
        rust_section::<T>(),
        "{file} vs {}",
        T::TYPE_NAME
    );
}

fn check_srv<S: RosService>() {
    let file = format!("{}.srv", S::NAME);
    let text = std::fs::read_to_string(root().join("srv").join(&file)).expect("srv file");
    let (req, resp) = text.split_once("\n---").expect("--- separator");
    assert_eq!(
        parse_section(req),
        rust_section::<S::Request>(),
        "{file} request"
    );
    assert_eq!(
        parse_section(resp),
        rust_section::<S::Response>(),
        "{file} response"
    );
}

#[test]
fn every_msg_file_matches_its_rust_type() {
    check_msg::<Alarm>("Alarm.msg");
    check_msg::<ActiveAlarms>("ActiveAlarms.msg");
    check_msg::<AlarmEvent>("AlarmEvent.msg");
    check_msg::<Axis>("Axis.msg");
    check_msg::<AxisState>("AxisState.msg");
    check_msg::<MachineState>("MachineState.msg");
    check_msg::<PartCount>("PartCount.msg");
    check_msg::<SpindleState>("SpindleState.msg");
    check_msg::<ServoStats>("ServoStats.msg");
    check_msg::<MotionBlock>("MotionBlock.msg");
    check_msg::<MotionStatus>("MotionStatus.msg");
    check_msg::<TaskCommand>("TaskCommand.msg");
    check_msg::<MotionCommand>("MotionCommand.msg");
    check_msg::<CommandResult>("CommandResult.msg");
    check_msg::<SimInput>("SimInput.msg");
    check_msg::<PlcStatus>("PlcStatus.msg");
    check_msg::<PlcSignals>("PlcSignals.msg");
    check_msg::<PlcProgram>("PlcProgram.msg");
    check_msg::<CommandEvent>("CommandEvent.msg");
    check_msg::<ProgramEvent>("ProgramEvent.msg");
    check_msg::<RobotHandshake>("RobotHandshake.msg");
    check_msg::<CellMachine>("CellMachine.msg");
    check_msg::<CellState>("CellState.msg");
    check_msg::<Overrides>("Overrides.msg");
    check_msg::<ToolOffset>("ToolOffset.msg");
    check_msg::<WorkOffset>("WorkOffset.msg");
}

#[test]
fn every_srv_file_matches_its_rust_types() {
    check_srv::<LoadProgram>();
    check_srv::<StartProgram>();
    check_srv::<Stop>();
    check_srv::<Reset>();
    check_srv::<RobotRequest>();
    check_srv::<ListPrograms>();
    check_srv::<DeleteProgram>();
    check_srv::<SetOverrides>();
    check_srv::<GetOffsets>();
    check_srv::<SetToolOffset>();
    check_srv::<SetWorkOffset>();
    check_srv::<SetMode>();
    check_srv::<Mdi>();
    check_srv::<Jog>();
    check_srv::<GetParameters>();
    check_srv::<SetParameter>();
    check_srv::<AcknowledgeAlarm>();
}

/// `action/RunProgram.action`: goal, result and feedback sections against their Rust types.
#[test]
fn the_action_file_matches_its_rust_types() {
    use cnc_msgs::action::*;
    let text = std::fs::read_to_string(root().join("action/RunProgram.action")).expect("action");
    let sections: Vec<&str> = text.split("\n---").collect();
    assert_eq!(sections.len(), 3, "goal, result, feedback");
    assert_eq!(parse_section(sections[0]), rust_section::<RunProgramGoal>());
    assert_eq!(
        parse_section(sections[1]),
        rust_section::<RunProgramResult>()
    );
    assert_eq!(
        parse_section(sections[2]),
        rust_section::<RunProgramFeedback>()
    );
    let cmake = std::fs::read_to_string(root().join("CMakeLists.txt")).expect("CMakeLists.txt");
    assert!(cmake.contains("\"action/RunProgram.action\""));
    let dir: Vec<_> = std::fs::read_dir(root().join("action"))
        .expect("dir")
        .collect();
    assert_eq!(dir.len(), 1, "every .action file is checked here");
}

#[test]
fn every_interface_file_is_checked_and_listed_in_cmake() {
    let cmake = std::fs::read_to_string(root().join("CMakeLists.txt")).expect("CMakeLists.txt");
    let checked = [
        "Alarm",
        "ActiveAlarms",
        "AlarmEvent",
        "Axis",
        "AxisState",
        "MachineState",
        "PartCount",
        "SpindleState",
        "ServoStats",
        "MotionBlock",
        "MotionStatus",
        "TaskCommand",
        "MotionCommand",
        "CommandResult",
        "SimInput",
        "PlcStatus",
        "PlcSignals",
        "PlcProgram",
        "CommandEvent",
        "ProgramEvent",
        "RobotHandshake",
        "CellMachine",
        "CellState",
        "RobotRequest",
        "ListPrograms",
        "DeleteProgram",
        "Overrides",
        "SetOverrides",
        "ToolOffset",
        "WorkOffset",
        "GetOffsets",
        "SetToolOffset",
        "SetWorkOffset",
        "SetMode",
        "Mdi",
        "Jog",
        "GetParameters",
        "SetParameter",
        "AcknowledgeAlarm",
        "LoadProgram",
        "StartProgram",
        "Stop",
        "Reset",
    ];
    for dir in ["msg", "srv"] {
        for entry in std::fs::read_dir(root().join(dir)).expect("dir") {
            let path = entry.expect("entry").path();
            let stem = path
                .file_stem()
                .and_then(|s| s.to_str())
                .expect("name")
                .to_string();
            assert!(
                checked.contains(&stem.as_str()),
                "{} has no field check",
                path.display()
            );
            let rel = format!(
                "\"{dir}/{}\"",
                path.file_name().and_then(|s| s.to_str()).expect("name")
            );
            assert!(
                cmake.contains(&rel),
                "{rel} missing from rosidl_generate_interfaces"
            );
        }
    }
}

#[test]
fn cdr_of_spindle_state_has_the_ros_layout() {
    // Same bytes a ROS 2 C++ node writes for this message: Time (8), f64 (8), f64 (8), u8,
    // pad to 4, f32, f32, bool, bool, pad to 8, f64.
    let msg = SpindleState {
        stamp: Time { sec: 1, nanosec: 2 },
        commanded_rpm: 600.0,
        actual_rpm: 599.5,
        direction: SpindleState::DIRECTION_CW,
        load: 0.25,
        override_percent: 100.0,
        at_speed: true,
        positioned: false,
        position_deg: 14.3,
    };
    let bytes = cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&msg).expect("cdr");
    let mut expected = vec![];
    expected.extend(1i32.to_le_bytes());
    expected.extend(2u32.to_le_bytes());
    expected.extend(600.0f64.to_le_bytes());
    expected.extend(599.5f64.to_le_bytes());
    expected.extend([1u8, 0, 0, 0]);
    expected.extend(0.25f32.to_le_bytes());
    expected.extend(100.0f32.to_le_bytes());
    expected.push(1);
    // bool, pad to 8, f64.
    expected.extend([0u8, 0, 0]);
    expected.extend(14.3f64.to_le_bytes());
    assert_eq!(bytes, expected);
}

/// Recordings carry `MSG_FILES` as their schemas: it must hold every `.msg` file as it is.
#[test]
fn msg_files_embeds_every_msg_file() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("msg");
    let mut on_disk: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "msg"))
        .map(|p| {
            (
                p.file_stem().unwrap().to_string_lossy().to_string(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    on_disk.sort();
    let embedded: Vec<(String, String)> = cnc_msgs::MSG_FILES
        .iter()
        .map(|(n, t)| (n.to_string(), t.to_string()))
        .collect();
    assert_eq!(embedded, on_disk);
}
