//! A block's words after evaluation, sorted by meaning, and their decoding: each word checked
//! against the dialect's tables and the machine's axes.

use cnc_interpreter_core::{show, Fault, ProgramError};

use super::codes::{WordUnit, G, M};
use super::syntax::Word;
use super::{Family, Fanuc};

/// Most M codes in one block (decision D6).
const MAX_M_PER_BLOCK: usize = 3;

/// A block's words after evaluation.
#[derive(Debug)]
pub struct Block<D: Family> {
    pub number: Option<u32>,
    /// G codes in the order written: group, meaning, number ×10.
    pub g: Vec<(u8, G<D::G>, u32)>,
    /// M codes in the order written: meaning, number ×10.
    pub m: Vec<(M<D::M>, u32)>,
    /// Address values other than G, M, N, O: letter → (value, written with a decimal point).
    pub words: Words,
}

impl<D: Family> Default for Block<D> {
    fn default() -> Self {
        Block {
            number: None,
            g: Vec::new(),
            m: Vec::new(),
            words: Words::default(),
        }
    }
}

/// A block's address values by letter A–Z: a fixed table, so reading a block allocates
/// nothing for its words (the parser gives only upper-case letters).
#[derive(Debug, Default)]
pub struct Words([Option<(f64, bool)>; 26]);

impl Words {
    fn slot(c: char) -> Option<usize> {
        c.is_ascii_uppercase().then(|| usize::from(c as u8 - b'A'))
    }
    pub fn get(&self, c: &char) -> Option<&(f64, bool)> {
        Self::slot(*c).and_then(|i| self.0[i].as_ref())
    }
    pub fn contains_key(&self, c: &char) -> bool {
        self.get(c).is_some()
    }
    /// Sets the letter's value; returns the value it had.
    pub fn insert(&mut self, c: char, w: (f64, bool)) -> Option<(f64, bool)> {
        Self::slot(c).and_then(|i| self.0[i].replace(w))
    }
    /// Sets the value of letter `i` (0 = A), if it was given.
    fn set(&mut self, i: usize, w: (f64, bool)) {
        if let Some(slot) = self.0.get_mut(i).filter(|s| s.is_some()) {
            *slot = Some(w);
        }
    }
    /// The letters given, in alphabetical order.
    pub fn iter(&self) -> impl Iterator<Item = (char, (f64, bool))> + '_ {
        (b'A'..=b'Z')
            .zip(self.0.iter())
            .filter_map(|(c, w)| w.map(|w| (char::from(c), w)))
    }
}

impl<D: Family> Block<D> {
    pub fn get(&self, c: char) -> Option<f64> {
        self.words.get(&c).map(|w| w.0)
    }
    pub fn has(&self, c: char) -> bool {
        self.words.contains_key(&c)
    }
    pub fn group(&self, group: u8) -> Option<G<D::G>> {
        self.g.iter().rev().find(|g| g.0 == group).map(|g| g.1)
    }
    pub fn has_g(&self, meaning: G<D::G>) -> bool {
        self.g.iter().any(|g| g.1 == meaning)
    }
}

/// `value × 10` as an integer code number (G50.1 → 501), if it has at most one decimal.
pub fn code_x10(v: f64) -> Option<u32> {
    let x10 = (v * 10.0).round();
    ((v * 10.0 - x10).abs() < 1e-6 && (0.0..1e8).contains(&x10)).then_some(x10 as u32)
}

/// A word that must be a whole number 0..10⁷ (T, a call's program number, a line number):
/// None for fractions and negatives.
pub fn integer_word(v: f64) -> Option<u32> {
    code_x10(v).filter(|c| c % 10 == 0).map(|c| c / 10)
}

pub fn whole(v: f64) -> u32 {
    if v.is_finite() && v >= 0.0 {
        v.round().min(u32::MAX as f64) as u32
    } else {
        0
    }
}

/// The incremental address of an axis on a lathe (U for X, W for Z, ...).
pub fn incremental_letter(axis: char) -> Option<char> {
    match axis {
        'X' => Some('U'),
        'Z' => Some('W'),
        'Y' => Some('V'),
        'C' => Some('H'),
        _ => None,
    }
}

