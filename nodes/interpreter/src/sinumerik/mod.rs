//! The SINUMERIK 802D sl mill (`001`), a front end of its own over the interpreter's core
//! (issue 23): its language is not FANUC's. Follow a block: [`lex`] makes tokens, [`block`]
//! parses them into items, [`Sinumerik::run_block`] (`exec.rs`) sorts the items into
//! assignments, addresses and keywords and runs them in the control's order, [`motion`]
//! computes lines, circles, helices and polar moves, [`frames`] the programmable frames and
//! zero offsets, [`tool`] tools, cutting edges and radius compensation; [`vars`] holds the
//! variables and [`alarms`] the alarm numbers.

pub mod alarms;
pub mod block;
mod contour;
mod contour_cycle;
mod cutter_path;
mod cycle_call;
mod drilling;
mod exec;
mod face;
pub use exec::g_group;
pub use names::{NOT_BUILT, NOT_BUILT_G};
pub mod expr;
mod frames;
mod fxs;
pub mod lex;
mod limits;
mod milling_calls;
pub mod monitor;
mod motion;
mod names;
mod pocket;
mod rect_pocket;
mod slots;
mod spigot;
mod thread_mill;
mod timers;
mod tool;
mod tracyl;
mod trail;
mod transfer;
pub mod vars;
mod wab;

use std::sync::Arc;

use cnc_interpreter_core::comp::Side;
use cnc_interpreter_core::geometry::Pt;
use cnc_interpreter_core::{
    CompRules, Core, Fault, FrontEnd, Library, Plane, ProgramError, Rules, Setup, NO_WORK_OFFSET,
};

use self::expr::{eval, EvalError, Expr, Val};
use self::vars::{PlcArea, Scope, Var, R_BASE, R_COUNT};

/// Group 1: how the axes move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    Rapid,
    Line,
    Cw,
    Ccw,
    /// CIP: a circle through an intermediate point.
    Cip,
    /// CT: a circle tangent to the path before it.
    Ct,
    /// G33: a thread locked to the spindle.
    Thread,
    /// G331 (in) and G332 (out, the spindle reversed): rigid tapping, the axes following
    /// the positioned spindle (D101).
    TapIn,
    TapOut,
}

