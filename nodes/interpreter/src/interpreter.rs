//! The interpreter core: reads a program block by block and yields canonical commands.
//!
//! Pure and streaming: it holds the program text and a cursor, and produces commands only as
//! they are asked for, so the motion queue's credit decides how far ahead it reads. An error
//! stops it for good: nothing after the bad line is produced, and nothing of the bad block.
//!
//! A block's path: [`crate::syntax`] parses the line, [`Interpreter::decode`] checks its words
//! against the dialect's tables, [`Interpreter::execute`] applies modal state, offsets and
//! program flow, and motion-producing blocks end in [`Interpreter::emit`], which turns work
//! coordinates into machine coordinates.

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

use crate::canon::{Aux, Canon, Command};
use crate::dialect::{Dialect, HoleKind, ReturnOrder, Rules, ToolMacro, G, M};
use crate::error::{Fault, ProgramError};
use crate::expr::{truth, variable_number, EvalError, Expr, Value, Variables};
use crate::geometry::{self, ArcError, Elem, Pt};
use crate::program::{find_number, line_number, read_line, Library, Pos};
use crate::rough::{Move, Rough};
use crate::setup::{Setup, MAX_OFFSET};
use crate::syntax::{parse_line, Line, Stmt};

/// Most M codes in one block (`000` alarm 10; decision D6).
const MAX_M_PER_BLOCK: usize = 3;
/// Deepest subprogram nesting (`000` §4.1.3: four levels).
const MAX_CALL_DEPTH: usize = 4;
/// Most blocks in a G70–G73 contour (`000` alarm 45).
const MAX_CONTOUR_BLOCKS: usize = 100;
/// Most blocks read without producing a command before the program is judged stuck in a
/// loop that never moves (macro `GOTO` loops): alarm instead of hanging.
const MAX_SILENT_BLOCKS: u32 = 1_000_000;
/// Most commands a check collects: a program that jumps back forever must end a check with an
/// alarm, not hang it.
pub const MAX_CHECK_COMMANDS: usize = 5_000_000;
/// Most passes or pecks one cycle block may generate.
const MAX_CYCLE_STEPS: usize = 1_000_000;
/// Number of local variables per program level (`000` §5.27.2: #1–#40).
const LOCALS: usize = 41;

/// A block's words after evaluation, sorted by meaning.
#[derive(Debug, Default)]
struct Block {
    number: Option<u32>,
    /// G codes in the order written, with their group.
    g: Vec<(u8, G, u32)>,
    m: Vec<(M, u32)>,
    /// Address values other than G, M, N, O: letter → (value, written with a decimal point).
    words: Words,
}

/// A block's address values by letter A–Z: a fixed table, so reading a block allocates
/// nothing for its words (the parser gives only upper-case letters).
#[derive(Debug, Default)]
struct Words([Option<(f64, bool)>; 26]);

impl Words {
    fn slot(c: char) -> Option<usize> {
        c.is_ascii_uppercase().then(|| usize::from(c as u8 - b'A'))
    }
    fn get(&self, c: &char) -> Option<&(f64, bool)> {
        Self::slot(*c).and_then(|i| self.0[i].as_ref())
    }
    fn contains_key(&self, c: &char) -> bool {
        self.get(c).is_some()
    }
    /// Sets the letter's value; returns the value it had.
    fn insert(&mut self, c: char, w: (f64, bool)) -> Option<(f64, bool)> {
        Self::slot(c).and_then(|i| self.0[i].replace(w))
    }
    /// The letters given, in alphabetical order.
    fn iter(&self) -> impl Iterator<Item = (char, (f64, bool))> + '_ {
        (b'A'..=b'Z')
            .zip(self.0.iter())
            .filter_map(|(c, w)| w.map(|w| (char::from(c), w)))
    }
}

impl Block {
    fn get(&self, c: char) -> Option<f64> {
        self.words.get(&c).map(|w| w.0)
    }
    fn has(&self, c: char) -> bool {
        self.words.contains_key(&c)
    }
    fn group(&self, group: u8) -> Option<G> {
        self.g.iter().rev().find(|g| g.0 == group).map(|g| g.1)
    }
    fn has_g(&self, meaning: G) -> bool {
        self.g.iter().any(|g| g.1 == meaning)
    }
}

/// A loop or block-range repetition inside one program text.
#[derive(Debug, Clone)]
enum Repeat {
    /// Run lines up to and including the one numbered `last`, `remaining` more times (None:
    /// forever), then continue at `then` (None: after `last`), optionally returning to `home`.
    Range {
        first: Pos,
        last: u32,
        remaining: Option<u32>,
        then: Option<Pos>,
        home: Option<Vec<f64>>,
        /// Program end of the block that started the range (`G70 P Q M30`), run after it.
        end_code: Option<i32>,
    },
    /// GTC2E `M98 P L`: a subroutine by line number, ended by M99.
    LineCall {
        first: Pos,
        remaining: u32,
        ret: Pos,
    },
    /// GTC2E `G22 L` … `G80`.
    Loop { first: Pos, remaining: u32 },
}

/// One program level: the main program or a called subprogram.
#[derive(Debug, Clone)]
struct Frame {
    text: Arc<str>,
    name: String,
    pos: Pos,
    /// Times the subprogram still runs after this pass (M98 repeat count).
    remaining: u32,
    repeats: Vec<Repeat>,
    locals: Vec<Value>,
    /// Open WHILE … DO loops: loop number and where its WHILE line starts.
    loops: Vec<(u32, Pos)>,
}

/// Retained words of a Huaxing single cycle (G90/G92/G94, `000` §5.21.3).
#[derive(Debug, Clone, Copy, Default)]
struct CycleWords {
    x: Option<f64>,
    z: Option<f64>,
    r: f64,
}

/// Retained definition of a GTC2E cycle: the shape relative to the start point, repeated by
/// follow-on blocks that move the start point (`002` §4.3.2-5..10).
#[derive(Debug, Clone, Copy)]
struct GtcCycle {
    kind: G,
    dx: f64,
    dz: f64,
    lead: f64,
    starts: u32,
    dwell: f64,
}

/// Thread modal words (`000` §5.23.1: F/I lead, J/K run-out).
#[derive(Debug, Clone, Copy, Default)]
struct ThreadWords {
    lead: f64,
    j: Option<f64>,
    k: Option<f64>,
}

/// GTC2E G31 settings: X retract length and early-retract distance.
#[derive(Debug, Clone, Copy, Default)]
struct GtcRetract {
    u: Option<f64>,
    w: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SpindleDir {
    Stopped,
    Cw,
    Ccw,
}

/// Streaming interpreter for one program run.
pub struct Interpreter {
    dialect: Dialect,
    rules: Rules,
    setup: Setup,
    library: Library,
    frames: Vec<Frame>,
    /// Commanded machine position per axis (X as diameter).
    pos: Vec<f64>,
    /// Work position at the program start (GTC2E G26/G27/G29 return there).
    program_start: Vec<f64>,
    /// Work position at the start of the previous block (GTC2E G60).
    previous_start: Vec<f64>,
    /// GTC2E G25 memory.
    stored: Option<Vec<f64>>,
    motion: G,
    /// G17/G18/G19 on the mill (the lathe always turns in Z-X).
    plane: G,
    incremental: bool,
    feed: f64,
    feed_per_rev: bool,
    exact_stop_mode: bool,
    css: bool,
    css_speed: f64,
    /// Last programmed spindle speed in rpm.
    rpm: f64,
    /// Last spindle speed sent to the PLC.
    sent_rpm: Option<f64>,
    /// G50 S clamp.
    max_rpm: Option<f64>,
    /// GTC2E G96: the rpm and |X| where G96 was given (linear rpm rule, decision D18).
    gtc_css_from: (f64, f64),
    spindle: SpindleDir,
    /// Tool-nose radius compensation while G41/G42 is in force.
    nose_comp: Option<nose::NoseComp>,
    /// Machine position of the last G28/G30 intermediate point, for G29.
    intermediate: Option<Vec<f64>>,
    /// Where the line being run starts (a WHILE comes back to it).
    block_start: Pos,
    /// The mill's D: the offset whose radius G41/G42 use (modal, D0 = no radius).
    radius_offset: u32,
    /// G40 given: the next move leaves compensation.
    nose_cancel: bool,
    /// A G01 with chamfer L or rounding D, waiting for the next move.
    corner: Option<corner::Corner>,
    /// Set while compensated moves are being queued (they are not compensated again).
    emitting_comp: bool,
    /// While compensation holds an element back, commands from this index of `pending` on
    /// wait for it (they come after it in the program).
    hold_at: Option<usize>,
    work_system: u8,
    /// G50 floating shift, G52 local shift and GTC2E cumulative shifts, per axis.
    shift: Vec<f64>,
    tool_offset: Vec<f64>,
    /// The tool last commanded (T or M57), for M52 and the tool-change macro's #1.
    tool: u32,
    /// The frame depth of a running tool-change macro: T words inside it do not call it again.
    tool_macro_depth: Option<usize>,
    /// Active offset number (0 = none).
    offset_number: u32,
    gang_mode: bool,
    return_order: ReturnOrder,
    thread: ThreadWords,
    cycle: CycleWords,
    gtc_cycle: Option<GtcCycle>,
    gtc_retract: GtcRetract,
    compound: compound::CompoundWords,
    /// G74/G75 retract per peck (`000` GS#43 default 1 mm).
    groove_retract: f64,
    /// G83/G87 modal words (`000` §5.22.7).
    drill: drilling::DrillWords,
    /// The mill's modal hole-machining cycle (G73–G89 until G80 or a group-01 code).
    hole: Option<hole_cycle::HoleCycle>,
    /// G99: cycles return to the R level (G98: to the initial level).
    cycle_return_r: bool,
    /// The way the spindle turned before a cycle stopped or oriented it.
    cycle_spindle: SpindleDir,
    /// G43 (+1) / G44 (−1) / G49 (0) on the mill.
    length_sign: i8,
    /// The H offset number of tool length compensation.
    length_offset: u32,
    /// G52 local system zero per axis, in work coordinates (mill).
    local: Vec<f64>,
    /// G07 K L linear chip breaking while set (`000` §5.6).
    chip_break: Option<chip_break::ChipBreak>,
    /// G92 number of starts (`000` §5.23.5, modal).
    cycle_starts: u32,
    /// The sign of the approach move before a GTC2E thread cycle (its retract goes the other way).
    last_x_direction: f64,
    common: HashMap<i64, f64>,
    pending: VecDeque<Canon>,
    line: u32,
    done: bool,
    error: Option<ProgramError>,
    silent_blocks: u32,
    saw_end: bool,
}

impl Interpreter {
    pub fn new(dialect: Dialect, text: &str, setup: Setup) -> Self {
        Interpreter::with_library(dialect, text, setup, Library::new())
    }

    pub fn with_library(dialect: Dialect, text: &str, setup: Setup, mut library: Library) -> Self {
        let rules = dialect.rules();
        // A tape of several programs: the first runs, the others go into program memory
        // beside the library's (`003` §7.1; GTC2E has no O programs).
        let mut text = text;
        if dialect != Dialect::Gtc2eLathe {
            let (main_end, others) = crate::program::split_programs(text);
            for (number, sub) in others {
                library.insert(number, &format!("O{number:04}"), sub);
            }
            text = &text[..main_end];
        }
        let n = setup.axes.len();
        let mut common = HashMap::new();
        for (&k, &v) in &setup.kept {
            common.insert(k, v);
        }
        let mut it = Interpreter {
            dialect,
            rules,
            library,
            frames: vec![Frame {
                text: Arc::from(text),
                name: String::new(),
                pos: Pos::default(),
                remaining: 0,
                repeats: Vec::new(),
                locals: vec![None; LOCALS],
                loops: Vec::new(),
            }],
            pos: setup.start.clone(),
            program_start: Vec::new(),
            previous_start: Vec::new(),
            stored: None,
            motion: rules.initial_motion,
            plane: G::PlaneXy,
            incremental: false,
            feed: rules.initial_feed,
            feed_per_rev: false,
            exact_stop_mode: false,
            css: false,
            css_speed: 0.0,
            rpm: 0.0,
            sent_rpm: None,
            max_rpm: None,
            gtc_css_from: (0.0, 0.0),
            spindle: SpindleDir::Stopped,
            nose_comp: None,
            radius_offset: 0,
            block_start: Pos::default(),
            intermediate: None,
            nose_cancel: false,
            corner: None,
            emitting_comp: false,
            hold_at: None,
            work_system: setup.work_system.min(5),
            shift: vec![0.0; n],
            tool_offset: vec![0.0; n],
            tool: 0,
            tool_macro_depth: None,
            offset_number: 0,
            gang_mode: false,
            return_order: ReturnOrder::XThenZ,
            thread: ThreadWords::default(),
            cycle: CycleWords::default(),
            gtc_cycle: None,
            gtc_retract: GtcRetract::default(),
            last_x_direction: -1.0,
            cycle_starts: 1,
            compound: compound::CompoundWords::default(),
            groove_retract: 1.0,
            drill: drilling::DrillWords::default(),
            chip_break: None,
            hole: None,
            cycle_return_r: false,
            cycle_spindle: SpindleDir::Cw,
            length_sign: 0,
            length_offset: 0,
            local: vec![0.0; n],
            common,
            pending: VecDeque::new(),
            line: 0,
            done: false,
            error: None,
            silent_blocks: 0,
            saw_end: false,
            setup,
        };
        it.program_start = it.work_position();
        it.previous_start = it.program_start.clone();
        it
    }

