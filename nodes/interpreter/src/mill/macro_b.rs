//! FANUC user macro B on the mill (`003` inventory Appendix A.3; decision D49): G65 calls
//! and G66/G67 modal calls (D129) with argument specification I, the #3000 alarm, and the
//! mill's variable map (#1–#33 local, #100–#199 and #500–#999 common, #2001– offsets, #4001–
//! modal information, #5001– positions, #5221– work offsets). WHILE … DO m … END m loops are
//! the family's.

use cnc_interpreter_core::comp::Side;
use cnc_interpreter_core::{Fault, ProgramError};

use super::{Mill, MillG};
use crate::fanuc::block::{integer_word, Block};
use crate::fanuc::codes::G;
use crate::fanuc::expr::{EvalError, Value};
use crate::fanuc::syntax::Word;
use crate::fanuc::{Family, Fanuc};

/// Argument specification I: the local variable each address of a G65 block sets (A.3).
fn argument_number(letter: char) -> Option<usize> {
    Some(match letter {
        'A' => 1,
        'B' => 2,
        'C' => 3,
        'I' => 4,
        'J' => 5,
        'K' => 6,
        'D' => 7,
        'E' => 8,
        'F' => 9,
        'H' => 11,
        'M' => 13,
        'Q' => 17,
        'R' => 18,
        'S' => 19,
        'T' => 20,
        'U' => 21,
        'V' => 22,
        'W' => 23,
        'X' => 24,
        'Y' => 25,
        'Z' => 26,
        _ => return None,
    })
}

/// A modal macro call (G66, D129): the macro, how often it runs after each move block, the
/// locals its G66 block set, and the call level it was given at (the macro's own moves, one
/// level deeper, do not call it again).
#[derive(Debug, Clone)]
pub struct ModalCall {
    program: u32,
    count: u32,
    locals: Vec<Value>,
    level: usize,
}

impl Fanuc<Mill> {
    /// `G65 P<program> L<count> <arguments>`: calls the macro with its locals set from the
    /// argument table; P missing is P/S 076, an address that is no argument P/S 129.
    pub(super) fn macro_call(&mut self, words: &[Word]) -> Result<(), ProgramError> {
        let (program, count, locals) = self.macro_arguments(words, 65)?;
        self.core
            .call_program(program, count, Some(locals), "G65: macro")
    }

    /// `G66 P<program> L<count> <arguments>`: the macro is called after every later block that
    /// moves an axis, until G67 (D129). The block itself moves nothing: its X, Y, Z are
    /// arguments. One modal call at a time: a G66 while one is active is P/S 077.
    pub(super) fn modal_call(&mut self, words: &[Word]) -> Result<(), ProgramError> {
        let (program, count, locals) = self.macro_arguments(words, 66)?;
        if self.d.modal_call.is_some() {
            return Err(self.fault(
                Fault::CallDepth,
                "G66: a modal macro call is already active (G67 first)",
            ));
        }
        if self.core.library.get(program).is_none() {
            return Err(self.fault(
                Fault::UndefinedSubprogram,
                format!("G66: macro O{program:04} not in the library"),
            ));
        }
        self.d.modal_call = Some(ModalCall {
            program,
            count,
            locals,
            level: self.core.levels.len(),
        });
        Ok(())
    }

    /// After a block at G66's call level that moved an axis, the modal call's macro runs.
    /// Blocks whose axis words are no move (G04's time, G10's data, G92's position) do not
    /// call it, nor do blocks of the macro itself.
    pub(super) fn modal_call_after(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let Some(call) = &self.d.modal_call else {
            return Ok(());
        };
        let no_move =
            b.has_g(G::Dwell) || b.has_g(G::SetCoordinate) || b.has_g(G::Own(MillG::SetOffsetData));
        if call.level != self.core.levels.len() || no_move || !self.has_axis_words(b) {
            return Ok(());
        }
        let (program, count, locals) = (call.program, call.count, call.locals.clone());
        self.core
            .call_program(program, count, Some(locals), "G66: macro")
    }