/// The 802D front end: the core plus the control's own modal state.
pub struct Sinumerik {
    pub core: Core,
    motion: Motion,
    /// G90 (else G91).
    absolute: bool,
    /// G70/G700: geometry in inches.
    inch: bool,
    /// G700: the feed too.
    inch_feed: bool,
    /// The pole of polar coordinates, in the plane's work coordinates (§9.2.5).
    pole: Pt,
    /// The last polar angle and radius (modal until the pole or plane changes).
    polar: (f64, f64),
    /// G17/G18/G19 as 17, 18, 19.
    plane_code: u8,
    /// Active tool T and cutting edge D (0: none).
    tool: u32,
    edge: u32,
    /// A T word waiting for M6 (when the machine changes tools with M6).
    preselected: Option<u32>,
    /// The edge a preselecting block named for the tool to come (D127).
    preselected_edge: Option<u32>,
    /// The cutting edges used since the last SETPIECE (§9.13.3).
    setpiece_memory: Vec<(u32, u32)>,
    /// G41/G42 asked for; started with the next move.
    comp_side: Option<Side>,
    /// G41/G42 programmed again while compensation runs: it starts over with the next move
    /// (§9.6.7, D104).
    comp_again: bool,
    /// The path's direction at the end of the last move in the plane (CT continues it).
    tangent: Option<Pt>,
    /// Each program level's own `DEF` variables, innermost last.
    scopes: Vec<Scope>,
    /// A program level may still define variables (nothing else has run in it yet).
    may_define: Vec<bool>,
    plc: PlcArea,
    /// Every MSG text with its line (§9.1.6); the last one is shown (`MSG()` clears).
    pub messages: Vec<(u32, String)>,
    /// A jump the block asked for, done once its other words ran.
    jump: Option<(bool, String)>,
    /// The lists a block's words are sorted into, kept for the next block.
    words: exec::Words,
    /// The run-time timers as the last preprocessing stop read them (D121).
    timers: cnc_interpreter_core::MachineTimers,
    /// The block being read again after its preprocessing stop: it runs now.
    synced: bool,
    /// A tool on the offset page is monitored by its life (`$TC_TP9` bit 1, D122): edge
    /// changes and the program's end are preprocessing stops that account its cutting time.
    life_used: bool,
    /// The machine's cutting time when the active edge's life was last accounted (`None`
    /// before the run's first preprocessing stop).
    life_start: Option<f64>,
    /// `$A_MONIFACT`: minutes of life a minute of cutting takes (1.0 at the start).
    monifact: f64,
    /// The token and item lists of the last block, their room kept for the next.
    parse_room: block::Buffers,
    /// A move's start and end in the work's coordinates, their room kept for the next move.
    here_room: Vec<f64>,
    end_room: Vec<f64>,
    /// The drilling cycle MCALL made modal.
    modal_cycle: Option<cycle_call::CycleCall>,
    /// G25/G26 working area and spindle limits, WALIMON.
    limits: limits::Limits,
    /// RNDM: the rounding of every corner (None: off); FRCM: the corners' feed.
    rndm: Option<f64>,
    frcm: Option<f64>,
    /// The corner the block's move ends with (CHF/CHR/RND/RNDM), taken by its last element.
    corner: contour::BlockCorner,
    /// A line given only its angle (`ANG=α`), waiting for the block that closes it.
    ang: Option<contour::AngPending>,
    /// The text of the program whose block runs (CYCLE72 finds label sections in it).
    program_text: Option<Arc<str>>,
    /// SF=: the thread's start angle after the spindle's index pulse, degrees (modal).
    thread_angle: f64,
    /// OFFN=, the contour's normal offset added to the cutter radius of G41/G42 (§9.15).
    contour_offset: f64,
    /// The machine position where the block in hand started (kept to spare an allocation).
    block_start: Vec<f64>,
    /// The spindle is in position control (SPOS, M19, a tap) until M3/M4/M5 or the end.
    positioned: bool,
    /// Per axis, the setting data of travel to a fixed stop: clamping torque (percent) and
    /// monitoring window (FXST, FXSW; §9.3.23).
    fxs_torque: Vec<f64>,
    fxs_window: Vec<f64>,
    /// Inside a STOPFIFO section: the machine runs it from its buffer, so no block in it may
    /// wait for the machine (D119).
    fifo: bool,
    /// The text each output of the message service sent last (serial, file), §8.4.4.
    service_last: [Option<String>; 2],
    /// The direction of the last G331 (+1 the way M3 turns), which G332 reverses; 0: none.
    tap_hand: f64,
    /// G341: WAB comes down to the contour in the plane (else G340, in space).
    approach_in_plane: bool,
    /// A WAB approach waiting for the element after the contour's start (§9.14).
    wab: Option<wab::Approach>,
    /// The motion and feed in force before the block in hand (WAB moves at them).
    block_entry: (Motion, f64),
    /// Moves an approach put before the block in hand's own (its work area check skips
    /// them: they were checked where they were made).
    moved_before: usize,
}

/// The plane of G17, G18 or G19 (`001` §9.2.2).
fn plane_of(code: u8) -> Plane {
    let (h, v, normal) = match code {
        18 => ('Z', 'X', 'Y'),
        19 => ('Y', 'Z', 'X'),
        _ => ('X', 'Y', 'Z'),
    };
    Plane {
        h,
        v,
        normal: Some(normal),
        missing: (
            Fault::PlaneAxis,
            "the plane names an axis this machine does not have",
        ),
    }
}

impl Sinumerik {
    pub fn rules() -> Rules {
        Rules {
            alarms: alarms::alarm,
            // F range 0.001…99 999.999 (§9.3.14).
            max_feed: 99_999.999,
            initial_feed: 0.0,
            needs_end: None,
            locals: 0,
            work_offsets: true,
            plane: plane_of(17),
            comp: CompRules {
                refuse_rapid: false,
                name: "tool radius compensation",
            },
            // 8 program levels including the main program (§9.11.1).
            max_call_depth: 7,
        }
    }

