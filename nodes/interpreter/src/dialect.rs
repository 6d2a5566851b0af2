//! Dialect tables: which G and M codes a control knows, their modal groups and meanings.
//!
//! The shared interpreter core works on [`G`] meanings; a dialect maps its numbers onto them.
//! Three tables:
//! - `huaxing-lathe`: the Huaxing WA-N7xx lathe (`000` §5.1, FANUC "G-code system A" style:
//!   G50 sets coordinates, G90/G92/G94 are cycles, U/W incremental).
//! - `gtc2e-lathe`: the GTC2E lathe (`002` §4.2.2): the same numbers often mean other things
//!   (G50/G51 turret mode, G22/G80 loops, G24/G77 cycles, G54–G57 cumulative shifts).
//! - `iso-lathe`: the skeleton's FANUC lathe "system B" subset with G90/G91 absolute/incremental
//!   (decision D1), kept for programs written for it.

use crate::error::{fanuc_number, gtc2e_number, huaxing_number, Fault};

/// What a G code does in the shared core.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum G {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    /// G05 (`absolute` false: mid point relative to start) / G05.1 (absolute).
    ThreePointArc {
        absolute: bool,
    },
    Dwell,
    ExactStopBlock,
    ExactStopMode,
    ContinuousMode,
    ReferenceReturn,
    /// G50: set the work coordinate of the current point (or with S: max spindle speed).
    SetCoordinate,
    /// G50.1: assign work coordinate, remember the difference as local coordinate.
    AssignCoordinate,
    /// G50.2: assign work coordinate and clear the local coordinate.
    AssignClearLocal,
    /// G50.3: shift the work coordinate by U/W and clear the local coordinate.
    ShiftCoordinate,
    LocalCoordinate,
    /// G54–G59 (index 0–5).
    WorkSystem(u8),
    /// G10 L2 P: write a work offset from the program (FANUC 0-M, `003` Appendix A).
    SetOffsetData,
    /// G53: this block's positions are machine coordinates (`003` §4.3.1).
    MachineCoordinates,
    FeedPerMinute,
    FeedPerRevolution,
    ConstantSurfaceSpeed,
    ConstantRpm,
    PlaneXy,
    PlaneZx,
    PlaneYz,
    /// G21 on the mill: millimetre input (the only input unit here).
    MetricInput,
    NoseCancel,
    NoseLeft,
    NoseRight,
    Absolute,
    Incremental,
    // Huaxing single and compound cycles (`000` §5.21–5.23).
    TurningCycle,
    FacingCycle,
    ThreadCycle,
    Thread,
    VariableLeadThread,
    TappingCycle,
    MultiThreadCycle,
    RoughTurning,
    RoughFacing,
    PatternRepeat,
    Finishing,
    FaceGrooving,
    RadialGrooving,
    /// G83 (axial, `radial` false) / G87 (radial) peck drilling (`000` §5.22.7).
    Drilling {
        radial: bool,
    },
    /// G07 K L: pause K s after every L mm of a G01; plain G07 cancels (`000` §5.6).
    ChipBreak,
    // Huaxing program flow (`000` §5.12, §5.13).
    /// G21 (`high` false) / G23 (`high` true): input-conditioned range repeat.
    ConditionalRepeat {
        high: bool,
    },
    JumpRange,
    CallRange,
    LoopRange,
    // GTC2E codes (`002` §4.3.2).
    GtcThread,
    GtcThreadCycle,
    GtcTapping,
    GtcTaperCycle,
    GtcCylinderCycle,
    GtcDrillCycle,
    GtcGroovingCycle,
    LoopStart,
    LoopEnd,
    /// G26 (X and Z), G27 (X), G29 (Z) return to the program start point.
    ReturnToStart {
        x: bool,
        z: bool,
    },
    ReturnToPreviousStart,
    ReturnToStored,
    StorePosition,
    ThreadRetract,
    /// G54–G57 on GTC2E: add offset group n (0–3) to the coordinates, cumulatively.
    OffsetShift(u8),
    TurretMode {
        gang: bool,
    },
    // FANUC 0-M mill codes (`003` Table 1.1).
    HoleCycle(HoleKind),
    CycleCancel,
    /// G98 (`false`: back to the initial level) / G99 (`true`: to the R level).
    CycleReturn {
        r_level: bool,
    },
    /// G43 (+1), G44 (−1), G49 (0): tool length compensation.
    LengthComp(i8),
    /// G52: a local coordinate system inside the work system (not cumulative).
    MillLocal,
    /// Defined by the manual but not implemented by this controller: alarm with the reason.
    Unsupported(&'static str),
    /// G65 user macro call (FANUC mill): run by the statement itself, never as a block.
    MacroCall,
    /// G27 reference position return check (mill).
    ReferenceCheck,
    /// G29 return from the reference point through G28's intermediate point (mill).
    FromReference,
    /// G30 return to the second reference point (mill).
    SecondReference,
    /// G60 single-direction positioning (mill).
    OneDirection,
}