    /// A macro call's P, L and arguments (specification I) for G`code`; a number without a
    /// decimal point in a length or angle argument counts least increments (D52).
    fn macro_arguments(
        &self,
        words: &[Word],
        code: u32,
    ) -> Result<(u32, u32, Vec<Value>), ProgramError> {
        let mut locals = vec![None; Mill::LOCALS];
        let (mut program, mut count) = (None, 1);
        for w in words {
            let v = w.value.eval(self).map_err(|e| self.eval_err(e))?;
            match w.letter {
                'G' if v == Some(f64::from(code)) => {}
                'P' => program = v,
                'L' => {
                    count = v
                        .and_then(integer_word)
                        .filter(|c| (1..=9999).contains(c))
                        .ok_or_else(|| {
                            self.fault(
                                Fault::OutOfRange,
                                format!("G{code} L: a repeat count 1–9999"),
                            )
                        })?;
                }
                letter => {
                    let n = argument_number(letter).ok_or_else(|| {
                        self.fault(
                            Fault::MacroCallFormat,
                            format!("G{code}: address {letter} cannot be an argument"),
                        )
                    })?;
                    if locals[n].is_some() {
                        return Err(self.fault(
                            Fault::RepeatedWord,
                            format!("G{code}: argument {letter} given twice"),
                        ));
                    }
                    // A number without a decimal point counts least input increments for
                    // the addresses that take lengths and angles (D52); the macro gets it in
                    // program units (inches under G20), as it computes in them.
                    let counted = !self.calculator && !w.value.has_point();
                    let scaled = matches!(letter, 'A'..='C' | 'I'..='K' | 'Q' | 'R' | 'U'..='Z');
                    locals[n] = match v {
                        Some(x) if counted && scaled => Some(x * self.step()),
                        other => other,
                    };
                }
            }
        }
        let number = program
            .and_then(integer_word)
            .filter(|&p| p <= 9999)
            .ok_or_else(|| {
                self.fault(
                    Fault::Call,
                    format!("G{code} needs P (the macro's program number)"),
                )
            })?;
        Ok((number, count, locals))
    }

    /// The least input increment in program units: 0.001 mm, or 0.0001 inch under G20.
    fn step(&self) -> f64 {
        if self.inch {
            self.rules.increment / 10.0
        } else {
            self.rules.increment
        }
    }

    /// A length in program units (inches under G20) of a length in mm.
    fn mm_to_program(&self, mm: f64) -> f64 {
        if self.inch {
            mm / 25.4
        } else {
            mm
        }
    }

    /// A length in mm of a length in program units.
    fn program_to_mm(&self, v: f64) -> f64 {
        if self.inch {
            v * 25.4
        } else {
            v
        }
    }

    /// Reads a variable of the mill's map; offsets and positions in program units.
    pub(super) fn fanuc_read(&self, n: i64) -> Result<Value, EvalError> {
        let axis = |base: i64| {
            usize::try_from(n - base)
                .ok()
                .filter(|&i| i < self.core.pos.len())
        };
        Ok(match n {
            0 => None,
            1..=33 => self.core.locals().get(n as usize).copied().flatten(),
            100..=199 | 500..=999 => self.core.common.get(&n).copied(),
            2001..=2200 => {
                let t = self.core.setup.offsets.tool((n - 2000) as u32);
                Some(self.mm_to_program(t.z + t.wear_z))
            }
            2201..=2400 => {
                Some(self.mm_to_program(self.core.setup.offsets.tool((n - 2200) as u32).radius))
            }
            4001..=4022 | 4107 | 4109 | 4111 | 4119 | 4120 => self.modal_information(n),
            5001..=5020 | 5041..=5060 => {
                let i = axis(if n < 5041 { 5001 } else { 5041 });
                i.map(|i| self.mm_to_program(self.core.work_position()[i]))
            }
            5021..=5040 => axis(5021).map(|i| self.mm_to_program(self.core.pos[i])),
            5081..=5100 => axis(5081).map(|i| self.mm_to_program(self.core.tool_offset[i])),
            5221..=5340 => match self.work_offset_slot(n) {
                Some((system, a)) => {
                    Some(self.mm_to_program(self.core.setup.offsets.work(system, a)))
                }
                None => return Err(no_variable(n)),
            },
            _ => return Err(no_variable(n)),
        })
    }

    /// #5221–#5340: G54–G59 in blocks of 20, one variable per axis in the machine's order.
    fn work_offset_slot(&self, n: i64) -> Option<(u8, char)> {
        let (system, i) = ((n - 5221) / 20, (n - 5221) % 20);
        let letter = self
            .core
            .setup
            .axes
            .get(usize::try_from(i).ok()?)
            .copied()?;
        Some((u8::try_from(system).ok()?, letter))
    }

