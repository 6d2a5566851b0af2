//! The 802D's alarm numbers for program errors. The manual (`001` §10.7, inventory §10.1)
//! lists only the cycles' alarms and 12340; the numbers of the language's own errors are
//! those of the SINUMERIK alarm list the 802D shares with its family (decision D81): 12080
//! syntax error, 12550 name not defined, 14040 circle end point, 14080 jump destination not
//! found, 14011 program does not exist, 14920 CIP intermediate point, 14800 path feed ≤ 0,
//! 14051 arithmetic error, 17020 array index, 17070 write-protected, 12140 not implemented,
//! 10750–10753 radius compensation, 17190/17180 T/D numbers. A fault with no number of its
//! own takes the nearest of these.

use cnc_interpreter_core::Fault;

pub fn alarm(f: Fault) -> u32 {
    use Fault::*;
    match f {
        DataFormat | NoAddress | NoNumber | IllegalMinus | DecimalPoint | TooManyDigits
        | MacroBrackets | IllegalWord | MustStartBlock | MissingWord | AbsAndInc
        | Group00With01 | MacroCallFormat => 12080,
        NoSuchAddress | MacroVariable => 12550,
        UndefinedCode | WorkOffset => 12470,
        SameGroup => 12060,
        RepeatedWord => 12000,
        TooManyM => 14750,
        ArcRadius | ArcEnd | ArcRAndIk => 14040,
        ThreePointArc => 14920,
        TargetNotFound => 14080,
        UndefinedSubprogram | ProgramNotFound | Call => 14011,
        CallDepth => 15010,
        ReturnWithoutCall | NoProgramEnd | LoopWithoutStart => 14000,
        FeedRange => 14800,
        MacroDivide | MacroArgument => 14051,
        OutOfRange => 17020,
        MacroReadOnly => 17070,
        Macro | MacroEnd | MacroLoop | RangeError => 12080,
        NotSupported => 12140,
        ToolNumber => 17190,
        CompRadiusZero => 10750,
        CompNoIntersection | CompInterference | CompArcVanishes => 10751,
        CompStartNotLine | CompDirection | CompBlocks => 10752,
        CompPlane | CompInCycle | CompRapid => 10753,
        PlaneAxis | AxisAddress | NoSuchAxis | RotaryWord | RotaryAxis | PolarAxes => 14092,
        DwellTime => 14800,
        ReferenceCheck | ToolChangePosition => 12140,
        ThreadLead | TaperTooLarge | CssWithoutS | Chamfer | ChamferTooShort | CycleZero
        | CycleFormat | ContourTooLong | ContourData | ContourStart | ContourBeyondStart
        | ThreadDepthMissing | PatternReliefZero | SpindleClamp => 14040,
        PolarMode | PolarStart | LiveToolSpeed => 12140,
    }
}
