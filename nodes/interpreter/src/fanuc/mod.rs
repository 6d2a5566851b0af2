//! The FANUC family of front ends: the language the Huaxing, GTC2E, ISO lathe and FANUC 0-M
//! mill dialects share (address words, `N` numbers, `/` skip, macro statements, most G and M
//! codes) over the interpreter core. A dialect is a [`Family`]: its code tables, its alarm
//! numbers, its variable map and the places where it differs, each a hook here.
//!
//! Follow a block: [`syntax`] parses the line ([`expr`] for macro expressions), [`Fanuc::decode`]
//! (`block.rs`) checks its words against the dialect's tables, [`Fanuc::execute`]
//! (`execute.rs`, which lists the order of execution inside a block) applies modal state and
//! program flow, and motion ends in the core's emitter.

pub mod block;
pub mod codes;
pub mod expr;
pub mod syntax;

mod body;
mod coords;
mod execute;
pub mod lathe;
mod macros;

use cnc_interpreter_core::comp::Side;
use cnc_interpreter_core::{Core, CssRule, Fault, FrontEnd, Library, ProgramError, Setup};

use self::block::{code_x10, Block};
use self::codes::{GCode, Rules, WordUnit, G, M};
use self::expr::{EvalError, Value, Variables};
use self::syntax::{parse_line, Stmt, Word};
use crate::library::split_programs;

pub use self::lathe::ThreadWords;

