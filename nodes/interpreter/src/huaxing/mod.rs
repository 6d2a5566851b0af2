//! The Huaxing WA-N7xx lathe (`000`): FANUC "G-code system A" style (G50 sets coordinates,
//! G90/G92/G94 are cycles, U/W incremental), single and multiple repetitive cycles, G07 chip
//! breaking, block-range repeats G21–G27, chamfers in G01, macro variables, and the tool-change
//! macro.

mod alarms;
mod c_axis;
mod compound;
mod drilling;
mod flow;
mod grooving;
mod live_tool;
mod polar;
mod rigid_tap;
mod skip;
mod threads;
mod tool;

use cnc_interpreter_core::corner::Chamfer;
use cnc_interpreter_core::{Fault, ProgramError, Setup};

use crate::fanuc::block::Block;
use crate::fanuc::codes::{GCode, Rules, G, M};
use crate::fanuc::expr::{EvalError, Value};
use crate::fanuc::lathe::{LATHE_COMP, LATHE_PLANE};
use crate::fanuc::{Family, Fanuc, ThreadWords};

pub use alarms::alarm;
pub use tool::ToolMacro;

/// The Huaxing's own G meanings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HuaxingG {
    /// G05 (`absolute` false: mid point relative to start) / G05.1 (absolute).
    ThreePointArc {
        absolute: bool,
    },
    /// G50.1: assign work coordinate, remember the difference as local coordinate.
    AssignCoordinate,
    /// G50.2: assign work coordinate and clear the local coordinate.
    AssignClearLocal,
    /// G50.3: shift the work coordinate by U/W and clear the local coordinate.
    ShiftCoordinate,
    /// G52: add to the local shift.
    LocalCoordinate,
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
    /// G83 (axial, `radial` false) / G87 (radial) peck drilling (§5.22.7).
    Drilling {
        radial: bool,
    },
    /// G07 K L: pause K s after every L mm of a G01; plain G07 cancels (§5.6).
    ChipBreak,
    /// G21 (`high` false) / G23 (`high` true): input-conditioned range repeat (§5.12).
    ConditionalRepeat {
        high: bool,
    },
    JumpRange,
    CallRange,
    LoopRange,
    /// G99.1: feed per revolution whose next cut starts on the encoder's Z pulse (§5.25, D132).
    FeedPerRevolutionOnIndex,
    /// G08 (`orient` none) / G08.n (M14.n first): the C axis turned, X and Z along (§5.7,
    /// D138).
    Rotary {
        orient: Option<u8>,
    },
    /// G31: a feed move that ends on the skip input (§5.17, D139).
    Skip,
    /// G12.1 / G13.1: polar interpolation on / off (§5.8, D141).
    PolarOn,
    PolarOff,
    /// G14.n: a tap with the live tool, axis n (§5.9, D142).
    LiveTap {
        axis: u8,
    },
    /// G84 (face, `side` false) / G88 (side): rigid tapping after M29 (§5.23.4, D142).
    RigidTap {
        side: bool,
    },
    /// G80: rigid tapping off.
    CancelRigid,
}

/// Retained words of a single cycle (G90/G92/G94, §5.21.3).
#[derive(Debug, Clone, Copy, Default)]
pub struct CycleWords {
    pub x: Option<f64>,
    pub z: Option<f64>,
    pub r: f64,
}

/// The Huaxing's own modal state.
pub struct Huaxing {
    pub thread: ThreadWords,
    pub cycle: CycleWords,
    pub compound: compound::CompoundWords,
    /// G74/G75 retract per peck (GS#43 default 1 mm).
    pub groove_retract: f64,
    /// G83/G87 modal words (§5.22.7).
    pub drill: drilling::DrillWords,
    /// G92 number of starts (§5.23.5, modal).
    pub cycle_starts: u32,
    /// The call depth of a running tool-change macro: T words inside it do not call it again.
    pub tool_macro_depth: Option<usize>,
    /// G99.1 given: the next cut starts on the spindle encoder's Z pulse (D132).
    pub start_on_index: bool,
    /// The C axis's speed of the last G08, r/min (its F, modal apart from the feed).
    pub rotary_rpm: Option<f64>,
    /// A skip's programmed end, to be written over the coordinates once the machine has
    /// told where the skip came (B19.6 = 0, D139).
    pub skip_end: Option<Vec<f64>>,
    /// G14's modal words (D142).
    pub live_tap: live_tool::LiveTapWords,
    /// M29's rigid tapping and G84/G88's modal words (D142).
    pub rigid: rigid_tap::RigidTap,
}