    pub fn new(text: &str, setup: Setup, mut library: Library) -> Sinumerik {
        // A transfer listing's later programs are stored under their names, in place of
        // stored ones, as reading the listing in stores them (D95).
        let (text, sections) = transfer::split(text);
        for s in sections {
            library.replace_named(&s.name, &s.file, s.text);
        }
        let mut core = Core::new(Sinumerik::rules(), text, setup, library);
        // G500 at program start: no settable zero offset (§9.1.6 table, `*`).
        core.work_system = NO_WORK_OFFSET;
        core.program_start = core.work_position();
        // G60, exact stop, is the power-on path mode (§9.3.16).
        core.set_path_mode(true);
        // CFC: F holds on the contour of a compensated arc (§9.1.6 `*`, §9.3.15, D98).
        core.feed_on_contour = true;
        // The tool the machine holds stays active, with its first edge (§9.6.2).
        let tool = core.setup.active_tool;
        let n = core.setup.axes.len();
        let mut front = Sinumerik {
            core,
            motion: Motion::Line,
            absolute: true,
            inch: false,
            inch_feed: false,
            pole: Pt::new(0.0, 0.0),
            polar: (0.0, 0.0),
            plane_code: 17,
            tool,
            edge: u32::from(tool > 0),
            preselected: None,
            preselected_edge: None,
            setpiece_memory: Vec::new(),
            comp_side: None,
            comp_again: false,
            tangent: None,
            scopes: vec![Scope::new()],
            may_define: vec![true],
            plc: PlcArea::default(),
            messages: Vec::new(),
            jump: None,
            words: exec::Words::default(),
            timers: cnc_interpreter_core::MachineTimers::default(),
            synced: false,
            life_used: false,
            life_start: None,
            monifact: 1.0,
            parse_room: block::Buffers::default(),
            here_room: Vec::new(),
            end_room: Vec::new(),
            modal_cycle: None,
            limits: limits::Limits::default(),
            rndm: None,
            frcm: None,
            corner: None,
            ang: None,
            program_text: None,
            thread_angle: 0.0,
            contour_offset: 0.0,
            block_start: Vec::new(),
            positioned: false,
            tap_hand: 0.0,
            approach_in_plane: false,
            wab: None,
            block_entry: (Motion::Line, 0.0),
            moved_before: 0,
            fxs_torque: vec![fxs::DEFAULT_TORQUE; n],
            fxs_window: vec![fxs::DEFAULT_WINDOW; n],
            fifo: false,
            service_last: [None, None],
        };
        front.apply_length();
        front.life_used = front.life_in_use();
        front
    }

    /// The message shown now: the last MSG's text.
    pub fn message(&self) -> &str {
        self.messages.last().map_or("", |m| m.1.as_str())
    }

    /// R parameter `n` as the program has left it.
    pub fn r(&self, n: i64) -> f64 {
        self.core.common.get(&(R_BASE + n)).copied().unwrap_or(0.0)
    }

    /// A `DEF` variable of the innermost program level (for checks).
    pub fn variable(&self, name: &str) -> Option<&Var> {
        self.scopes.last().and_then(|s| s.get(name))
    }

    /// The PLC data area's byte `k` (`$A_DBB[k]`), as the program has left it.
    pub fn plc_byte(&self, k: usize) -> Option<u8> {
        self.plc.bytes.get(k).copied()
    }

    /// The active tool and cutting edge.
    pub fn tool_edge(&self) -> (u32, u32) {
        (self.tool, self.edge)
    }

    pub fn fault(&self, f: Fault, text: impl Into<String>) -> ProgramError {
        self.core.fault(f, text)
    }

    fn eval_error(&self, e: EvalError) -> ProgramError {
        self.fault(e.fault, e.text)
    }

    // ------------------------------------------------------------------ variables

    /// Keeps one scope per program level (a call pushes one, a return pops it, a repeat
    /// of the same program starts it afresh).
    fn sync_scopes(&mut self) {
        let depth = self.core.depth();
        self.scopes.truncate(depth);
        self.may_define.truncate(depth);
        while self.scopes.len() < depth {
            self.scopes.push(Scope::new());
            self.may_define.push(true);
        }
    }

    /// The value of an expression.
    pub fn value(&self, e: &Expr) -> Result<Val, ProgramError> {
        eval(e, &|name, idx| self.read(name, idx)).map_err(|e| self.eval_error(e))
    }

