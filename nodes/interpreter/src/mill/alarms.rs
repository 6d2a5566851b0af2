//! The FANUC 0-M P/S alarm numbers.

use cnc_interpreter_core::Fault;

/// The P/S alarm number a fault has on the FANUC 0-M (`003` inventory Appendix A.4; decision
/// D49). The appendix lists the numbers, not which of this controller's checks raises each:
/// a fault with no number of its own takes the nearest family (003 a value beyond its
/// address's range, 009 a word or character where it may not be, 010 a code used wrongly
/// or not built).
pub fn alarm(f: Fault) -> u32 {
    use Fault::*;
    match f {
        DwellTime | OutOfRange | TooManyDigits => 3,
        NoAddress => 4,
        NoNumber => 5,
        IllegalMinus => 6,
        DecimalPoint => 7,
        DataFormat | IllegalWord | AbsAndInc | TooManyM | RepeatedWord | AxisAddress
        | NoSuchAxis | ArcRAndIk | NoSuchAddress | RotaryWord | RotaryAxis | PolarAxes => 9,
        UndefinedCode | NotSupported | SameGroup | Group00With01 | MissingWord | ThreadLead
        | TaperTooLarge | CssWithoutS | Chamfer | ChamferTooShort | RangeError
        | LoopWithoutStart | NoProgramEnd | CompInCycle | CycleZero | CycleFormat
        | ContourTooLong | ContourData | ContourStart | ContourBeyondStart | ThreadDepthMissing
        | PatternReliefZero | ThreePointArc | CompBlocks | CompDirection | CompRapid
        | MustStartBlock | SpindleClamp | PolarMode | PolarStart | LiveToolSpeed => 10,
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