impl Family for Huaxing {
    type G = HuaxingG;
    type M = ToolMacro;

    fn g_code(x10: u32) -> Option<GCode<HuaxingG>> {
        g_code(x10)
    }
    fn m_code(x10: u32) -> Option<M<ToolMacro>> {
        m_code(x10)
    }
    fn alarm(f: Fault) -> u32 {
        alarm(f)
    }
    fn rules() -> Rules<HuaxingG> {
        Rules {
            macros: true,
            // Least input increment 0.0001 mm (§1.2).
            increment: 0.0001,
            max_coordinate: 99999.9999,
            initial_motion: G::Linear,
        }
    }
    fn core_rules() -> cnc_interpreter_core::Rules {
        cnc_interpreter_core::Rules {
            alarms: alarm,
            max_feed: 15000.0,
            // Power-on feed F 50 (§5.25).
            initial_feed: 50.0,
            needs_end: None,
            locals: 41,
            work_offsets: true,
            plane: LATHE_PLANE,
            comp: LATHE_COMP,
            // Four levels of subprograms (§4.1.3).
            max_call_depth: 4,
        }
    }
    fn new(_setup: &Setup) -> Self {
        Huaxing {
            thread: ThreadWords::default(),
            cycle: CycleWords::default(),
            compound: compound::CompoundWords::default(),
            groove_retract: 1.0,
            drill: drilling::DrillWords::default(),
            cycle_starts: 1,
            tool_macro_depth: None,
            start_on_index: false,
            rotary_rpm: None,
            skip_end: None,
            live_tap: live_tool::LiveTapWords::default(),
            rigid: rigid_tap::RigidTap::default(),
        }
    }

    const REFUSE_GROUP00_WITH_01: bool = true;
    const INCREMENTAL_ADDRESSES: bool = true;

    fn extra_address(c: char) -> bool {
        // C and H: the C axis of a turn-mill, checked in `words`.
        matches!(c, 'U' | 'W' | 'C' | 'H')
    }

    fn read_var(f: &Fanuc<Self>, n: i64) -> Result<Value, EvalError> {
        f.lathe_read(n)
    }
    fn write_var(f: &mut Fanuc<Self>, n: i64, v: Value) -> Result<(), ProgramError> {
        f.lathe_write(n, v)
    }