    /// The next canonical command; `Ok(None)` once the program has ended.
    /// The kept variables and the offset page as the program has left them, for the shell to
    /// store.
    pub fn memory(&self) -> crate::setup::Memory {
        crate::setup::Memory {
            kept: self
                .common
                .iter()
                .filter(|(n, _)| crate::setup::Memory::is_kept(**n))
                .map(|(&n, &v)| (n, v))
                .collect(),
            tools: self.setup.offsets.tools.clone(),
            work: self.setup.offsets.work.clone(),
        }
    }

    pub fn next_command(&mut self) -> Result<Option<Canon>, ProgramError> {
        loop {
            if let Some(e) = &self.error {
                return Err(e.clone());
            }
            if self.hold_at != Some(0) {
                if let Some(c) = self.pending.pop_front() {
                    if let Some(h) = self.hold_at.as_mut() {
                        *h -= 1;
                    }
                    self.silent_blocks = 0;
                    return Ok(Some(c));
                }
            }
            if self.done {
                return Ok(None);
            }
            self.silent_blocks += 1;
            let result = if self.silent_blocks > MAX_SILENT_BLOCKS {
                Err(self.fault(Fault::Macro, "program loops without producing any command"))
            } else {
                self.read_block()
            };
            if let Err(e) = result {
                self.error = Some(e.clone());
                self.pending.clear();
                return Err(e);
            }
        }
    }

    // ---------------------------------------------------------------- errors

    fn fault(&self, f: Fault, text: impl Into<String>) -> ProgramError {
        let mut e = ProgramError::new(self.dialect.alarm(f), self.line, text);
        if let Some(frame) = self.frames.last() {
            e.program.clone_from(&frame.name);
        }
        e
    }

    fn eval_err(&self, e: EvalError) -> ProgramError {
        self.fault(e.1, e.0)
    }

    // ---------------------------------------------------------------- reading

    fn frame(&mut self) -> &mut Frame {
        // There is always a main frame: the last one is popped only by ending the program.
        let last = self.frames.len() - 1;
        &mut self.frames[last]
    }

    /// Reads one line and queues its commands.
    fn read_block(&mut self) -> Result<(), ProgramError> {
        let frame = self.frame();
        let text = frame.text.clone();
        let pos = frame.pos;
        let Some((raw, next)) = read_line(&text, pos) else {
            return self.end_of_text();
        };
        self.frame().pos = next;
        self.block_start = pos;
        self.line = next.line;
        let line = parse_line(raw, self.rules.macros).map_err(|e| self.fault(e.fault, e.text))?;
        if line.percent && !self.saw_any_block() && line.stmt == Stmt::Empty {
            return Ok(()); // `%` opening a tape
        }
        if line.percent {
            return self.end_of_text();
        }
        if line.skip.is_some() && self.setup.block_skip {
            return self.after_line(line_number(raw));
        }
        self.statement(&line, &line.stmt)?;
        self.after_line(line.number)
    }

    fn saw_any_block(&self) -> bool {
        self.line > 1 || self.frames.len() > 1
    }

    /// End of the text without M02/M30.
    fn end_of_text(&mut self) -> Result<(), ProgramError> {
        if self.frames.len() > 1 {
            // A subprogram that runs off its end returns like M99.
            return self.subprogram_return();
        }
        if self.rules.needs_end && !self.saw_end {
            return Err(self.fault(Fault::NoProgramEnd, "program has no M02, M20 or M30"));
        }
        self.finish();
        Ok(())
    }

    fn finish(&mut self) {
        // A chamfer with no move after it: the line runs to its corner (decision D31).
        let _ = self.resolve_corner(None);
        // Program end cancels tool-nose compensation (`000` §5.3): the held element ends at
        // its offset end.
        if let Some(mut comp) = self.nose_comp.take() {
            let outs = comp.flush();
            let here = self.work_position();
            let _ = self.emit_outs(outs, &here);
        }
        self.hold_at = None;
        self.push(Command::ProgramEnd);
        self.done = true;
    }

    /// Range repeats end after the line numbered `last` has run.
    fn after_line(&mut self, number: Option<u32>) -> Result<(), ProgramError> {
        let Some(n) = number else { return Ok(()) };
        loop {
            let frame = self.frame();
            let Some(Repeat::Range {
                first,
                last,
                remaining,
                then,
                home,
                end_code,
            }) = frame.repeats.last().cloned()
            else {
                return Ok(());
            };
            if last != n {
                return Ok(());
            }
            match remaining {
                Some(r) if r <= 1 => {
                    frame.repeats.pop();
                    if let Some(t) = then {
                        frame.pos = t;
                    }
                    if let Some(home) = home {
                        self.rapid_to(&home);
                    }
                    if let Some(code) = end_code {
                        self.saw_end = true;
                        self.aux(Aux::M(code));
                        self.finish();
                        return Ok(());
                    }
                    // An enclosing range may end on the same line.
                    continue;
                }
                Some(r) => {
                    if let Some(Repeat::Range { remaining, .. }) = frame.repeats.last_mut() {
                        *remaining = Some(r - 1);
                    }
                    frame.pos = first;
                }
                None => {
                    if self.setup.single_pass {
                        self.finish();
                    } else {
                        self.frame().pos = first;
                    }
                }
            }
            return Ok(());
        }
    }

    fn statement(&mut self, line: &Line, stmt: &Stmt) -> Result<(), ProgramError> {
        match stmt {
            Stmt::Empty => Ok(()),
            Stmt::Assign { var, value } => {
                let n = self.var_number(var)?;
                let v = value.eval(self).map_err(|e| self.eval_err(e))?;
                self.write_var(n, v)
            }
            Stmt::Goto(target) => {
                let v = target
                    .eval(self)
                    .map_err(|e| self.eval_err(e))?
                    .ok_or_else(|| self.fault(Fault::Macro, "GOTO to a null value"))?;
                let n = variable_number(v).map_err(|e| self.eval_err(e))?;
                if !(0..=99999).contains(&n) {
                    return Err(
                        self.fault(Fault::TargetNotFound, format!("GOTO {n}: no such block"))
                    );
                }
                self.jump_to_number(n as u32)
            }
            Stmt::If { cond, then } => {
                let c = cond.eval(self).map_err(|e| self.eval_err(e))?;
                if truth(c) {
                    self.statement(line, then)
                } else {
                    Ok(())
                }
            }
            Stmt::While { cond, id } => self.while_loop(cond.as_ref(), *id),
            Stmt::End(id) => self.end_loop(*id),
            Stmt::Words(words)
                if self.dialect == Dialect::FanucMill
                    && words.iter().any(|w| {
                        w.letter == 'G'
                            && matches!(w.value, Expr::Num { value, .. } if value == 65.0)
                    }) =>
            {
                self.macro_call(words)
            }
            Stmt::Words(words) => {
                let mut b = Block {
                    number: line.number,
                    ..Block::default()
                };
                self.decode(words, &mut b)?;
                self.execute(b)
            }
        }
    }

    fn var_number(&self, var: &Expr) -> Result<i64, ProgramError> {
        let v = var
            .eval(self)
            .map_err(|e| self.eval_err(e))?
            .ok_or_else(|| self.fault(Fault::MacroVariable, "variable number is null"))?;
        variable_number(v).map_err(|e| self.eval_err(e))
    }

