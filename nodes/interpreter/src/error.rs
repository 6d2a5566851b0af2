//! Program errors: every rejection is an alarm with the manual's number, a text and the line.
//!
//! The interpreter raises a [`Fault`] (what went wrong, in the controller's own terms); the
//! dialect turns it into the number of its manual's alarm table: the Huaxing list (`000`
//! Appendix 1, inventory §11.1), the GTC2E list (`002` §6.3, inventory §10, numbered 1–28 in
//! the order printed, decision D13) or FANUC's P/S numbers (`003` inventory Appendix A.4,
//! decision D49).

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

/// What went wrong, independent of the dialect's numbering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// G04 time out of range (`000` 1).
    DwellTime,
    /// Thread lead wrong, F and I together, lead 0 (`000` 2).
    ThreadLead,
    /// G90/G92 taper R larger than half of U with opposite sign (`000` 3).
    TaperTooLarge,
    /// G96/G97 without S (`000` 4).
    CssWithoutS,
    /// Tool or offset number out of range (`000` 6).
    ToolNumber,
    /// Unknown G or M code, or a word that does not exist (`000` 7, `002` 15).
    UndefinedCode,
    /// G codes of groups 00 and 01 in one block (`000` 8).
    Group00With01,
    /// Absolute and incremental word for one axis (`000` 9).
    AbsAndInc,
    /// More than three M codes (`000` 10).
    TooManyM,
    /// Arc radius too small, or full circle with R (`000` 11).
    ArcRadius,
    /// Chamfer or corner rounding impossible (`000` 12).
    Chamfer,
    /// Malformed number or text (`000` 13, `002` 15).
    DataFormat,
    /// Axis address error (`000` 14).
    AxisAddress,
    /// R and I/K in one arc (`000` 15).
    ArcRAndIk,
    /// Feed out of range (`000` 16, `002` 23).
    FeedRange,
    /// Macro statement or variable error (`000` 20).
    Macro,
    /// Subprogram or macro call error, or nose radius 0 (`000` 21).
    Call,
    /// Program not found (`000` 22, `002` 10).
    ProgramNotFound,
    /// Cycle words missing (`000` 23, `002` 18).
    MissingWord,
    /// Jump or cycle target block not found (`000` 24, `002` 20).
    TargetNotFound,
    /// G25/G26/G27 range error (`000` 25).
    RangeError,
    /// M98 of an undefined program (`000` 26, `002` 20).
    UndefinedSubprogram,
    /// M99 without a call (`000` 27, `002` 22).
    ReturnWithoutCall,
    /// Two codes of one group in a block (`002` 16; `000` has no own number: 13).
    SameGroup,
    /// Address repeated in a block (`002` 17; `000` 13).
    RepeatedWord,
    /// A word the block's command does not take (`002` 19; `000` 7).
    IllegalWord,
    /// Value out of the address's range (`002` 23; `000` 13).
    OutOfRange,
    /// G80 without G22 (`002` 21).
    LoopWithoutStart,
    /// No program end M02/M20/M30 (`002` 14).
    NoProgramEnd,
    /// Tool-nose compensation active on entering a roughing cycle (`000` 42).
    CompInCycle,
    /// G71/G72 allowance or depth zero (`000` 43).
    CycleZero,
    /// G71 format error (`000` 44).
    CycleFormat,
    /// Contour too long (`000` 45/56).
    ContourTooLong,
    /// Contour data error: not monotonic, not closed (`000` 47).
    ContourData,
    /// Type I/II ns block rule (`000` 48).
    ContourStart,
    /// Arc end not on the circle (`000` 50).
    ArcEnd,
    /// Contour point beyond the start point (`000` 57).
    ContourBeyondStart,
    /// G76 P(k)/Q(Δd) missing (`000` 58).
    ThreadDepthMissing,
    /// G73 relief 0 (`000` 59).
    PatternReliefZero,
    /// Work offset number wrong (`000` 62).
    WorkOffset,
    /// Unknown axis for reference return (`000` 75).
    NoSuchAxis,
    /// Three-point arc points collinear (`000` 80 covers G05).
    ThreePointArc,
    /// Too few blocks between G41/G42 and G40, or G40 without G41/G42 (`000` 82).
    CompBlocks,
    /// Compensation start or cancel not on a G01 line (`000` 85).
    CompStartNotLine,
    /// Compensated path has no intersection (`000` 88/97; `002` inner corner).
    CompNoIntersection,
    /// Compensation direction changed at start/cancel (`000` 89).
    CompDirection,
    /// Tool-nose compensation asked for with a nose radius of 0 (`000` 21).
    CompRadiusZero,
    /// A concave arc smaller than the nose radius (`000` 87).
    CompArcVanishes,
    /// The offset path would cut into the contour: its direction reverses (FANUC P/S 041).
    CompInterference,
    /// Plane change while cutter compensation is active (FANUC P/S 037).
    CompPlane,
    /// G00 while tool-nose compensation is active (`000` 118).
    CompRapid,
    /// Code must start the block (`000` 103, 92).
    MustStartBlock,
    /// Chamfer line too short (`000` 119).
    ChamferTooShort,
    /// G50 S format (`000` 112).
    G50S,
    /// A function this controller does not implement yet: alarm 7 with the reason.
    NotSupported,
    /// A number with no address letter before it (FANUC P/S 004; `000` 13, `002` 15).
    NoAddress,
    /// An address with no number after it (FANUC P/S 005).
    NoNumber,
    /// A sign where none may be: `X--5` (FANUC P/S 006).
    IllegalMinus,
    /// A number with two decimal points (FANUC P/S 007).
    DecimalPoint,
    /// A number with more digits than the control reads (FANUC P/S 003).
    TooManyDigits,
    /// An address letter that is neither a word nor an axis of this machine (`000` 7,
    /// `002` 15, FANUC P/S 009).
    NoSuchAddress,
    /// The plane names an axis the machine lacks (FANUC P/S 021).
    PlaneAxis,
    /// Subprograms or macros nested too deep (FANUC P/S 077).
    CallDepth,
    /// Division by zero in an expression (FANUC P/S 112).
    MacroDivide,
    /// A variable number that does not exist (FANUC P/S 115).
    MacroVariable,
    /// A write to a read-only variable (FANUC P/S 116).
    MacroReadOnly,
    /// A function argument outside its domain, SQRT of a negative (FANUC P/S 119).
    MacroArgument,
    /// Brackets nested too deep or not closed (FANUC P/S 118).
    MacroBrackets,
    /// DO/END number other than 1–3, or END without its DO (FANUC P/S 126).
    MacroLoop,
    /// WHILE … DO m without its END m (FANUC P/S 124).
    MacroEnd,
    /// A G65 address that is no argument (FANUC P/S 129).
    MacroCallFormat,
    /// G27 ended away from the reference point (FANUC P/S 092).
    ReferenceCheck,
    /// M06 away from the second reference point (a machine alarm on the 0-M, decision D50).
    ToolChangePosition,
}