    fn f_is_lead(f: &Fanuc<Self>, b: &Block<Self>) -> bool {
        let motion = b.group(1).unwrap_or(f.motion);
        matches!(
            motion,
            G::Own(
                HuaxingG::Thread
                    | HuaxingG::VariableLeadThread
                    | HuaxingG::ThreadCycle
                    | HuaxingG::TappingCycle
                    | HuaxingG::Rotary { .. }
                    | HuaxingG::LiveTap { .. }
                    | HuaxingG::RigidTap { .. }
            )
        ) || b.has_g(G::Own(HuaxingG::MultiThreadCycle))
    }
    fn tool_word(f: &mut Fanuc<Self>, t: f64) -> Result<(), ProgramError> {
        f.huaxing_tool_word(t)
    }
    fn speed_word(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<bool, ProgramError> {
        f.live_tool_speed_word(b)
    }
    fn m_to_nc(f: &mut Fanuc<Self>, code: u32) -> Result<bool, ProgramError> {
        f.live_tool_m(code)
    }
    fn m_in_cycle(f: &Fanuc<Self>, b: &Block<Self>) -> bool {
        // In a G83/G87 (G84/G88) block an M word is the spindle clamp code of the cycle
        // (§5.22.7, §5.23.4).
        matches!(
            b.group(1).unwrap_or(f.motion),
            G::Own(HuaxingG::Drilling { .. } | HuaxingG::RigidTap { .. })
        ) && f.has_axis_words(b)
    }
    fn own_m_before(
        f: &mut Fanuc<Self>,
        m: ToolMacro,
        b: &Block<Self>,
    ) -> Result<(), ProgramError> {
        match m {
            ToolMacro::RigidTapping => f.rigid_mode_on(),
            _ => f.tool_macro_code(m, b),
        }
    }
    fn flow_waits(_f: &Fanuc<Self>, b: &Block<Self>) -> bool {
        b.has_g(G::Own(HuaxingG::Finishing))
    }
    fn start_comp(
        f: &mut Fanuc<Self>,
        b: &Block<Self>,
        g: G<HuaxingG>,
    ) -> Result<(), ProgramError> {
        f.lathe_start_comp(b, g)
    }
    fn cancel_comp(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.lathe_cancel_comp(b)
    }
    fn ret(f: &mut Fanuc<Self>) -> Result<(), ProgramError> {
        f.core.return_from_call();
        if f.d.tool_macro_depth.is_some_and(|d| f.core.depth() < d) {
            f.d.tool_macro_depth = None;
        }
        Ok(())
    }
    fn one_shot(
        f: &mut Fanuc<Self>,
        g: HuaxingG,
        b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        use HuaxingG::*;
        Some(match g {
            AssignCoordinate | AssignClearLocal => f.set_coordinate(b, g == AssignClearLocal),
            ShiftCoordinate => f.shift_coordinate(b),
            LocalCoordinate => {
                for (i, &a) in f.core.setup.axes.clone().iter().enumerate() {
                    if let Some(v) = b.get(a) {
                        f.core.shift[i] += v;
                    }
                }
                Ok(())
            }
            ConditionalRepeat { high } => f.conditional_repeat(b, high),
            JumpRange | CallRange | LoopRange => f.range(b, g),
            RoughTurning | RoughFacing | PatternRepeat => f.compound_cycle(b, g),
            Finishing => f.finishing(b),
            FaceGrooving | RadialGrooving => f.grooving(b, g == RadialGrooving),
            ChipBreak => f.set_chip_break(b),
            MultiThreadCycle => f.g76(b),
            _ => return None,
        })
    }
    fn is_motion(g: HuaxingG) -> bool {
        use HuaxingG::*;
        matches!(
            g,
            ThreePointArc { .. }
                | Thread
                | VariableLeadThread
                | TappingCycle
                | TurningCycle
                | FacingCycle
                | ThreadCycle
                | Drilling { .. }
                | Rotary { .. }
                | Skip
                | LiveTap { .. }
                | RigidTap { .. }
        )
    }
    fn motion_selected(
        f: &mut Fanuc<Self>,
        _new: G<HuaxingG>,
        changed: bool,
        _b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        if changed {
            // A new cycle or motion code drops the retained cycle words; another group-01
            // code than G84/G88 ends rigid tapping (§5.23.4).
            f.d.cycle = CycleWords::default();
            if !matches!(_new, G::Own(HuaxingG::RigidTap { .. })) {
                f.d.rigid = rigid_tap::RigidTap::default();
            }
        }
        None
    }
    fn words(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.after_skip();
        f.polar_restrictions(b)?;
        f.live_tool_words(b)?;
        f.c_words(b)
    }
    fn moves_without_axes(f: &Fanuc<Self>, b: &Block<Self>) -> bool {
        matches!(f.motion, G::Own(HuaxingG::Rotary { .. })) && (b.has('C') || b.has('H'))
    }
    fn motion_words(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        match f.motion {
            G::Own(HuaxingG::Drilling { .. }) => f.drill_words(b)?,
            G::Own(HuaxingG::LiveTap { .. }) => f.live_tap_words(b)?,
            G::Own(HuaxingG::RigidTap { .. }) => f.rigid_tap_words(b)?,
            _ => {}
        }
        Ok(())
    }
    fn modal(f: &mut Fanuc<Self>, g: HuaxingG, _b: &Block<Self>) -> Result<(), ProgramError> {
        match g {
            HuaxingG::PolarOn => return f.polar_on(),
            HuaxingG::PolarOff => return f.core.polar_off(),
            HuaxingG::RigidTap { .. } => f.rigid_tap_selected(f.motion),
            HuaxingG::Drilling { radial } => f.drilling_selected(radial),
            HuaxingG::CancelRigid => f.rigid_tap_cancel(),
            _ => {}
        }
        if g == HuaxingG::FeedPerRevolutionOnIndex {
            if !f.core.feed_per_rev() {
                f.core.set_feed_mode(true);
            }
            f.d.start_on_index = true;
        }
        Ok(())
    }
    fn before_motion(f: &mut Fanuc<Self>, b: &Block<Self>) -> Option<Result<(), ProgramError>> {
        f.rapid_c(b).or_else(|| f.cut_on_index(b))
    }
    fn motion(f: &mut Fanuc<Self>, g: HuaxingG, b: &Block<Self>) -> Result<(), ProgramError> {
        use HuaxingG::*;
        match g {
            ThreePointArc { absolute } => f.three_point_arc(b, absolute),
            Drilling { radial } => f.drilling(b, radial),
            Thread => f.g32(b),
            VariableLeadThread => f.g34(b),
            TappingCycle => f.g33(b),
            TurningCycle | FacingCycle | ThreadCycle => f.single_cycle(b, g),
            Rotary { orient } => f.rotary(b, orient),
            Skip => f.skip(b),
            LiveTap { axis } => f.live_tap(b, axis),
            RigidTap { side } => f.rigid_tap(b, side),
            other => Err(f.fault(Fault::UndefinedCode, format!("{other:?} is not a motion"))),
        }
    }
    fn chamfer(f: &Fanuc<Self>, b: &Block<Self>) -> Result<Option<Chamfer>, ProgramError> {
        f.chamfer_words(b)
    }
}

impl Fanuc<Huaxing> {
    /// G50.3: shift the work coordinates by the block's words.
    fn shift_coordinate(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let here = self.core.work_position();
        let end = self.end_point(b)?;
        for i in 0..here.len() {
            self.core.shift[i] -= end[i] - here[i];
        }
        Ok(())
    }

