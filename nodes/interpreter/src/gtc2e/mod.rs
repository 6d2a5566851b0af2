//! The GTC2E lathe (`002`): the same numbers often mean other things than on the Huaxing (G50/G51
//! turret mode, G22/G80 loops, G24/G77 cycles, G54–G57 cumulative shifts), one code per modal
//! group in a block, no macros, and subroutines by line number.

mod alarms;
mod cycles;

use cnc_interpreter_core::comp::Startup;
use cnc_interpreter_core::{
    show, Aux, CompRules, CssRule, Fault, Pos, ProgramError, Repeat, Setup,
};

use crate::fanuc::block::{code_x10, integer_word, Block};
use crate::fanuc::codes::{GCode, Rules, G, M};
use crate::fanuc::expr::{EvalError, Value};
use crate::fanuc::lathe::LATHE_PLANE;
use crate::fanuc::{Family, Fanuc};

pub use alarms::alarm;

/// The GTC2E's own G meanings (§4.3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GtcG {
    /// G33 thread.
    Thread,
    /// G76 thread cycle.
    ThreadCycle,
    /// G74 tapping cycle.
    Tapping,
    /// G24 taper cycle.
    TaperCycle,
    /// G77 cylinder cycle.
    CylinderCycle,
    /// G83 drilling cycle.
    DrillCycle,
    /// G75 grooving cycle.
    GroovingCycle,
    /// G22 L: loop start.
    LoopStart,
    /// G80: loop end.
    LoopEnd,
    /// G26 (X and Z), G27 (X), G29 (Z) return to the program start point.
    ReturnToStart { x: bool, z: bool },
    /// G60: return to where the previous block started.
    ReturnToPreviousStart,
    /// G61: return to the point G25 stored.
    ReturnToStored,
    /// G25: store the position.
    StorePosition,
    /// G31: thread retract settings.
    ThreadRetract,
    /// G54–G57: add offset group n (0–3) to the coordinates, cumulatively.
    OffsetShift(u8),
    /// G50 (row tool post) / G51 (gang).
    TurretMode { gang: bool },
}

/// The GTC2E's own M meanings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GtcM {
    /// M20: spindle and coolant off, then the program restarts from the top.
    EndAndRestart,
    /// M97: jump to line P.
    Jump,
    /// M52/M53/M65: order of axes in returns.
    ReturnOrder(ReturnOrder),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReturnOrder {
    #[default]
    XThenZ,
    ZThenX,
    Together,
}

/// Retained definition of a cycle: the shape relative to the start point, repeated by
/// follow-on blocks that move the start point (§4.3.2-5..10).
#[derive(Debug, Clone, Copy)]
pub struct GtcCycle {
    pub kind: GtcG,
    pub dx: f64,
    pub dz: f64,
    pub lead: f64,
    pub starts: u32,
    pub dwell: f64,
}

/// G31 settings: X retract length and early-retract distance.
#[derive(Debug, Clone, Copy, Default)]
pub struct GtcRetract {
    pub u: Option<f64>,
    pub w: f64,
}

/// The GTC2E's own modal state.
pub struct Gtc2e {
    pub gtc_cycle: Option<GtcCycle>,
    pub gtc_retract: GtcRetract,
    pub gang_mode: bool,
    pub return_order: ReturnOrder,
    /// Work position at the start of the previous block (G60); the program start until then.
    pub previous_start: Option<Vec<f64>>,
    /// G25 memory.
    pub stored: Option<Vec<f64>>,
}

impl Family for Gtc2e {
    type G = GtcG;
    type M = GtcM;

    fn g_code(x10: u32) -> Option<GCode<GtcG>> {
        g_code(x10)
    }
    fn m_code(x10: u32) -> Option<M<GtcM>> {
        m_code(x10)
    }
    fn alarm(f: Fault) -> u32 {
        alarm(f)
    }
    fn rules() -> Rules<GtcG> {
        Rules {
            macros: false,
            // Least input increment 0.001 mm (§2.2).
            increment: 0.001,
            max_coordinate: 7999.999,
            initial_motion: G::Rapid,
        }
    }
    fn core_rules() -> cnc_interpreter_core::Rules {
        cnc_interpreter_core::Rules {
            alarms: alarm,
            max_feed: 3000.0,
            initial_feed: 0.0,
            // The program must end with M02/M20/M30 (§4.1 rule 9).
            needs_end: Some("program has no M02, M20 or M30"),
            locals: 41,
            // G54–G57 are cumulative shifts, not work systems (decision D19).
            work_offsets: false,
            plane: LATHE_PLANE,
            comp: CompRules {
                refuse_rapid: false,
                name: "tool-nose compensation",
            },
            max_call_depth: 4,
        }
    }
    fn new(_setup: &Setup) -> Self {
        Gtc2e {
            gtc_cycle: None,
            gtc_retract: GtcRetract::default(),
            gang_mode: false,
            return_order: ReturnOrder::XThenZ,
            previous_start: None,
            stored: None,
        }
    }