/// The alarm number a fault has in the Huaxing table (`000` Appendix 1).
pub fn huaxing_number(f: Fault) -> u32 {
    use Fault::*;
    match f {
        DwellTime => 1,
        ThreadLead => 2,
        TaperTooLarge => 3,
        CssWithoutS => 4,
        ToolNumber => 6,
        UndefinedCode | IllegalWord | NotSupported | NoSuchAddress => 7,
        Group00With01 => 8,
        AbsAndInc => 9,
        TooManyM => 10,
        ArcRadius => 11,
        Chamfer => 12,
        DataFormat | SameGroup | RepeatedWord | OutOfRange | NoAddress | NoNumber
        | IllegalMinus | DecimalPoint | TooManyDigits => 13,
        AxisAddress => 14,
        ArcRAndIk => 15,
        FeedRange => 16,
        Macro => 20,
        Call => 21,
        ProgramNotFound => 22,
        MissingWord => 23,
        TargetNotFound => 24,
        RangeError | LoopWithoutStart => 25,
        UndefinedSubprogram => 26,
        ReturnWithoutCall => 27,
        NoProgramEnd => 22,
        CompInCycle => 42,
        CycleZero => 43,
        CycleFormat => 44,
        ContourTooLong => 45,
        ContourData => 47,
        ContourStart => 48,
        ArcEnd => 50,
        ContourBeyondStart => 57,
        ThreadDepthMissing => 58,
        PatternReliefZero => 59,
        WorkOffset => 62,
        NoSuchAxis => 75,
        ThreePointArc => 80,
        CompBlocks => 82,
        CompStartNotLine => 85,
        CompNoIntersection | CompInterference => 88,
        CompPlane => 7,
        CompDirection => 89,
        CompRadiusZero => 21,
        CompArcVanishes => 87,
        CompRapid => 118,
        MustStartBlock => 103,
        ChamferTooShort => 119,
        G50S => 112,
        PlaneAxis => 14,
        CallDepth => 21,
        MacroDivide | MacroVariable | MacroReadOnly | MacroArgument | MacroBrackets | MacroLoop
        | MacroEnd | MacroCallFormat => 20,
        ReferenceCheck | ToolChangePosition => 7,
    }
}

