//! The ISO lathe: the skeleton's FANUC lathe "system B" subset with G90/G91 absolute and
//! incremental (decision D1), kept for programs written for it. Its M codes and alarm numbers
//! are the Huaxing's.

use cnc_interpreter_core::{Fault, ProgramError, Setup};

use crate::fanuc::block::Block;
use crate::fanuc::codes::{GCode, Nothing, Rules, G, M};
use crate::fanuc::expr::{EvalError, Value};
use crate::fanuc::lathe::MAX_OFFSET;
use crate::fanuc::lathe::{LATHE_COMP, LATHE_PLANE};
use crate::fanuc::{Family, Fanuc};
use crate::huaxing::{self, ToolMacro};

/// The ISO lathe has no state of its own.
pub struct IsoLathe;

impl Family for IsoLathe {
    type G = Nothing;
    type M = ToolMacro;

    fn g_code(x10: u32) -> Option<GCode<Nothing>> {
        g_code(x10)
    }
    fn m_code(x10: u32) -> Option<M<ToolMacro>> {
        huaxing::m_code(x10)
    }
    fn alarm(f: Fault) -> u32 {
        huaxing::alarm(f)
    }
    fn rules() -> Rules<Nothing> {
        // The skeleton's table: G00 at power-on and no feed until F is given.
        Rules {
            macros: false,
            increment: 0.001,
            max_coordinate: 99999.999,
            initial_motion: G::Rapid,
        }
    }
    fn core_rules() -> cnc_interpreter_core::Rules {
        cnc_interpreter_core::Rules {
            alarms: huaxing::alarm,
            max_feed: 15000.0,
            initial_feed: 0.0,
            needs_end: None,
            locals: 41,
            work_offsets: true,
            plane: LATHE_PLANE,
            comp: LATHE_COMP,
            max_call_depth: 4,
        }
    }
    fn new(_setup: &Setup) -> Self {
        IsoLathe
    }

    const REFUSE_GROUP00_WITH_01: bool = true;
    const INCREMENTAL_ADDRESSES: bool = true;

    fn read_var(f: &Fanuc<Self>, n: i64) -> Result<Value, EvalError> {
        f.lathe_read(n)
    }
    fn write_var(f: &mut Fanuc<Self>, n: i64, v: Value) -> Result<(), ProgramError> {
        f.lathe_write(n, v)
    }
    fn tool_word(f: &mut Fanuc<Self>, t: f64) -> Result<(), ProgramError> {
        let (tool, offset) = f.lathe_tool_numbers(t)?;
        if offset > MAX_OFFSET {
            return Err(f.fault(
                Fault::ToolNumber,
                format!("offset number {offset} out of range"),
            ));
        }
        f.select_tool(tool, offset)
    }
    fn own_m_before(
        f: &mut Fanuc<Self>,
        m: ToolMacro,
        b: &Block<Self>,
    ) -> Result<(), ProgramError> {
        f.tool_macro_code(m, b)
    }
    fn start_comp(f: &mut Fanuc<Self>, b: &Block<Self>, g: G<Nothing>) -> Result<(), ProgramError> {
        f.lathe_start_comp(b, g)
    }
    fn cancel_comp(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.lathe_cancel_comp(b)
    }
    fn motion(_f: &mut Fanuc<Self>, g: Nothing, _b: &Block<Self>) -> Result<(), ProgramError> {
        match g {}
    }
}

fn g_code(n: u32) -> Option<GCode<Nothing>> {
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