    fn jump_to_number(&mut self, n: u32) -> Result<(), ProgramError> {
        let text = self.frame().text.clone();
        let pos = find_number(&text, self.frame().pos, n)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("block N{n} not found")))?;
        self.frame().pos = pos;
        Ok(())
    }

    // ---------------------------------------------------------------- variables

    fn write_var(&mut self, n: i64, v: Value) -> Result<(), ProgramError> {
        if self.dialect == Dialect::FanucMill {
            return self.fanuc_write(n, v);
        }
        match n {
            1..=40 => {
                self.frame().locals[n as usize] = v;
                Ok(())
            }
            100..=289 => {
                match v {
                    Some(x) => self.common.insert(n, x),
                    None => self.common.remove(&n),
                };
                Ok(())
            }
            // G54–G59 zero offsets (`000` §6.2): what a program sets is kept (decision D33).
            5220..=5325 if (n - 5220) % 20 < 6 => {
                let system = ((n - 5220) / 20) as u8;
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][((n - 5220) % 20) as usize];
                self.write_work_offset(n, system, letter, v, Fault::Macro)
            }
            4001..=4499 => {
                let (table, num) = (n / 100 - 40, (n % 100) as u32);
                let x = v.unwrap_or(0.0);
                let t = self.setup.offsets.tools.entry(num).or_default();
                match table {
                    0 => t.x = x,
                    2 => t.z = x,
                    3 => t.radius = x,
                    4 => t.tip = x.clamp(0.0, 9.0) as u8,
                    _ => return Err(self.fault(Fault::Macro, format!("#{n}: no Y axis offsets"))),
                }
                Ok(())
            }
            _ => Err(self.fault(Fault::MacroReadOnly, format!("#{n} cannot be written"))),
        }
    }

    /// Variable `n` sets work system `system`'s zero on axis `letter` (`fault` when the value
    /// is beyond ±99999.999).
    fn write_work_offset(
        &mut self,
        n: i64,
        system: u8,
        letter: char,
        v: Value,
        fault: Fault,
    ) -> Result<(), ProgramError> {
        let x = v.unwrap_or(0.0);
        if !x.is_finite() || x.abs() > 99_999.0 {
            return Err(self.fault(fault, format!("#{n}: offset {x} out of range")));
        }
        self.setup
            .offsets
            .work
            .entry(system)
            .or_default()
            .insert(letter, x);
        Ok(())
    }

    // ---------------------------------------------------------------- decoding

    /// Evaluates and checks every word of a block.
    fn decode(&self, words: &[crate::syntax::Word], b: &mut Block) -> Result<(), ProgramError> {
        let mut groups: Vec<u32> = Vec::new();
        let mut m_groups: Vec<u32> = Vec::new();
        for w in words {
            let value = w.value.eval(self).map_err(|e| self.eval_err(e))?;
            // A null word disappears (`000` §5.27.3).
            let Some(v) = value else { continue };
            let point = w.value.has_point();
            match w.letter {
                'O' | 'N' => {}
                'G' => {
                    let (x10, code) = self.lookup('G', v, |n| self.dialect.g_code(n))?;
                    if let G::Unsupported(why) = code.meaning {
                        return Err(self.fault(Fault::NotSupported, format!("G{}: {why}", show(v))));
                    }
                    self.one_per_group('G', v, code.group != 0, code.group as u32, &mut groups)?;
                    b.g.push((code.group, code.meaning, x10));
                }
                'M' => {
                    let (x10, m) = self.lookup('M', v, |n| self.dialect.m_code(n))?;
                    if let M::Unsupported(why) = m {
                        return Err(self.fault(Fault::NotSupported, format!("M{}: {why}", show(v))));
                    }
                    self.one_per_group('M', v, true, gtc_m_group(x10), &mut m_groups)?;
                    b.m.push((m, x10));
                    if b.m.len() > MAX_M_PER_BLOCK {
                        return Err(self.fault(Fault::TooManyM, "more than 3 M codes in one block"));
                    }
                }
                c => {
                    if b.words.insert(c, (v, point)).is_some() {
                        return Err(self.fault(
                            Fault::RepeatedWord,
                            format!("address {c} twice in one block"),
                        ));
                    }
                }
            }
        }
        // Group 00 and group 01 in one block (`000` alarm 8). G04 and the coordinate codes
        // are allowed with motion words only through their own meaning; G09 is group 15.
        // FANUC 0-M allows both (`G53 G00 Z0`): the group-00 code acts, the other stays modal.
        if self.dialect.is_lathe() && self.dialect != Dialect::Gtc2eLathe {
            let g0 = b.g.iter().any(|g| g.0 == 0);
            let g1 = b.g.iter().any(|g| g.0 == 1);
            if g0 && g1 {
                return Err(self.fault(
                    Fault::Group00With01,
                    "G codes of groups 00 and 01 in one block",
                ));
            }
        }
        for (c, (v, _)) in b.words.iter() {
            let axis_word = self.setup.axes.contains(&c)
                || self
                    .setup
                    .axes
                    .iter()
                    .any(|&a| self.inc_letter(a) == Some(c));
            let known = axis_word
                || matches!(
                    c,
                    'F' | 'S' | 'T' | 'P' | 'Q' | 'R' | 'I' | 'J' | 'K' | 'L' | 'D' | 'E'
                )
                || (c == 'H' && !self.dialect.is_lathe())
                || (c == 'U' || c == 'W')
                    && self.dialect.is_lathe()
                    && self.dialect != Dialect::IsoLathe;
            if !known {
                return Err(self.fault(
                    Fault::NoSuchAddress,
                    format!("address {c}: no such word or axis on this machine"),
                ));
            }
            let limit = match c {
                'F' => f64::MAX,
                'P' | 'Q' | 'K' | 'H' | 'L' => 1e9,
                _ => self.rules.max_coordinate,
            };
            if v.abs() > limit {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("{c}{} out of range ±{limit}", show(v)),
                ));
            }
        }
        Ok(())
    }

    /// A G or M word's code number (×10) and its meaning in the dialect's table.
    fn lookup<T>(
        &self,
        letter: char,
        v: f64,
        table: impl Fn(u32) -> Option<T>,
    ) -> Result<(u32, T), ProgramError> {
        code_x10(v)
            .and_then(|n| Some((n, table(n)?)))
            .ok_or_else(|| {
                self.fault(
                    Fault::UndefinedCode,
                    format!("undefined {letter} code {letter}{}", show(v)),
                )
            })
    }

    /// GTC2E allows one code per modal group in a block (`002` §4.1 rule 1, message 16).
    fn one_per_group(
        &self,
        letter: char,
        v: f64,
        modal: bool,
        group: u32,
        seen: &mut Vec<u32>,
    ) -> Result<(), ProgramError> {
        if self.dialect == Dialect::Gtc2eLathe && modal && seen.contains(&group) {
            return Err(self.fault(
                Fault::SameGroup,
                format!(
                    "{letter}{} shares its group with another {letter} code of the block",
                    show(v)
                ),
            ));
        }
        seen.push(group);
        Ok(())
    }

    // ---------------------------------------------------------------- coordinates

    fn axis(&self, letter: char) -> Option<usize> {
        self.setup.axes.iter().position(|&a| a == letter)
    }

    fn origin(&self, i: usize) -> f64 {
        let letter = self.setup.axes[i];
        let work = if self.dialect == Dialect::Gtc2eLathe {
            0.0
        } else {
            self.setup.offsets.work(self.work_system, letter)
        };
        work + self.shift[i] + self.local[i] + self.tool_offset[i]
    }

    /// Program zero per axis in machine coordinates (work offset, shifts, tool offset) as it
    /// stands after the blocks read so far: the HMI's work position is measured from it.
    pub fn program_origin(&self) -> Vec<f64> {
        (0..self.pos.len()).map(|i| self.origin(i)).collect()
    }

    /// Current position in work coordinates (X as diameter).
    fn work_position(&self) -> Vec<f64> {
        (0..self.pos.len())
            .map(|i| self.pos[i] - self.origin(i))
            .collect()
    }

    fn to_machine(&self, work: &[f64]) -> Vec<f64> {
        (0..work.len()).map(|i| work[i] + self.origin(i)).collect()
    }

    /// The work-coordinate end point of a block's axis words.
    fn end_point(&self, b: &Block) -> Result<Vec<f64>, ProgramError> {
        let mut end = self.work_position();
        for (i, &letter) in self.setup.axes.iter().enumerate() {
            let inc = self.inc_letter(letter);
            let (abs, rel) = (b.get(letter), inc.and_then(|c| b.get(c)));
            if abs.is_some() && rel.is_some() {
                return Err(self.fault(
                    Fault::AbsAndInc,
                    format!("{letter} and {} in one block", inc.unwrap_or('?')),
                ));
            }
            if let Some(v) = abs {
                end[i] = if self.incremental { end[i] + v } else { v };
            } else if let Some(d) = rel {
                end[i] += d;
            }
        }
        Ok(end)
    }

    fn has_axis_words(&self, b: &Block) -> bool {
        self.setup
            .axes
            .iter()
            .any(|&a| b.has(a) || self.inc_letter(a).is_some_and(|c| b.has(c)))
    }

    fn xz(&self) -> Result<(usize, usize), ProgramError> {
        match (self.axis('X'), self.axis('Z')) {
            (Some(x), Some(z)) => Ok((x, z)),
            _ => Err(self.fault(Fault::AxisAddress, "this function needs the X and Z axes")),
        }
    }

    /// The incremental address of an axis (U for X, W for Z, ...): lathe dialects only; on
    /// the mill U, V, W are not addresses and G91 gives incremental moves.
    fn inc_letter(&self, axis: char) -> Option<char> {
        if self.dialect.is_lathe() {
            incremental_letter(axis)
        } else {
            None
        }
    }

    /// The working plane as (horizontal, vertical) axis indices, counter-clockwise turning
    /// from the first to the second: the lathe's Z-X plane, the mill's G17 X-Y, G18 Z-X and
    /// G19 Y-Z (`003` §2.3, §4.4).
    fn plane_axes(&self) -> Result<(usize, usize), ProgramError> {
        if self.dialect.is_lathe() {
            let (xi, zi) = self.xz()?;
            return Ok((zi, xi));
        }
        let (h, v, name) = match self.plane {
            G::PlaneZx => ('Z', 'X', "G18"),
            G::PlaneYz => ('Y', 'Z', "G19"),
            _ => ('X', 'Y', "G17"),
        };
        match (self.axis(h), self.axis(v)) {
            (Some(h), Some(v)) => Ok((h, v)),
            _ => Err(self.fault(
                Fault::PlaneAxis,
                format!("{name} needs the {h} and {v} axes"),
            )),
        }
    }

    /// The axis along the plane's normal on the mill (Z in G17, Y in G18, X in G19): cutter
    /// compensation carries it along unchanged. None on the lathe.
    fn plane_normal(&self) -> Option<usize> {
        if self.dialect.is_lathe() {
            return None;
        }
        self.axis(match self.plane {
            G::PlaneZx => 'Y',
            G::PlaneYz => 'X',
            _ => 'Z',
        })
    }

    /// Display units → plane units: a diameter axis counts half.
    fn axis_scale(&self, i: usize) -> f64 {
        if self.setup.diameter.get(i) == Some(&true) {
            0.5
        } else {
            1.0
        }
    }

    /// Work position as a plane point (`z` horizontal, `r` vertical; X as radius).
    fn plane_point(&self, work: &[f64]) -> Result<Pt, ProgramError> {
        let (h, v) = self.plane_axes()?;
        Ok(Pt::new(
            work[h] * self.axis_scale(h),
            work[v] * self.axis_scale(v),
        ))
    }

    /// The centre-offset addresses of the plane's axes (I for X, J for Y, K for Z).
    fn center_letters(&self) -> (char, char) {
        let letter = |i: usize| match self.setup.axes.get(i) {
            Some('X') => 'I',
            Some('Y') => 'J',
            _ => 'K',
        };
        match self.plane_axes() {
            Ok((h, v)) => (letter(h), letter(v)),
            Err(_) => ('K', 'I'),
        }
    }

    fn x_scale(&self) -> f64 {
        match self.axis('X') {
            Some(i) if self.setup.diameter.get(i) == Some(&true) => 0.5,
            _ => 1.0,
        }
    }

    /// Sets the plane axes of work position `w` to the plane point `p`.
    fn set_plane_point(&self, w: &mut [f64], p: Pt) {
        if let Ok((h, v)) = self.plane_axes() {
            w[v] = p.r / self.axis_scale(v);
            w[h] = p.z / self.axis_scale(h);
        }
    }

    fn with_point(&self, base: &[f64], p: Pt) -> Vec<f64> {
        let mut w = base.to_vec();
        self.set_plane_point(&mut w, p);
        w
    }

    // ---------------------------------------------------------------- emitting

    fn push(&mut self, command: Command) {
        self.pending.push_back(Canon {
            line: self.line,
            command,
        });
    }

    fn aux(&mut self, a: Aux) {
        self.push(Command::Aux(a));
    }

    /// Sends the spindle speed for a block ending at work position `end` (G96: the speed at
    /// the end point, `000` §4.2.3; decision D17).
    fn spindle_for(&mut self, end: &[f64]) {
        if !self.css {
            return;
        }
        let x = self.axis('X').map(|i| end[i].abs()).unwrap_or(0.0);
        let rpm = if self.dialect == Dialect::Gtc2eLathe {
            // GTC2E G96 S = rpm at X0, reached linearly from the rpm where G96 was given.
            let (rpm0, x0) = self.gtc_css_from;
            if x0 <= 0.0 {
                self.css_speed
            } else {
                self.css_speed + (rpm0 - self.css_speed) * (x / x0).min(1.0)
            }
        } else {
            let d = x.max(1e-3);
            let mut rpm = self.css_speed * 1000.0 / (std::f64::consts::PI * d);
            if let Some(m) = self.max_rpm {
                rpm = rpm.min(m);
            }
            rpm.max(10.0)
        };
        let rpm = (rpm * 10.0).round() / 10.0;
        if self.sent_rpm != Some(rpm) {
            self.sent_rpm = Some(rpm);
            self.aux(Aux::S(rpm));
        }
    }

    /// Emits a move to work position `end` and makes it the current position.
    fn emit(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        if self.corner.is_some() {
            self.resolve_corner(Some((end, kind)))?;
        }
        if self.nose_comp.is_some() && !self.emitting_comp {
            return self.emit_compensated(end, kind);
        }
        for (i, v) in end.iter().enumerate() {
            if !v.is_finite() || v.abs() > 1e6 {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("{} end point {v} out of range", self.setup.axes[i]),
                ));
            }
        }
        // Feed and lead are checked before anything changes: a bad block moves nothing.
        let feed = match kind {
            MoveKind::Feed(feed) | MoveKind::Arc { feed, .. } => self.check_feed(feed)?,
            MoveKind::Rapid => 0.0,
            MoveKind::Thread { lead, .. } => {
                if !(lead > 0.0 && lead.is_finite()) {
                    return Err(self.fault(
                        Fault::ThreadLead,
                        format!("thread lead {lead} is not valid"),
                    ));
                }
                0.0
            }
        };
        self.spindle_for(end);
        let m = self.to_machine(end);
        // The machine position becomes `m`; the command takes `m` itself (no copy per move).
        self.pos.copy_from_slice(&m);
        let command = match kind {
            MoveKind::Rapid => Command::Rapid { end: m },
            MoveKind::Feed(_) => Command::Linear { end: m, feed },
            MoveKind::Arc { center, ccw, .. } => {
                // Axes outside the plane keep the end's value (a helix's centre is at its end).
                let c = self.to_machine(&self.with_point(end, center));
                let plane = self
                    .plane_axes()
                    .ok()
                    .and_then(|(h, v)| Some([u8::try_from(h).ok()?, u8::try_from(v).ok()?]));
                Command::Arc {
                    end: m,
                    center: c,
                    clockwise: !ccw,
                    feed,
                    plane,
                }
            }
            MoveKind::Thread { lead, angle } => Command::Thread {
                end: m,
                lead,
                start_angle: angle,
            },
        };
        self.push(command);
        Ok(())
    }

    // ---------------------------------------------------------------- nose compensation

    /// G41/G42. Huaxing: in a G01 block with axis words (alarm 85), radius and tip direction
    /// from the tool table (`000` §6.1.2). GTC2E: `G41 R..` on its own, R the nose radius
    /// (negative: the other side), programmed point = nose centre (`002` §4.3.2-18).
    fn start_nose(&mut self, b: &Block, g: G) -> Result<(), ProgramError> {
        if self.nose_comp.is_some() {
            return Err(self.fault(
                Fault::CompDirection,
                "G41/G42 while tool-nose compensation is active: cancel with G40 first",
            ));
        }
        let mut side = self.nose_side(g);
        let (radius, tip, startup) = match self.dialect {
            Dialect::Gtc2eLathe => {
                let r = b.get('R').ok_or_else(|| {
                    self.fault(Fault::MissingWord, "G41/G42 needs R (nose radius)")
                })?;
                if r < 0.0 {
                    side = side.other();
                }
                (self.nose_radius(r.abs(), "R")?, 0, nose::Startup::Connect)
            }
            Dialect::FanucMill => {
                let r = self.cutter_radius(b)?;
                if r < 0.0 {
                    side = side.other();
                }
                (r.abs(), 0, nose::Startup::AlongEntry)
            }
            _ => {
                if !self.compensation_line(b) {
                    return Err(self.fault(
                        Fault::CompStartNotLine,
                        "G41/G42 must be given in a G01 block with X/Z (or U/W)",
                    ));
                }
                let offset = self.nose_offset_number(b);
                let t = self.setup.offsets.tool(offset);
                (
                    self.nose_radius(t.radius, &format!("offset {offset}"))?,
                    t.tip,
                    nose::Startup::ToNextElement,
                )
            }
        };
        let from = self.plane_point(&self.work_position())?;
        self.nose_comp = Some(nose::NoseComp::new(side, radius, tip, from, startup));
        self.nose_cancel = false;
        Ok(())
    }

    /// The side G41/G42 names as compensation sees it: sides are named as seen from the tool
    /// post, so with the turret in front (X toward the operator) they are mirrored against
    /// the X-up view compensation works in (`000` §6.1, decision D30).
    fn nose_side(&self, g: G) -> nose::Side {
        let side = if g == G::NoseLeft {
            nose::Side::Left
        } else {
            nose::Side::Right
        };
        if self.setup.front_tool_post {
            side.other()
        } else {
            side
        }
    }

    /// A nose radius compensation can use (alarm 21 otherwise); `of` names where it came from.
    fn nose_radius(&self, radius: f64, of: &str) -> Result<f64, ProgramError> {
        if radius > 0.0 && radius <= 1000.0 {
            Ok(radius)
        } else {
            Err(self.fault(
                Fault::CompRadiusZero,
                format!("tool-nose radius {} of {of} is not usable", show(radius)),
            ))
        }
    }

    /// The offset whose nose radius and tip G41/G42 use: a T word in the same block (its
    /// offset takes effect with this block's move), else the active one.
    fn nose_offset_number(&self, b: &Block) -> u32 {
        match b.get('T') {
            Some(t) if t >= 0.0 && t.fract() == 0.0 && t <= 9999.0 => {
                let code = t as u32;
                if code < 100 {
                    code
                } else {
                    code % 100
                }
            }
            _ => self.offset_number,
        }
    }

    /// G40: the next move leaves compensation. Huaxing wants it in a G01 block with axis words
    /// (alarm 85); GTC2E allows it alone (the next move cancels); the FANUC mill allows it
    /// alone or with G00/G01, never in an arc (P/S 034).
    fn cancel_nose(&mut self, b: &Block) -> Result<(), ProgramError> {
        if self.nose_comp.is_none() {
            return Ok(());
        }
        match self.dialect {
            Dialect::Gtc2eLathe => {}
            Dialect::FanucMill => self.refuse_arc_for_comp(b, "G40")?,
            _ if !self.compensation_line(b) => {
                return Err(self.fault(
                    Fault::CompStartNotLine,
                    "G40 must be given in a G01 block with X/Z (or U/W)",
                ))
            }
            _ => {}
        }
        self.nose_cancel = true;
        Ok(())
    }

    /// A G01 block with axis words: where Huaxing starts and cancels compensation.
    fn compensation_line(&self, b: &Block) -> bool {
        b.group(1).unwrap_or(self.motion) == G::Linear && self.has_axis_words(b)
    }

    fn comp_fault(&self, e: nose::CompError) -> ProgramError {
        let what = if self.dialect.is_lathe() {
            "tool-nose compensation"
        } else {
            "cutter compensation"
        };
        let (fault, text) = match e {
            nose::CompError::NoIntersection => (
                Fault::CompNoIntersection,
                "the offset path has no intersection here",
            ),
            nose::CompError::ArcVanishes => (
                Fault::CompArcVanishes,
                "arc radius smaller than the tool radius",
            ),
            nose::CompError::ArcStartup => (
                Fault::CompStartNotLine,
                "it cannot start in an arc: start it in a G00/G01 block",
            ),
            nose::CompError::Interference => (
                Fault::CompInterference,
                "the tool would cut into the contour here (interference)",
            ),
        };
        self.fault(fault, format!("{what}: {text}"))
    }

    /// A move while compensation is active: handed to the compensation, which returns the
    /// moves of the controlled point that are now certain.
    fn emit_compensated(&mut self, end: &[f64], kind: MoveKind) -> Result<(), ProgramError> {
        let here = self.work_position();
        let from = self.plane_point(&here)?;
        let to = self.plane_point(end)?;
        let normal = self.plane_normal();
        let depth = normal.map_or(0.0, |i| end[i]);
        // Compensation carries the plane and its normal; a rotary axis would be left behind.
        let (h, v) = self.plane_axes()?;
        let other = (0..end.len())
            .find(|&i| i != h && i != v && Some(i) != normal && (end[i] - here[i]).abs() > 1e-9);
        if let Some(i) = other {
            return Err(self.fault(
                Fault::CompInCycle,
                format!(
                    "{} cannot move while compensation is active: G40 first",
                    self.setup.axes[i]
                ),
            ));
        }
        let (path, ck) = match kind {
            MoveKind::Rapid if self.dialect.is_lathe() && self.dialect != Dialect::Gtc2eLathe => {
                return Err(self.fault(
                    Fault::CompRapid,
                    "G00 while tool-nose compensation is active: cancel with G40 first",
                ))
            }
            MoveKind::Rapid => (Elem::Line { a: from, b: to }, nose::Kind::Rapid),
            MoveKind::Feed(f) => (Elem::Line { a: from, b: to }, nose::Kind::Feed(f)),
            MoveKind::Arc { center, ccw, feed } => (
                Elem::Arc {
                    a: from,
                    b: to,
                    c: center,
                    ccw,
                },
                nose::Kind::Feed(feed),
            ),
            MoveKind::Thread { .. } => {
                return Err(self.fault(
                    Fault::CompInCycle,
                    "thread cutting while tool-nose compensation is active",
                ))
            }
        };
        let line = self.line;
        let still = (from.z - to.z).hypot(from.r - to.r) < 1e-9;
        let outs = if self.nose_cancel {
            self.nose_cancel = false;
            match self.nose_comp.take() {
                Some(mut comp) => comp.cancel(to, depth, ck, line),
                None => Vec::new(),
            }
        } else if still {
            // No move in the plane: a move along the normal waits for the held element's
            // end (decision D48); no move at all compensates nothing.
            match (normal, self.nose_comp.as_mut()) {
                (Some(i), Some(comp)) if (end[i] - here[i]).abs() > 1e-9 => {
                    comp.push_still(from, depth, ck, line)
                }
                _ => return Ok(()),
            }
        } else {
            let pushed = match self.nose_comp.as_mut() {
                Some(comp) => comp.push(path, depth, ck, line),
                None => Ok(Vec::new()),
            };
            pushed.map_err(|e| self.comp_fault(e))?
        };
        self.emit_outs(outs, end)
    }

    /// Runs `f`, which queues the moves of an element that was held back (nose compensation,
    /// chamfer), and moves what it queued to where the element was in program order: before
    /// the commands of later blocks queued meanwhile. Returns `f`'s result and the index just
    /// after the moved commands. The source line is restored afterwards.
    fn queue_held(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<(), ProgramError>,
    ) -> (Result<(), ProgramError>, usize) {
        let before = self.pending.len();
        let at = self.hold_at.take().unwrap_or(before).min(before);
        let saved_line = self.line;
        let result = f(self);
        self.line = saved_line;
        let moved: Vec<Canon> = self.pending.drain(before..).collect();
        let n = moved.len();
        for (k, c) in moved.into_iter().enumerate() {
            self.pending.insert(at + k, c);
        }
        (result, at + n)
    }

    /// Queues compensated moves where they belong in program order (before anything queued
    /// after the element compensation held back), then puts the program's position back on
    /// the programmed end point: incremental words and the next element start there.
    fn emit_outs(
        &mut self,
        outs: Vec<nose::Out>,
        programmed_end: &[f64],
    ) -> Result<(), ProgramError> {
        self.emitting_comp = true;
        let (result, held_end) = self.queue_held(|me| {
            for o in outs {
                me.line = o.line;
                let base = me.work_position();
                let mut end = me.with_point(&base, o.path.end());
                if let Some(i) = me.plane_normal() {
                    end[i] = o.depth;
                }
                let kind = match (o.path, o.kind) {
                    (Elem::Arc { c, ccw, .. }, nose::Kind::Feed(feed)) => MoveKind::Arc {
                        center: c,
                        ccw,
                        feed,
                    },
                    (_, nose::Kind::Feed(f)) => MoveKind::Feed(f),
                    (_, nose::Kind::Rapid) => MoveKind::Rapid,
                };
                me.emit(&end, kind)?;
            }
            Ok(())
        });
        self.emitting_comp = false;
        self.hold_at = self
            .nose_comp
            .as_ref()
            .filter(|c| c.holding())
            .map(|_| held_end);
        self.pos = self.to_machine(programmed_end);
        result
    }

    fn check_feed(&self, feed: f64) -> Result<f64, ProgramError> {
        if feed.is_nan() || feed <= 0.0 {
            return Err(self.fault(
                Fault::FeedRange,
                "no feed programmed for a cutting move (F missing or 0)",
            ));
        }
        let limit = if self.feed_per_rev {
            500.0
        } else {
            self.rules.max_feed
        };
        if feed > limit {
            return Err(self.fault(
                Fault::FeedRange,
                format!("feed F{} out of range (max {limit})", show(feed)),
            ));
        }
        Ok(feed)
    }

    fn rapid_to(&mut self, work: &[f64]) {
        // Only for points computed from known positions: cannot fail the range check.
        let _ = self.emit(work, MoveKind::Rapid);
    }

    /// Emits cycle moves given in the plane (radius), starting from the current position.
    fn emit_plane(&mut self, moves: &[Move], feed: f64) -> Result<(), ProgramError> {
        let mut end = self.work_position();
        for m in moves {
            // `end` is the work position the last move reached; only the plane axes change.
            match *m {
                Move::Rapid(p) => {
                    self.set_plane_point(&mut end, p);
                    self.emit(&end, MoveKind::Rapid)?
                }
                Move::Feed(p) => {
                    self.set_plane_point(&mut end, p);
                    self.emit(&end, MoveKind::Feed(feed))?
                }
                Move::Arc { to, c, ccw } => {
                    self.set_plane_point(&mut end, to);
                    self.emit(
                        &end,
                        MoveKind::Arc {
                            center: c,
                            ccw,
                            feed,
                        },
                    )?
                }
            }
        }
        Ok(())
    }

    // ---------------------------------------------------------------- execution

    /// Queues a decoded block's commands in execution order: F, S, T and the M codes that
    /// start things, then the motion or dwell, then the M codes that stop things, then program
    /// end or flow (decision D6).
    fn execute(&mut self, b: Block) -> Result<(), ProgramError> {
        let start_of_block = self.work_position();
        let produced = self.pending.len();
        // Modal settings first.
        for &(_, g, _) in &b.g {
            match g {
                G::Absolute => self.incremental = false,
                G::Incremental => self.incremental = true,
                G::ExactStopMode => {
                    self.exact_stop_mode = true;
                    self.push(Command::PathMode { exact_stop: true });
                }
                G::ContinuousMode => {
                    self.exact_stop_mode = false;
                    self.push(Command::PathMode { exact_stop: false });
                }
                G::FeedPerMinute | G::FeedPerRevolution => {
                    let per_rev = g == G::FeedPerRevolution;
                    if per_rev != self.feed_per_rev {
                        self.feed_per_rev = per_rev;
                        self.push(Command::FeedMode { per_rev });
                    }
                }
                G::WorkSystem(n) => {
                    // Keep the machine position; the work coordinates change.
                    self.work_system = n;
                }
                G::PlaneXy | G::PlaneZx | G::PlaneYz if !self.dialect.is_lathe() => {
                    if self.nose_comp.is_some() && g != self.plane {
                        return Err(self.fault(
                            Fault::CompPlane,
                            "the plane cannot change while cutter compensation is active: G40 first",
                        ));
                    }
                    self.plane = g;
                }
                G::MetricInput => {}
                G::PlaneXy | G::PlaneYz => {
                    return Err(self.fault(
                        Fault::NotSupported,
                        "G17/G19 need a Y axis; this lathe works in G18",
                    ))
                }
                G::NoseLeft | G::NoseRight => self.start_nose(&b, g)?,
                G::NoseCancel => self.cancel_nose(&b)?,
                G::TurretMode { gang } => self.gang_mode = gang,
                G::OffsetShift(n) => self.gtc_offset_shift(n),
                G::CycleReturn { r_level } => self.cycle_return_r = r_level,
                G::LengthComp(sign) => self.length_compensation(&b, Some(sign))?,
                _ => {}
            }
        }
        if !self.dialect.is_lathe() && b.group(8).is_none() && b.has('H') {
            self.length_compensation(&b, None)?;
        }
        if !self.dialect.is_lathe() && b.group(7).is_none() {
            // D is modal: the next G41/G42 uses it.
            if let Some(d) = self.offset_word(&b, 'D')? {
                self.radius_offset = d;
            }
        }
        if let Some(f) = b.get('F') {
            // GTC2E's F is a feed; in G32/G92/G76 blocks F is the lead (handled there).
            if !self.is_thread_block(&b) {
                if f < 0.0 {
                    return Err(
                        self.fault(Fault::FeedRange, format!("feed F{} is negative", show(f)))
                    );
                }
                self.feed = f;
            }
        }
        self.spindle_words(&b)?;
        if let Some(t) = b.get('T') {
            if self.dialect.is_lathe() {
                self.tool_word(t)?;
            } else {
                self.mill_tool_word(t)?;
            }
        }
        // In a G83/G87 block an M word is the spindle clamp code of the cycle (`000` §5.22.7).
        let drill_block = matches!(b.group(1).unwrap_or(self.motion), G::Drilling { .. })
            && self.has_axis_words(&b);
        for &(m, code) in &b.m {
            match m {
                M::AuxBefore | M::AuxAfter if drill_block => {}
                M::AuxBefore => {
                    if code == 60 && self.dialect == Dialect::FanucMill {
                        self.check_tool_change_position()?;
                    }
                    self.track_spindle(code);
                    self.aux(Aux::M((code / 10) as i32));
                }
                M::ReturnOrder(o) => self.return_order = o,
                M::ToolMacro(op) => self.tool_macro_code(op, &b)?,
                _ => {}
            }
        }
        self.block_body(&b)?;
        for &(m, code) in &b.m {
            match m {
                M::AuxBefore | M::AuxAfter if drill_block => {}
                M::AuxAfter | M::Stop | M::CountPart => {
                    self.track_spindle(code);
                    self.aux(Aux::M((code / 10) as i32));
                }
                // Motion stops on M01 if the optional-stop switch is on when it gets there.
                M::OptionalStop => self.aux(Aux::M(1)),
                _ => {}
            }
        }
        if b.has_g(G::ExactStopBlock) && self.pending.len() > produced && !self.exact_stop_mode {
            // G09: this block ends at rest; the next blends again.
            let first = self.pending.iter().skip(produced).position(is_motion);
            if let Some(i) = first {
                self.pending.insert(
                    produced + i,
                    Canon {
                        line: self.line,
                        command: Command::PathMode { exact_stop: true },
                    },
                );
                self.push(Command::PathMode { exact_stop: false });
            }
        }
        if !b.has_g(G::Finishing) {
            self.flow_m_codes(&b)?;
        }
        if self.has_axis_words(&b) || self.pending.len() > produced {
            self.previous_start = start_of_block;
        }
        Ok(())
    }

    fn is_thread_block(&self, b: &Block) -> bool {
        let motion = b.group(1).unwrap_or(self.motion);
        matches!(
            motion,
            G::Thread | G::VariableLeadThread | G::ThreadCycle | G::TappingCycle
        ) || b.has_g(G::MultiThreadCycle)
    }

    fn track_spindle(&mut self, code: u32) {
        self.spindle = match code {
            30 => SpindleDir::Cw,
            40 => SpindleDir::Ccw,
            50 | 200 | 300 => SpindleDir::Stopped,
            _ => self.spindle,
        };
    }

    fn spindle_words(&mut self, b: &Block) -> Result<(), ProgramError> {
        let s = b.get('S');
        // G50 S is the clamp, not a speed (`000` §4.2.3).
        if b.has_g(G::SetCoordinate) {
            if let Some(s) = s {
                if s <= 0.0 {
                    return Err(
                        self.fault(Fault::G50S, format!("G50 S{} must be positive", show(s)))
                    );
                }
                self.max_rpm = Some(s);
                // Decision D37: a G50 block that starts the spindle under G97 with no speed
                // yet commanded also runs it at S (the §5.23.6 example threads that way).
                let starts = b.m.iter().any(|&(_, code)| code == 30 || code == 40);
                if starts && !self.css && self.rpm == 0.0 {
                    self.set_rpm(s);
                }
            }
            return Ok(());
        }
        if let Some(s) = s {
            if !(0.0..=99999.0).contains(&s) {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("spindle speed S{} out of range", show(s)),
                ));
            }
        }
        match b.group(if self.dialect == Dialect::Gtc2eLathe {
            1
        } else {
            2
        }) {
            Some(G::ConstantSurfaceSpeed) => {
                let v = s.or(if self.css_speed > 0.0 {
                    Some(self.css_speed)
                } else {
                    None
                });
                let v = v.ok_or_else(|| self.fault(Fault::CssWithoutS, "G96 without S"))?;
                if self.dialect == Dialect::Gtc2eLathe {
                    let x = self
                        .axis('X')
                        .map(|i| self.work_position()[i].abs())
                        .unwrap_or(0.0);
                    self.gtc_css_from = (self.rpm, x);
                }
                self.css = true;
                self.css_speed = v;
                let here = self.work_position();
                self.spindle_for(&here);
                return Ok(());
            }
            Some(G::ConstantRpm) => {
                self.css = false;
                // G96 → G97 without S: the last rpm under G96 becomes the G97 speed.
                let rpm = s.or(self.sent_rpm).unwrap_or(self.rpm);
                self.set_rpm(rpm);
                return Ok(());
            }
            _ => {}
        }
        if let Some(s) = s {
            if self.css {
                self.css_speed = s;
                let here = self.work_position();
                self.spindle_for(&here);
            } else {
                self.set_rpm(s);
            }
        }
        Ok(())
    }

    fn set_rpm(&mut self, rpm: f64) {
        self.rpm = rpm;
        if self.sent_rpm != Some(rpm) {
            self.sent_rpm = Some(rpm);
            self.aux(Aux::S(rpm));
        }
    }

    /// T word: Huaxing `Tmmnn` (tool mm, offset nn; `T1` = tool 1 offset 1, decision D16);
    /// GTC2E `T0x` (index station x and apply offset x) or `Tx0` (offset x only).
    fn tool_word(&mut self, t: f64) -> Result<(), ProgramError> {
        let code = integer_word(t).ok_or_else(|| {
            self.fault(
                Fault::ToolNumber,
                format!("tool word T{} must be an integer", show(t)),
            )
        })?;
        let (tool, offset) = if self.dialect == Dialect::Gtc2eLathe {
            match code {
                1..=8 => (if self.gang_mode { None } else { Some(code) }, code),
                10..=80 if code % 10 == 0 => (None, code / 10),
                _ => {
                    return Err(self.fault(
                        Fault::ToolNumber,
                        format!("T{code}: tools are T01–T08 and T10–T80"),
                    ))
                }
            }
        } else if code < 100 {
            (Some(code), code)
        } else if code <= 9999 {
            (Some(code / 100), code % 100)
        } else {
            return Err(self.fault(Fault::ToolNumber, format!("T{code} out of range")));
        };
        if offset > MAX_OFFSET {
            return Err(self.fault(
                Fault::ToolNumber,
                format!("offset number {offset} out of range"),
            ));
        }
        if let Some(program) = self
            .setup
            .tool_change_macro
            .filter(|_| self.dialect == Dialect::HuaxingLathe && self.tool_macro_depth.is_none())
        {
            return self.call_tool_macro(program, tool.unwrap_or(0), offset);
        }
        if let Some(tool) = tool.filter(|&t| t > 0) {
            self.aux(Aux::T(tool as i32));
            self.tool = tool;
        }
        self.apply_offset(offset);
        Ok(())
    }

    /// Calls the tool-change macro (`000` §4.3.1–4.3.3) with #1 the current tool, #2 the
    /// current offset, #3 the target tool, #4 the target offset.
    fn call_tool_macro(
        &mut self,
        program: u32,
        tool: u32,
        offset: u32,
    ) -> Result<(), ProgramError> {
        let mut locals = vec![None; LOCALS];
        for (i, v) in [self.tool, self.offset_number, tool, offset]
            .into_iter()
            .enumerate()
        {
            locals[i + 1] = Some(v as f64);
        }
        self.call_program(program, 1, locals, "tool-change macro")?;
        self.tool_macro_depth = Some(self.frames.len());
        Ok(())
    }

    /// Makes `offset` the active tool offset (0 = none).
    fn apply_offset(&mut self, offset: u32) {
        // The offset takes effect with the next move (`000` §5.18): the work position shifts.
        self.offset_number = offset;
        let o = self.setup.offsets.tool(offset);
        for (i, &a) in self.setup.axes.iter().enumerate() {
            self.tool_offset[i] = if offset == 0 {
                0.0
            } else {
                match a {
                    'X' => o.x + o.wear_x,
                    'Z' => o.z + o.wear_z,
                    _ => 0.0,
                }
            };
        }
    }

    /// M52/M53/M54/M57/M58 of a tool-change macro (`000` §4.3.3).
    fn tool_macro_code(&mut self, op: ToolMacro, b: &Block) -> Result<(), ProgramError> {
        let k = || {
            b.get('K')
                .filter(|v| v.fract() == 0.0 && *v >= 0.0 && *v <= 9999.0)
                .map(|v| v as u32)
        };
        let need_k = |me: &Self| {
            k().ok_or_else(|| me.fault(Fault::MissingWord, "the code needs K, a whole number"))
        };
        match op {
            ToolMacro::ReadTool => {
                let n = need_k(self)?;
                if !(1..=40).contains(&n) {
                    return Err(self.fault(Fault::OutOfRange, format!("M52 K{n}: #1–#40")));
                }
                let tool = self.tool as f64;
                self.write_var(n as i64, Some(tool))
            }
            ToolMacro::SetOffset => {
                let n = need_k(self)?;
                if n > MAX_OFFSET {
                    return Err(
                        self.fault(Fault::ToolNumber, format!("offset number {n} out of range"))
                    );
                }
                self.apply_offset(n);
                Ok(())
            }
            // Execution follows the program in order here; the tool M52 reads is the one the
            // PLC confirmed (its FIN comes before motion goes on).
            ToolMacro::Sync => Ok(()),
            ToolMacro::ToolToPlc => {
                let n = need_k(self)?;
                if n == 0 || n > 99 {
                    return Err(self.fault(Fault::ToolNumber, format!("M57 K{n}: tool 1–99")));
                }
                self.aux(Aux::T(n as i32));
                self.tool = n;
                Ok(())
            }
            ToolMacro::RaiseAlarm => {
                let n = need_k(self)?;
                Err(self.fault(
                    Fault::ToolNumber,
                    format!("alarm {n} raised by the tool-change macro (M58 K{n})"),
                ))
                .map_err(|mut e| {
                    e.number = n;
                    e
                })
            }
        }
    }

    fn gtc_offset_shift(&mut self, n: u8) {
        // GTC2E G54–G57 add the group's offset, cumulatively (`002` §4.3.2-15, decision D19):
        // the displayed coordinates change by −offset, nothing moves.
        for (i, &a) in self.setup.axes.iter().enumerate() {
            self.shift[i] += self.setup.offsets.work(n, a);
        }
    }

    fn clear_gtc_shifts(&mut self) {
        if self.dialect == Dialect::Gtc2eLathe {
            for v in &mut self.shift {
                *v = 0.0;
            }
        }
    }

    fn flow_m_codes(&mut self, b: &Block) -> Result<(), ProgramError> {
        for &(m, code) in &b.m {
            match m {
                M::ProgramEnd => {
                    self.saw_end = true;
                    self.track_spindle(code);
                    self.aux(Aux::M((code / 10) as i32));
                    self.clear_gtc_shifts();
                    self.finish();
                    return Ok(());
                }
                M::EndAndRestart => {
                    self.saw_end = true;
                    self.aux(Aux::M(5));
                    self.aux(Aux::M(9));
                    self.spindle = SpindleDir::Stopped;
                    self.clear_gtc_shifts();
                    if self.setup.single_pass {
                        self.finish();
                    } else {
                        let f = self.frame();
                        f.pos = Pos::default();
                        f.repeats.clear();
                    }
                    return Ok(());
                }
                M::SubprogramCall => return self.subprogram_call(b),
                M::SubprogramReturn => return self.subprogram_return(),
                M::Jump => {
                    let p = self.line_target(b)?;
                    self.frame().pos = p;
                    return Ok(());
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// GTC2E `P____`: the line numbered P.
    fn line_target(&self, b: &Block) -> Result<Pos, ProgramError> {
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::MissingWord, "P (line number) missing"))?;
        let n = integer_word(p);
        let (text, here) = self
            .frames
            .last()
            .map(|f| (f.text.clone(), f.pos))
            .unwrap_or_else(|| (Arc::from(""), Pos::default()));
        n.and_then(|n| find_number(&text, here, n)).ok_or_else(|| {
            self.fault(
                Fault::TargetNotFound,
                format!("line N{} not found", show(p)),
            )
        })
    }

    fn subprogram_call(&mut self, b: &Block) -> Result<(), ProgramError> {
        if self.dialect == Dialect::Gtc2eLathe {
            let first = self.line_target(b)?;
            let count = b.get('L').unwrap_or(1.0);
            let count = code_x10(count)
                .map(|c| c / 10)
                .filter(|&c| (1..=99).contains(&c))
                .ok_or_else(|| self.fault(Fault::OutOfRange, format!("L{}: 1–99", show(count))))?;
            let ret = self.frame().pos;
            let f = self.frame();
            f.repeats.push(Repeat::LineCall {
                first,
                remaining: count,
                ret,
            });
            f.pos = first;
            return Ok(());
        }
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::MissingWord, "M98 needs P (program number)"))?;
        let p = integer_word(p).ok_or_else(|| {
            self.fault(
                Fault::Call,
                format!("M98 P{}: not a program number", show(p)),
            )
        })?;
        // P up to 4 digits: the program; 5–8 digits: repeat count then program (decision D20).
        let (mut count, number) = if p > 9999 {
            (p / 10000, p % 10000)
        } else {
            (1, p)
        };
        if let Some(l) = b.get('L') {
            count = code_x10(l)
                .map(|c| c / 10)
                .ok_or_else(|| self.fault(Fault::Call, "L must be a count"))?;
        }
        if count == 0 || count > 9999 {
            return Err(self.fault(Fault::Call, format!("repeat count {count} out of 1–9999")));
        }
        self.call_program(number, count, vec![None; LOCALS], "M98: program")
    }

    /// Runs library program `number` `count` times as a subprogram with the given locals;
    /// `what` names the caller in the alarm when the program is missing.
    fn call_program(
        &mut self,
        number: u32,
        count: u32,
        locals: Vec<Value>,
        what: &str,
    ) -> Result<(), ProgramError> {
        if self.frames.len() > MAX_CALL_DEPTH {
            return Err(self.fault(Fault::CallDepth, "subprograms nested deeper than 4 levels"));
        }
        let (name, text) = self.library.get(number).ok_or_else(|| {
            self.fault(
                Fault::UndefinedSubprogram,
                format!("{what} O{number:04} not in the library"),
            )
        })?;
        let name = name.to_string();
        self.frames.push(Frame {
            text,
            name,
            pos: Pos::default(),
            remaining: count.saturating_sub(1),
            repeats: Vec::new(),
            locals,
            loops: Vec::new(),
        });
        Ok(())
    }

    fn subprogram_return(&mut self) -> Result<(), ProgramError> {
        if self.dialect == Dialect::Gtc2eLathe {
            let f = self.frame();
            let Some(i) = f
                .repeats
                .iter()
                .rposition(|r| matches!(r, Repeat::LineCall { .. }))
            else {
                return Err(self.fault(Fault::ReturnWithoutCall, "M99 without M98"));
            };
            f.repeats.truncate(i + 1);
            if let Some(Repeat::LineCall {
                first,
                remaining,
                ret,
            }) = f.repeats.last_mut()
            {
                if *remaining > 1 {
                    *remaining -= 1;
                    f.pos = *first;
                } else {
                    f.pos = *ret;
                    f.repeats.pop();
                }
            }
            return Ok(());
        }
        if self.frames.len() == 1 {
            // M99 in a main program: it starts over (`000` §4.1.4).
            if self.setup.single_pass {
                self.finish();
            } else {
                let f = self.frame();
                f.pos = Pos::default();
                f.repeats.clear();
            }
            return Ok(());
        }
        let f = self.frame();
        if f.remaining > 0 {
            f.remaining -= 1;
            f.pos = Pos::default();
            f.repeats.clear();
            f.loops.clear();
        } else {
            self.frames.pop();
            if self.tool_macro_depth.is_some_and(|d| self.frames.len() < d) {
                self.tool_macro_depth = None;
            }
        }
        Ok(())
    }

    /// The body of a block: one-shot codes, cycles, motion.
    fn block_body(&mut self, b: &Block) -> Result<(), ProgramError> {
        if !self.dialect.is_lathe() && self.nose_comp.is_some() {
            self.refuse_under_cutter_comp(b)?;
        }
        if !self.dialect.is_lathe() && b.g.iter().any(|g| g.0 == 0) {
            // A motion code beside a one-shot code becomes modal for the blocks after it.
            if let Some(m) = b.group(1) {
                self.motion = m;
                self.hole = None;
            }
        }
        // One-shot (group 00, and GTC2E's non-motion group-1 codes) first.
        for &(_, g, _) in &b.g {
            match g {
                G::Dwell => return self.dwell(b),
                G::SetCoordinate => return self.set_coordinate(b, false),
                G::SetOffsetData => return self.set_offset_data(b),
                G::MachineCoordinates => return self.machine_coordinates(b),
                G::AssignCoordinate | G::AssignClearLocal => {
                    return self.set_coordinate(b, g == G::AssignClearLocal)
                }
                G::ShiftCoordinate => {
                    let here = self.work_position();
                    let end = self.end_point(b)?;
                    for i in 0..here.len() {
                        self.shift[i] -= end[i] - here[i];
                    }
                    return Ok(());
                }
                G::LocalCoordinate => {
                    for (i, &a) in self.setup.axes.clone().iter().enumerate() {
                        if let Some(v) = b.get(a) {
                            self.shift[i] += v;
                        }
                    }
                    return Ok(());
                }
                G::ReferenceReturn => return self.reference_return(b),
                G::SecondReference => return self.second_reference(b),
                G::ReferenceCheck => return self.reference_check(b),
                G::FromReference => return self.return_from_reference(b),
                G::OneDirection => return self.one_direction(b),
                G::MillLocal => return self.local_system(b),
                G::ConditionalRepeat { high } => return self.conditional_repeat(b, high),
                G::JumpRange | G::CallRange | G::LoopRange => return self.range(b, g),
                G::RoughTurning | G::RoughFacing | G::PatternRepeat => {
                    return self.compound_cycle(b, g)
                }
                G::Finishing => return self.finishing(b),
                G::FaceGrooving | G::RadialGrooving => {
                    return self.grooving(b, g == G::RadialGrooving)
                }
                G::ChipBreak => return self.set_chip_break(b),
                G::MultiThreadCycle => return self.g76(b),
                G::LoopStart => return self.gtc_loop_start(b),
                G::LoopEnd => return self.gtc_loop_end(),
                G::ReturnToStart { x, z } => {
                    self.clear_gtc_shifts();
                    let target = self.program_start.clone();
                    return self.gtc_return(&target, x, z);
                }
                G::ReturnToPreviousStart => {
                    let target = self.previous_start.clone();
                    return self.gtc_return(&target, true, true);
                }
                G::ReturnToStored => {
                    let target = self
                        .stored
                        .clone()
                        .unwrap_or_else(|| self.program_start.clone());
                    return self.gtc_return(&target, true, true);
                }
                G::StorePosition => {
                    self.stored = Some(self.work_position());
                    return Ok(());
                }
                G::ThreadRetract => return self.gtc_g31(b),
                _ => {}
            }
        }
        if !self.dialect.is_lathe() {
            // A group-01 code ends a canned cycle (`003` §1.2); G80 too.
            if b.group(1).is_some() || b.group(9) == Some(G::CycleCancel) {
                self.hole = None;
            }
            if let Some(G::HoleCycle(kind)) = b.group(9) {
                self.select_hole_cycle(kind)?;
            }
            if self.hole.is_some() {
                return self.hole_block(b);
            }
        }
        if let Some(m) = b.group(1) {
            if matches!(
                m,
                G::Rapid
                    | G::Linear
                    | G::ArcCw
                    | G::ArcCcw
                    | G::ThreePointArc { .. }
                    | G::Thread
                    | G::VariableLeadThread
                    | G::TappingCycle
                    | G::TurningCycle
                    | G::FacingCycle
                    | G::ThreadCycle
                    | G::GtcThread
                    | G::GtcThreadCycle
                    | G::GtcTapping
                    | G::GtcTaperCycle
                    | G::GtcCylinderCycle
                    | G::GtcDrillCycle
                    | G::GtcGroovingCycle
                    | G::Drilling { .. }
            ) {
                if self.motion != m {
                    // A new cycle or motion code drops the retained cycle words.
                    self.cycle = CycleWords::default();
                    if !matches!(
                        m,
                        G::GtcThreadCycle
                            | G::GtcTapping
                            | G::GtcTaperCycle
                            | G::GtcCylinderCycle
                            | G::GtcDrillCycle
                            | G::GtcGroovingCycle
                    ) {
                        self.gtc_cycle = None;
                    }
                }
                self.motion = m;
                if matches!(
                    m,
                    G::GtcThreadCycle
                        | G::GtcTapping
                        | G::GtcTaperCycle
                        | G::GtcCylinderCycle
                        | G::GtcDrillCycle
                        | G::GtcGroovingCycle
                ) {
                    return self.gtc_cycle_define(b, m);
                }
            }
        }
        if let G::Drilling { .. } = self.motion {
            // The cycle's modal words are kept even from a block without a hole position.
            self.drill_words(b)?;
        }
        if !self.has_axis_words(b) {
            // A block of only modal words; arcs may still be full circles by I/K.
            let arc_ik = matches!(self.motion, G::ArcCw | G::ArcCcw) && (b.has('I') || b.has('K'));
            if !arc_ik {
                return Ok(());
            }
        }
        if self.nose_comp.is_some()
            && !matches!(self.motion, G::Rapid | G::Linear | G::ArcCw | G::ArcCcw)
        {
            return Err(self.fault(
                Fault::CompInCycle,
                "tool-nose compensation active: cycles, threads and three-point arcs need G40 first",
            ));
        }
        match self.motion {
            G::Rapid => {
                let end = self.end_point(b)?;
                self.track_x_direction(&end);
                self.emit(&end, MoveKind::Rapid)
            }
            G::Linear => {
                let chamfer = self.chamfer_words(b)?;
                let end = self.end_point(b)?;
                self.track_x_direction(&end);
                let f = self.feed;
                match (chamfer, self.chip_break) {
                    (Some(c), _) => self.hold_corner(end, f, c),
                    (None, Some(cb)) => self.linear_with_chip_break(&end, f, cb),
                    (None, None) => self.emit(&end, MoveKind::Feed(f)),
                }
            }
            G::ArcCw | G::ArcCcw => self.arc(b),
            G::ThreePointArc { absolute } => self.three_point_arc(b, absolute),
            G::Drilling { radial } => self.drilling(b, radial),
            G::Thread => self.g32(b),
            G::VariableLeadThread => self.g34(b),
            G::TappingCycle => self.g33(b),
            G::TurningCycle | G::FacingCycle | G::ThreadCycle => self.single_cycle(b, self.motion),
            G::GtcThread => self.gtc_thread(b),
            G::GtcThreadCycle
            | G::GtcTapping
            | G::GtcTaperCycle
            | G::GtcCylinderCycle
            | G::GtcDrillCycle
            | G::GtcGroovingCycle => self.gtc_cycle_follow_on(b),
            other => Err(self.fault(Fault::UndefinedCode, format!("{other:?} is not a motion"))),
        }
    }

    fn track_x_direction(&mut self, end: &[f64]) {
        if let Some(i) = self.axis('X') {
            let d = end[i] - self.work_position()[i];
            if d.abs() > 1e-9 {
                self.last_x_direction = d.signum();
            }
        }
    }

    fn dwell(&mut self, b: &Block) -> Result<(), ProgramError> {
        let seconds = if self.dialect == Dialect::Gtc2eLathe {
            let d = b
                .get('D')
                .ok_or_else(|| self.fault(Fault::MissingWord, "G04 needs D (seconds)"))?;
            if !(0.001..=65.0).contains(&d) {
                return Err(self.fault(Fault::OutOfRange, format!("G04 D{}: 0.001–65 s", show(d))));
            }
            d
        } else {
            // Priority P (ms) > X (s) > U (s), `000` §5.15.
            let s = b
                .get('P')
                .map(|p| p / 1000.0)
                .or(b.get('X'))
                .or(b.get('U'))
                .unwrap_or(0.0);
            if s.abs() > 99_999_999.0 / 1000.0 {
                return Err(self.fault(Fault::DwellTime, "G04 dwell time out of range"));
            }
            s.max(0.0)
        };
        self.push(Command::Dwell { seconds });
        Ok(())
    }

    fn set_coordinate(&mut self, b: &Block, clear_local: bool) -> Result<(), ProgramError> {
        if clear_local {
            for v in &mut self.shift {
                *v = 0.0;
            }
        }
        // G50 X Z: the current point gets these work coordinates.
        let here = self.work_position();
        let end = self.end_point(b)?;
        for i in 0..here.len() {
            self.shift[i] += here[i] - end[i];
        }
        Ok(())
    }

    /// G10 L2 Pp: work offset p (1–6 = G54–G59) gets the axis words, added under G91.
    fn set_offset_data(&mut self, b: &Block) -> Result<(), ProgramError> {
        match b.get('L') {
            Some(2.0) => {}
            Some(l) => {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("G10 L{}: only L2 (work offsets) is built", show(l)),
                ))
            }
            None => return Err(self.fault(Fault::MissingWord, "G10 needs L2")),
        }
        let p = match b.get('P') {
            Some(p) if (1.0..=6.0).contains(&p) && p.fract() == 0.0 => p as u8 - 1,
            Some(p) => {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("G10 L2 P{}: work offset 1–6 (G54–G59)", show(p)),
                ))
            }
            None => return Err(self.fault(Fault::MissingWord, "G10 L2 needs P (1–6)")),
        };
        for &a in &self.setup.axes.clone() {
            if let Some(v) = b.get(a) {
                let base = if self.incremental {
                    self.setup.offsets.work(p, a)
                } else {
                    0.0
                };
                self.setup
                    .offsets
                    .work
                    .entry(p)
                    .or_default()
                    .insert(a, base + v);
            }
        }
        Ok(())
    }

    /// G53: a rapid to the block's axis words as machine coordinates (absolute only).
    fn machine_coordinates(&mut self, b: &Block) -> Result<(), ProgramError> {
        let mut target = self.work_position();
        for (i, &a) in self.setup.axes.clone().iter().enumerate() {
            if let Some(v) = b.get(a) {
                if self.incremental {
                    return Err(self.fault(Fault::IllegalWord, "G53 takes absolute positions"));
                }
                target[i] = v - self.origin(i);
            }
        }
        self.emit(&target, MoveKind::Rapid)
    }

    fn reference_return(&mut self, b: &Block) -> Result<(), ProgramError> {
        let reference = self.setup.reference.clone();
        self.return_through(b, &reference)
    }

    /// G28/G30: rapid to the intermediate point, then to `reference` (machine coordinates);
    /// named axes only. The intermediate point is kept for G29.
    fn return_through(&mut self, b: &Block, reference: &[f64]) -> Result<(), ProgramError> {
        let mid = self.end_point(b)?;
        let named = self.named_axes(b, &mid);
        if !named.iter().any(|&n| n) {
            return Ok(());
        }
        self.emit(&mid, MoveKind::Rapid)?;
        self.intermediate = Some(self.pos.clone());
        let mut target = self.pos.clone();
        for i in 0..target.len() {
            if named[i] {
                target[i] = reference.get(i).copied().unwrap_or(target[i]);
            }
        }
        self.push(Command::Rapid {
            end: target.clone(),
        });
        self.pos = target;
        Ok(())
    }

    /// The axes a block names (or moves, incremental words included).
    fn named_axes(&self, b: &Block, end: &[f64]) -> Vec<bool> {
        let here = self.work_position();
        (0..here.len())
            .map(|i| {
                (end[i] - here[i]).abs() > 0.0 || {
                    let a = self.setup.axes[i];
                    b.has(a) || self.inc_letter(a).is_some_and(|c| b.has(c))
                }
            })
            .collect()
    }

    fn range(&mut self, b: &Block, g: G) -> Result<(), ProgramError> {
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::RangeError, "P (first block) missing"))?;
        let q = b
            .get('Q')
            .ok_or_else(|| self.fault(Fault::RangeError, "Q (last block) missing"))?;
        let count = match b.get('L') {
            Some(l) => Some(
                code_x10(l)
                    .map(|c| c / 10)
                    .filter(|&c| c >= 1)
                    .ok_or_else(|| self.fault(Fault::RangeError, "L must be a count ≥ 1"))?,
            ),
            None if g == G::LoopRange => None,
            None => Some(1),
        };
        if g == G::LoopRange
            && self.frame().repeats.iter().any(|r| {
                matches!(
                    r,
                    Repeat::Range {
                        remaining: None,
                        ..
                    }
                )
            })
        {
            return Err(self.fault(Fault::RangeError, "G27 inside G27"));
        }
        let (p, q) = (whole(p), whole(q));
        let text = self.frame().text.clone();
        let first = find_number(&text, self.frame().pos, p)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{p} not found")))?;
        let last = find_number(&text, first, q)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{q} not found")))?;
        if last.offset < first.offset || (g == G::LoopRange && b.number == Some(q)) {
            return Err(self.fault(Fault::RangeError, format!("block range N{p}–N{q} is wrong")));
        }
        let here = self.frame().pos;
        let then = match g {
            // G25: continue after Q; G26: come back after the G26 block; G27: after the G27 block.
            G::JumpRange => None,
            _ => Some(here),
        };
        let f = self.frame();
        f.repeats.push(Repeat::Range {
            first,
            last: q,
            remaining: count,
            then,
            home: None,
            end_code: None,
        });
        f.pos = first;
        Ok(())
    }

    fn conditional_repeat(&mut self, b: &Block, high: bool) -> Result<(), ProgramError> {
        // G21/G23 (`000` §5.12): the manual's worked examples run the range when the input has
        // a signal (G21) or has none (G23), the opposite of the headings (decision D21).
        let run = match b.get('X') {
            None => false,
            Some(x) => {
                let byte = x.trunc() as u32;
                let bit = ((x.fract() * 10.0).round() as u8).min(7);
                let on = self.setup.inputs.contains(&(byte, bit));
                if high {
                    !on
                } else {
                    on
                }
            }
        };
        if !run {
            return Ok(());
        }
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::RangeError, "P missing"))?;
        let text = self.frame().text.clone();
        let q = b.get('Q').map(whole);
        let first = find_number(&text, self.frame().pos, whole(p))
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{} not found", show(p))))?;
        let Some(q) = q else {
            // Q omitted: to the end of the program.
            self.frame().pos = first;
            return Ok(());
        };
        let count = b.get('L').map(whole).unwrap_or(1).max(1);
        let f = self.frame();
        f.repeats.push(Repeat::Range {
            first,
            last: q,
            remaining: Some(count),
            then: None,
            home: None,
            end_code: None,
        });
        f.pos = first;
        Ok(())
    }

    // ---------------------------------------------------------------- arcs

    fn arc(&mut self, b: &Block) -> Result<(), ProgramError> {
        let end = self.end_point(b)?;
        let here = self.work_position();
        let (a, e) = (self.plane_point(&here)?, self.plane_point(&end)?);
        let ccw = self.motion == G::ArcCcw;
        // Centre offsets of the plane's axes: K, I on the lathe (Z-X), I, J on the mill (G17).
        let (lh, lv) = self.center_letters();
        let ik = b.has(lh) || b.has(lv);
        let center = match (b.get('R'), ik) {
            (Some(_), true) => return Err(self.fault(Fault::ArcRAndIk, "arc with both R and I/K")),
            (Some(r), false) => geometry::center_from_radius(a, e, r, ccw),
            (None, true) => {
                // The lathe's I is the centre's X offset from the start; GTC2E gives it in
                // diameter (`002` §4.3.2-3), Huaxing in radius (decision D3).
                let i = b.get(lv).unwrap_or(0.0);
                let i = if self.dialect == Dialect::Gtc2eLathe {
                    i * self.x_scale()
                } else {
                    i
                };
                let c = Pt::new(a.z + b.get(lh).unwrap_or(0.0), a.r + i);
                geometry::check_center(a, e, c)
            }
            (None, false) => return Err(self.fault(Fault::ArcRadius, "arc needs R or I/K")),
        }
        .map_err(|e| self.arc_error(e))?;
        let f = self.feed;
        self.emit(
            &end,
            MoveKind::Arc {
                center,
                ccw,
                feed: f,
            },
        )
    }

    fn arc_error(&self, e: ArcError) -> ProgramError {
        match e {
            ArcError::RadiusTooSmall => self.fault(
                Fault::ArcRadius,
                "arc radius R smaller than half the chord, or a full circle with R",
            ),
            ArcError::EndNotOnCircle => self.fault(
                Fault::ArcEnd,
                "arc end point is not on the circle of the start and I/K",
            ),
            ArcError::Collinear => self.fault(
                Fault::ThreePointArc,
                "three-point arc: the points are on one line",
            ),
        }
    }

    fn three_point_arc(&mut self, b: &Block, absolute: bool) -> Result<(), ProgramError> {
        if !b.has('I') && !b.has('K') {
            return Err(self.fault(Fault::ThreePointArc, "G05 needs the intermediate point I/K"));
        }
        let end = self.end_point(b)?;
        let here = self.work_position();
        let (a, e) = (self.plane_point(&here)?, self.plane_point(&end)?);
        // I is the mid point's X in radius (G05: relative to the start), or its absolute
        // X diameter (G05.1), K its Z (`000` §5.5; decision D22).
        let (i, k) = (b.get('I').unwrap_or(0.0), b.get('K').unwrap_or(0.0));
        let m = if absolute {
            Pt::new(k, i * self.x_scale())
        } else {
            Pt::new(a.z + k, a.r + i)
        };
        let (c, ccw) = geometry::three_point(a, m, e).map_err(|e| self.arc_error(e))?;
        let f = self.feed;
        self.emit(
            &end,
            MoveKind::Arc {
                center: c,
                ccw,
                feed: f,
            },
        )
    }

    // ---------------------------------------------------------------- threads

    /// Lead from F (mm) or I (threads per inch); `000` alarm 2 for both, none or zero.
    fn lead(&mut self, b: &Block, modal: bool) -> Result<f64, ProgramError> {
        let lead = match (b.get('F'), b.get('I')) {
            (Some(_), Some(_)) => {
                return Err(self.fault(Fault::ThreadLead, "thread with both F and I"))
            }
            (Some(f), None) => f,
            (None, Some(i)) if i > 0.0 => 25.4 / i,
            (None, Some(i)) => {
                return Err(self.fault(Fault::ThreadLead, format!("I{} threads per inch", show(i))))
            }
            (None, None) if modal && self.thread.lead > 0.0 => self.thread.lead,
            (None, None) => return Err(self.fault(Fault::ThreadLead, "thread lead F or I missing")),
        };
        if !(lead > 0.0 && lead <= 500.0) {
            return Err(self.fault(
                Fault::ThreadLead,
                format!("thread lead {lead} out of 0.0001–500 mm"),
            ));
        }
        self.thread.lead = lead;
        Ok(lead)
    }

    /// A word in least-input increments: without a decimal point it counts increments, with
    /// one it is mm (decision D12).
    fn increments(&self, b: &Block, c: char) -> Option<f64> {
        b.words
            .get(&c)
            .map(|&(v, point)| if point { v } else { v * self.rules.increment })
    }

    /// A thread from the current point to `end` (work), with run-out: within `k` of the end
    /// along the long axis the short axis moves `j` (radius, signed) (`000` §5.23.1).
    fn thread_to(
        &mut self,
        end: &[f64],
        lead: f64,
        angle: f64,
        j: f64,
        k: f64,
    ) -> Result<(), ProgramError> {
        let here = self.work_position();
        let (a, e) = (self.plane_point(&here)?, self.plane_point(end)?);
        let long_is_z = (e.z - a.z).abs() >= (e.r - a.r).abs();
        let len = if long_is_z {
            (e.z - a.z).abs()
        } else {
            (e.r - a.r).abs()
        };
        if j != 0.0 && k > 0.0 && k < len {
            let s = 1.0 - k / len;
            let mid = a.lerp(e, s);
            let out = if long_is_z {
                Pt::new(e.z, e.r + j)
            } else {
                Pt::new(e.z + j, e.r)
            };
            self.emit(
                &self.with_point(&here, mid),
                MoveKind::Thread { lead, angle },
            )?;
            // The thread's long axis keeps its lead through the run-out (D36; `000` §5.23.5: "the
            // long axis continues"); motion reads a lead along the piece's own long axis, which
            // is the short axis when the retract J is longer than K.
            let runout_lead = if j.abs() > k {
                lead * j.abs() / k
            } else {
                lead
            };
            self.emit(
                &self.with_point(&here, out),
                MoveKind::Thread {
                    lead: runout_lead,
                    angle,
                },
            )?;
        } else {
            self.emit(end, MoveKind::Thread { lead, angle })?;
        }
        Ok(())
    }

    /// Run-out words J/K with the G32 rules (`000` §5.23.1).
    fn runout(&mut self, b: &Block, g92: bool) -> (f64, f64) {
        if let Some(j) = b.get('J') {
            self.thread.j = Some(j);
        }
        if let Some(k) = b.get('K') {
            self.thread.k = Some(k.abs());
        }
        let (j, k) = (self.thread.j, self.thread.k);
        let j = if g92 { j.map(f64::abs) } else { j };
        match (j, k) {
            (None, _) | (Some(_), None) if !g92 && j.is_none() => (0.0, 0.0),
            (Some(j), None) => (j, j.abs()),
            (Some(j), Some(k)) if j != 0.0 => (j, if k == 0.0 { j.abs() } else { k }),
            _ => (0.0, 0.0),
        }
    }

    fn g32(&mut self, b: &Block) -> Result<(), ProgramError> {
        let lead = self.lead(b, true)?;
        let (j, k) = self.runout(b, false);
        // Q: start angle in 0.001° (a decimal point is ignored, `000` §5.23.1).
        let angle = b.get('Q').map(|q| q / 1000.0).unwrap_or(0.0);
        if !(0.0..=360.0).contains(&angle) {
            return Err(self.fault(Fault::OutOfRange, "Q start angle out of 0–360000"));
        }
        let end = self.end_point(b)?;
        self.thread_to(&end, lead, angle, j, k)
    }

    fn g34(&mut self, b: &Block) -> Result<(), ProgramError> {
        let lead = self.lead(b, true)?;
        let dl = b.get('R').ok_or_else(|| {
            self.fault(
                Fault::ThreadLead,
                "G34 needs R (lead change per revolution)",
            )
        })?;
        let end = self.end_point(b)?;
        let here = self.work_position();
        let (a, e) = (self.plane_point(&here)?, self.plane_point(&end)?);
        let len = (e.z - a.z).abs().max((e.r - a.r).abs());
        // Variable lead as one-revolution pieces of constant lead (the average of each turn).
        let mut s = 0.0;
        let mut l = lead;
        let mut pieces = 0;
        while s < len - 1e-9 {
            pieces += 1;
            if l <= 0.0 || l > 500.0 || pieces > 100_000 {
                return Err(self.fault(Fault::ThreadLead, format!("G34 lead becomes {l:.4} mm")));
            }
            let step = (l + dl / 2.0).max(1e-6).min(len - s);
            s += step;
            let p = a.lerp(e, s / len);
            self.emit(
                &self.with_point(&here, p),
                MoveKind::Thread {
                    lead: l + dl / 2.0,
                    angle: 0.0,
                },
            )?;
            l += dl;
        }
        Ok(())
    }

    fn g33(&mut self, b: &Block) -> Result<(), ProgramError> {
        // Z tapping cycle (`000` §5.23.3): feed in synchronised, M05, reverse, back, M05.
        let lead = self.lead(b, true)?;
        let reverse = match self.spindle {
            SpindleDir::Cw => 4,
            SpindleDir::Ccw => 3,
            SpindleDir::Stopped => {
                return Err(self.fault(
                    Fault::MissingWord,
                    "G33 tapping needs the spindle running (M03/M04)",
                ))
            }
        };
        let forward = if reverse == 4 { 3 } else { 4 };
        let starts = b.get('L').map(whole).unwrap_or(1).clamp(1, 99);
        let start = self.work_position();
        let (_, zi) = self.xz()?;
        let mut bottom = start.clone();
        bottom[zi] = match (b.get('Z'), b.get('W')) {
            (Some(z), None) => z,
            (None, Some(w)) => start[zi] + w,
            _ => return Err(self.fault(Fault::MissingWord, "G33 needs Z or W")),
        };
        for n in 0..starts {
            if n > 0 {
                self.aux(Aux::M(forward));
            }
            let angle = 360.0 * n as f64 / starts as f64;
            self.emit(&bottom, MoveKind::Thread { lead, angle })?;
            self.aux(Aux::M(5));
            self.aux(Aux::M(reverse));
            self.emit(&start, MoveKind::Thread { lead, angle })?;
            self.aux(Aux::M(5));
        }
        self.spindle = SpindleDir::Stopped;
        Ok(())
    }

    // ---------------------------------------------------------------- single cycles

    fn single_cycle(&mut self, b: &Block, g: G) -> Result<(), ProgramError> {
        let here = self.work_position();
        let (xi, zi) = self.xz()?;
        // Retained X, Z, R (`000` §5.21.3).
        let end = self.end_point(b)?;
        if b.has('X') || b.has('U') {
            self.cycle.x = Some(end[xi]);
        }
        if b.has('Z') || b.has('W') {
            self.cycle.z = Some(end[zi]);
        }
        if let Some(r) = b.get('R') {
            self.cycle.r = r;
        }
        let (Some(x), Some(z)) = (self.cycle.x, self.cycle.z) else {
            return Err(self.fault(Fault::MissingWord, "cycle needs X(U) and Z(W)"));
        };
        let r = self.cycle.r;
        let (x0, z0) = (here[xi], here[zi]);
        let at = |x: f64, z: f64| {
            let mut w = here.clone();
            w[xi] = x;
            w[zi] = z;
            w
        };
        let f = self.feed;
        let u = x - x0;
        match g {
            G::TurningCycle => {
                // R: cut start X minus cut end X, radius (`000` §5.21.1); alarm 3.
                if r != 0.0
                    && u.abs() > 1e-9
                    && r.signum() != u.signum()
                    && r.abs() > (u / 2.0).abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "R and U of opposite sign with |R| > |U/2|",
                    ));
                }
                let xs = x + 2.0 * r;
                self.emit(&at(xs, z0), MoveKind::Rapid)?;
                self.emit(&at(x, z), MoveKind::Feed(f))?;
                self.emit(&at(x0, z), MoveKind::Feed(f))?;
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            G::FacingCycle => {
                let w = z - z0;
                if r != 0.0
                    && w.abs() > 1e-9
                    && r.signum() != w.signum()
                    && r.abs() > w.abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "R and W of opposite sign with |R| > |W|",
                    ));
                }
                let zs = z + r;
                self.emit(&at(x0, zs), MoveKind::Rapid)?;
                self.emit(&at(x, z), MoveKind::Feed(f))?;
                self.emit(&at(x, z0), MoveKind::Feed(f))?;
                self.emit(&at(x0, z0), MoveKind::Rapid)?;
            }
            _ => {
                // G92 thread cycle (`000` §5.23.5).
                let lead = self.lead(b, true)?;
                if r != 0.0
                    && u.abs() > 1e-9
                    && r.signum() != u.signum()
                    && r.abs() > (u / 2.0).abs() + 1e-9
                {
                    return Err(self.fault(
                        Fault::TaperTooLarge,
                        "G92: R and U of opposite sign with |R| > |U/2|",
                    ));
                }
                if let Some(l) = b.get('L') {
                    let l = whole(l);
                    if !(1..=99).contains(&l) {
                        return Err(self.fault(Fault::OutOfRange, format!("G92 L{l}: 1–99 starts")));
                    }
                    self.cycle_starts = l;
                }
                let (j, k) = self.runout(b, true);
                // Run-out goes away from the part: toward the start X.
                let away = if x0 >= x { 1.0 } else { -1.0 };
                let starts = self.cycle_starts.max(1);
                for n in 0..starts {
                    let angle = 360.0 * n as f64 / starts as f64;
                    self.emit(&at(x + 2.0 * r, z0), MoveKind::Rapid)?;
                    self.thread_to(&at(x, z), lead, angle, away * j, k)?;
                    let cur = self.work_position();
                    self.emit(&at(x0, cur[zi]), MoveKind::Rapid)?;
                    self.emit(&at(x0, z0), MoveKind::Rapid)?;
                }
            }
        }
        Ok(())
    }
}