    pub fn number(&self, e: &Expr) -> Result<f64, ProgramError> {
        let v = self.value(e)?;
        v.num().map_err(|e| self.eval_error(e))
    }

    fn r_index(idx: &[Val]) -> Result<i64, EvalError> {
        let k = match idx {
            [v] => v.num()?,
            _ => return Err(EvalError::new(Fault::MacroVariable, "R needs one number")),
        };
        if k.fract() != 0.0 || k < 0.0 || k >= R_COUNT as f64 {
            return Err(EvalError::new(
                Fault::MacroVariable,
                format!("R{} does not exist: R0…R299", cnc_interpreter_core::show(k)),
            ));
        }
        Ok(k as i64)
    }

    /// Reads a variable (an R parameter, a `DEF` variable of this program, a system
    /// variable).
    fn read(&self, name: &str, idx: &[Val]) -> Result<Val, EvalError> {
        if name == "R" {
            let k = Sinumerik::r_index(idx)?;
            return Ok(Val::Num(
                self.core.common.get(&(R_BASE + k)).copied().unwrap_or(0.0),
            ));
        }
        if let Some(var) = self.scopes.last().and_then(|s| s.get(name)) {
            let at = var.slot(name, idx)?;
            return Ok(var.values[at].clone());
        }
        if PlcArea::is_plc(name) {
            return self.plc.read(name, idx).map(Val::Num);
        }
        self.system(name, idx).map(Val::Num)
    }

    /// The system variables the manual's programs read (§3.12 of the inventory).
    fn system(&self, name: &str, idx: &[Val]) -> Result<f64, EvalError> {
        let unknown = || {
            EvalError::new(
                Fault::NoSuchAddress,
                format!("{name} is not defined (no variable, address or keyword of this name)"),
            )
        };
        if let Some(value) = self.monitor_read(name, idx) {
            return value;
        }
        match name {
            "$P_TOOLNO" => Ok(f64::from(self.tool)),
            "$P_TOOL" => Ok(f64::from(self.edge)),
            "$AA_IW" => {
                let axis = match idx {
                    [Val::Str(a)] => a.clone(),
                    _ => return Err(EvalError::new(Fault::MacroVariable, "$AA_IW[axis]")),
                };
                let i = axis
                    .chars()
                    .next()
                    .and_then(|c| self.core.axis(c))
                    .filter(|_| axis.len() == 1)
                    .ok_or_else(|| EvalError::new(Fault::AxisAddress, format!("no axis {axis}")))?;
                // What a following axis travelled coupled is part of where it is.
                Ok(self.core.work_position()[i] + self.core.coupled[i])
            }
            // §9.3.12: the status of the last measuring job, 1 when the probe switched; the
            // table writes it $AC_MEAS (D116).
            "$AC_MEA" | "$AC_MEAS" => match idx {
                [Val::Num(k)] if *k == 1.0 => Ok(self
                    .core
                    .measurement
                    .as_ref()
                    .map_or(0.0, |m| f64::from(u8::from(m.triggered)))),
                _ => Err(EvalError::new(
                    Fault::OutOfRange,
                    format!("{name}[1]: the 802D has measuring input 1"),
                )),
            },
            // The measured position of an axis: machine (MM) or work (MW) coordinates, as
            // the frames stand when it is read.
            "$AA_MM" | "$AA_MW" => {
                let i = match idx {
                    [Val::Str(a)] => self.axis_named(a),
                    _ => None,
                }
                .ok_or_else(|| EvalError::new(Fault::AxisAddress, format!("{name}[axis]")))?;
                let at = self.core.measured_at.as_ref().ok_or_else(|| {
                    EvalError::new(
                        Fault::MacroVariable,
                        format!("{name}: no measurement has been made in this program"),
                    )
                })?;
                Ok(if name == "$AA_MM" {
                    at[i]
                } else {
                    self.core.work_of(at)[i]
                })
            }
            // §9.3.23: 0 not at a stop, 1 at it, 2 not reached, 3 selected.
            "$AA_FXS" => {
                let i = match idx {
                    [Val::Str(a)] => self.axis_named(a),
                    _ => None,
                };
                i.map(|i| f64::from(self.core.fixed_stops[i] as u8))
                    .ok_or_else(|| EvalError::new(Fault::AxisAddress, "$AA_FXS[axis]"))
            }
            "$AA_COUP_ACT" => {
                let i = match idx {
                    [Val::Str(a)] => self.axis_named(a),
                    _ => None,
                };
                i.map(|i| self.coupling_state(i))
                    .ok_or_else(|| EvalError::new(Fault::AxisAddress, "$AA_COUP_ACT[axis]"))
            }
            _ => match counter_key(name) {
                Some(k) => Ok(self.core.common.get(&k).copied().unwrap_or(0.0)),
                None => timers::timer(&self.timers, name).unwrap_or_else(|| Err(unknown())),
            },
        }
    }