/// The message number a fault has in the GTC2E list (`002` §6.3: 15 illegal command, 16
/// multiple commands, 17 multiple operands, 18 missing operand, 19 illegal operand, 20 P line
/// undefined, 21 G22 undefined, 22 M98 undefined, 23 data overflow, 14 no M02, 10 no such program).
pub fn gtc2e_number(f: Fault) -> u32 {
    use Fault::*;
    match f {
        UndefinedCode | DataFormat | NotSupported | Macro | MustStartBlock | NoSuchAddress
        | NoAddress | NoNumber | IllegalMinus | DecimalPoint | TooManyDigits | MacroVariable
        | ReferenceCheck | ToolChangePosition | MacroReadOnly | MacroBrackets | MacroLoop
        | MacroEnd | MacroCallFormat => 15,
        SameGroup | Group00With01 | TooManyM => 16,
        RepeatedWord | AbsAndInc => 17,
        MissingWord | ThreadDepthMissing | CssWithoutS => 18,
        IllegalWord | AxisAddress | PlaneAxis | ArcRAndIk | CycleFormat | ContourStart | Call
        | CallDepth => 19,
        TargetNotFound | RangeError => 20,
        LoopWithoutStart => 21,
        ReturnWithoutCall => 22,
        NoProgramEnd => 14,
        ProgramNotFound | UndefinedSubprogram => 10,
        // Geometry that cannot be made is an operand error on this control.
        _ => 23,
    }
}

/// The P/S alarm number a fault has on the FANUC 0-M (`003` inventory Appendix A.4; decision
/// D49). The appendix lists the numbers, not which of this controller's checks raises each:
/// a fault with no number of its own takes the nearest family (003 a value beyond its
/// address's range, 009 a word or character where it may not be, 010 a code used wrongly
/// or not built).
pub fn fanuc_number(f: Fault) -> u32 {
    use Fault::*;
    match f {
        DwellTime | OutOfRange | TooManyDigits => 3,
        NoAddress => 4,
        NoNumber => 5,
        IllegalMinus => 6,
        DecimalPoint => 7,
        DataFormat | IllegalWord | AbsAndInc | TooManyM | RepeatedWord | AxisAddress
        | NoSuchAxis | ArcRAndIk | NoSuchAddress => 9,
        UndefinedCode | NotSupported | SameGroup | Group00With01 | MissingWord | ThreadLead
        | TaperTooLarge | CssWithoutS | Chamfer | ChamferTooShort | RangeError
        | LoopWithoutStart | NoProgramEnd | CompInCycle | CycleZero | CycleFormat
        | ContourTooLong | ContourData | ContourStart | ContourBeyondStart | ThreadDepthMissing
        | PatternReliefZero | ThreePointArc | CompBlocks | CompDirection | CompRapid
        | MustStartBlock | G50S => 10,
        FeedRange => 11,
        ArcRadius | ArcEnd => 20,
        PlaneAxis => 21,
        CompRadiusZero => 29,
        ToolNumber | WorkOffset => 30,
        CompNoIntersection => 33,
        CompStartNotLine => 34,
        CompPlane => 37,
        CompInterference | CompArcVanishes => 41,
        ProgramNotFound => 59,
        Call => 76,
        CallDepth => 77,
        UndefinedSubprogram | ReturnWithoutCall => 78,
        MacroDivide => 112,
        Macro => 114,
        MacroVariable => 115,
        MacroReadOnly => 116,
        MacroBrackets => 118,
        MacroArgument => 119,
        MacroEnd => 124,
        MacroLoop => 126,
        ReferenceCheck => 92,
        TargetNotFound => 128,
        MacroCallFormat => 129,
        ToolChangePosition => 1006,
    }
}