#[derive(Debug, Clone, Copy)]
enum MoveKind {
    Rapid,
    Feed(f64),
    Arc { center: Pt, ccw: bool, feed: f64 },
    Thread { lead: f64, angle: f64 },
}

fn is_motion(c: &Canon) -> bool {
    c.command.end().is_some()
}

/// `value × 10` as an integer code number (G50.1 → 501), if it has at most one decimal.
fn code_x10(v: f64) -> Option<u32> {
    let x10 = (v * 10.0).round();
    ((v * 10.0 - x10).abs() < 1e-6 && (0.0..1e8).contains(&x10)).then_some(x10 as u32)
}

/// A word that must be a whole number 0..10⁷ (T, M98 P, GTC2E line P): None for fractions and
/// negatives.
fn integer_word(v: f64) -> Option<u32> {
    code_x10(v).filter(|c| c % 10 == 0).map(|c| c / 10)
}

fn whole(v: f64) -> u32 {
    if v.is_finite() && v >= 0.0 {
        v.round().min(u32::MAX as f64) as u32
    } else {
        0
    }
}

/// Shows a number without trailing zeros.
fn show(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

fn incremental_letter(axis: char) -> Option<char> {
    match axis {
        'X' => Some('U'),
        'Z' => Some('W'),
        'Y' => Some('V'),
        'C' => Some('H'),
        _ => None,
    }
}

fn gtc_m_group(x10: u32) -> u32 {
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

impl Variables for Interpreter {
    fn round_decimals(&self) -> i32 {
        if self.dialect == Dialect::FanucMill {
            0
        } else {
            3
        }
    }

    fn read(&self, n: i64) -> Result<Value, EvalError> {
        if self.dialect == Dialect::FanucMill {
            return self.fanuc_read(n);
        }
        let frame = self
            .frames
            .last()
            .ok_or_else(|| EvalError("no program".into(), Fault::Macro))?;
        Ok(match n {
            0 => None,
            1..=40 => frame.locals[n as usize],
            100..=289 => self.common.get(&n).copied(),
            1000..=1033 => {
                return Err(EvalError(
                    format!("#{n}: PLC inputs are not connected to the interpreter yet"),
                    Fault::MacroVariable,
                ))
            }
            4001..=4499 => {
                let (table, num) = (n / 100 - 40, (n % 100) as u32);
                let t = self.setup.offsets.tool(num);
                Some(match table {
                    0 => t.x,
                    1 => 0.0,
                    2 => t.z,
                    3 => t.radius,
                    _ => t.tip as f64,
                })
            }
            5000..=5005 | 5020..=5025 => {
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][(n % 10) as usize];
                let machine = n >= 5020;
                self.axis(letter).map(|i| {
                    if machine {
                        self.pos[i]
                    } else {
                        self.work_position()[i]
                    }
                })
            }
            5220..=5325 if (n - 5220) % 20 < 6 => {
                let sys = ((n - 5220) / 20) as u8;
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][((n - 5220) % 20) as usize];
                Some(self.setup.offsets.work(sys, letter))
            }
            _ => {
                return Err(EvalError(
                    format!("#{n} is not a variable of this control"),
                    Fault::MacroVariable,
                ))
            }
        })
    }
}