    /// Writes a variable; `name` is no address (the caller checked).
    fn write(&mut self, name: &str, idx: &[Expr], value: &Expr) -> Result<(), ProgramError> {
        let idx: Vec<Val> = idx
            .iter()
            .map(|e| self.value(e))
            .collect::<Result<_, _>>()?;
        self.write_at(name, &idx, value)
    }

    /// `R12=value`: an arithmetic parameter by its number.
    fn write_param(&mut self, number: f64, value: &Expr) -> Result<(), ProgramError> {
        self.write_at("R", &[Val::Num(number)], value)
    }

    /// Writes a variable at evaluated indexes.
    fn write_at(&mut self, name: &str, idx: &[Val], value: &Expr) -> Result<(), ProgramError> {
        // SET(…) / REP(…): successive elements from the one named (§9.9.2).
        if let Expr::Call(f, args) = value {
            if f == "SET" || f == "REP" {
                let mut vals = Vec::new();
                for a in args {
                    let a = a.as_ref().ok_or_else(|| {
                        self.fault(Fault::MacroArgument, format!("{f}: empty value"))
                    })?;
                    vals.push(self.value(a)?);
                }
                return self.write_list(name, idx, &vals, f == "REP");
            }
        }
        let v = self.value(value)?;
        self.write_one(name, idx, v)
    }

    fn write_one(&mut self, name: &str, idx: &[Val], v: Val) -> Result<(), ProgramError> {
        let r = self.write_value(name, idx, v);
        r.map_err(|e| self.eval_error(e))
    }

    fn write_value(&mut self, name: &str, idx: &[Val], v: Val) -> Result<(), EvalError> {
        if name == "R" {
            let k = Sinumerik::r_index(idx)?;
            let x = v.num()?;
            if !x.is_finite() {
                return Err(EvalError::new(Fault::OutOfRange, "R value not finite"));
            }
            self.core.common.insert(R_BASE + k, x);
            return Ok(());
        }
        if let Some(var) = self.scopes.last_mut().and_then(|s| s.get_mut(name)) {
            let at = var.slot(name, idx)?;
            var.values[at] = var.coerce(name, v)?;
            return Ok(());
        }
        if PlcArea::is_plc(name) {
            return self.plc.write(name, idx, v.num()?);
        }
        if let Some(k) = counter_key(name).filter(|_| name.ends_with("_PARTS")) {
            let x = v.num()?;
            if x.fract() != 0.0 || !(0.0..=999_999_999.0).contains(&x) {
                return Err(EvalError::new(
                    Fault::OutOfRange,
                    format!("{name}: 0…999999999"),
                ));
            }
            self.core.common.insert(k, x);
            return Ok(());
        }
        if let Some(done) = self.monitor_write(name, idx, &v) {
            return done;
        }
        if name.starts_with('$') {
            return Err(EvalError::new(
                Fault::MacroReadOnly,
                format!("{name} cannot be written from a program"),
            ));
        }
        Err(EvalError::new(
            Fault::NoSuchAddress,
            format!("{name} is not defined (no variable, address or keyword of this name)"),
        ))
    }

