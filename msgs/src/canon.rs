//! Canonical commands: the dialect-free language between interpreter and motion, in machine
//! coordinates (mm; lathe X as diameter, as the position display shows it), and their wire form
//! [`MotionBlock`]. The interpreter produces them, motion consumes them; the conversion both ways
//! lives here once.

use crate::msg::MotionBlock;

/// `Command::Acceleration`'s axis number for the spindle (`ACC[S]`).
pub const SPINDLE_AXIS: u8 = u8::MAX;

#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Each axis at its own rapid rate (dog-leg path).
    Rapid {
        end: Vec<f64>,
    },
    /// Straight line at `feed` mm/min along the path.
    Linear {
        end: Vec<f64>,
        feed: f64,
    },
    /// Circular arc around `center`; `end == start` is a full circle. Axes outside the plane
    /// move linearly with the arc (a helix).
    Arc {
        end: Vec<f64>,
        center: Vec<f64>,
        clockwise: bool,
        feed: f64,
        /// The plane as (first, second) axis indices, counter-clockwise turning from the first
        /// towards the second (G17: X, Y; G18: Z, X; G19: Y, Z). `None`: the machine's
        /// configured arc plane.
        plane: Option<[u8; 2]>,
    },
    /// Thread cutting: a straight move whose long axis advances `lead` mm per spindle
    /// revolution, starting `start_angle` degrees after the spindle's index pulse. Feed
    /// override does not apply.
    Thread {
        end: Vec<f64>,
        lead: f64,
        start_angle: f64,
    },
    /// Rigid tapping: the spindle, in position control, turns through `length of the long
    /// axis / |lead|` revolutions at `rpm` (the way M3 turns for a positive `lead`) and the
    /// axes follow its angle to `end`; the block ends with the spindle standing there.
    Tap {
        end: Vec<f64>,
        lead: f64,
        rpm: f64,
    },
    /// The turn-mill's C axis (the main spindle in position control, D138): the spindle turns
    /// at `rpm` to `degrees`, an angle 0–360 reached the way `way` says or, with
    /// [`Turn::Incremental`], a signed travel; the axes follow its angle to `end` (the Huaxing
    /// G08). The block ends with the spindle standing there.
    Rotary {
        end: Vec<f64>,
        degrees: f64,
        way: Turn,
        rpm: f64,
    },
    /// A measuring move (touch probe, measuring input 1): a straight line at `feed` during
    /// which the probe's rising (`rising`) or falling edge latches every axis's position. With
    /// `stop` (delete distance to go) the axes brake at the edge and the rest of the line is
    /// dropped; without it the line runs to its end. Motion reports the result when the block
    /// is done (`MotionStatus::probe_*`); the program waits for it before it reads on.
    Probe {
        end: Vec<f64>,
        feed: f64,
        rising: bool,
        stop: bool,
    },
    /// Travel to a fixed stop on `axis` (its index in the machine's order): on, its drive's
    /// torque is limited to `torque` percent for the move that follows, which ends where the
    /// axis meets the stop (the rest of it dropped); the axis then presses against it and
    /// must stay within `window` (mm or degrees). Off, the limit is lifted for the move that
    /// follows, which leaves the stop. Motion reports the move's end as it does a measuring
    /// block's; the program waits for it.
    FixedStop {
        axis: u8,
        on: bool,
        torque: f64,
        window: f64,
    },
    /// The compressor on or off for the lines that follow: a run of short lines whose end
    /// points lie on one circle is cut as its arc, within the compressor's tolerance. A run
    /// starts with it off.
    Compressor {
        on: bool,
    },
    /// The look-ahead's buffer: `fill` (STOPFIFO) holds the blocks after it until the queue
    /// is full, the buffer's end (`fill` false, STARTFIFO) or the program end is queued, so
    /// the section runs without waiting for the interpreter.
    Fifo {
        fill: bool,
    },
    /// A preprocessing stop that reads the machine: motion reports it done, with its run-time
    /// timers, once every block before it has finished; the program waits for it (a block
    /// that reads a timer, `$AC_CUTTING_TIME`).
    Sync,
    /// The turn-mill's C axis in contour control (`on`, polar interpolation G12.1, D141): the
    /// main spindle, standing in position control at C 0, follows the path's C setpoints (the
    /// block ends' last coordinate, degrees from where it stood) until `on` is false (G13.1).
    Contour {
        on: bool,
    },
    /// The turn-mill's live tool in speed mode at `rpm` (its positive way; the Huaxing M65
    /// S…, D143), or, at 0, out of it: the tool brakes at its time constant and stands in
    /// position control where it stopped, its program angle 0 there (M66). The program
    /// waits until the tool turns at the speed (or stands).
    LiveTool {
        rpm: f64,
    },
    Dwell {
        seconds: f64,
    },
    /// Feed words of the following moves are mm/min (`false`, G98) or mm/rev (`true`, G99).
    FeedMode {
        per_rev: bool,
    },
    /// Exact stop (`true`: G09/G61, each block ends at rest) or blending (`false`, G64).
    PathMode {
        exact_stop: bool,
    },
    /// The acceleration profile of the moves that follow: jerk-limited (`true`, S-curve) or
    /// acceleration-limited (`false`, trapezoidal). A run starts with the machine's own.
    Profile {
        jerk_limited: bool,
    },
    /// Feedforward of the drives on or off for the moves that follow: the axes' velocity
    /// times their drive lag is added to the setpoint, so the slides follow the path with
    /// (nearly) no following error. A run starts with it off.
    Feedforward {
        on: bool,
    },
    /// The acceleration of one axis (its index in the machine's order, or [`SPINDLE_AXIS`] for
    /// the spindle) for the moves that follow, in percent of its rated acceleration (1–200).
    /// A run starts at 100 %.
    Acceleration {
        axis: u8,
        percent: f64,
    },
    /// An M, S or T function for the PLC, which answers with FIN.
    Aux(Aux),
    /// M02/M30: the program is finished; motion completes everything before it.
    ProgramEnd,
}

