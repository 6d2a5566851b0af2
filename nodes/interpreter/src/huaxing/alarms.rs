//! The Huaxing alarm table (`000` Appendix 1, inventory §11.1).

use cnc_interpreter_core::Fault;

/// The alarm number a fault has in the Huaxing table (`000` Appendix 1).
pub fn alarm(f: Fault) -> u32 {
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
        // "G05/G08 programmed without a rotary axis" and "rotary axis not defined".
        ThreePointArc | RotaryWord => 80,
        RotaryAxis => 74,
        // "function not allowed in polar interpolation", "S#20 axis definition error",
        // "G12.1 start: linear axis > 0, rotary axis = 0" (`000` §5.8, alarm table).
        PolarMode => 106,
        PolarAxes => 107,
        PolarStart => 108,
        // "M65 spindle/live tool speed 0 or overspeed".
        LiveToolSpeed => 73,
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
        SpindleClamp => 112,
        PlaneAxis => 14,
        CallDepth => 21,
        MacroDivide | MacroVariable | MacroReadOnly | MacroArgument | MacroBrackets | MacroLoop
        | MacroEnd | MacroCallFormat => 20,
        ReferenceCheck | ToolChangePosition => 7,
    }
}
