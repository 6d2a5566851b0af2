//! Positions from a block's words, the family's coordinate codes (G50/G92, G28) and the
//! words every dialect reads the same way.

use cnc_interpreter_core::{show, Command, Fault, MoveKind, ProgramError};

use super::block::{code_x10, integer_word, Block};
use super::{Family, Fanuc};

impl<D: Family> Fanuc<D> {
    /// The work-coordinate end point of a block's axis words.
    pub fn end_point(&self, b: &Block<D>) -> Result<Vec<f64>, ProgramError> {
        let mut end = self.core.work_position();
        for (i, &letter) in self.core.setup.axes.iter().enumerate() {
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

    pub fn has_axis_words(&self, b: &Block<D>) -> bool {
        self.core
            .setup
            .axes
            .iter()
            .any(|&a| b.has(a) || self.inc_letter(a).is_some_and(|c| b.has(c)))
    }

    /// The axes a block names (or moves, incremental words included).
    pub fn named_axes(&self, b: &Block<D>, end: &[f64]) -> Vec<bool> {
        let here = self.core.work_position();
        (0..here.len())
            .map(|i| {
                (end[i] - here[i]).abs() > 0.0 || {
                    let a = self.core.setup.axes[i];
                    b.has(a) || self.inc_letter(a).is_some_and(|c| b.has(c))
                }
            })
            .collect()
    }

    /// G50 X Z (lathe) / G92 (mill): the current point gets these work coordinates;
    /// `clear_local` first clears the shifts set so far.
    pub fn set_coordinate(&mut self, b: &Block<D>, clear_local: bool) -> Result<(), ProgramError> {
        if clear_local {
            for v in &mut self.core.shift {
                *v = 0.0;
            }
        }
        let here = self.core.work_position();
        let end = self.end_point(b)?;
        for i in 0..here.len() {
            self.core.shift[i] += here[i] - end[i];
        }
        Ok(())
    }

    pub(super) fn reference_return(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        let reference = self.core.setup.reference.clone();
        self.return_through(b, &reference)
    }

    /// G28/G30: rapid to the intermediate point, then to `reference` (machine coordinates);
    /// named axes only. The intermediate point is kept for G29.
    pub fn return_through(&mut self, b: &Block<D>, reference: &[f64]) -> Result<(), ProgramError> {
        let mid = self.end_point(b)?;
        let named = self.named_axes(b, &mid);
        if !named.iter().any(|&n| n) {
            return Ok(());
        }
        self.core.emit(&mid, MoveKind::Rapid)?;
        self.intermediate = Some(self.core.pos.clone());
        let mut target = self.core.pos.clone();
        for i in 0..target.len() {
            if named[i] {
                target[i] = reference.get(i).copied().unwrap_or(target[i]);
            }
        }
        self.core.push(Command::Rapid {
            end: target.clone(),
        });
        self.core.pos = target;
        Ok(())
    }

    /// G04 with P (ms) before X (s) before U (s).
    pub fn dwell_p_x_u(&self, b: &Block<D>) -> Result<f64, ProgramError> {
        let s = b
            .get('P')
            .map(|p| p / 1000.0)
            .or(b.get('X'))
            .or(b.get('U'))
            .unwrap_or(0.0);
        if s.abs() > 99_999_999.0 / 1000.0 {
            return Err(self.fault(Fault::DwellTime, "G04 dwell time out of range"));
        }
        Ok(s.max(0.0))
    }

    /// A word in least-input increments: without a decimal point it counts increments, with
    /// one it is mm (decision D12).
    pub fn increments(&self, b: &Block<D>, c: char) -> Option<f64> {
        b.words
            .get(&c)
            .map(|&(v, point)| if point { v } else { v * self.rules.increment })
    }

    /// M98 P: the program (up to 4 digits) or repeat count and program (5–8 digits, decision
    /// D20), or the count in L.
    pub fn call_program_word(&mut self, b: &Block<D>) -> Result<(), ProgramError> {
        let p = b
            .get('P')
            .ok_or_else(|| self.fault(Fault::MissingWord, "M98 needs P (program number)"))?;
        let p = integer_word(p).ok_or_else(|| {
            self.fault(
                Fault::Call,
                format!("M98 P{}: not a program number", show(p)),
            )
        })?;
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
        // A subprogram opens a level of local variables where the dialect says so (D51).
        let locals = D::SUBPROGRAM_LOCALS.then(|| vec![None; D::LOCALS]);
        self.core
            .call_program(number, count, locals, "M98: program")
    }
}