/// The mill's hole-machining cycles (`003` §8.1, inventory Appendix A.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HoleKind {
    /// G73 high-speed peck drilling.
    HighSpeedPeck,
    /// G74 left-hand tapping.
    LeftTap,
    /// G76 fine boring.
    FineBore,
    /// G81 drilling.
    Drill,
    /// G82 drilling with a dwell (counter-boring).
    Counterbore,
    /// G83 peck drilling.
    Peck,
    /// G84 tapping.
    Tap,
    /// G85 boring, feed out.
    Bore,
    /// G86 boring, spindle stop, rapid out.
    BoreSpindleStop,
    /// G87 back boring.
    BackBore,
    /// G88 boring, manual retract.
    BoreManual,
    /// G89 boring with a dwell, feed out.
    BoreDwell,
}

/// A G code's modal group; group 0 is one-shot (non-modal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GCode {
    pub group: u8,
    pub meaning: G,
}

/// What the interpreter does with an M code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum M {
    /// Sent to the PLC before the block's motion (spindle on, coolant on, clamp).
    AuxBefore,
    /// Sent to the PLC after the block's motion (spindle off, coolant off).
    AuxAfter,
    /// Program stop M00 (sent to the PLC after motion; cycle start resumes).
    Stop,
    /// Optional stop M01.
    OptionalStop,
    /// M02/M30: sent to the PLC after motion, then the program ends.
    ProgramEnd,
    /// GTC2E M20: spindle and coolant off, then the program restarts from the top.
    EndAndRestart,
    SubprogramCall,
    SubprogramReturn,
    /// GTC2E M97: jump to line P.
    Jump,
    /// Huaxing M48: count a part (sent to the PLC).
    CountPart,
    /// GTC2E M52/M53/M65: order of axes in returns.
    ReturnOrder(ReturnOrder),
    /// Huaxing tool-change macro codes (`000` §4.1.5, §4.3.3).
    ToolMacro(ToolMacro),
    /// Defined by the manual but not implemented by this controller.
    Unsupported(&'static str),
}

/// The Huaxing codes a tool-change macro program uses (`000` §4.3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolMacro {
    /// M52 Kn: the current tool number into local variable #n.
    ReadTool,
    /// M53 / M53.1 K: make K the active tool-offset number.
    SetOffset,
    /// M54: wait until execution has caught up with interpretation.
    Sync,
    /// M57 K: the target tool to the PLC with the T strobe.
    ToolToPlc,
    /// M58 Kn: raise alarm number n.
    RaiseAlarm,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReturnOrder {
    #[default]
    XThenZ,
    ZThenX,
    Together,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    HuaxingLathe,
    Gtc2eLathe,
    IsoLathe,
    /// FANUC 0-M-style mill (`003`): for now the subset the motion benchmarks use (issue 7
    /// brings the full manual).
    FanucMill,
}

