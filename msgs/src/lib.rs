//! `cnc_msgs`: the ROS 2 interfaces of the controller and their Rust types.
//!
//! The `.msg`/`.srv` files in `msg/` and `srv/` are the source of truth for other ROS 2 and DDS
//! participants; the Rust types here serialise to the same CDR. Each type is declared with
//! [`ros_message!`], which also records its fields with their ROS types (taken from the Rust
//! field types through [`RosType`]), so `tests/interface_files.rs` can compare both field by field.
//!
//! `servo` and `signals` hold the fixed-size `#[repr(C)]` payloads exchanged over iceoryx2 shared
//! memory; they never go over DDS.

pub mod action;
pub mod canon;
pub mod jog;
pub mod msg;
pub mod servo;
pub mod signals;
pub mod srv;
pub mod task;

/// The ROS 2 package name of these interfaces.
pub const PACKAGE: &str = "cnc_msgs";

/// Every `msg/*.msg` file of the package: (type name, text). Recordings carry these texts as
/// their `ros2msg` schemas, so a reader needs nothing but the recording.
pub const MSG_FILES: &[(&str, &str)] = &[
    ("ActiveAlarms", include_str!("../msg/ActiveAlarms.msg")),
    ("Alarm", include_str!("../msg/Alarm.msg")),
    ("AlarmEvent", include_str!("../msg/AlarmEvent.msg")),
    ("Axis", include_str!("../msg/Axis.msg")),
    ("AxisState", include_str!("../msg/AxisState.msg")),
    ("CellMachine", include_str!("../msg/CellMachine.msg")),
    ("CellState", include_str!("../msg/CellState.msg")),
    ("CommandEvent", include_str!("../msg/CommandEvent.msg")),
    ("CommandResult", include_str!("../msg/CommandResult.msg")),
    ("MachineState", include_str!("../msg/MachineState.msg")),
    ("MotionBlock", include_str!("../msg/MotionBlock.msg")),
    ("MotionCommand", include_str!("../msg/MotionCommand.msg")),
    ("MotionStatus", include_str!("../msg/MotionStatus.msg")),
    ("Overrides", include_str!("../msg/Overrides.msg")),
    ("PartCount", include_str!("../msg/PartCount.msg")),
    ("PlcProgram", include_str!("../msg/PlcProgram.msg")),
    ("PlcSignals", include_str!("../msg/PlcSignals.msg")),
    ("PlcStatus", include_str!("../msg/PlcStatus.msg")),
    ("ProgramEvent", include_str!("../msg/ProgramEvent.msg")),
    ("RobotHandshake", include_str!("../msg/RobotHandshake.msg")),
    ("ServoStats", include_str!("../msg/ServoStats.msg")),
    ("SimInput", include_str!("../msg/SimInput.msg")),
    ("SpindleState", include_str!("../msg/SpindleState.msg")),
    ("TaskCommand", include_str!("../msg/TaskCommand.msg")),
    ("ToolOffset", include_str!("../msg/ToolOffset.msg")),
    ("WorkOffset", include_str!("../msg/WorkOffset.msg")),
];

/// A Rust type with a ROS 2 interface type name, e.g. `float64`, `string`, `cnc_msgs/Alarm`.
pub trait RosType {
    fn ros_type() -> String;
}

/// A ROS 2 message type: its full name and its fields in declaration order.
pub trait RosMessage: RosType {
    /// `package/msg/Name` or `package/srv/Name_Request` style name.
    const TYPE_NAME: &'static str;
    /// `(field name, ROS type)` in declaration order; ROS types as written in `.msg` files.
    fn fields() -> Vec<(&'static str, String)>;
    /// `(constant name, ROS type, value as text)`.
    fn constants() -> Vec<(&'static str, String, String)>;
}

macro_rules! primitive {
    ($($t:ty => $n:literal),* $(,)?) => {
        $(impl RosType for $t { fn ros_type() -> String { $n.to_string() } })*
    };
}
primitive!(bool => "bool", u8 => "uint8", i8 => "int8", u16 => "uint16", i16 => "int16",
    u32 => "uint32", i32 => "int32", u64 => "uint64", i64 => "int64", f32 => "float32",
    f64 => "float64", String => "string");

impl<T: RosType> RosType for Vec<T> {
    fn ros_type() -> String {
        format!("{}[]", T::ros_type())
    }
}

/// Declares a message struct together with its ROS description.
///
/// ```text
/// ros_message! {
///     /// Doc.
///     pub struct PartCount("cnc_msgs/msg/PartCount") {
///         consts { }
///         stamp: Time,
///         count: u32,
///     }
/// }
/// ```
/// What a message needs to travel on DDS: ros2-client's message trait with the `ros2`
/// feature, nothing without it (the pure cores' build).
#[cfg(feature = "ros2")]
pub trait Transport: ros2_client::Message {}
#[cfg(feature = "ros2")]
impl<T: ros2_client::Message> Transport for T {}
#[cfg(not(feature = "ros2"))]
pub trait Transport {}
#[cfg(not(feature = "ros2"))]
impl<T> Transport for T {}

#[macro_export]
macro_rules! ros_message {
    (
        $(#[$meta:meta])*
        pub struct $name:ident ($full:literal) {
            consts { $($cname:ident : $cty:ty = $cval:expr),* $(,)? }
            $($(#[$fmeta:meta])* $field:ident : $fty:ty),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $fty,)*
        }
        impl $name {
            $(pub const $cname: $cty = $cval;)*
        }
        #[cfg(feature = "ros2")]
        impl ros2_client::Message for $name {}
        impl $crate::RosType for $name {
            fn ros_type() -> String {
                // `cnc_msgs/msg/Alarm` is written `cnc_msgs/Alarm` inside other .msg files.
                let mut parts = $full.split('/');
                let pkg = parts.next().unwrap_or_default();
                let name = parts.last().unwrap_or_default();
                format!("{}/{}", pkg, name)
            }
        }
        impl $crate::RosMessage for $name {
            const TYPE_NAME: &'static str = $full;
            fn fields() -> Vec<(&'static str, String)> {
                vec![$((stringify!($field), <$fty as $crate::RosType>::ros_type()),)*]
            }
            fn constants() -> Vec<(&'static str, String, String)> {
                vec![$((stringify!($cname), <$cty as $crate::RosType>::ros_type(), format!("{}", $name::$cname)),)*]
            }
        }
    };
}