    /// The chamfer or rounding words of a G01 block (§5.11); a value outside 0–1000 is
    /// ignored, as the manual says.
    fn chamfer_words(&self, b: &Block<Huaxing>) -> Result<Option<Chamfer>, ProgramError> {
        let usable = |v: f64| v > 0.0 && v <= 1000.0;
        match (b.get('L'), b.get('D')) {
            (Some(_), Some(_)) => Err(self.fault(
                Fault::Chamfer,
                "chamfer L and corner rounding D in one block",
            )),
            (Some(l), None) if usable(l) => Ok(Some(Chamfer::Line(l))),
            (None, Some(d)) if usable(d) => Ok(Some(Chamfer::Round(d))),
            _ => Ok(None),
        }
    }
}

pub fn g_code(n: u32) -> Option<GCode<HuaxingG>> {
    use HuaxingG::*;
    use G::*;
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        40 => (0, Dwell),
        50 => (1, G::Own(ThreePointArc { absolute: false })),
        51 => (1, G::Own(ThreePointArc { absolute: true })),
        70 => (0, G::Own(ChipBreak)),
        71 => (
            0,
            // D140: the manual does not define the oscillation's motion.
            Unsupported(
                "G07.1 thread chip breaking: §5.6 does not define the oscillation's motion",
            ),
        ),
        80 => (1, G::Own(Rotary { orient: None })),
        // G08.n names axis n (1…6, X…C) as the spindle's: on a machine whose spindle is
        // another axis, alarm 74 "rotary axis not defined" (`position_mode`, D138).
        81..=86 => (
            1,
            G::Own(Rotary {
                orient: Some((n - 80) as u8),
            }),
        ),
        90 => (15, ExactStopBlock),
        121 => (16, G::Own(PolarOn)),
        131 => (16, G::Own(PolarOff)),
        141..=146 => (
            1,
            G::Own(LiveTap {
                axis: (n - 140) as u8,
            }),
        ),
        170 => (16, PlaneXy),
        180 => (16, PlaneZx),
        190 => (16, PlaneYz),
        210 => (0, G::Own(ConditionalRepeat { high: false })),
        230 => (0, G::Own(ConditionalRepeat { high: true })),
        250 => (0, G::Own(JumpRange)),
        260 => (0, G::Own(CallRange)),
        270 => (0, G::Own(LoopRange)),
        280 => (0, ReferenceReturn),
        310 => (1, G::Own(Skip)),
        320 => (1, G::Own(Thread)),
        330 => (1, G::Own(TappingCycle)),
        340 => (1, G::Own(VariableLeadThread)),
        400 => (7, NoseCancel),
        410 => (7, NoseLeft),
        420 => (7, NoseRight),
        430 | 440 | 490 => (
            8,
            Unsupported("G43/G44/G49 tool length compensation is milling"),
        ),
        500 => (0, SetCoordinate),
        501 => (0, G::Own(AssignCoordinate)),
        502 => (0, G::Own(AssignClearLocal)),
        503 => (0, G::Own(ShiftCoordinate)),
        520 => (0, G::Own(LocalCoordinate)),
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
        700 => (0, G::Own(Finishing)),
        710 => (0, G::Own(RoughTurning)),
        720 => (0, G::Own(RoughFacing)),
        730 => (0, G::Own(PatternRepeat)),
        740 => (0, G::Own(FaceGrooving)),
        750 => (0, G::Own(RadialGrooving)),
        760 => (0, G::Own(MultiThreadCycle)),
        770 => (
            0,
            Unsupported("G77 clears an absolute encoder's multi-turn count"),
        ),
        800 => (1, G::Own(CancelRigid)),
        830 => (1, G::Own(Drilling { radial: false })),
        870 => (1, G::Own(Drilling { radial: true })),
        840 => (1, G::Own(RigidTap { side: false })),
        880 => (1, G::Own(RigidTap { side: true })),
        850 | 860 | 890 => (1, Unsupported("not described in the manual")),
        900 => (1, G::Own(TurningCycle)),
        920 => (1, G::Own(ThreadCycle)),
        921 => (1, Unsupported("G92.1 rigid thread cycle is only listed")),
        940 => (1, G::Own(FacingCycle)),
        960 => (2, ConstantSurfaceSpeed),
        970 => (2, ConstantRpm),
        980 => (5, FeedPerMinute),
        990 => (5, FeedPerRevolution),
        991 => (5, G::Own(FeedPerRevolutionOnIndex)),
        _ => return None,
    };
    Some(GCode { group, meaning })
}