    // No O programs: a file is one program.
    const TAPES: bool = false;
    // One code per modal group in a block (§4.1 rule 1, message 16).
    const ONE_CODE_PER_GROUP: bool = true;
    const INCREMENTAL_ADDRESSES: bool = true;
    const CSS_GROUP: u8 = 1;
    // I is a diameter (§4.3.2-3).
    const ARC_I_DIAMETER: bool = true;
    const WANTS_BLOCK_START: bool = true;

    fn extra_address(c: char) -> bool {
        c == 'U' || c == 'W'
    }
    fn m_group(x10: u32) -> u32 {
        match x10 / 10 {
            0 | 2 | 30 | 20 => 4,
            3..=5 => 5,
            8 | 9 => 6,
            10 | 11 => 7,
            54 | 55 => 8,
            12 | 13 => 9,
            22..=25 => 10,
            52 | 53 | 65 => 11,
            _ => 12,
        }
    }

    fn read_var(f: &Fanuc<Self>, n: i64) -> Result<Value, EvalError> {
        f.lathe_read(n)
    }
    fn write_var(f: &mut Fanuc<Self>, n: i64, v: Value) -> Result<(), ProgramError> {
        f.lathe_write(n, v)
    }

    fn modal(f: &mut Fanuc<Self>, g: GtcG, _b: &Block<Self>) -> Result<(), ProgramError> {
        match g {
            GtcG::TurretMode { gang } => f.d.gang_mode = gang,
            GtcG::OffsetShift(n) => {
                // G54–G57 add the group's offset, cumulatively (§4.3.2-15, decision D19):
                // the displayed coordinates change by −offset, nothing moves.
                for (i, &a) in f.core.setup.axes.iter().enumerate() {
                    f.core.shift[i] += f.core.setup.offsets.work(n, a);
                }
            }
            _ => {}
        }
        Ok(())
    }
    fn css_rule(f: &Fanuc<Self>) -> CssRule {
        // G96 S = rpm at X0, reached linearly from the rpm where G96 was given (decision D18).
        let x = f
            .core
            .axis('X')
            .map(|i| f.core.work_position()[i].abs())
            .unwrap_or(0.0);
        CssRule::LinearToCenter {
            rpm0: f.core.rpm,
            x0: x,
        }
    }
    /// `T0x` (index station x and apply offset x) or `Tx0` (offset x only).
    fn tool_word(f: &mut Fanuc<Self>, t: f64) -> Result<(), ProgramError> {
        let code = integer_word(t).ok_or_else(|| {
            f.fault(
                Fault::ToolNumber,
                format!("tool word T{} must be an integer", show(t)),
            )
        })?;
        let (tool, offset) = match code {
            1..=8 => (if f.d.gang_mode { None } else { Some(code) }, code),
            10..=80 if code % 10 == 0 => (None, code / 10),
            _ => {
                return Err(f.fault(
                    Fault::ToolNumber,
                    format!("T{code}: tools are T01–T08 and T10–T80"),
                ))
            }
        };
        f.select_tool(tool, offset)
    }
    fn own_m_before(f: &mut Fanuc<Self>, m: GtcM, _b: &Block<Self>) -> Result<(), ProgramError> {
        if let GtcM::ReturnOrder(o) = m {
            f.d.return_order = o;
        }
        Ok(())
    }
    fn own_m_flow(
        f: &mut Fanuc<Self>,
        m: GtcM,
        b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        match m {
            GtcM::EndAndRestart => {
                f.core.saw_end = true;
                f.core.spindle_code(5);
                f.core.aux(Aux::M(9));
                f.clear_shifts();
                if f.core.setup.single_pass {
                    f.core.finish();
                } else {
                    f.core.restart();
                }
                Some(Ok(()))
            }
            GtcM::Jump => Some(f.line_target(b).map(|p| f.core.level().pos = p)),
            GtcM::ReturnOrder(_) => None,
        }
    }
    fn on_program_end(f: &mut Fanuc<Self>) {
        f.clear_shifts();
    }
    /// `G41 R..` on its own, R the nose radius (negative: the other side), programmed point =
    /// nose centre (§4.3.2-18).
    fn start_comp(f: &mut Fanuc<Self>, b: &Block<Self>, g: G<GtcG>) -> Result<(), ProgramError> {
        f.refuse_second_start()?;
        let mut side = f.comp_side(g);
        let r = b
            .get('R')
            .ok_or_else(|| f.fault(Fault::MissingWord, "G41/G42 needs R (nose radius)"))?;
        if r < 0.0 {
            side = side.other();
        }
        let radius = f.nose_radius(r.abs(), "R")?;
        f.core.start_comp(side, radius, 0, Startup::Connect)
    }
    /// G40 alone: the next move cancels.
    fn cancel_comp(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// `M98 P L`: a subroutine by line number, L times, ended by M99.
    fn call(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        let first = f.line_target(b)?;
        let count = b.get('L').unwrap_or(1.0);
        let count = code_x10(count)
            .map(|c| c / 10)
            .filter(|&c| (1..=99).contains(&c))
            .ok_or_else(|| f.fault(Fault::OutOfRange, format!("L{}: 1–99", show(count))))?;
        let level = f.core.level();
        let ret = level.pos;
        level.repeats.push(Repeat::LineCall {
            first,
            remaining: count,
            ret,
        });
        level.pos = first;
        Ok(())
    }
    fn ret(f: &mut Fanuc<Self>) -> Result<(), ProgramError> {
        let level = f.core.level();
        let Some(i) = level
            .repeats
            .iter()
            .rposition(|r| matches!(r, Repeat::LineCall { .. }))
        else {
            return Err(f.fault(Fault::ReturnWithoutCall, "M99 without M98"));
        };
        level.repeats.truncate(i + 1);
        if let Some(Repeat::LineCall {
            first,
            remaining,
            ret,
        }) = level.repeats.last_mut()
        {
            if *remaining > 1 {
                *remaining -= 1;
                level.pos = *first;
            } else {
                level.pos = *ret;
                level.repeats.pop();
            }
        }
        Ok(())
    }
    /// G04 D: seconds.
    fn dwell_seconds(f: &Fanuc<Self>, b: &Block<Self>) -> Result<f64, ProgramError> {
        let d = b
            .get('D')
            .ok_or_else(|| f.fault(Fault::MissingWord, "G04 needs D (seconds)"))?;
        if !(0.001..=65.0).contains(&d) {
            return Err(f.fault(Fault::OutOfRange, format!("G04 D{}: 0.001–65 s", show(d))));
        }
        Ok(d)
    }
    fn one_shot(f: &mut Fanuc<Self>, g: GtcG, b: &Block<Self>) -> Option<Result<(), ProgramError>> {
        Some(match g {
            GtcG::LoopStart => f.gtc_loop_start(b),
            GtcG::LoopEnd => f.gtc_loop_end(),
            GtcG::ReturnToStart { x, z } => {
                f.clear_shifts();
                let target = f.core.program_start.clone();
                f.gtc_return(&target, x, z)
            }
            GtcG::ReturnToPreviousStart => {
                let target =
                    f.d.previous_start
                        .clone()
                        .unwrap_or_else(|| f.core.program_start.clone());
                f.gtc_return(&target, true, true)
            }
            GtcG::ReturnToStored => {
                let target =
                    f.d.stored
                        .clone()
                        .unwrap_or_else(|| f.core.program_start.clone());
                f.gtc_return(&target, true, true)
            }
            GtcG::StorePosition => {
                f.d.stored = Some(f.core.work_position());
                Ok(())
            }
            GtcG::ThreadRetract => f.gtc_g31(b),
            _ => return None,
        })
    }
    fn is_motion(g: GtcG) -> bool {
        g == GtcG::Thread || is_cycle(g)
    }
    fn motion_selected(
        f: &mut Fanuc<Self>,
        new: G<GtcG>,
        changed: bool,
        b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        let cycle = matches!(new, G::Own(g) if is_cycle(g));
        if changed && !cycle {
            // A new motion code drops the retained cycle.
            f.d.gtc_cycle = None;
        }
        match new {
            G::Own(g) if cycle => Some(f.gtc_cycle_define(b, g)),
            _ => None,
        }
    }
    fn motion(f: &mut Fanuc<Self>, g: GtcG, b: &Block<Self>) -> Result<(), ProgramError> {
        if g == GtcG::Thread {
            f.gtc_thread(b)
        } else if is_cycle(g) {
            f.gtc_cycle_follow_on(b)
        } else {
            Err(f.fault(Fault::UndefinedCode, format!("{g:?} is not a motion")))
        }
    }
    fn block_ran(f: &mut Fanuc<Self>, start: Vec<f64>) {
        f.d.previous_start = Some(start);
    }
}

/// The cycles whose shape a follow-on block repeats.
fn is_cycle(g: GtcG) -> bool {
    matches!(
        g,
        GtcG::ThreadCycle
            | GtcG::Tapping
            | GtcG::TaperCycle
            | GtcG::CylinderCycle
            | GtcG::DrillCycle
            | GtcG::GroovingCycle
    )
}

impl Fanuc<Gtc2e> {
    /// Program end and G26 clear the cumulative shifts of G54–G57.
    fn clear_shifts(&mut self) {
        for v in &mut self.core.shift {
            *v = 0.0;
        }
    }