impl Command {
    /// Where a move ends (display units); `None` for commands that do not move.
    pub fn end(&self) -> Option<&[f64]> {
        match self {
            Command::Rapid { end }
            | Command::Linear { end, .. }
            | Command::Arc { end, .. }
            | Command::Thread { end, .. }
            | Command::Tap { end, .. }
            | Command::Rotary { end, .. }
            | Command::Probe { end, .. } => Some(end),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Aux {
    M(i32),
    S(f64),
    T(i32),
    /// Spindle positioning: the spindle leaves speed control and the drive holds it at an
    /// angle, degrees (the M19 handshake with its stop position; decisions D100).
    Orient {
        degrees: f64,
        way: Turn,
    },
    /// A value for the PLC under an address (H0–H9999), its meaning the machine builder's
    /// (the second auxiliary function's handshake; decisions D107).
    H {
        address: u16,
        value: f64,
    },
}

/// Highest H address.
pub const MAX_H_ADDRESS: u16 = 9999;

/// How a positioned spindle reaches its angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// The shortest way from standstill; turning, on in the direction it turns.
    Shortest = 0,
    /// Turning the way M3 turns (positive angles).
    Plus = 1,
    /// Turning the way M4 turns.
    Minus = 2,
    /// `degrees` is a signed travel from where the spindle stands, any number of turns.
    Incremental = 3,
}

impl Turn {
    pub fn from_code(code: i32) -> Option<Turn> {
        Some(match code {
            0 => Turn::Shortest,
            1 => Turn::Plus,
            2 => Turn::Minus,
            3 => Turn::Incremental,
            _ => return None,
        })
    }

    /// The largest travel one positioning may ask for, degrees (the manual's IC range).
    pub const MAX_INCREMENT: f64 = 99_999.999;

    /// Whether `degrees` is a target this way can take: 0 ≤ angle < 360 for the absolute
    /// ways, a finite travel within [`Turn::MAX_INCREMENT`] for the incremental.
    pub fn accepts(self, degrees: f64) -> bool {
        match self {
            Turn::Incremental => degrees.is_finite() && degrees.abs() <= Turn::MAX_INCREMENT,
            _ => (0.0..360.0).contains(&degrees),
        }
    }
}

/// The wire form of `command`, block `seq` of run `run_id`, from `program` line `line`.
pub fn to_motion_block(
    run_id: u64,
    seq: u64,
    program: &str,
    line: u32,
    command: &Command,
) -> MotionBlock {
    let mut m = MotionBlock {
        run_id,
        seq,
        program: program.into(),
        line,
        ..MotionBlock::default()
    };
    match command {
        Command::Rapid { end } => {
            m.kind = MotionBlock::KIND_RAPID;
            m.end.clone_from(end);
        }
        Command::Linear { end, feed } => {
            m.kind = MotionBlock::KIND_LINEAR;
            m.end.clone_from(end);
            m.feed = *feed;
        }
        Command::Arc {
            end,
            center,
            clockwise,
            feed,
            plane,
        } => {
            m.plane = plane.map(|p| p.to_vec()).unwrap_or_default();
            m.kind = if *clockwise {
                MotionBlock::KIND_ARC_CW
            } else {
                MotionBlock::KIND_ARC_CCW
            };
            m.end.clone_from(end);
            m.center.clone_from(center);
            m.feed = *feed;
        }
        Command::Thread {
            end,
            lead,
            start_angle,
        } => {
            m.kind = MotionBlock::KIND_THREAD;
            m.end.clone_from(end);
            m.lead = *lead;
            m.start_angle = *start_angle;
        }
        Command::Tap { end, lead, rpm } => {
            m.kind = MotionBlock::KIND_TAP;
            m.end.clone_from(end);
            m.lead = *lead;
            m.aux_value = *rpm;
        }
        Command::Rotary {
            end,
            degrees,
            way,
            rpm,
        } => {
            m.kind = MotionBlock::KIND_ROTARY;
            m.end.clone_from(end);
            m.aux_code = *way as i32;
            m.aux_value = *degrees;
            m.feed = *rpm;
        }
        Command::Probe {
            end,
            feed,
            rising,
            stop,
        } => {
            m.kind = MotionBlock::KIND_PROBE;
            m.end.clone_from(end);
            m.feed = *feed;
            m.aux_code = if *rising { 1 } else { -1 };
            m.flag = *stop;
        }
        Command::FixedStop {
            axis,
            on,
            torque,
            window,
        } => {
            m.kind = MotionBlock::KIND_FIXED_STOP;
            m.aux_code = i32::from(*axis);
            m.flag = *on;
            m.aux_value = *torque;
            m.lead = *window;
        }
        Command::Compressor { on } => {
            m.kind = MotionBlock::KIND_COMPRESSOR;
            m.flag = *on;
        }
        Command::Fifo { fill } => {
            m.kind = MotionBlock::KIND_FIFO;
            m.flag = *fill;
        }
        Command::Sync => m.kind = MotionBlock::KIND_SYNC,
        Command::Contour { on } => {
            m.kind = MotionBlock::KIND_CONTOUR;
            m.flag = *on;
        }
        Command::LiveTool { rpm } => {
            m.kind = MotionBlock::KIND_LIVE_TOOL;
            m.aux_value = *rpm;
        }
        Command::Dwell { seconds } => {
            m.kind = MotionBlock::KIND_DWELL;
            m.dwell_seconds = *seconds;
        }
        Command::FeedMode { per_rev } => {
            m.kind = MotionBlock::KIND_FEED_MODE;
            m.flag = *per_rev;
        }
        Command::PathMode { exact_stop } => {
            m.kind = MotionBlock::KIND_PATH_MODE;
            m.flag = *exact_stop;
        }
        Command::Profile { jerk_limited } => {
            m.kind = MotionBlock::KIND_PROFILE;
            m.flag = *jerk_limited;
        }
        Command::Feedforward { on } => {
            m.kind = MotionBlock::KIND_FEEDFORWARD;
            m.flag = *on;
        }
        Command::Acceleration { axis, percent } => {
            m.kind = MotionBlock::KIND_ACCELERATION;
            m.aux_code = i32::from(*axis);
            m.aux_value = *percent;
        }
        Command::Aux(aux) => {
            m.kind = MotionBlock::KIND_AUX;
            (m.aux_kind, m.aux_code, m.aux_value) = aux_wire(*aux);
        }
        Command::ProgramEnd => m.kind = MotionBlock::KIND_PROGRAM_END,
    }
    m
}

/// An auxiliary function's wire fields: its kind, code and value.
fn aux_wire(aux: Aux) -> (u8, i32, f64) {
    match aux {
        Aux::M(code) => (MotionBlock::AUX_M, code, 0.0),
        Aux::S(value) => (MotionBlock::AUX_S, 0, value),
        Aux::T(code) => (MotionBlock::AUX_T, code, 0.0),
        Aux::Orient { degrees, way } => (MotionBlock::AUX_ORIENT, way as i32, degrees),
        Aux::H { address, value } => (MotionBlock::AUX_H, i32::from(address), value),
    }
}

/// The command a block carries. Anyone on the DDS domain can publish blocks, so every value is
/// checked: a block that could not run to its end (non-finite numbers, no feed) is refused with
/// the reason.
pub fn from_motion_block(m: &MotionBlock) -> Result<Command, String> {
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    let feed = || {
        if m.feed.is_finite() && m.feed > 0.0 {
            Ok(m.feed)
        } else {
            Err(format!("feed {} is not a positive number", m.feed))
        }
    };
    if !finite(&m.end) || !finite(&m.center) {
        return Err("end point or centre is not a finite number".into());
    }
    Ok(match m.kind {
        MotionBlock::KIND_RAPID => Command::Rapid { end: m.end.clone() },
        MotionBlock::KIND_LINEAR => Command::Linear {
            end: m.end.clone(),
            feed: feed()?,
        },
        MotionBlock::KIND_ARC_CW | MotionBlock::KIND_ARC_CCW => Command::Arc {
            end: m.end.clone(),
            center: m.center.clone(),
            clockwise: m.kind == MotionBlock::KIND_ARC_CW,
            feed: feed()?,
            plane: match m.plane[..] {
                [] => None,
                [a, b] if a != b => Some([a, b]),
                _ => {
                    return Err(format!(
                        "arc plane {:?} does not name two different axes",
                        m.plane
                    ))
                }
            },
        },
        MotionBlock::KIND_THREAD | MotionBlock::KIND_TAP | MotionBlock::KIND_ROTARY => {
            spindle_locked(m)?
        }
        MotionBlock::KIND_PROBE => Command::Probe {
            end: m.end.clone(),
            feed: feed()?,
            rising: match m.aux_code {
                1 => true,
                -1 => false,
                other => {
                    return Err(format!(
                        "probe edge {other} is neither rising (1) nor falling (-1)"
                    ))
                }
            },
            stop: m.flag,
        },
        MotionBlock::KIND_FIXED_STOP => {
            let limits_ok = (m.aux_value > 0.0 && m.aux_value <= 100.0) && m.lead > 0.0;
            match u8::try_from(m.aux_code) {
                Ok(axis) if !m.flag || (limits_ok && m.lead.is_finite()) => Command::FixedStop {
                    axis,
                    on: m.flag,
                    torque: m.aux_value,
                    window: m.lead,
                },
                _ => {
                    return Err(format!(
                        "fixed stop on axis {} with torque {} % and window {} is not valid \
                         (0 < torque ≤ 100, window > 0)",
                        m.aux_code, m.aux_value, m.lead
                    ))
                }
            }
        }
        MotionBlock::KIND_COMPRESSOR => Command::Compressor { on: m.flag },
        MotionBlock::KIND_FIFO => Command::Fifo { fill: m.flag },
        MotionBlock::KIND_SYNC => Command::Sync,
        MotionBlock::KIND_CONTOUR => Command::Contour { on: m.flag },
        MotionBlock::KIND_LIVE_TOOL if m.aux_value.is_finite() && m.aux_value >= 0.0 => {
            Command::LiveTool { rpm: m.aux_value }
        }
        MotionBlock::KIND_FEED_MODE => Command::FeedMode { per_rev: m.flag },
        MotionBlock::KIND_PATH_MODE => Command::PathMode { exact_stop: m.flag },
        MotionBlock::KIND_PROFILE => Command::Profile {
            jerk_limited: m.flag,
        },
        MotionBlock::KIND_FEEDFORWARD => Command::Feedforward { on: m.flag },
        MotionBlock::KIND_ACCELERATION => match u8::try_from(m.aux_code) {
            Ok(axis) if (1.0..=200.0).contains(&m.aux_value) => Command::Acceleration {
                axis,
                percent: m.aux_value,
            },
            _ => {
                return Err(format!(
                    "acceleration {} % of axis {} is not 1…200 % of an axis",
                    m.aux_value, m.aux_code
                ))
            }
        },
        MotionBlock::KIND_DWELL if m.dwell_seconds.is_finite() && m.dwell_seconds >= 0.0 => {
            Command::Dwell {
                seconds: m.dwell_seconds,
            }
        }
        MotionBlock::KIND_DWELL => {
            return Err(format!("dwell {} s is not a time", m.dwell_seconds))
        }
        MotionBlock::KIND_LIVE_TOOL => {
            return Err(format!(
                "live tool speed {} r/min is not a speed",
                m.aux_value
            ))
        }
        MotionBlock::KIND_AUX => Command::Aux(aux(m)?),
        MotionBlock::KIND_PROGRAM_END => Command::ProgramEnd,
        other => return Err(format!("unknown block kind {other}")),
    })
}

/// A block locked to the spindle: a thread, a rigid tap or a turn of the C axis, checked.
fn spindle_locked(m: &MotionBlock) -> Result<Command, String> {
    Ok(match m.kind {
        MotionBlock::KIND_THREAD => {
            if !(m.lead.is_finite() && m.lead > 0.0 && m.start_angle.is_finite()) {
                return Err(format!(
                    "thread lead {} or start angle {} is not valid",
                    m.lead, m.start_angle
                ));
            }
            Command::Thread {
                end: m.end.clone(),
                lead: m.lead,
                start_angle: m.start_angle,
            }
        }
        MotionBlock::KIND_TAP => {
            let lead_ok = m.lead.is_finite() && m.lead != 0.0;
            if !(lead_ok && m.aux_value.is_finite() && m.aux_value > 0.0) {
                return Err(format!(
                    "tapping lead {} or spindle speed {} is not valid",
                    m.lead, m.aux_value
                ));
            }
            Command::Tap {
                end: m.end.clone(),
                lead: m.lead,
                rpm: m.aux_value,
            }
        }
        MotionBlock::KIND_ROTARY => {
            let way = Turn::from_code(m.aux_code)
                .filter(|w| w.accepts(m.aux_value))
                .ok_or_else(|| {
                    format!(
                        "rotary move to {} the way {} is not valid",
                        m.aux_value, m.aux_code
                    )
                })?;
            Command::Rotary {
                end: m.end.clone(),
                degrees: m.aux_value,
                way,
                rpm: match m.feed.is_finite() && m.feed > 0.0 {
                    true => m.feed,
                    false => return Err(format!("C-axis speed {} is not positive", m.feed)),
                },
            }
        }
        _ => return Err(format!("block kind {} is not spindle-locked", m.kind)),
    })
}

/// An auxiliary block's function: M, S, T, a spindle position or an H function, checked.
fn aux(m: &MotionBlock) -> Result<Aux, String> {
    Ok(match m.aux_kind {
        MotionBlock::AUX_M => Aux::M(m.aux_code),
        MotionBlock::AUX_S if m.aux_value.is_finite() && m.aux_value >= 0.0 => Aux::S(m.aux_value),
        MotionBlock::AUX_T => Aux::T(m.aux_code),
        MotionBlock::AUX_ORIENT => match Turn::from_code(m.aux_code) {
            Some(way) if way.accepts(m.aux_value) => Aux::Orient {
                degrees: m.aux_value,
                way,
            },
            _ => {
                return Err(format!(
                    "spindle position {} ({}) is no angle the spindle can take",
                    m.aux_value, m.aux_code
                ))
            }
        },
        MotionBlock::AUX_H => match u16::try_from(m.aux_code) {
            Ok(address) if address <= MAX_H_ADDRESS && m.aux_value.is_finite() => Aux::H {
                address,
                value: m.aux_value,
            },
            _ => {
                return Err(format!(
                    "H{}={} is no H function (H0–H9999, a finite value)",
                    m.aux_code, m.aux_value
                ))
            }
        },
        other => {
            return Err(format!(
                "aux kind {other} with value {} is not an M, S, T, H or spindle position",
                m.aux_value
            ))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_survives_the_wire_form() {
        let commands = [
            Command::Rapid {
                end: vec![1.0, 2.0],
            },
            Command::Linear {
                end: vec![3.0, -4.0],
                feed: 200.0,
            },
            Command::Arc {
                end: vec![5.0, 6.0],
                center: vec![5.0, 0.0],
                clockwise: true,
                feed: 90.0,
                plane: None,
            },
            Command::Arc {
                end: vec![5.0, 6.0],
                center: vec![5.0, 0.0],
                clockwise: false,
                feed: 90.0,
                plane: Some([2, 0]),
            },
            Command::Probe {
                end: vec![5.0, -6.0],
                feed: 300.0,
                rising: false,
                stop: true,
            },
            Command::FixedStop {
                axis: 2,
                on: true,
                torque: 12.3,
                window: 2.0,
            },
            Command::Compressor { on: true },
            Command::Fifo { fill: true },
            Command::Sync,
            Command::Contour { on: true },
            Command::Contour { on: false },
            Command::LiveTool { rpm: 1500.0 },
            Command::LiveTool { rpm: 0.0 },
            Command::Dwell { seconds: 1.5 },
            Command::Tap {
                end: vec![10.0, 10.0, -25.0],
                lead: -0.8,
                rpm: 600.0,
            },
            Command::Rotary {
                end: vec![190.0, 120.0],
                degrees: 330.0,
                way: Turn::Minus,
                rpm: 1000.0,
            },
            Command::Rotary {
                end: vec![190.0, 120.0],
                degrees: -750.0,
                way: Turn::Incremental,
                rpm: 800.0,
            },
            Command::FeedMode { per_rev: true },
            Command::PathMode { exact_stop: true },
            Command::Profile { jerk_limited: true },
            Command::Profile {
                jerk_limited: false,
            },
            Command::Feedforward { on: true },
            Command::Acceleration {
                axis: 2,
                percent: 80.0,
            },
            Command::Feedforward { on: false },
            Command::Aux(Aux::M(3)),
            Command::Aux(Aux::S(1200.0)),
            Command::Aux(Aux::T(101)),
            Command::Aux(Aux::Orient {
                degrees: 14.3,
                way: Turn::Shortest,
            }),
            Command::Aux(Aux::Orient {
                degrees: -720.5,
                way: Turn::Incremental,
            }),
            Command::Aux(Aux::H {
                address: 99,
                value: -8978.234,
            }),
            Command::ProgramEnd,
        ];
        for c in commands {
            let m = to_motion_block(7, 3, "p.nc", 12, &c);
            assert_eq!(
                (m.run_id, m.seq, m.line, m.program.as_str()),
                (7, 3, 12, "p.nc")
            );
            assert_eq!(from_motion_block(&m), Ok(c));
        }
    }

    #[test]
    fn blocks_that_could_never_finish_are_refused() {
        let mut m = to_motion_block(
            1,
            1,
            "",
            1,
            &Command::Linear {
                end: vec![1.0],
                feed: 100.0,
            },
        );
        for bad_feed in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            m.feed = bad_feed;
            assert!(from_motion_block(&m).is_err(), "feed {bad_feed}");
        }
        m.feed = 100.0;
        m.end = vec![f64::NAN];
        assert!(from_motion_block(&m).is_err());
        // A rotary move's angle outside 0–360 for an absolute way, its way unknown, no speed.
        let rotary = Command::Rotary {
            end: vec![1.0],
            degrees: 100.0,
            way: Turn::Plus,
            rpm: 1000.0,
        };
        for (degrees, way, rpm) in [(360.0, 1, 1000.0), (10.0, 7, 1000.0), (10.0, 1, 0.0)] {
            let mut r = to_motion_block(1, 1, "", 1, &rotary);
            (r.aux_value, r.aux_code, r.feed) = (degrees, way, rpm);
            assert!(from_motion_block(&r).is_err(), "{degrees} {way} {rpm}");
        }
        let mut d = to_motion_block(1, 1, "", 1, &Command::Dwell { seconds: 1.0 });
        d.dwell_seconds = f64::NAN;
        assert!(from_motion_block(&d).is_err());
        let mut k = d.clone();
        k.kind = 99;
        assert!(from_motion_block(&k).is_err());
        let mut arc = m.clone();
        arc.end = vec![1.0];
        arc.kind = MotionBlock::KIND_ARC_CW;
        for bad_plane in [vec![0], vec![1, 1], vec![0, 1, 2]] {
            arc.plane.clone_from(&bad_plane);
            assert!(from_motion_block(&arc).is_err(), "plane {bad_plane:?}");
        }
        let mut o = to_motion_block(
            1,
            1,
            "",
            1,
            &Command::Aux(Aux::Orient {
                degrees: 0.0,
                way: Turn::Plus,
            }),
        );
        let mut t = to_motion_block(
            1,
            1,
            "",
            1,
            &Command::Tap {
                end: vec![0.0],
                lead: 1.0,
                rpm: 100.0,
            },
        );
        for (lead, rpm) in [(0.0, 100.0), (f64::NAN, 100.0), (1.0, 0.0), (1.0, -5.0)] {
            (t.lead, t.aux_value) = (lead, rpm);
            assert!(from_motion_block(&t).is_err(), "lead {lead} rpm {rpm}");
        }
        for (way, degrees) in [(1, 360.0), (0, -0.5), (2, f64::NAN), (3, 1e6), (4, 10.0)] {
            (o.aux_code, o.aux_value) = (way, degrees);
            assert!(from_motion_block(&o).is_err(), "way {way} {degrees}");
        }
        // A measuring block names its edge and has a feed.
        let mut p = to_motion_block(
            1,
            1,
            "",
            1,
            &Command::Probe {
                end: vec![0.0],
                feed: 100.0,
                rising: true,
                stop: false,
            },
        );
        for (edge, feed) in [(0, 100.0), (2, 100.0), (1, 0.0), (-1, f64::NAN)] {
            (p.aux_code, p.feed) = (edge, feed);
            assert!(from_motion_block(&p).is_err(), "edge {edge} feed {feed}");
        }
    }
}
