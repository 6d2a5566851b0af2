//! The FANUC 0-M mill (`003`): G17/G18/G19 planes, cutter radius and tool length
//! compensation, canned cycles G73–G89, G10/G52/G53/G92 coordinates, G27–G30 reference
//! points, G60, user macro B with G65, and FANUC's P/S alarm numbers (issue 7).

mod alarms;
mod hole_cycle;
mod macro_b;
mod tapping;
mod words;

use cnc_interpreter_core::comp::Startup;
use cnc_interpreter_core::{CompRules, Fault, Plane, ProgramError, Setup, SpindleDir};

use crate::fanuc::block::Block;
use crate::fanuc::codes::{GCode, Rules, WordUnit, G, M};
use crate::fanuc::expr::{EvalError, Value};
use crate::fanuc::syntax::Word;
use crate::fanuc::{Family, Fanuc};

pub use alarms::alarm;
use hole_cycle::HoleCycle;

/// The mill's own G meanings (`003` Table 1.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MillG {
    /// G10 L2 P: write a work offset from the program.
    SetOffsetData,
    /// G53: this block's positions are machine coordinates (§4.3.1).
    MachineCoordinates,
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
    /// G65 user macro call: run by the statement itself, never as a block.
    MacroCall,
    /// G66 modal macro call: registered by the statement itself (its words are arguments).
    ModalCall,
    /// G67: the modal macro call cancelled.
    ModalCallCancel,
    /// G63 tapping mode (group 15, until G61 or G64; D131).
    TappingMode,
    /// G27 reference position return check.
    ReferenceCheck,
    /// G29 return from the reference point through G28's intermediate point.
    FromReference,
    /// G30 return to the second reference point.
    SecondReference,
    /// G60 single-direction positioning.
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

/// The mill's own modal state.
pub struct Mill {
    /// G17/G18/G19.
    pub plane: G<MillG>,
    /// D: the offset whose radius G41/G42 use (modal, D0 = no radius).
    pub radius_offset: u32,
    /// The modal hole-machining cycle (G73–G89 until G80 or a group-01 code).
    pub hole: Option<HoleCycle>,
    /// G99: cycles return to the R level (G98: to the initial level).
    pub cycle_return_r: bool,
    /// The way the spindle turned before a cycle stopped or oriented it.
    pub cycle_spindle: SpindleDir,
    /// G43 (+1) / G44 (−1) / G49 (0).
    pub length_sign: i8,
    /// The H offset number of tool length compensation.
    pub length_offset: u32,
    /// G66's macro, called after every move block until G67 (D129).
    pub modal_call: Option<macro_b::ModalCall>,
    /// G63: linear moves are taps in a floating holder (D131).
    pub tapping_mode: bool,
    /// M29: G84/G74 tap rigidly, the axis following the spindle (D130).
    pub rigid_tapping: bool,
}

/// The mill's own M codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MillM {
    /// M29 S: rigid tapping, the spindle in position control (`003` §6.4; D130).
    RigidTapping,
}

/// The working plane of G17, G18 or G19 (`003` §2.3, §4.4).
fn plane_of(g: G<MillG>) -> Plane {
    let (h, v, normal, missing) = match g {
        G::PlaneZx => ('Z', 'X', 'Y', "G18 needs the Z and X axes"),
        G::PlaneYz => ('Y', 'Z', 'X', "G19 needs the Y and Z axes"),
        _ => ('X', 'Y', 'Z', "G17 needs the X and Y axes"),
    };
    Plane {
        h,
        v,
        normal: Some(normal),
        missing: (Fault::PlaneAxis, missing),
    }
}

impl Family for Mill {
    type G = MillG;
    type M = MillM;

    fn g_code(x10: u32) -> Option<GCode<MillG>> {
        g_code(x10)
    }
    fn m_code(x10: u32) -> Option<M<MillM>> {
        m_code(x10)
    }
    fn alarm(f: Fault) -> u32 {
        alarm(f)
    }
    fn rules() -> Rules<MillG> {
        // §7.2.2: least input increment 0.001 mm, ±99999.999; power-on G00. User macro B.
        Rules {
            macros: true,
            increment: 0.001,
            max_coordinate: 99999.999,
            initial_motion: G::Rapid,
        }
    }
    fn core_rules() -> cnc_interpreter_core::Rules {
        cnc_interpreter_core::Rules {
            alarms: alarm,
            max_feed: 24000.0,
            initial_feed: 0.0,
            needs_end: None,
            locals: 41,
            work_offsets: true,
            plane: plane_of(G::PlaneXy),
            comp: CompRules {
                refuse_rapid: false,
                name: "cutter compensation",
            },
            max_call_depth: 4,
        }
    }
    fn new(_setup: &Setup) -> Self {
        Mill {
            plane: G::PlaneXy,
            radius_offset: 0,
            hole: None,
            cycle_return_r: false,
            cycle_spindle: SpindleDir::Cw,
            length_sign: 0,
            length_offset: 0,
            modal_call: None,
            tapping_mode: false,
            rigid_tapping: false,
        }
    }