// Cycles that need more room live in their own files.
mod chip_break;
mod compound;
mod corner;
mod drilling;
mod grooving;
mod gtc;
mod hole_cycle;
mod macro_b;
mod mill;
mod nose;

/// Interprets a whole program without running it: every command, or the first error.
pub fn check(dialect: Dialect, text: &str, setup: Setup) -> Result<Vec<Canon>, ProgramError> {
    check_with_library(dialect, text, setup, Library::new())
}

pub fn check_with_library(
    dialect: Dialect,
    text: &str,
    setup: Setup,
    library: Library,
) -> Result<Vec<Canon>, ProgramError> {
    check_limited(dialect, text, setup, library, MAX_CHECK_COMMANDS)
}

/// As [`check_with_library`], ending with an alarm after `limit` commands.
pub fn check_limited(
    dialect: Dialect,
    text: &str,
    setup: Setup,
    library: Library,
    limit: usize,
) -> Result<Vec<Canon>, ProgramError> {
    let mut interp = Interpreter::with_library(dialect, text, setup, library);
    let mut out = Vec::new();
    while let Some(c) = interp.next_command()? {
        if out.len() >= limit {
            return Err(ProgramError::new(
                dialect.alarm(Fault::Macro),
                c.line,
                format!("program does not end within {limit} commands (endless loop?)"),
            ));
        }
        out.push(c);
    }
    Ok(out)
}

