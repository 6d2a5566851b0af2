//! The action `action/RunProgram.action` as ROS 2 carries it: three services and two topics
//! under `/<ns>/run_program/_action/`, with the `action_msgs` and `unique_identifier_msgs`
//! types they use.

use crate::msg::{Alarm, Time};
use crate::ros_message;

/// `unique_identifier_msgs/UUID`: a goal's id, 16 bytes.
pub type Uuid = [u8; 16];

impl crate::RosType for Uuid {
    fn ros_type() -> String {
        "uint8[16]".into()
    }
}

ros_message! {
    /// `action_msgs/GoalInfo`.
    pub struct GoalInfo("action_msgs/msg/GoalInfo") {
        consts {}
        goal_id: Uuid,
        stamp: Time,
    }
}

ros_message! {
    /// `action_msgs/GoalStatus`.
    pub struct GoalStatus("action_msgs/msg/GoalStatus") {
        consts {
            STATUS_UNKNOWN: i8 = 0,
            STATUS_ACCEPTED: i8 = 1,
            STATUS_EXECUTING: i8 = 2,
            STATUS_CANCELING: i8 = 3,
            STATUS_SUCCEEDED: i8 = 4,
            STATUS_CANCELED: i8 = 5,
            STATUS_ABORTED: i8 = 6,
        }
        goal_info: GoalInfo,
        status: i8,
    }
}

ros_message! {
    /// `action_msgs/GoalStatusArray`: published on `…/_action/status`.
    pub struct GoalStatusArray("action_msgs/msg/GoalStatusArray") {
        consts {}
        status_list: Vec<GoalStatus>,
    }
}

ros_message! {
    pub struct CancelGoalRequest("action_msgs/srv/CancelGoal_Request") {
        consts {}
        goal_info: GoalInfo,
    }
}

ros_message! {
    pub struct CancelGoalResponse("action_msgs/srv/CancelGoal_Response") {
        consts {
            ERROR_NONE: i8 = 0,
            ERROR_REJECTED: i8 = 1,
            ERROR_UNKNOWN_GOAL_ID: i8 = 2,
            ERROR_GOAL_TERMINATED: i8 = 3,
        }
        return_code: i8,
        goals_canceling: Vec<GoalInfo>,
    }
}

ros_message! {
    pub struct RunProgramGoal("cnc_msgs/action/RunProgram_Goal") {
        consts {}
        program: String,
        cycles: u32,
        start_line: u32,
        start_block: String,
    }
}

ros_message! {
    pub struct RunProgramResult("cnc_msgs/action/RunProgram_Result") {
        consts {}
        parts_made: u32,
        cycle_times: Vec<f64>,
        alarms: Vec<Alarm>,
        message: String,
    }
}

ros_message! {
    pub struct RunProgramFeedback("cnc_msgs/action/RunProgram_Feedback") {
        consts {}
        line: u32,
        block: u64,
        percent: f32,
        cycle: u32,
        part_count: u32,
    }
}

ros_message! {
    pub struct RunProgramSendGoalRequest("cnc_msgs/action/RunProgram_SendGoal_Request") {
        consts {}
        goal_id: Uuid,
        goal: RunProgramGoal,
    }
}

ros_message! {
    pub struct RunProgramSendGoalResponse("cnc_msgs/action/RunProgram_SendGoal_Response") {
        consts {}
        accepted: bool,
        stamp: Time,
    }
}

ros_message! {
    pub struct RunProgramGetResultRequest("cnc_msgs/action/RunProgram_GetResult_Request") {
        consts {}
        goal_id: Uuid,
    }
}

ros_message! {
    pub struct RunProgramGetResultResponse("cnc_msgs/action/RunProgram_GetResult_Response") {
        consts {}
        status: i8,
        result: RunProgramResult,
    }
}

ros_message! {
    /// Published on `…/_action/feedback`.
    pub struct RunProgramFeedbackMessage("cnc_msgs/action/RunProgram_FeedbackMessage") {
        consts {}
        goal_id: Uuid,
        feedback: RunProgramFeedback,
    }
}

// `…/_action/send_goal`, `…/_action/get_result`, `…/_action/cancel_goal`.
crate::service!(
    RunProgramSendGoal,
    type "cnc_msgs/action/RunProgram_SendGoal",
    "RunProgram_SendGoal",
    RunProgramSendGoalRequest,
    RunProgramSendGoalResponse
);
crate::service!(
    RunProgramGetResult,
    type "cnc_msgs/action/RunProgram_GetResult",
    "RunProgram_GetResult",
    RunProgramGetResultRequest,
    RunProgramGetResultResponse
);
crate::service!(
    CancelGoal,
    type "action_msgs/srv/CancelGoal",
    "CancelGoal",
    CancelGoalRequest,
    CancelGoalResponse
);