impl<D: Family> Fanuc<D> {
    /// Evaluates and checks every word of a block.
    pub fn decode(&self, words: &[Word], b: &mut Block<D>) -> Result<(), ProgramError> {
        let mut groups: Vec<u32> = Vec::new();
        let mut m_groups: Vec<u32> = Vec::new();
        for w in words {
            let value = w.value.eval(self).map_err(|e| self.eval_err(e))?;
            // A null word disappears (the null variable rules).
            let Some(v) = value else { continue };
            let point = w.value.has_point();
            match w.letter {
                'O' | 'N' => {}
                'G' => {
                    let (x10, code) = self.lookup('G', v, D::g_code)?;
                    if let G::Unsupported(why) = code.meaning {
                        return Err(self.fault(Fault::NotSupported, format!("G{}: {why}", show(v))));
                    }
                    self.one_per_group('G', v, code.group != 0, code.group as u32, &mut groups)?;
                    b.g.push((code.group, code.meaning, x10));
                }
                'M' => {
                    let (x10, m) = self.lookup('M', v, D::m_code)?;
                    if let M::Unsupported(why) = m {
                        return Err(self.fault(Fault::NotSupported, format!("M{}: {why}", show(v))));
                    }
                    self.one_per_group('M', v, true, D::m_group(x10), &mut m_groups)?;
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
        if D::REFUSE_GROUP00_WITH_01 {
            // Group 00 and group 01 in one block. G04 and the coordinate codes are allowed
            // with motion words only through their own meaning; G09 is group 15.
            let g0 = b.g.iter().any(|g| g.0 == 0);
            let g1 = b.g.iter().any(|g| g.0 == 1);
            if g0 && g1 {
                return Err(self.fault(
                    Fault::Group00With01,
                    "G codes of groups 00 and 01 in one block",
                ));
            }
        }
        self.units(b);
        for (c, (v, _)) in b.words.iter() {
            let axis_word = self.core.setup.axes.contains(&c)
                || self
                    .core
                    .setup
                    .axes
                    .iter()
                    .any(|&a| self.inc_letter(a) == Some(c));
            let known = axis_word
                || matches!(
                    c,
                    'F' | 'S' | 'T' | 'P' | 'Q' | 'R' | 'I' | 'J' | 'K' | 'L' | 'D' | 'E'
                )
                || D::extra_address(c);
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

    /// Reads the block's words in millimetres, degrees, seconds and mm/min: a number without
    /// a decimal point counts least input increments where the machine reads numbers so
    /// (D52), and lengths and feeds are in inches under G20 (D53). The range checks after it
    /// see millimetres.
    fn units(&self, b: &mut Block<D>) {
        let inch = if b.has_g(G::InchInput) {
            true
        } else if b.has_g(G::MetricInput) {
            false
        } else {
            self.inch
        };
        if self.calculator && !inch {
            return;
        }
        let mut units = [WordUnit::Plain; 26];
        for (c, _) in b.words.iter() {
            units[usize::from(c as u8 - b'A')] = D::word_unit(self, b, c);
        }
        let increments = !self.calculator;
        // The least input increment: 0.001 mm, 0.0001 inch, 0.001 degree, 1 ms on the mill.
        let step = if inch {
            self.rules.increment / 10.0
        } else {
            self.rules.increment
        };
        let scale = if inch { 25.4 } else { 1.0 };
        for (i, unit) in units.into_iter().enumerate() {
            let Some(&(v, point)) = b.words.get(&char::from(b'A' + i as u8)) else {
                continue;
            };
            let counted = increments && !point;
            let v = match unit {
                WordUnit::Plain => continue,
                WordUnit::Length if counted => v * step * scale,
                WordUnit::Length | WordUnit::Feed => v * scale,
                WordUnit::Angle | WordUnit::Time if counted => v * self.rules.increment,
                WordUnit::Angle | WordUnit::Time => v,
            };
            // A counted value is a value in mm now, as one written with a point.
            b.words.set(i, (v, point || counted));
        }
    }

    /// The family's word units: F a feed; I, J, K, R lengths; linear axes (and their
    /// incremental addresses) lengths, rotary axes angles; X or U of G04 a time.
    pub fn default_word_unit(&self, b: &Block<D>, c: char) -> WordUnit {
        let axes = &self.core.setup.axes;
        let axis = axes.contains(&c) || axes.iter().any(|&a| self.inc_letter(a) == Some(c));
        match c {
            'F' => WordUnit::Feed,
            'I' | 'J' | 'K' | 'R' => WordUnit::Length,
            'X' | 'U' if axis && b.has_g(G::Dwell) => WordUnit::Time,
            'A' | 'B' | 'C' if axis => WordUnit::Angle,
            _ if axis => WordUnit::Length,
            _ => WordUnit::Plain,
        }
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

    /// One code per modal group in a block, where the dialect allows no more.
    fn one_per_group(
        &self,
        letter: char,
        v: f64,
        modal: bool,
        group: u32,
        seen: &mut Vec<u32>,
    ) -> Result<(), ProgramError> {
        if D::ONE_CODE_PER_GROUP && modal && seen.contains(&group) {
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

    /// The incremental address of an axis (U for X, W for Z, ...), in dialects that have
    /// them; elsewhere incremental moves come from G91.
    pub fn inc_letter(&self, axis: char) -> Option<char> {
        if D::INCREMENTAL_ADDRESSES {
            incremental_letter(axis)
        } else {
            None
        }
    }
}
