//! The GTC2E message list (`002` §6.3, inventory §10, numbered 1–28 in the order printed,
//! decision D13).

use cnc_interpreter_core::Fault;

/// The message number a fault has in the GTC2E list (`002` §6.3: 15 illegal command, 16
/// multiple commands, 17 multiple operands, 18 missing operand, 19 illegal operand, 20 P line
/// undefined, 21 G22 undefined, 22 M98 undefined, 23 data overflow, 14 no M02, 10 no such program).
pub fn alarm(f: Fault) -> u32 {
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