/// A dialect of the family: its tables and where it differs. Hooks take the whole front end
/// (`Fanuc<Self>`): a dialect's state is `f.d`, the core `f.core`.
pub trait Family: Sized + Send + 'static {
    /// The dialect's own G meanings.
    type G: Copy + PartialEq + Eq + std::fmt::Debug + Send;
    /// The dialect's own M meanings.
    type M: Copy + PartialEq + Eq + std::fmt::Debug + Send;

    // ---------------------------------------------------------------- tables

    /// `G<number>`, the number ×10 (G50.1 is 501).
    fn g_code(x10: u32) -> Option<GCode<Self::G>>;
    /// `M<number>`, the number ×10.
    fn m_code(x10: u32) -> Option<M<Self::M>>;
    /// The alarm number of a fault in the dialect's manual.
    fn alarm(f: Fault) -> u32;
    fn rules() -> Rules<Self::G>;
    fn core_rules() -> cnc_interpreter_core::Rules;
    /// The dialect's own state at program start.
    fn new(setup: &Setup) -> Self;

    // ---------------------------------------------------------------- reading

    /// A file may hold several programs (a tape): the first runs, the others are called.
    const TAPES: bool = true;
    /// Two codes of one modal group in a block are refused.
    const ONE_CODE_PER_GROUP: bool = false;
    /// A one-shot code and a motion code in one block are refused.
    const REFUSE_GROUP00_WITH_01: bool = false;
    /// U, W, V, H are the incremental addresses of X, Z, Y, C.
    const INCREMENTAL_ADDRESSES: bool = false;
    /// Decimal places ROUND keeps.
    const ROUND_DECIMALS: i32 = 3;
    /// A number without a decimal point is millimetres (calculator type) unless the machine
    /// says otherwise; else least input increments (decision D52).
    const CALCULATOR_POINT: bool = true;
    /// The modal group of G96/G97.
    const CSS_GROUP: u8 = 2;
    /// The arc's I is a diameter (on a diameter axis).
    const ARC_I_DIAMETER: bool = false;
    /// Local variables per call level.
    const LOCALS: usize = 41;
    /// An M98 subprogram gets its own local variables (else it works with its caller's, and
    /// only a macro call opens a new level; decision D51).
    const SUBPROGRAM_LOCALS: bool = true;

    /// An address letter the dialect has beyond the axes and F S T P Q R I J K L D E.
    fn extra_address(_c: char) -> bool {
        false
    }
    /// What letter `c` of block `b` is, for the units it is read in.
    fn word_unit(f: &Fanuc<Self>, b: &Block<Self>, c: char) -> WordUnit {
        f.default_word_unit(b, c)
    }
    /// The modal group of an M code, where codes of one group may not share a block.
    fn m_group(_x10: u32) -> u32 {
        0
    }
    /// A statement of address words the dialect runs itself (a macro call), if this is one.
    fn words_statement(_f: &mut Fanuc<Self>, _words: &[Word]) -> Option<Result<(), ProgramError>> {
        None
    }

    // ---------------------------------------------------------------- variables

    fn read_var(f: &Fanuc<Self>, n: i64) -> Result<Value, EvalError>;
    fn write_var(f: &mut Fanuc<Self>, n: i64, v: Value) -> Result<(), ProgramError>;

    // ---------------------------------------------------------------- execution

    /// A modal code of the dialect's own, in the block's modal step.
    fn modal(_f: &mut Fanuc<Self>, _g: Self::G, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// G17/G18/G19.
    fn plane(f: &mut Fanuc<Self>, g: G<Self::G>) -> Result<(), ProgramError> {
        f.lathe_plane(g)
    }
    /// Words the dialect takes before F, S and T (the mill's H and D).
    fn words(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// A block that moves without axis words (the Huaxing's C axis, turned by G08 C or H).
    fn moves_without_axes(_f: &Fanuc<Self>, _b: &Block<Self>) -> bool {
        false
    }
    /// In this block F is a thread lead, not a feed.
    fn f_is_lead(_f: &Fanuc<Self>, _b: &Block<Self>) -> bool {
        false
    }
    /// The rule constant surface speed follows, as G96 is given.
    fn css_rule(_f: &Fanuc<Self>) -> CssRule {
        CssRule::SurfaceSpeed
    }
    /// The T word.
    fn tool_word(f: &mut Fanuc<Self>, t: f64) -> Result<(), ProgramError>;
    /// In this block the M codes belong to its cycle (a clamp code), not to the block.
    fn m_in_cycle(_f: &Fanuc<Self>, _b: &Block<Self>) -> bool {
        false
    }
    /// S words the dialect's NC takes itself on this machine (the turn-mill's live tool in
    /// speed mode, D143): true when it took them.
    fn speed_word(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<bool, ProgramError> {
        Ok(false)
    }
    /// An M code of the table the dialect's NC takes on this machine instead of the PLC (the
    /// turn-mill's M65, D143): true when it took it.
    fn m_to_nc(_f: &mut Fanuc<Self>, _code: u32) -> Result<bool, ProgramError> {
        Ok(false)
    }
    /// An M code sent before the block's motion, as it is sent (the mill's M06 check).
    fn m_before(_f: &mut Fanuc<Self>, _code: u32) -> Result<(), ProgramError> {
        Ok(())
    }
    /// The dialect's own M code before the block's motion.
    fn own_m_before(
        _f: &mut Fanuc<Self>,
        _m: Self::M,
        _b: &Block<Self>,
    ) -> Result<(), ProgramError> {
        Ok(())
    }
    /// The dialect's own M code in the flow step: `Some` ends the step.
    fn own_m_flow(
        _f: &mut Fanuc<Self>,
        _m: Self::M,
        _b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        None
    }
    /// The program ends (M02/M30).
    fn on_program_end(_f: &mut Fanuc<Self>) {}
    /// The block's flow codes wait (a finishing cycle's block runs them after the cycle).
    fn flow_waits(_f: &Fanuc<Self>, _b: &Block<Self>) -> bool {
        false
    }
    /// The dialect remembers where each block that did something started ([`Family::block_ran`]).
    const WANTS_BLOCK_START: bool = false;
    /// A block that had axis words or produced commands has run; it started at `start` (work
    /// coordinates).
    fn block_ran(_f: &mut Fanuc<Self>, _start: Vec<f64>) {}

    /// After a block has run entirely (its move, its M codes, its flow): the mill's modal
    /// macro call (G66) calls its macro here.
    fn after_block(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// G41/G42 (`g`) and G40.
    fn start_comp(f: &mut Fanuc<Self>, b: &Block<Self>, g: G<Self::G>) -> Result<(), ProgramError>;
    fn cancel_comp(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError>;
    /// M98 and M99.
    fn call(f: &mut Fanuc<Self>, b: &Block<Self>) -> Result<(), ProgramError> {
        f.call_program_word(b)
    }
    fn ret(f: &mut Fanuc<Self>) -> Result<(), ProgramError> {
        f.core.return_from_call();
        Ok(())
    }
    /// G04: the dwell in seconds.
    fn dwell_seconds(f: &Fanuc<Self>, b: &Block<Self>) -> Result<f64, ProgramError> {
        f.dwell_p_x_u(b)
    }
    /// Before the block's one-shot codes (the mill's checks under compensation).
    fn before_one_shots(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// A one-shot code of the dialect's own: `Some` is the whole block body.
    fn one_shot(
        _f: &mut Fanuc<Self>,
        _g: Self::G,
        _b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        None
    }
    /// After the one-shot codes, before motion: `Some` is the rest of the block body (the
    /// mill's modal canned cycles).
    fn before_motion(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Option<Result<(), ProgramError>> {
        None
    }
    /// The dialect's own code is a modal motion (group 01).
    fn is_motion(_g: Self::G) -> bool {
        false
    }
    /// A motion code was given (`new` differs from the motion in force when `changed`): the
    /// dialect drops what the old one kept; `Some` is the rest of the block body.
    fn motion_selected(
        _f: &mut Fanuc<Self>,
        _new: G<Self::G>,
        _changed: bool,
        _b: &Block<Self>,
    ) -> Option<Result<(), ProgramError>> {
        None
    }
    /// The modal motion's words, taken even from a block without axis words.
    fn motion_words(_f: &mut Fanuc<Self>, _b: &Block<Self>) -> Result<(), ProgramError> {
        Ok(())
    }
    /// The dialect's own modal motion, in a block with axis words.
    fn motion(f: &mut Fanuc<Self>, g: Self::G, b: &Block<Self>) -> Result<(), ProgramError>;
    /// A G01 block's chamfer or corner rounding words.
    fn chamfer(
        _f: &Fanuc<Self>,
        _b: &Block<Self>,
    ) -> Result<Option<cnc_interpreter_core::corner::Chamfer>, ProgramError> {
        Ok(None)
    }
}

/// A FANUC-family front end: the core, the dialect's own state, and what the family keeps.
pub struct Fanuc<D: Family> {
    pub core: Core,
    /// The dialect's own state.
    pub d: D,
    pub rules: Rules<D::G>,
    /// The modal motion (group 01).
    pub motion: G<D::G>,
    pub incremental: bool,
    /// Machine position of the last reference-return intermediate point.
    pub intermediate: Option<Vec<f64>>,
    /// The tool last commanded.
    pub tool: u32,
    /// Active tool offset number (0 = none).
    pub offset_number: u32,
    /// The sign of the last move along X (a thread's retract goes the other way).
    pub last_x_direction: f64,
    /// Numbers without a decimal point are millimetres (calculator type), not least input
    /// increments (decision D52).
    pub calculator: bool,
    /// G20: words of length are in inches (decision D53).
    pub inch: bool,
}

impl<D: Family> Fanuc<D> {
    pub fn new(text: &str, setup: Setup, mut library: Library) -> Self {
        // A tape of several programs: the first runs, the others go into program memory
        // beside the library's.
        let mut text = text;
        if D::TAPES {
            let (main_end, others) = split_programs(text);
            for (number, sub) in others {
                library.insert(number, &format!("O{number:04}"), sub);
            }
            text = &text[..main_end];
        }
        let rules = D::rules();
        let d = D::new(&setup);
        let calculator = setup
            .calculator_decimal_point
            .unwrap_or(D::CALCULATOR_POINT);
        Fanuc {
            core: Core::new(D::core_rules(), text, setup, library),
            d,
            motion: rules.initial_motion,
            rules,
            incremental: false,
            intermediate: None,
            tool: 0,
            offset_number: 0,
            last_x_direction: -1.0,
            calculator,
            inch: false,
        }
    }

    pub fn fault(&self, f: Fault, text: impl Into<String>) -> ProgramError {
        self.core.fault(f, text)
    }

    pub fn eval_err(&self, e: EvalError) -> ProgramError {
        self.fault(e.1, e.0)
    }

    /// Ends the text of the innermost level: a called program returns, the main program
    /// ends.
    fn end_of_text(&mut self) -> Result<(), ProgramError> {
        if self.core.depth() > 1 {
            return D::ret(self);
        }
        self.core.end_of_main()
    }

    /// Runs one statement of a line.
    fn statement(&mut self, number: Option<u32>, stmt: &Stmt) -> Result<(), ProgramError> {
        match stmt {
            Stmt::Empty => Ok(()),
            Stmt::Assign { var, value } => {
                let n = self.var_number(var)?;
                let v = value.eval(self).map_err(|e| self.eval_err(e))?;
                D::write_var(self, n, v)
            }
            Stmt::Goto(target) => self.goto(target),
            Stmt::If { cond, then } => {
                let c = cond.eval(self).map_err(|e| self.eval_err(e))?;
                if expr::truth(c) {
                    self.statement(number, then)
                } else {
                    Ok(())
                }
            }
            Stmt::While { cond, id } => self.while_loop(cond.as_ref(), *id),
            Stmt::End(id) => self.end_loop(*id),
            Stmt::Words(words) => {
                if let Some(r) = D::words_statement(self, words) {
                    return r;
                }
                let mut b = Block {
                    number,
                    ..Block::default()
                };
                self.decode(words, &mut b)?;
                self.execute(b)
            }
        }
    }

    /// Every error of a program's lines found without running it: each line's syntax and
    /// codes are checked on their own.
    pub fn line_errors(text: &str) -> Vec<ProgramError> {
        let macros = D::rules().macros;
        let mut errors = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = (i + 1) as u32;
            match parse_line(raw, macros) {
                Err(e) => errors.push(ProgramError::new(D::alarm(e.fault), line, e.text)),
                Ok(l) => {
                    let Stmt::Words(words) = &l.stmt else {
                        continue;
                    };
                    for w in words {
                        let (expr::Expr::Num { value, .. }, 'G' | 'M') = (&w.value, w.letter)
                        else {
                            continue;
                        };
                        let known = code_x10(*value).and_then(|c| {
                            if w.letter == 'G' {
                                D::g_code(c).map(|_| ())
                            } else {
                                D::m_code(c).map(|_| ())
                            }
                        });
                        if known.is_none() {
                            errors.push(ProgramError::new(
                                D::alarm(Fault::UndefinedCode),
                                line,
                                format!(
                                    "undefined {} code {}{}",
                                    w.letter,
                                    w.letter,
                                    cnc_interpreter_core::show(*value)
                                ),
                            ));
                        }
                    }
                }
            }
        }
        errors
    }

    /// The side G41/G42 names as compensation sees it: sides are named as seen from the tool
    /// post, so with the turret in front (X toward the operator) they are mirrored against
    /// the X-up view compensation works in (decision D30).
    pub fn comp_side(&self, g: G<D::G>) -> Side {
        let side = if g == G::NoseLeft {
            Side::Left
        } else {
            Side::Right
        };
        if self.core.setup.front_tool_post {
            side.other()
        } else {
            side
        }
    }
}

impl<D: Family> FrontEnd for Fanuc<D> {
    fn core(&self) -> &Core {
        &self.core
    }

    fn core_mut(&mut self) -> &mut Core {
        &mut self.core
    }

    /// Reads one line and queues its commands.
    fn read_block(&mut self) -> Result<(), ProgramError> {
        let Some((text, range)) = self.core.next_line() else {
            return self.end_of_text();
        };
        let raw = &text[range];
        let line = parse_line(raw, self.rules.macros).map_err(|e| self.fault(e.fault, e.text))?;
        if line.percent && !self.core.saw_any_block() && line.stmt == Stmt::Empty {
            return Ok(()); // `%` opening a tape
        }
        if line.percent {
            return self.end_of_text();
        }
        if line.skip.is_some() && self.core.setup.block_skip {
            return self.core.after_line(cnc_interpreter_core::line_number(raw));
        }
        self.statement(line.number, &line.stmt)?;
        self.core.after_line(line.number)
    }
}

impl<D: Family> Variables for Fanuc<D> {
    fn round_decimals(&self) -> i32 {
        D::ROUND_DECIMALS
    }

    fn read(&self, n: i64) -> Result<Value, EvalError> {
        D::read_var(self, n)
    }
}