/// Dialect properties the core needs besides the code tables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rules {
    /// Macro statements (`#`, IF, GOTO) exist.
    pub macros: bool,
    /// Least input increment, mm (`000` 0.0001 §1.2; `002` 0.001 §2.2).
    pub increment: f64,
    /// Largest coordinate value, mm.
    pub max_coordinate: f64,
    /// Largest programmable feed, mm/min.
    pub max_feed: f64,
    /// Power-on group-01 code (decision D14).
    pub initial_motion: G,
    /// Power-on feed, mm/min (`000` §5.25: F 50).
    pub initial_feed: f64,
    /// The program must end with M02/M20/M30 (`002` §4.1 rule 9).
    pub needs_end: bool,
}

impl Dialect {
    pub const ALL: [Dialect; 4] = [
        Dialect::HuaxingLathe,
        Dialect::Gtc2eLathe,
        Dialect::IsoLathe,
        Dialect::FanucMill,
    ];

    /// Lathe dialects: X in diameter, the Z-X plane, U/W incremental words.
    pub fn is_lathe(self) -> bool {
        self != Dialect::FanucMill
    }

    pub fn from_name(name: &str) -> Option<Dialect> {
        Dialect::ALL.into_iter().find(|d| d.name() == name)
    }

    pub fn name(self) -> &'static str {
        match self {
            Dialect::HuaxingLathe => "huaxing-lathe",
            Dialect::Gtc2eLathe => "gtc2e-lathe",
            Dialect::IsoLathe => "iso-lathe",
            Dialect::FanucMill => "fanuc-mill",
        }
    }

    pub fn rules(self) -> Rules {
        match self {
            Dialect::HuaxingLathe => Rules {
                macros: true,
                increment: 0.0001,
                max_coordinate: 99999.9999,
                max_feed: 15000.0,
                initial_motion: G::Linear,
                initial_feed: 50.0,
                needs_end: false,
            },
            // The skeleton's table: G00 at power-on and no feed until F is given.
            Dialect::IsoLathe => Rules {
                macros: false,
                increment: 0.001,
                max_coordinate: 99999.999,
                max_feed: 15000.0,
                initial_motion: G::Rapid,
                initial_feed: 0.0,
                needs_end: false,
            },
            // `003` §7.2.2: least input increment 0.001 mm, ±99999.999; power-on G00. User
            // macro B (`003` contents, inventory Appendix A).
            Dialect::FanucMill => Rules {
                macros: true,
                increment: 0.001,
                max_coordinate: 99999.999,
                max_feed: 24000.0,
                initial_motion: G::Rapid,
                initial_feed: 0.0,
                needs_end: false,
            },
            Dialect::Gtc2eLathe => Rules {
                macros: false,
                increment: 0.001,
                max_coordinate: 7999.999,
                max_feed: 3000.0,
                initial_motion: G::Rapid,
                initial_feed: 0.0,
                needs_end: true,
            },
        }
    }

    /// The alarm number of a fault in this dialect's manual.
    pub fn alarm(self, f: Fault) -> u32 {
        match self {
            Dialect::Gtc2eLathe => gtc2e_number(f),
            Dialect::FanucMill => fanuc_number(f),
            _ => huaxing_number(f),
        }
    }

    /// Looks up `G<number>`; `number_x10` is ×10 so G50.1 is 501.
    pub fn g_code(self, number_x10: u32) -> Option<GCode> {
        match self {
            Dialect::HuaxingLathe => huaxing_g(number_x10),
            Dialect::Gtc2eLathe => gtc2e_g(number_x10),
            Dialect::IsoLathe => iso_g(number_x10),
            Dialect::FanucMill => mill_g(number_x10),
        }
    }

    /// Looks up `M<number>`; `number_x10` is ×10 so M14.6 is 146.
    pub fn m_code(self, number_x10: u32) -> Option<M> {
        match self {
            Dialect::Gtc2eLathe => gtc2e_m(number_x10),
            Dialect::FanucMill => mill_m(number_x10),
            _ => huaxing_m(number_x10),
        }
    }

    /// Every G code of the table, as `(number ×10, code)`, for the code table document.
    pub fn all_g(self) -> Vec<(u32, GCode)> {
        (0..1000)
            .filter_map(|n| Some((n, self.g_code(n)?)))
            .collect()
    }

    pub fn all_m(self) -> Vec<(u32, M)> {
        (0..1000)
            .filter_map(|n| Some((n, self.m_code(n)?)))
            .collect()
    }
}