    /// SET/REP into an array (or R parameters from the one named on).
    fn write_list(
        &mut self,
        name: &str,
        idx: &[Val],
        vals: &[Val],
        rep: bool,
    ) -> Result<(), ProgramError> {
        if name == "R" {
            let k = Sinumerik::r_index(idx).map_err(|e| self.eval_error(e))?;
            for (j, v) in vals.iter().enumerate() {
                self.write_one("R", &[Val::Num((k + j as i64) as f64)], v.clone())?;
            }
            return Ok(());
        }
        let Some(var) = self.scopes.last().and_then(|s| s.get(name)).cloned() else {
            return Err(self.fault(
                Fault::MacroVariable,
                format!("SET/REP need an array: {name} is none"),
            ));
        };
        let start = if idx.is_empty() {
            0
        } else {
            var.slot(name, idx).map_err(|e| self.eval_error(e))?
        };
        let n = var.values.len();
        let list: Vec<Val> = if rep {
            let v = vals.first().cloned().unwrap_or(Val::Num(0.0));
            vec![v; n - start]
        } else {
            if start + vals.len() > n {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!(
                        "SET: {} values from element {start} overrun {name}[{n}]",
                        vals.len()
                    ),
                ));
            }
            vals.to_vec()
        };
        let mut coerced = Vec::with_capacity(list.len());
        for v in list {
            coerced.push(var.coerce(name, v).map_err(|e| self.eval_error(e))?);
        }
        if let Some(var) = self.scopes.last_mut().and_then(|s| s.get_mut(name)) {
            var.values[start..start + coerced.len()].clone_from_slice(&coerced);
        }
        Ok(())
    }

    /// `DEF`: new variables of this program, at its start only (§9.9.2).
    fn define(&mut self, d: &block::Def) -> Result<(), ProgramError> {
        if !self.may_define.last().copied().unwrap_or(false) {
            return Err(self.fault(
                Fault::Macro,
                "DEF only at the start of a program, before its other blocks",
            ));
        }
        for v in &d.vars {
            if !name_ok(&v.name) || names::is_address(&v.name) || self.core.axis_named(&v.name) {
                return Err(self.fault(
                    Fault::Macro,
                    format!("{} cannot name a variable: 2–32 letters, digits or _, the first two letters, and no address or keyword", v.name),
                ));
            }
            if self
                .scopes
                .last()
                .is_some_and(|s| s.contains_key(v.name.as_ref()))
            {
                return Err(self.fault(Fault::Macro, format!("{} is defined twice", v.name)));
            }
            let var = Var::new(d.ty, d.len, &v.dims);
            if let Some(s) = self.scopes.last_mut() {
                s.insert(v.name.to_string(), var);
            }
            if let Some(init) = &v.init {
                self.write(&v.name, &[], init)?;
            }
        }
        Ok(())
    }
}

impl Sinumerik {
    /// M2/M30 of the main program finishes a workpiece (§9.12.2, decision D82): the total and
    /// the actual count go up by one; the actual count starts again from 0 once it reaches a
    /// required count above 0. Both stay within 0…999 999 999.
    pub(super) fn count_part(&mut self) {
        let [Some(total), Some(required), Some(actual)] =
            ["$AC_TOTAL_PARTS", "$AC_REQUIRED_PARTS", "$AC_ACTUAL_PARTS"].map(counter_key)
        else {
            return;
        };
        let get = |me: &Self, k: i64| me.core.common.get(&k).copied().unwrap_or(0.0);
        let next = |n: f64| if n >= 999_999_999.0 { 0.0 } else { n + 1.0 };
        let t = next(get(self, total));
        self.core.common.insert(total, t);
        let need = get(self, required);
        let a = next(get(self, actual));
        let a = if need > 0.0 && a >= need { 0.0 } else { a };
        self.core.common.insert(actual, a);
    }
}

/// Where the part counters of §9.12 live in the core's common store.
fn counter_key(name: &str) -> Option<i64> {
    let names = [
        "$AC_TOTAL_PARTS",
        "$AC_REQUIRED_PARTS",
        "$AC_ACTUAL_PARTS",
        "$AC_SPECIAL_PARTS",
    ];
    names
        .iter()
        .position(|n| *n == name)
        .map(|i| R_BASE + 1000 + i as i64)
}

/// A variable name: 2–32 characters, letters, digits or `_`, the first two letters or `_`
/// (§9.9.2).
fn name_ok(n: &str) -> bool {
    let c: Vec<char> = n.chars().collect();
    (2..=32).contains(&c.len())
        && c[..2].iter().all(|c| c.is_ascii_alphabetic() || *c == '_')
        && c.iter().all(|c| c.is_ascii_alphanumeric() || *c == '_')
}

trait AxisNamed {
    fn axis_named(&self, name: &str) -> bool;
}