/// Every error of a program without running it: each line's syntax and codes are checked on
/// their own, then the program is interpreted up to its first error (after which the state
/// is undefined). Sorted by line, one per line.
pub fn diagnose(dialect: Dialect, text: &str, setup: Setup, library: Library) -> Vec<ProgramError> {
    let rules = dialect.rules();
    let mut errors: Vec<ProgramError> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = (i + 1) as u32;
        match parse_line(raw, rules.macros) {
            Err(e) => errors.push(ProgramError::new(dialect.alarm(e.fault), line, e.text)),
            Ok(l) => {
                if let Stmt::Words(words) = &l.stmt {
                    for w in words {
                        let (Expr::Num { value, .. }, 'G' | 'M') = (&w.value, w.letter) else {
                            continue;
                        };
                        let known = code_x10(*value).and_then(|c| {
                            if w.letter == 'G' {
                                dialect.g_code(c).map(|_| ())
                            } else {
                                dialect.m_code(c).map(|_| ())
                            }
                        });
                        if known.is_none() {
                            errors.push(ProgramError::new(
                                dialect.alarm(Fault::UndefinedCode),
                                line,
                                format!("undefined {} code {}{}", w.letter, w.letter, show(*value)),
                            ));
                        }
                    }
                }
            }
        }
    }
    if let Err(e) = check_with_library(dialect, text, setup, library) {
        errors.push(e);
    }
    errors.sort_by_key(|e| e.line);
    errors.dedup_by_key(|e| e.line);
    errors
}