fn huaxing_g(n: u32) -> Option<GCode> {
    use G::*;
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        40 => (0, Dwell),
        50 => (1, ThreePointArc { absolute: false }),
        51 => (1, ThreePointArc { absolute: true }),
        70 => (0, ChipBreak),
        71 => (
            0,
            Unsupported("G07.1 thread chip breaking needs an oscillation superimposed in motion"),
        ),
        80..=86 => (
            1,
            Unsupported("G08 rotary-axis interpolation needs a rotary axis"),
        ),
        90 => (15, ExactStopBlock),
        121 => (16, Unsupported("G12.1 polar interpolation needs a C axis")),
        131 => (16, Unsupported("G13.1 polar interpolation needs a C axis")),
        141..=146 => (
            1,
            Unsupported("G14.n live-tool tapping needs a live tool axis"),
        ),
        170 => (16, PlaneXy),
        180 => (16, PlaneZx),
        190 => (16, PlaneYz),
        210 => (0, ConditionalRepeat { high: false }),
        230 => (0, ConditionalRepeat { high: true }),
        250 => (0, JumpRange),
        260 => (0, CallRange),
        270 => (0, LoopRange),
        280 => (0, ReferenceReturn),
        310 => (1, Unsupported("G31 skip needs a skip input in motion")),
        320 => (1, Thread),
        330 => (1, TappingCycle),
        340 => (1, VariableLeadThread),
        400 => (7, NoseCancel),
        410 => (7, NoseLeft),
        420 => (7, NoseRight),
        430 | 440 | 490 => (
            8,
            Unsupported("G43/G44/G49 tool length compensation is milling"),
        ),
        500 => (0, SetCoordinate),
        501 => (0, AssignCoordinate),
        502 => (0, AssignClearLocal),
        503 => (0, ShiftCoordinate),
        520 => (0, LocalCoordinate),
        540..=590 if n.is_multiple_of(10) => (14, WorkSystem(((n - 540) / 10) as u8)),
        610 => (15, ExactStopMode),
        640 => (15, ContinuousMode),
        650 => (
            0,
            Unsupported("G65 macro call: format not documented in the manual"),
        ),
        660 => (
            0,
            Unsupported("G66 modal macro call: format not documented in the manual"),
        ),
        700 => (0, Finishing),
        710 => (0, RoughTurning),
        720 => (0, RoughFacing),
        730 => (0, PatternRepeat),
        740 => (0, FaceGrooving),
        750 => (0, RadialGrooving),
        760 => (0, MultiThreadCycle),
        770 => (
            0,
            Unsupported("G77 clears an absolute encoder's multi-turn count"),
        ),
        800 => (
            1,
            Unsupported("G80 cancels rigid tapping, which needs a position spindle"),
        ),
        830 => (1, Drilling { radial: false }),
        870 => (1, Drilling { radial: true }),
        840 | 880 => (
            1,
            Unsupported("G84/G88 rigid tapping needs a position spindle"),
        ),
        850 | 860 | 890 => (1, Unsupported("not described in the manual")),
        900 => (1, TurningCycle),
        920 => (1, ThreadCycle),
        921 => (1, Unsupported("G92.1 rigid thread cycle is only listed")),
        940 => (1, FacingCycle),
        960 => (2, ConstantSurfaceSpeed),
        970 => (2, ConstantRpm),
        980 => (5, FeedPerMinute),
        990 => (5, FeedPerRevolution),
        991 => (5, Unsupported("G99.1 needs the encoder Z pulse in motion")),
        _ => return None,
    };
    Some(GCode { group, meaning })
}

