//! Program errors: every rejection is an alarm with a number, a text and the line.
//!
//! The core and the front ends raise a [`Fault`]: what went wrong, in the controller's own
//! terms. Each front end owns its manual's alarm table, an [`AlarmTable`], which turns a fault
//! into the number the operator looks up.

use std::fmt;

/// A program error, raised before any motion of the bad block.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramError {
    pub number: u32,
    pub text: String,
    /// 1-based source line; 0 when the error is not tied to a line.
    pub line: u32,
    /// The program the line belongs to (empty for the main program).
    pub program: String,
}

impl fmt::Display for ProgramError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.program.is_empty() {
            write!(
                f,
                "alarm {} at line {}: {}",
                self.number, self.line, self.text
            )
        } else {
            write!(
                f,
                "alarm {} at line {} of {}: {}",
                self.number, self.line, self.program, self.text
            )
        }
    }
}

impl std::error::Error for ProgramError {}

impl ProgramError {
    pub fn new(number: u32, line: u32, text: impl Into<String>) -> Self {
        ProgramError {
            number,
            text: text.into(),
            line,
            program: String::new(),
        }
    }
}

/// A front end's alarm table: the number of each fault in its manual.
pub type AlarmTable = fn(Fault) -> u32;

/// What went wrong, independent of any manual's numbering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Dwell time out of range.
    DwellTime,
    /// Thread lead wrong, given twice, or 0.
    ThreadLead,
    /// A single cycle's taper larger than half the infeed, with the opposite sign.
    TaperTooLarge,
    /// Constant surface speed without a surface speed.
    CssWithoutS,
    /// Tool or offset number out of range.
    ToolNumber,
    /// Unknown code, or a word that does not exist.
    UndefinedCode,
    /// A one-shot code and a motion code in one block where the control refuses it.
    Group00With01,
    /// Absolute and incremental word for one axis.
    AbsAndInc,
    /// Too many M codes in one block.
    TooManyM,
    /// Arc radius too small, or a full circle given by its radius.
    ArcRadius,
    /// Chamfer or corner rounding impossible.
    Chamfer,
    /// Malformed number or text.
    DataFormat,
    /// Axis address error.
    AxisAddress,
    /// Radius and centre offsets in one arc.
    ArcRAndIk,
    /// Feed out of range.
    FeedRange,
    /// Macro statement or variable error.
    Macro,
    /// Subprogram or macro call error.
    Call,
    /// Program not found.
    ProgramNotFound,
    /// Words a cycle needs are missing.
    MissingWord,
    /// Jump or cycle target block not found.
    TargetNotFound,
    /// Block-range repeat error.
    RangeError,
    /// Call of a program that is not in memory.
    UndefinedSubprogram,
    /// Return without a call.
    ReturnWithoutCall,
    /// Two codes of one group in a block.
    SameGroup,
    /// Address repeated in a block.
    RepeatedWord,
    /// A word the block's command does not take.
    IllegalWord,
    /// Value out of the address's range.
    OutOfRange,
    /// Loop end without its start.
    LoopWithoutStart,
    /// The program has no program end where the control needs one.
    NoProgramEnd,
    /// Compensation active where it may not be (cycles, threads, axes outside the plane).
    CompInCycle,
    /// Roughing allowance or depth zero.
    CycleZero,
    /// Roughing cycle format error.
    CycleFormat,
    /// Contour too long.
    ContourTooLong,
    /// Contour data error: not monotonic, not closed.
    ContourData,
    /// Type I/II first-block rule of a roughing contour.
    ContourStart,
    /// Arc end not on the circle.
    ArcEnd,
    /// Contour point beyond the cycle's start point.
    ContourBeyondStart,
    /// Thread height or first depth missing.
    ThreadDepthMissing,
    /// Pattern-repeat relief 0.
    PatternReliefZero,
    /// Work offset number wrong.
    WorkOffset,
    /// Unknown axis for reference return.
    NoSuchAxis,
    /// A rotary-axis move (G08) without its rotary axis's word.
    RotaryWord,
    /// A rotary axis the machine does not have (no C axis, not that axis's spindle).
    RotaryAxis,
    /// A function polar interpolation does not allow while it is on.
    PolarMode,
    /// Polar interpolation's axes are not defined on this machine.
    PolarAxes,
    /// Polar interpolation started away from its start (linear axis > 0, rotary axis at 0).
    PolarStart,
    /// A live tool speed of 0 or above the tool's top speed.
    LiveToolSpeed,
    /// Three-point arc points collinear.
    ThreePointArc,
    /// Too few blocks between compensation start and cancel.
    CompBlocks,
    /// Compensation start or cancel not on a straight line.
    CompStartNotLine,
    /// Compensated path has no intersection.
    CompNoIntersection,
    /// Compensation asked for twice, or its direction changed.
    CompDirection,
    /// Compensation with an unusable radius.
    CompRadiusZero,
    /// A concave arc smaller than the tool radius.
    CompArcVanishes,
    /// The offset path would cut into the contour: its direction reverses.
    CompInterference,
    /// Plane change while compensation is active.
    CompPlane,
    /// Rapid move while compensation is active, where the control refuses it.
    CompRapid,
    /// Code must start the block.
    MustStartBlock,
    /// Chamfer line too short.
    ChamferTooShort,
    /// Spindle speed clamp not positive.
    SpindleClamp,
    /// A function this controller does not implement: the alarm says why.
    NotSupported,
    /// A number with no address letter before it.
    NoAddress,
    /// An address with no number after it.
    NoNumber,
    /// A sign where none may be: `X--5`.
    IllegalMinus,
    /// A number with two decimal points.
    DecimalPoint,
    /// A number with more digits than the control reads.
    TooManyDigits,
    /// An address letter that is neither a word nor an axis of this machine.
    NoSuchAddress,
    /// The plane names an axis the machine lacks.
    PlaneAxis,
    /// Subprograms or macros nested too deep.
    CallDepth,
    /// Division by zero in an expression.
    MacroDivide,
    /// A variable number that does not exist.
    MacroVariable,
    /// A write to a read-only variable.
    MacroReadOnly,
    /// A function argument outside its domain.
    MacroArgument,
    /// Brackets nested too deep or not closed.
    MacroBrackets,
    /// Loop number out of range, or a loop end without its start.
    MacroLoop,
    /// A loop start without its end.
    MacroEnd,
    /// A macro call address that is no argument.
    MacroCallFormat,
    /// A reference-point check ended away from the reference point.
    ReferenceCheck,
    /// Tool change away from the tool change position.
    ToolChangePosition,
}