    // FANUC's ROUND in an expression rounds to a whole number (A.3).
    const ROUND_DECIMALS: i32 = 0;
    // Only G65 opens a level of locals; an M98 subprogram works with its caller's (D51).
    const SUBPROGRAM_LOCALS: bool = false;

    // Numbers without a decimal point count 0.001 mm (§7.2.1; decision D52).
    const CALCULATOR_POINT: bool = false;

    fn extra_address(c: char) -> bool {
        c == 'H'
    }
    /// Q (peck depth, shift) is a length; K is a repeat count in a canned-cycle block.
    fn word_unit(f: &Fanuc<Self>, b: &Block<Self>, c: char) -> WordUnit {
        match c {
            'Q' => WordUnit::Length,
            'K' if f.cycle_block(b) => WordUnit::Plain,
            _ => f.default_word_unit(b, c),
        }
    }
    fn words_statement(f: &mut Fanuc<Self>, words: &[Word]) -> Option<Result<(), ProgramError>> {
        use crate::fanuc::expr::Expr;
        let code = |n: f64| {
            words.iter().any(|w| {
                w.letter == 'G' && matches!(w.value, Expr::Num { value, .. } if value == n)
            })
        };
        if code(65.0) {
            Some(f.macro_call(words))
        } else if code(66.0) {
            Some(f.modal_call(words))
        } else {
            None
        }
    }

    fn read_var(f: &Fanuc<Self>, n: i64) -> Result<Value, EvalError> {
        f.fanuc_read(n)
    }
    fn write_var(f: &mut Fanuc<Self>, n: i64, v: Value) -> Result<(), ProgramError> {
        f.fanuc_write(n, v)
    }

    fn modal(f: &mut Fanuc<Self>, g: MillG, b: &Block<Self>) -> Result<(), ProgramError> {
        match g {
            MillG::CycleReturn { r_level } => f.d.cycle_return_r = r_level,
            MillG::LengthComp(sign) => f.length_compensation(b, Some(sign))?,
            MillG::ModalCallCancel => f.d.modal_call = None,
            MillG::TappingMode => f.d.tapping_mode = true,
            _ => {}
        }
        Ok(())
    }
    fn after_block(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.modal_call_after(b)
    }
    /// The program's end cancels a modal macro call, as reset does (G67 is the power-on state).
    fn on_program_end(f: &mut Fanuc<Self>) {
        f.d.modal_call = None;
        f.d.tapping_mode = false;
        f.d.rigid_tapping = false;
    }
    fn own_m_before(f: &mut Fanuc<Self>, m: MillM, _b: &Block<Self>) -> Result<(), ProgramError> {
        match m {
            MillM::RigidTapping => f.rigid_tapping_on(),
        }
    }
    fn plane(f: &mut Fanuc<Self>, g: G<MillG>) -> Result<(), ProgramError> {
        if f.core.comp.is_some() && g != f.d.plane {
            return Err(f.fault(
                Fault::CompPlane,
                "the plane cannot change while cutter compensation is active: G40 first",
            ));
        }
        f.d.plane = g;
        f.core.plane = plane_of(g);
        Ok(())
    }
    fn words(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        // G61 and G64 end G63's tapping mode (group 15).
        if matches!(b.group(15), Some(G::ExactStopMode | G::ContinuousMode)) {
            f.d.tapping_mode = false;
        }
        if b.group(8).is_none() && b.has('H') {
            f.length_compensation(b, None)?;
        }
        if b.group(7).is_none() {
            // D is modal: the next G41/G42 uses it.
            if let Some(d) = f.offset_word(b, 'D')? {
                f.d.radius_offset = d;
            }
        }
        Ok(())
    }
    fn tool_word(f: &mut Fanuc<Self>, t: f64) -> Result<(), ProgramError> {
        f.mill_tool_word(t)
    }
    fn m_before(f: &mut Fanuc<Self>, code: u32) -> Result<(), ProgramError> {
        if code == 60 {
            f.check_tool_change_position()?;
        }
        Ok(())
    }
    /// G41/G42 with the radius of D (negative: the other side); type B start-up (D48).
    fn start_comp(f: &mut Fanuc<Self>, b: &Block<Self>, g: G<MillG>) -> Result<(), ProgramError> {
        if f.core.comp.is_some() {
            return Err(f.fault(
                Fault::CompDirection,
                "G41/G42 while tool-nose compensation is active: cancel with G40 first",
            ));
        }
        let mut side = f.comp_side(g);
        let r = f.cutter_radius(b)?;
        if r < 0.0 {
            side = side.other();
        }
        f.core.start_comp(side, r.abs(), 0, Startup::AlongEntry)
    }
    /// G40 alone or with G00/G01, never in an arc (P/S 034).
    fn cancel_comp(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.refuse_arc_for_comp(b, "G40")
    }
    fn before_one_shots(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        if f.core.comp.is_some() {
            f.refuse_under_cutter_comp(b)?;
        }
        if b.g.iter().any(|g| g.0 == 0) {
            // A motion code beside a one-shot code becomes modal for the blocks after it.
            if let Some(m) = b.group(1) {
                f.motion = m;
                f.d.hole = None;
            }
        }
        Ok(())
    }
    fn one_shot(
        f: &mut Fanuc<Self>,
        g: MillG,
        b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        Some(match g {
            MillG::SetOffsetData => f.set_offset_data(b),
            MillG::MachineCoordinates => f.machine_coordinates(b),
            MillG::SecondReference => f.second_reference(b),
            MillG::ReferenceCheck => f.reference_check(b),
            MillG::FromReference => f.return_from_reference(b),
            MillG::OneDirection => f.one_direction(b),
            MillG::MillLocal => f.local_system(b),
            _ => return None,
        })
    }
    fn before_motion(f: &mut Fanuc<Self>, b: &Block<Self>) -> Option<Result<(), ProgramError>> {
        // A group-01 code ends a canned cycle (§1.2); G80 too, and rigid tapping with it
        // (D130).
        if b.group(1).is_some() || b.group(9) == Some(G::Own(MillG::CycleCancel)) {
            f.d.hole = None;
            f.d.rigid_tapping = false;
        }
        if let Some(G::Own(MillG::HoleCycle(kind))) = b.group(9) {
            if let Err(e) = f.select_hole_cycle(kind) {
                return Some(Err(e));
            }
        }
        if f.d.hole.is_some() {
            return Some(f.hole_block(b));
        }
        f.tapping_move(b)
    }
    fn motion(f: &mut Fanuc<Self>, g: MillG, _b: &Block<Self>) -> Result<(), ProgramError> {
        Err(f.fault(Fault::UndefinedCode, format!("{g:?} is not a motion")))
    }
}