fn gtc2e_g(n: u32) -> Option<GCode> {
    use G::*;
    // Group 1 holds motion, cycles, returns, G25/G31 and the offsets (`002` §4.2.2 as
    // reconstructed in the inventory §3.1): no two of them in one block.
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        330 => (1, GtcThread),
        960 => (1, ConstantSurfaceSpeed),
        970 => (1, ConstantRpm),
        770 => (1, GtcCylinderCycle),
        240 => (1, GtcTaperCycle),
        740 => (1, GtcTapping),
        760 => (1, GtcThreadCycle),
        830 => (1, GtcDrillCycle),
        750 => (1, GtcGroovingCycle),
        220 => (1, LoopStart),
        800 => (1, LoopEnd),
        260 => (1, ReturnToStart { x: true, z: true }),
        270 => (1, ReturnToStart { x: true, z: false }),
        290 => (1, ReturnToStart { x: false, z: true }),
        600 => (1, ReturnToPreviousStart),
        610 => (1, ReturnToStored),
        250 => (1, StorePosition),
        310 => (1, ThreadRetract),
        540..=570 if n.is_multiple_of(10) => (1, OffsetShift(((n - 540) / 10) as u8)),
        40 => (2, Dwell),
        500 => (3, TurretMode { gang: false }),
        510 => (3, TurretMode { gang: true }),
        400 => (15, NoseCancel),
        410 => (15, NoseLeft),
        420 => (15, NoseRight),
        _ => return None,
    };
    Some(GCode { group, meaning })
}

fn iso_g(n: u32) -> Option<GCode> {
    use G::*;
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        40 => (0, Dwell),
        900 => (3, Absolute),
        910 => (3, Incremental),
        _ => return None,
    };
    Some(GCode { group, meaning })
}

/// The FANUC 0-M codes of `003` Table 1.1 (issue 7).
fn mill_g(n: u32) -> Option<GCode> {
    use G::*;
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        40 => (0, Dwell),
        90 => (0, ExactStopBlock),
        170 => (2, PlaneXy),
        180 => (2, PlaneZx),
        190 => (2, PlaneYz),
        200 => (
            6,
            Unsupported("G20 inch input: this controller works in millimetres"),
        ),
        210 => (6, MetricInput),
        100 => (0, SetOffsetData),
        270 => (0, ReferenceCheck),
        280 => (0, ReferenceReturn),
        290 => (0, FromReference),
        300 => (0, SecondReference),
        600 => (0, OneDirection),
        530 => (0, MachineCoordinates),
        540..=590 if n.is_multiple_of(10) => (14, WorkSystem(((n - 540) / 10) as u8)),
        610 => (15, ExactStopMode),
        640 => (15, ContinuousMode),
        630 => (
            15,
            Unsupported("G63 tapping mode: feed override suppression is not built"),
        ),
        900 => (3, Absolute),
        910 => (3, Incremental),
        920 => (0, SetCoordinate),
        940 => (5, FeedPerMinute),
        950 => (5, FeedPerRevolution),
        400 => (7, NoseCancel),
        410 => (7, NoseLeft),
        420 => (7, NoseRight),
        650 => (0, MacroCall),
        660 | 670 => (
            12,
            Unsupported("G66/G67 modal macro calls are not built: call with G65 per block"),
        ),
        430 => (8, LengthComp(1)),
        440 => (8, LengthComp(-1)),
        490 => (8, LengthComp(0)),
        520 => (0, MillLocal),
        730 => (9, HoleCycle(HoleKind::HighSpeedPeck)),
        740 => (9, HoleCycle(HoleKind::LeftTap)),
        760 => (9, HoleCycle(HoleKind::FineBore)),
        800 => (9, CycleCancel),
        810 => (9, HoleCycle(HoleKind::Drill)),
        820 => (9, HoleCycle(HoleKind::Counterbore)),
        830 => (9, HoleCycle(HoleKind::Peck)),
        840 => (9, HoleCycle(HoleKind::Tap)),
        850 => (9, HoleCycle(HoleKind::Bore)),
        860 => (9, HoleCycle(HoleKind::BoreSpindleStop)),
        870 => (9, HoleCycle(HoleKind::BackBore)),
        880 => (9, HoleCycle(HoleKind::BoreManual)),
        890 => (9, HoleCycle(HoleKind::BoreDwell)),
        980 => (10, CycleReturn { r_level: false }),
        990 => (10, CycleReturn { r_level: true }),
        _ => return None,
    };
    Some(GCode { group, meaning })
}

