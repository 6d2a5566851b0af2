//! Service types of `srv/`. ROS 2 gives an empty request or response one `uint8` member named
//! `structure_needs_at_least_one_member`; the types here do the same so the CDR matches.

use crate::msg::{ToolOffset, WorkOffset};
use crate::ros_message;

/// A service: its ROS name and its request and response types.
pub trait RosService {
    type Request: crate::RosMessage + crate::Transport + Clone + std::fmt::Debug + 'static;
    type Response: crate::RosMessage + crate::Transport + Clone + std::fmt::Debug + 'static;
    /// `cnc_msgs/srv/Name`.
    const TYPE_NAME: &'static str;
    /// Name of the `.srv` file without extension.
    const NAME: &'static str;
}

ros_message! {
    pub struct LoadProgramRequest("cnc_msgs/srv/LoadProgram_Request") {
        consts {}
        name: String,
        text: String,
    }
}
ros_message! {
    pub struct LoadProgramResponse("cnc_msgs/srv/LoadProgram_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct StartProgramRequest("cnc_msgs/srv/StartProgram_Request") {
        consts {}
        name: String,
    }
}
ros_message! {
    pub struct StartProgramResponse("cnc_msgs/srv/StartProgram_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct StopRequest("cnc_msgs/srv/Stop_Request") {
        consts { FEED_HOLD: u8 = 1, CYCLE_STOP: u8 = 2 }
        mode: u8,
    }
}
ros_message! {
    pub struct StopResponse("cnc_msgs/srv/Stop_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct ResetRequest("cnc_msgs/srv/Reset_Request") {
        consts {}
        structure_needs_at_least_one_member: u8,
    }
}
ros_message! {
    pub struct ResetResponse("cnc_msgs/srv/Reset_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}

ros_message! {
    pub struct RobotRequestRequest("cnc_msgs/srv/RobotRequest_Request") {
        consts {
            DOOR_OPEN: u8 = 1,
            DOOR_CLOSE: u8 = 2,
            CHUCK_UNCLAMP: u8 = 3,
            CHUCK_CLAMP: u8 = 4,
            CLEAR: u8 = 5,
            NOT_CLEAR: u8 = 6,
            CYCLE_START: u8 = 7,
        }
        request: u8,
    }
}
ros_message! {
    pub struct RobotRequestResponse("cnc_msgs/srv/RobotRequest_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}

ros_message! {
    pub struct ListProgramsRequest("cnc_msgs/srv/ListPrograms_Request") {
        consts {}
        structure_needs_at_least_one_member: u8,
    }
}
ros_message! {
    pub struct ListProgramsResponse("cnc_msgs/srv/ListPrograms_Response") {
        consts {}
        names: Vec<String>,
        sizes: Vec<u64>,
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct DeleteProgramRequest("cnc_msgs/srv/DeleteProgram_Request") {
        consts {}
        name: String,
    }
}
ros_message! {
    pub struct DeleteProgramResponse("cnc_msgs/srv/DeleteProgram_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}

ros_message! {
    pub struct SetOverridesRequest("cnc_msgs/srv/SetOverrides_Request") {
        consts {}
        feed_percent: u8,
        spindle_percent: u8,
        rapid_percent: u8,
    }
}
ros_message! {
    pub struct SetOverridesResponse("cnc_msgs/srv/SetOverrides_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}

ros_message! {
    pub struct GetOffsetsRequest("cnc_msgs/srv/GetOffsets_Request") {
        consts {}
        structure_needs_at_least_one_member: u8,
    }
}
ros_message! {
    pub struct GetOffsetsResponse("cnc_msgs/srv/GetOffsets_Response") {
        consts {}
        accepted: bool,
        message: String,
        tools: Vec<ToolOffset>,
        work: Vec<WorkOffset>,
    }
}
ros_message! {
    pub struct SetToolOffsetRequest("cnc_msgs/srv/SetToolOffset_Request") {
        consts {}
        offset: ToolOffset,
    }
}
ros_message! {
    pub struct SetToolOffsetResponse("cnc_msgs/srv/SetToolOffset_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct SetWorkOffsetRequest("cnc_msgs/srv/SetWorkOffset_Request") {
        consts {}
        offset: WorkOffset,
    }
}
ros_message! {
    pub struct SetWorkOffsetResponse("cnc_msgs/srv/SetWorkOffset_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct SetModeRequest("cnc_msgs/srv/SetMode_Request") {
        consts {}
        mode: u8,
    }
}
ros_message! {
    pub struct SetModeResponse("cnc_msgs/srv/SetMode_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct JogRequest("cnc_msgs/srv/Jog_Request") {
        consts {}
        axis: String,
        direction: i8,
        feed: f64,
        increment: f64,
    }
}
ros_message! {
    pub struct JogResponse("cnc_msgs/srv/Jog_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct MdiRequest("cnc_msgs/srv/Mdi_Request") {
        consts {}
        text: String,
    }
}
ros_message! {
    pub struct MdiResponse("cnc_msgs/srv/Mdi_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct GetParametersRequest("cnc_msgs/srv/GetParameters_Request") {
        consts {}
        prefix: String,
    }
}
ros_message! {
    pub struct GetParametersResponse("cnc_msgs/srv/GetParameters_Response") {
        consts {}
        names: Vec<String>,
        values: Vec<String>,
        pending: Vec<String>,
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct SetParameterRequest("cnc_msgs/srv/SetParameter_Request") {
        consts {}
        name: String,
        value: String,
    }
}
ros_message! {
    pub struct SetParameterResponse("cnc_msgs/srv/SetParameter_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}
ros_message! {
    pub struct AcknowledgeAlarmRequest("cnc_msgs/srv/AcknowledgeAlarm_Request") {
        consts {}
        source: String,
        number: u32,
    }
}
ros_message! {
    pub struct AcknowledgeAlarmResponse("cnc_msgs/srv/AcknowledgeAlarm_Response") {
        consts {}
        accepted: bool,
        message: String,
    }
}

/// Declares a service's marker type: `service!(Stop, "Stop", StopRequest, StopResponse)` for
/// `cnc_msgs/srv/Stop`; with `type "pkg/…/Name"` first for a service of another kind (an
/// action's).
#[macro_export]
macro_rules! service {
    ($marker:ident, $name:literal, $req:ident, $resp:ident) => {
        $crate::service!($marker, type concat!("cnc_msgs/srv/", $name), $name, $req, $resp);
    };
    ($marker:ident, type $type_name:expr, $name:literal, $req:ident, $resp:ident) => {
        /// Marker type naming the service.
        pub struct $marker;
        impl $crate::srv::RosService for $marker {
            type Request = $req;
            type Response = $resp;
            const TYPE_NAME: &'static str = $type_name;
            const NAME: &'static str = $name;
        }
    };
}
service!(
    LoadProgram,
    "LoadProgram",
    LoadProgramRequest,
    LoadProgramResponse
);
service!(
    StartProgram,
    "StartProgram",
    StartProgramRequest,
    StartProgramResponse
);
service!(Stop, "Stop", StopRequest, StopResponse);
service!(Reset, "Reset", ResetRequest, ResetResponse);
service!(
    RobotRequest,
    "RobotRequest",
    RobotRequestRequest,
    RobotRequestResponse
);

service!(
    ListPrograms,
    "ListPrograms",
    ListProgramsRequest,
    ListProgramsResponse
);
service!(
    DeleteProgram,
    "DeleteProgram",
    DeleteProgramRequest,
    DeleteProgramResponse
);
service!(
    SetOverrides,
    "SetOverrides",
    SetOverridesRequest,
    SetOverridesResponse
);
service!(
    GetOffsets,
    "GetOffsets",
    GetOffsetsRequest,
    GetOffsetsResponse
);
service!(
    SetToolOffset,
    "SetToolOffset",
    SetToolOffsetRequest,
    SetToolOffsetResponse
);
service!(
    SetWorkOffset,
    "SetWorkOffset",
    SetWorkOffsetRequest,
    SetWorkOffsetResponse
);
service!(SetMode, "SetMode", SetModeRequest, SetModeResponse);
service!(Mdi, "Mdi", MdiRequest, MdiResponse);
service!(Jog, "Jog", JogRequest, JogResponse);
service!(
    GetParameters,
    "GetParameters",
    GetParametersRequest,
    GetParametersResponse
);
service!(
    SetParameter,
    "SetParameter",
    SetParameterRequest,
    SetParameterResponse
);
service!(
    AcknowledgeAlarm,
    "AcknowledgeAlarm",
    AcknowledgeAlarmRequest,
    AcknowledgeAlarmResponse
);

/// Answers of the services that say yes or no with a reason: `refused(why)` is the no (any
/// data the answer carries left empty).
macro_rules! refusable {
    ($($resp:ident),*) => {$(
        impl $resp {
            #[allow(clippy::needless_update)] // most answers are only `accepted` and `message`
            pub fn refused(message: String) -> Self {
                $resp {
                    accepted: false,
                    message,
                    ..Default::default()
                }
            }
        }
    )*};
}
refusable!(
    JogResponse,
    LoadProgramResponse,
    StartProgramResponse,
    StopResponse,
    ResetResponse,
    RobotRequestResponse,
    DeleteProgramResponse,
    SetOverridesResponse,
    SetToolOffsetResponse,
    SetWorkOffsetResponse,
    SetModeResponse,
    MdiResponse,
    SetParameterResponse,
    AcknowledgeAlarmResponse,
    GetOffsetsResponse,
    ListProgramsResponse,
    GetParametersResponse
);
