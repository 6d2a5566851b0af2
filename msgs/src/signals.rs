//! Signal images exchanged over iceoryx2: F (NC → PLC) and G (PLC → NC) between motion and plc,
//! Y (PLC → machine) and X (machine → PLC) between plc and io.
//!
//! For now the images are typed fields; the ladder engine will map them onto the byte addresses
//! of the manual's F/G/X/Y tables.

use iceoryx2::prelude::ZeroCopySend;

/// NC → PLC: the M/S/T strobes and the NC's state.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cnc_msgs::FImage")]
pub struct FImage {
    /// Increments with every new strobe, so a repeated `M08` is a new request.
    pub strobe_seq: u64,
    /// MF/SF/TF strobes (1 = set) and their codes.
    pub mf: u32,
    pub m_code: i32,
    pub sf: u32,
    pub s_value: f64,
    pub tf: u32,
    pub t_code: i32,
    /// 1 while a program runs (cycle start lamp, OP signal).
    pub op: u32,
    /// 1 while motion holds an alarm.
    pub alarm: u32,
}

/// PLC → NC: the answer to the strobes and the machine's requests to the NC.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cnc_msgs::GImage")]
pub struct GImage {
    /// `strobe_seq` of the strobe that is finished (FIN).
    pub fin_seq: u64,
    /// 1 = emergency stop: the NC stops at once and turns servos off.
    pub emergency_stop: u32,
    /// 1 = feed hold requested by the machine.
    pub feed_hold: u32,
    /// Spindle speed measured by the machine, rpm (for feed per revolution and display).
    pub spindle_actual_rpm: f64,
}

/// PLC → machine outputs.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cnc_msgs::YImage")]
pub struct YImage {
    /// 0 stop, 1 CW, 2 CCW.
    pub spindle_direction: u32,
    /// Speed command to the spindle drive, rpm.
    pub spindle_rpm: f64,
    pub coolant: u32,
    pub chuck_clamp: u32,
}

/// Machine inputs → PLC.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cnc_msgs::XImage")]
pub struct XImage {
    pub seq: u64,
    /// 1 = emergency-stop button pressed (the input is normally closed; 1 means open circuit).
    pub emergency_stop: u32,
    pub spindle_actual_rpm: f64,
    /// 1 = spindle drive reports speed reached.
    pub spindle_at_speed: u32,
    /// 1 = coolant pressure switch made.
    pub coolant_pressure: u32,
    pub chuck_clamped: u32,
}