impl AxisNamed for Core {
    fn axis_named(&self, name: &str) -> bool {
        name.len() == 1 && name.chars().next().and_then(|c| self.axis(c)).is_some()
    }
}

impl FrontEnd for Sinumerik {
    fn core(&self) -> &Core {
        &self.core
    }
    fn core_mut(&mut self) -> &mut Core {
        &mut self.core
    }
    fn read_block(&mut self) -> Result<(), ProgramError> {
        let Some((text, range)) = self.core.next_line() else {
            // The end of a called program returns as M17 does; of the main program, ends it.
            if self.core.depth() > 1 {
                self.core.return_from_call();
                self.sync_scopes();
                return Ok(());
            }
            // The last edge's life is accounted before the program ends (D122).
            if self.life_used {
                if !std::mem::take(&mut self.synced) {
                    self.synced = true;
                    return self.core.sync_with_machine();
                }
                self.machine_read();
            }
            return self.core.end_of_main();
        };
        self.sync_scopes();
        let line: &str = &text[range];
        let trimmed = line.trim_start();
        // Transfer headers (`%_N_NAME_MPF`) and empty lines are no blocks.
        if trimmed.starts_with('%') || lex::strip_comment(trimmed).trim().is_empty() {
            return Ok(());
        }
        let block = match self.parse_room.parse(line) {
            Ok(b) => b,
            Err(e) => return Err(self.fault(Fault::DataFormat, e)),
        };
        if block.skip && self.core.setup.block_skip {
            self.parse_room.recycle(block);
            return Ok(());
        }
        // A block that reads the machine (a run-time timer, D121) or changes a life-monitored
        // tool's edge (D122) runs after a preprocessing stop has read the timers.
        if std::mem::take(&mut self.synced) {
            self.machine_read();
        } else if timers::reads_timer(line) || self.life_stop(&block, line) {
            self.parse_room.recycle(block);
            self.synced = true;
            self.core.sync_with_machine()?;
            self.core.read_line_again();
            return Ok(());
        }
        let done = self.run_block(&block, &text);
        self.parse_room.recycle(block);
        done
    }
}

/// The errors each line shows on its own (its syntax), without running it.
pub fn line_errors(text: &str) -> Vec<ProgramError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with('%') {
            continue;
        }
        if let Err(e) = block::parse(line) {
            out.push(ProgramError::new(
                alarms::alarm(Fault::DataFormat),
                i as u32 + 1,
                e,
            ));
        }
    }
    out
}

/// Finds the line a jump goes to: a label (`NAME:`) or a block number (`N100`), forward
/// from the block after `from` to the end, or backward from `from` (the jumping block
/// included) to the top (§9.10.2).
fn find_target(
    text: &Arc<str>,
    from: cnc_interpreter_core::Pos,
    after: cnc_interpreter_core::Pos,
    forward: bool,
    target: &str,
) -> Option<cnc_interpreter_core::Pos> {
    let mut pos = if forward {
        after
    } else {
        cnc_interpreter_core::Pos::default()
    };
    let mut found = None;
    while let Some((line, next)) = cnc_interpreter_core::read_line(text, pos) {
        if !forward && pos.offset > from.offset {
            break;
        }
        if block_is(line, target) {
            if forward {
                return Some(pos);
            }
            found = Some(pos);
        }
        pos = next;
    }
    found
}

/// The line carries label `target`, or block number `target` (`N100`).
fn block_is(line: &str, target: &str) -> bool {
    let toks = match lex::tokens(lex::strip_comment(line)) {
        Ok(t) => t,
        // A line that does not parse may still carry the label: read up to the colon.
        Err(_) => match line.split_once(':') {
            Some((head, _)) => lex::tokens(head).unwrap_or_default(),
            None => return false,
        },
    };
    let mut t = toks.iter().peekable();
    if matches!(t.peek(), Some(lex::Tok::Op("/"))) {
        t.next();
    }
    if let Some(lex::Tok::Word {
        letter: 'N',
        digits,
        ..
    }) = t.peek()
    {
        if target == format!("N{}", digits.trim_start_matches('0')) {
            return true;
        }
        t.next();
    }
    matches!((t.next(), t.next()), (Some(lex::Tok::Name(n)), Some(lex::Tok::Op(":"))) if n == target)
}