/// `003` §6: M00/M01/M02/M30, spindle M03–M05, coolant M08/M09, M98/M99.
fn mill_m(n: u32) -> Option<M> {
    use M::*;
    Some(match n {
        0 => Stop,
        10 => OptionalStop,
        20 | 300 => ProgramEnd,
        30 | 40 | 60 | 80 | 190 => AuxBefore,
        50 | 90 | 180 => AuxAfter,
        290 => Unsupported("M29 rigid tapping needs a position-controlled spindle"),
        980 => SubprogramCall,
        990 => SubprogramReturn,
        _ => return None,
    })
}

fn huaxing_m(n: u32) -> Option<M> {
    use M::*;
    Some(match n {
        0 => Stop,
        10 => OptionalStop,
        20 | 300 => ProgramEnd,
        // Codes that start something go out before the block's motion (decision D6).
        30 | 40 | 60 | 80 | 100 | 120 | 140 | 170 | 180 | 190 | 200 | 220 | 320 | 410 | 420
        | 430 | 440 | 630 | 640 => AuxBefore,
        // Codes that stop something go out after it.
        50 | 90 | 110 | 130 | 150 | 210 | 230 | 330 | 650 => AuxAfter,
        480 => CountPart,
        980 => SubprogramCall,
        990 => SubprogramReturn,
        141..=146 => Unsupported("M14.n assigns the spindle angle to a rotary axis"),
        290 => Unsupported("M29 rigid tapping needs a position spindle"),
        500 => Unsupported("M50 bar feed drives outputs directly, not through the PLC"),
        510 => Unsupported("M51 sets the start block in MDI"),
        520 => ToolMacro(self::ToolMacro::ReadTool),
        530 | 531 => ToolMacro(self::ToolMacro::SetOffset),
        540 => ToolMacro(self::ToolMacro::Sync),
        570 => ToolMacro(self::ToolMacro::ToolToPlc),
        580 => ToolMacro(self::ToolMacro::RaiseAlarm),
        // M56 moves the turret toward the change position: the PLC's.
        560 => AuxBefore,
        550 => Unsupported("M55 writes PLC F026–F029, which the PLC program does not read"),
        590 | 600 | 660 | 850 | 860 | 870 | 880 | 890 => {
            Unsupported("NC-internal M code of multi-channel or live-tool machines")
        }
        90000..=99990 if n.is_multiple_of(10) => Unsupported(
            "M9000–M9999 call programs through an address table the manual does not give",
        ),
        _ => return None,
    })
}

fn gtc2e_m(n: u32) -> Option<M> {
    use M::*;
    Some(match n {
        0 => Stop,
        20 | 300 => ProgramEnd,
        200 => EndAndRestart,
        30 | 40 | 80 | 100 | 230 | 250 | 550 => AuxBefore,
        50 | 90 | 110 | 220 | 240 | 540 => AuxAfter,
        120 | 130 => AuxBefore,
        520 => ReturnOrder(self::ReturnOrder::XThenZ),
        530 => ReturnOrder(self::ReturnOrder::ZThenX),
        650 => ReturnOrder(self::ReturnOrder::Together),
        970 => Jump,
        980 => SubprogramCall,
        990 => SubprogramReturn,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The launch config accepts exactly the dialects the interpreter knows.
    #[test]
    fn the_configs_dialect_list_is_the_interpreters() {
        let names: Vec<&str> = Dialect::ALL.iter().map(|d| d.name()).collect();
        assert_eq!(names, cnc_runtime::config::DIALECTS);
    }
}
