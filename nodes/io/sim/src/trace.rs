//! The drive trace (issue 48): one CSV line per drive tick, the oscilloscope a commissioning
//! engineer reads: what the drives played, where their slides are, the queue's state.

use crate::drive_queue::Played;

/// The drive trace's header: tick (the drives' clock), queue depth, underrun, emergency
/// stop, hold (1 feed hold, 2 standing at a block's end for single block), where on the queued path the drives are, their rate along it and the rate
/// they head for (feed hold, overrides), per axis
/// its setpoint, actual position and following error, then the spindle encoder's speed (rpm)
/// and angle (degrees): the oscilloscope a commissioning engineer reads.
pub fn trace_header(axes: &[String]) -> String {
    let mut h = String::from("tick,queue_depth,underrun,emergency_stop,hold,index,scale,target");
    for a in axes {
        h.push_str(&format!(",{a}_setpoint,{a}_actual,{a}_following_error"));
    }
    h.push_str(",spindle_rpm,spindle_angle");
    h
}

/// One tick of the drive trace. Positions are written exactly (Rust's shortest round-trip
/// form), so two traces compare to the last bit. `flags`: emergency stop, hold (0, 1 feed hold,
/// 2 single block's stop).
pub fn trace_line(
    tick: u64,
    played: &Played,
    actual: &[f64],
    depth: u32,
    flags: (bool, u8),
    spindle: (f64, f64),
) -> String {
    use std::fmt::Write;
    let sp = &played.setpoint;
    let mut line = format!(
        "{tick},{depth},{},{},{},{:?},{:?},{:?}",
        u8::from(played.underrun),
        u8::from(flags.0),
        flags.1,
        played.index,
        played.scale,
        played.target
    );
    for (i, a) in actual.iter().enumerate() {
        let c = sp.position[i];
        let _ = write!(line, ",{c:?},{a:?},{:?}", c - a);
    }
    let _ = write!(line, ",{:?},{:?}", spindle.0, spindle.1);
    line
}