pub fn m_code(n: u32) -> Option<M<ToolMacro>> {
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
        // M48 counts a part: the PLC does, after the motion.
        480 => AuxAfter,
        980 => SubprogramCall,
        990 => SubprogramReturn,
        // M14.n as G08.n: axis n must be the machine's spindle axis (alarm 74 otherwise).
        141..=146 => Own(ToolMacro::PositionMode((n - 140) as u8)),
        290 => Own(ToolMacro::RigidTapping),
        500 => Unsupported("M50 bar feed drives outputs directly, not through the PLC"),
        510 => Unsupported("M51 sets the start block in MDI"),
        520 => Own(ToolMacro::ReadTool),
        530 | 531 => Own(ToolMacro::SetOffset),
        540 => Own(ToolMacro::Sync),
        570 => Own(ToolMacro::ToolToPlc),
        580 => Own(ToolMacro::RaiseAlarm),
        // M56 moves the turret toward the change position: the PLC's.
        560 => AuxBefore,
        550 => Unsupported("M55 writes PLC F026–F029, which the PLC program does not read"),
        // M66: the live tool into position control (D143); M65 is in the table above (the
        // second spindle's stop) and the live tool's speed mode on a turn-mill (`m_to_nc`).
        660 => Own(ToolMacro::LiveToolPosition),
        590 | 600 | 850 | 860 | 870 | 880 | 890 => {
            Unsupported("NC-internal M code of multi-channel machines")
        }
        90000..=99990 if n.is_multiple_of(10) => Unsupported(
            "M9000–M9999 call programs through an address table the manual does not give",
        ),
        _ => return None,
    })
}