    /// #4001– : the modal G codes (group numbers of Table 1.1) and #4107– D, F, H, S, T. Each
    /// G code is looked up in the dialect's own table, so the numbers cannot drift from it.
    fn modal_information(&self, n: i64) -> Value {
        let pick = |on: bool, yes: G<MillG>, no: G<MillG>| if on { yes } else { no };
        let g = match n {
            4001 => self.motion,
            4002 => self.d.plane,
            4003 => pick(self.incremental, G::Incremental, G::Absolute),
            4005 => pick(
                self.core.feed_per_rev(),
                G::FeedPerRevolution,
                G::FeedPerMinute,
            ),
            4006 => pick(self.inch, G::InchInput, G::MetricInput),
            4007 => match self.core.comp.as_ref().map(|c| c.side()) {
                None => G::NoseCancel,
                Some(Side::Left) => G::NoseLeft,
                Some(Side::Right) => G::NoseRight,
            },
            4008 => match self.d.length_sign {
                _ if self.d.length_offset == 0 => G::Own(MillG::LengthComp(0)),
                s => G::Own(MillG::LengthComp(s)),
            },
            4009 => G::Own(
                self.hole_kind()
                    .map_or(MillG::CycleCancel, MillG::HoleCycle),
            ),
            4010 => G::Own(MillG::CycleReturn {
                r_level: self.d.cycle_return_r,
            }),
            4014 => G::WorkSystem(self.core.work_system),
            4015 => pick(
                self.core.exact_stop_mode(),
                G::ExactStopMode,
                G::ContinuousMode,
            ),
            4107 => return Some(f64::from(self.d.radius_offset)),
            4109 => return Some(self.mm_to_program(self.core.feed)),
            4111 => return Some(f64::from(self.d.length_offset)),
            4119 => return Some(self.core.sent_rpm.unwrap_or(0.0)),
            4120 => return Some(f64::from(self.tool)),
            _ => return None,
        };
        (0..1000)
            .step_by(10)
            .find(|&x10| Mill::g_code(x10).is_some_and(|c| c.meaning == g))
            .map(|x10| f64::from(x10) / 10.0)
    }

    /// Writes a variable of the mill's map: #3000 = n raises macro alarm 3000 + n.
    pub(super) fn fanuc_write(&mut self, n: i64, v: Value) -> Result<(), ProgramError> {
        match n {
            1..=33 => {
                if let Some(slot) = self.core.locals_mut().get_mut(n as usize) {
                    *slot = v;
                }
            }
            100..=199 | 500..=999 => {
                match v {
                    Some(x) => self.core.common.insert(n, x),
                    None => self.core.common.remove(&n),
                };
            }
            2001..=2400 => {
                let x = self.program_to_mm(v.unwrap_or(0.0));
                if !x.is_finite() || x.abs() > 9999.0 {
                    return Err(self.fault(Fault::CompRadiusZero, format!("#{n}: {x} mm")));
                }
                let number = if n <= 2200 { n - 2000 } else { n - 2200 };
                let t = self
                    .core
                    .setup
                    .offsets
                    .tools
                    .entry(number as u32)
                    .or_default();
                if n <= 2200 {
                    t.z = x;
                    t.wear_z = 0.0;
                } else {
                    t.radius = x;
                }
            }
            3000 => {
                let code = v.and_then(integer_word).filter(|&c| c <= 999).unwrap_or(0);
                let mut e = self.fault(Fault::Macro, format!("macro alarm {code} (#3000)"));
                e.number = 3000 + code;
                return Err(e);
            }
            5221..=5340 => {
                let (system, letter) = self
                    .work_offset_slot(n)
                    .ok_or_else(|| self.fault(Fault::MacroVariable, no_variable(n).0))?;
                let v = v.map(|x| self.program_to_mm(x));
                return self.write_work_offset(n, system, letter, v, Fault::OutOfRange);
            }
            _ if self.fanuc_read(n).is_ok() => {
                return Err(self.fault(Fault::MacroReadOnly, format!("#{n} is read-only")))
            }
            _ => return Err(self.fault(Fault::MacroVariable, no_variable(n).0)),
        }
        Ok(())
    }
}

fn no_variable(n: i64) -> EvalError {
    EvalError(
        format!("#{n} is not a variable of this control"),
        Fault::MacroVariable,
    )
}