    /// `P____`: the line numbered P.
    fn line_target(&self, b: &Block<Gtc2e>) -> Result<Pos, ProgramError> {
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::MissingWord, "P (line number) missing"))?;
        let n = integer_word(p);
        let level = self.core.current();
        n.and_then(|n| cnc_interpreter_core::find_number(&level.text, level.pos, n))
            .ok_or_else(|| {
                self.fault(
                    Fault::TargetNotFound,
                    format!("line N{} not found", show(p)),
                )
            })
    }
}

fn g_code(n: u32) -> Option<GCode<GtcG>> {
    use GtcG::*;
    use G::*;
    // Group 1 holds motion, cycles, returns, G25/G31 and the offsets (`002` §4.2.2 as
    // reconstructed in the inventory §3.1): no two of them in one block.
    let (group, meaning) = match n {
        0 => (1, Rapid),
        10 => (1, Linear),
        20 => (1, ArcCw),
        30 => (1, ArcCcw),
        330 => (1, G::Own(Thread)),
        960 => (1, ConstantSurfaceSpeed),
        970 => (1, ConstantRpm),
        770 => (1, G::Own(CylinderCycle)),
        240 => (1, G::Own(TaperCycle)),
        740 => (1, G::Own(Tapping)),
        760 => (1, G::Own(ThreadCycle)),
        830 => (1, G::Own(DrillCycle)),
        750 => (1, G::Own(GroovingCycle)),
        220 => (1, G::Own(LoopStart)),
        800 => (1, G::Own(LoopEnd)),
        260 => (1, G::Own(ReturnToStart { x: true, z: true })),
        270 => (1, G::Own(ReturnToStart { x: true, z: false })),
        290 => (1, G::Own(ReturnToStart { x: false, z: true })),
        600 => (1, G::Own(ReturnToPreviousStart)),
        610 => (1, G::Own(ReturnToStored)),
        250 => (1, G::Own(StorePosition)),
        310 => (1, G::Own(ThreadRetract)),
        540..=570 if n.is_multiple_of(10) => (1, G::Own(OffsetShift(((n - 540) / 10) as u8))),
        40 => (2, Dwell),
        500 => (3, G::Own(TurretMode { gang: false })),
        510 => (3, G::Own(TurretMode { gang: true })),
        400 => (15, NoseCancel),
        410 => (15, NoseLeft),
        420 => (15, NoseRight),
        _ => return None,
    };
    Some(GCode { group, meaning })
}
fn m_code(n: u32) -> Option<M<GtcM>> {
    use M::*;
    Some(match n {
        0 => Stop,
        20 | 300 => ProgramEnd,
        200 => Own(GtcM::EndAndRestart),
        30 | 40 | 80 | 100 | 230 | 250 | 550 => AuxBefore,
        50 | 90 | 110 | 220 | 240 | 540 => AuxAfter,
        120 | 130 => AuxBefore,
        520 => Own(GtcM::ReturnOrder(ReturnOrder::XThenZ)),
        530 => Own(GtcM::ReturnOrder(ReturnOrder::ZThenX)),
        650 => Own(GtcM::ReturnOrder(ReturnOrder::Together)),
        970 => Own(GtcM::Jump),
        980 => SubprogramCall,
        990 => SubprogramReturn,
        _ => return None,
    })
}