fn g_code(n: u32) -> Option<GCode<MillG>> {
    use MillG::*;
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
        200 => (6, InchInput),
        210 => (6, MetricInput),
        100 => (0, G::Own(SetOffsetData)),
        270 => (0, G::Own(ReferenceCheck)),
        280 => (0, ReferenceReturn),
        290 => (0, G::Own(FromReference)),
        300 => (0, G::Own(SecondReference)),
        600 => (0, G::Own(OneDirection)),
        530 => (0, G::Own(MachineCoordinates)),
        540..=590 if n.is_multiple_of(10) => (14, WorkSystem(((n - 540) / 10) as u8)),
        610 => (15, ExactStopMode),
        640 => (15, ContinuousMode),
        630 => (15, G::Own(TappingMode)),
        900 => (3, Absolute),
        910 => (3, Incremental),
        920 => (0, SetCoordinate),
        940 => (5, FeedPerMinute),
        950 => (5, FeedPerRevolution),
        400 => (7, NoseCancel),
        410 => (7, NoseLeft),
        420 => (7, NoseRight),
        650 => (0, G::Own(MacroCall)),
        660 => (12, G::Own(ModalCall)),
        670 => (12, G::Own(ModalCallCancel)),
        430 => (8, G::Own(LengthComp(1))),
        440 => (8, G::Own(LengthComp(-1))),
        490 => (8, G::Own(LengthComp(0))),
        520 => (0, G::Own(MillLocal)),
        730 => (9, G::Own(HoleCycle(HoleKind::HighSpeedPeck))),
        740 => (9, G::Own(HoleCycle(HoleKind::LeftTap))),
        760 => (9, G::Own(HoleCycle(HoleKind::FineBore))),
        800 => (9, G::Own(CycleCancel)),
        810 => (9, G::Own(HoleCycle(HoleKind::Drill))),
        820 => (9, G::Own(HoleCycle(HoleKind::Counterbore))),
        830 => (9, G::Own(HoleCycle(HoleKind::Peck))),
        840 => (9, G::Own(HoleCycle(HoleKind::Tap))),
        850 => (9, G::Own(HoleCycle(HoleKind::Bore))),
        860 => (9, G::Own(HoleCycle(HoleKind::BoreSpindleStop))),
        870 => (9, G::Own(HoleCycle(HoleKind::BackBore))),
        880 => (9, G::Own(HoleCycle(HoleKind::BoreManual))),
        890 => (9, G::Own(HoleCycle(HoleKind::BoreDwell))),
        980 => (10, G::Own(CycleReturn { r_level: false })),
        990 => (10, G::Own(CycleReturn { r_level: true })),
        _ => return None,
    };
    Some(GCode { group, meaning })
}
fn m_code(n: u32) -> Option<M<MillM>> {
    use M::*;
    Some(match n {
        0 => Stop,
        10 => OptionalStop,
        20 | 300 => ProgramEnd,
        30 | 40 | 60 | 80 | 190 => AuxBefore,
        50 | 90 | 180 => AuxAfter,
        290 => Own(MillM::RigidTapping),
        980 => SubprogramCall,
        990 => SubprogramReturn,
        _ => return None,
    })
}
