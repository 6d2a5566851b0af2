//! The interpreter core: reads a program block by block and yields canonical commands.
//!
//! Pure and streaming: it holds the program text and a cursor, and produces commands only as
//! they are asked for, so the motion queue's credit decides how far ahead it reads. An error
//! stops it for good: nothing after the bad line is produced.

use std::collections::VecDeque;

use crate::canon::{Aux, Canon, Command};
use crate::dialect::{Dialect, GMeaning, MMeaning};
use crate::error::{alarm, ProgramError};
use crate::lexer::{lex_line, Word};

/// Tolerance for "the end point lies on the arc" and for "start equals end", mm.
const ARC_TOLERANCE: f64 = 0.005;
/// Most M codes in one block (`000` alarm 10).
const MAX_M_PER_BLOCK: usize = 3;
/// Largest feed accepted, mm/min (`000` alarm 113 names 15000 mm/min as the interpolation limit).
const MAX_FEED: f64 = 15000.0;

/// Words of one block after validation, before execution.
#[derive(Debug, Default)]
struct Block {
    motion: Option<GMeaning>,
    dwell: bool,
    distance: Option<GMeaning>,
    /// Per machine axis: absolute value, or incremental amount.
    absolute: Vec<Option<f64>>,
    incremental: Vec<Option<f64>>,
    r: Option<f64>,
    i: Option<f64>,
    k: Option<f64>,
    f: Option<f64>,
    s: Option<f64>,
    t: Option<i32>,
    p: Option<f64>,
    /// G04 X/U time in seconds (X wins over U).
    dwell_seconds: Option<f64>,
    m: Vec<(i32, MMeaning)>,
}

/// Streaming interpreter for one program run.
pub struct Interpreter {
    dialect: Dialect,
    text: String,
    cursor: usize,
    line: u32,
    /// Machine axis letters in machine order, e.g. `['X', 'Z']`.
    axes: Vec<char>,
    /// Axes programmed in diameter (lathe X).
    diameter: Vec<bool>,
    position: Vec<f64>,
    motion_mode: GMeaning,
    incremental: bool,
    feed: f64,
    pending: VecDeque<Canon>,
    done: bool,
    error: Option<ProgramError>,
}

impl Interpreter {
    /// `axes` are the machine's axis letters; `start` its commanded position (X as diameter).
    pub fn new(
        dialect: Dialect,
        text: &str,
        axes: &[char],
        diameter: &[bool],
        start: &[f64],
    ) -> Self {
        Interpreter {
            dialect,
            text: text.to_string(),
            cursor: 0,
            line: 0,
            axes: axes.to_vec(),
            diameter: diameter.to_vec(),
            // One value per axis whatever the caller passed: a missing one starts at 0.
            position: (0..axes.len())
                .map(|i| start.get(i).copied().unwrap_or(0.0))
                .collect(),
            motion_mode: GMeaning::Rapid,
            incremental: false,
            feed: 0.0,
            pending: VecDeque::new(),
            done: false,
            error: None,
        }
    }

    /// The next canonical command; `Ok(None)` once the program has ended.
    pub fn next_command(&mut self) -> Result<Option<Canon>, ProgramError> {
        loop {
            if let Some(e) = &self.error {
                return Err(e.clone());
            }
            if let Some(c) = self.pending.pop_front() {
                return Ok(Some(c));
            }
            if self.done {
                return Ok(None);
            }
            if let Err(e) = self.read_block() {
                self.error = Some(e.clone());
                self.pending.clear();
                return Err(e);
            }
        }
    }

    /// Reads one line and queues its commands.
    fn read_block(&mut self) -> Result<(), ProgramError> {
        if self.cursor >= self.text.len() {
            // End of text without M02/M30: the program ends here.
            self.finish(self.line);
            return Ok(());
        }
        let rest = &self.text[self.cursor..];
        let (raw, advance) = match rest.find('\n') {
            Some(i) => (&rest[..i], i + 1),
            None => (rest, rest.len()),
        };
        self.cursor += advance;
        self.line += 1;
        let line = lex_line(raw, self.line)?;
        if line.end_of_text {
            self.finish(self.line);
            return Ok(());
        }
        if line.block_skip || line.words.is_empty() {
            return Ok(());
        }
        let block = self.decode(&line.words)?;
        self.execute(block)
    }

    fn finish(&mut self, line: u32) {
        self.pending.push_back(Canon {
            line,
            command: Command::ProgramEnd,
        });
        self.done = true;
    }

    fn err(&self, number: u32, text: impl Into<String>) -> ProgramError {
        ProgramError::new(number, self.line, text)
    }

    /// Checks every word of a block and sorts it into a [`Block`].
    fn decode(&self, words: &[Word]) -> Result<Block, ProgramError> {
        let n = self.axes.len();
        let mut b = Block {
            absolute: vec![None; n],
            incremental: vec![None; n],
            ..Block::default()
        };
        let mut group1_explicit = false;
        let mut group0_explicit = false;
        let mut seen = Vec::new();
        // G04 takes X/U as its time: find it first.
        let dwell_block = words
            .iter()
            .any(|w| w.letter == 'G' && (w.value * 10.0).round() == 40.0);
        for w in words {
            let letter = w.letter;
            if letter != 'G' && letter != 'M' {
                if seen.contains(&letter) {
                    return Err(self.err(
                        alarm::DATA_FORMAT,
                        format!("address {letter} twice in one block"),
                    ));
                }
                seen.push(letter);
            }
            match letter {
                'O' | 'N' => {}
                'G' => {
                    let x10 = (w.value * 10.0).round();
                    let code =
                        if w.value >= 0.0 && (w.value * 10.0 - x10).abs() < 1e-6 && x10 < 10000.0 {
                            self.dialect.g_code(x10 as u32)
                        } else {
                            None
                        };
                    let code = code.ok_or_else(|| {
                        self.err(
                            alarm::UNDEFINED_CODE,
                            format!("undefined G code G{}", w.value),
                        )
                    })?;
                    match code.group {
                        0 => {
                            group0_explicit = true;
                            b.dwell = true;
                        }
                        1 => {
                            group1_explicit = true;
                            b.motion = Some(code.meaning); // same group twice: the last one wins
                        }
                        _ => b.distance = Some(code.meaning),
                    }
                }
                'M' => {
                    let m = integer(w).ok_or_else(|| {
                        self.err(
                            alarm::DATA_FORMAT,
                            format!("M code must be an integer, found M{}", w.value),
                        )
                    })?;
                    let meaning = u32::try_from(m)
                        .ok()
                        .and_then(|m| self.dialect.m_code(m))
                        .ok_or_else(|| {
                            self.err(alarm::UNDEFINED_CODE, format!("undefined M code M{m}"))
                        })?;
                    b.m.push((m, meaning));
                    if b.m.len() > MAX_M_PER_BLOCK {
                        return Err(self.err(alarm::TOO_MANY_M, "more than 3 M codes in one block"));
                    }
                }
                'X' | 'U' if dwell_block => {
                    if letter == 'X' || b.dwell_seconds.is_none() {
                        b.dwell_seconds = Some(w.value);
                    }
                }
                'P' => b.p = Some(w.value),
                'R' => b.r = Some(w.value),
                'I' => b.i = Some(w.value),
                'K' => b.k = Some(w.value),
                'F' => {
                    if !(0.0..=MAX_FEED).contains(&w.value) {
                        return Err(self.err(
                            alarm::FEED_OUT_OF_RANGE,
                            format!("feed F{} out of range 0..{MAX_FEED}", w.value),
                        ));
                    }
                    b.f = Some(w.value);
                }
                'S' => {
                    if !(0.0..=99999.0).contains(&w.value) {
                        return Err(self.err(
                            alarm::DATA_FORMAT,
                            format!("spindle speed S{} out of range", w.value),
                        ));
                    }
                    b.s = Some(w.value);
                }
                'T' => {
                    b.t = Some(
                        integer(w)
                            .filter(|t| (0..=9999).contains(t))
                            .ok_or_else(|| {
                                self.err(
                                    alarm::DATA_FORMAT,
                                    format!("tool word T{} must be an integer 0..9999", w.value),
                                )
                            })?,
                    );
                }
                _ => {
                    let axis = self.dialect.axis_words().iter().find_map(|&(abs, inc)| {
                        let idx = self.axes.iter().position(|&a| a == abs)?;
                        (letter == abs)
                            .then_some((idx, true))
                            .or((letter == inc).then_some((idx, false)))
                    });
                    match axis {
                        Some((idx, true)) => b.absolute[idx] = Some(w.value),
                        Some((idx, false)) => b.incremental[idx] = Some(w.value),
                        None => {
                            return Err(self
                                .err(alarm::UNDEFINED_CODE, format!("undefined address {letter}")))
                        }
                    }
                }
            }
        }
        if group0_explicit && group1_explicit {
            return Err(self.err(
                alarm::GROUP_00_WITH_01,
                "G codes of groups 00 and 01 in one block",
            ));
        }
        for idx in 0..n {
            if b.absolute[idx].is_some() && b.incremental[idx].is_some() {
                return Err(self.err(
                    alarm::ABS_AND_INC_SAME_AXIS,
                    format!(
                        "absolute and incremental word for axis {} in one block",
                        self.axes[idx]
                    ),
                ));
            }
        }
        Ok(b)
    }

    /// Queues a decoded block's commands in execution order: F, S, T and the M codes that start
    /// things, then the motion or dwell, then the M codes that stop things, then program end.
    fn execute(&mut self, b: Block) -> Result<(), ProgramError> {
        let line = self.line;
        let mut out = Vec::new();
        if let Some(f) = b.f {
            self.feed = f;
        }
        if let Some(d) = b.distance {
            self.incremental = d == GMeaning::Incremental;
        }
        if let Some(m) = b.motion {
            self.motion_mode = m;
        }
        if let Some(s) = b.s {
            out.push(Command::Aux(Aux::S(s)));
        }
        if let Some(t) = b.t {
            out.push(Command::Aux(Aux::T(t)));
        }
        for &(m, meaning) in &b.m {
            if meaning == MMeaning::AuxBefore {
                out.push(Command::Aux(Aux::M(m)));
            }
        }
        if b.dwell {
            // Priority P (ms) > X (s) > U (s), `000` §5.15.
            let ms = b.p.or(b.dwell_seconds.map(|s| s * 1000.0)).unwrap_or(0.0);
            if ms.abs() > 99_999_999.0 {
                return Err(self.err(alarm::DWELL_TIME, "G04 dwell time out of range"));
            }
            out.push(Command::Dwell {
                seconds: ms.max(0.0) / 1000.0,
            });
        } else {
            let has_axis = b.absolute.iter().chain(&b.incremental).any(Option::is_some);
            let arc = matches!(self.motion_mode, GMeaning::ArcCw | GMeaning::ArcCcw);
            if has_axis || (arc && (b.i.is_some() || b.k.is_some())) {
                let end = self.end_point(&b);
                out.push(self.motion(&b, end)?);
            }
        }
        for &(m, meaning) in &b.m {
            if meaning == MMeaning::AuxAfter {
                out.push(Command::Aux(Aux::M(m)));
            }
        }
        let ends = b.m.iter().find(|(_, m)| *m == MMeaning::ProgramEnd);
        if let Some(&(m, _)) = ends {
            out.push(Command::Aux(Aux::M(m)));
        }
        self.pending
            .extend(out.into_iter().map(|command| Canon { line, command }));
        if ends.is_some() {
            self.finish(line);
        }
        Ok(())
    }

    fn end_point(&self, b: &Block) -> Vec<f64> {
        (0..self.axes.len())
            .map(|i| match (b.absolute[i], b.incremental[i]) {
                (Some(v), _) if self.incremental => self.position[i] + v,
                (Some(v), _) => v,
                (None, Some(d)) => self.position[i] + d,
                (None, None) => self.position[i],
            })
            .collect()
    }

    fn motion(&mut self, b: &Block, end: Vec<f64>) -> Result<Command, ProgramError> {
        let cmd = match self.motion_mode {
            GMeaning::Rapid => Command::Rapid { end: end.clone() },
            GMeaning::Linear => Command::Linear {
                end: end.clone(),
                feed: self.cutting_feed()?,
            },
            GMeaning::ArcCw | GMeaning::ArcCcw => {
                let clockwise = self.motion_mode == GMeaning::ArcCw;
                let feed = self.cutting_feed()?;
                let center = self.arc_center(b, &end, clockwise)?;
                Command::Arc {
                    end: end.clone(),
                    center,
                    clockwise,
                    feed,
                }
            }
            other => {
                return Err(self.err(alarm::UNDEFINED_CODE, format!("{other:?} is not a motion")))
            }
        };
        self.position = end;
        Ok(cmd)
    }

    fn cutting_feed(&self) -> Result<f64, ProgramError> {
        if self.feed <= 0.0 {
            return Err(self.err(
                alarm::FEED_OUT_OF_RANGE,
                "no feed programmed for a cutting move (F missing or 0)",
            ));
        }
        Ok(self.feed)
    }

    /// Arc centre in machine coordinates. Geometry runs in the ZX plane with X as radius;
    /// seen with Z to the right and X up, G02 turns clockwise (decision D3).
    fn arc_center(
        &self,
        b: &Block,
        end: &[f64],
        clockwise: bool,
    ) -> Result<Vec<f64>, ProgramError> {
        let (xi, zi) = match (self.axis_index('X'), self.axis_index('Z')) {
            (Some(x), Some(z)) => (x, z),
            _ => return Err(self.err(alarm::AXIS_ADDRESS, "arcs need the X and Z axes")),
        };
        let scale = |i: usize| if self.diameter[i] { 0.5 } else { 1.0 };
        let (sx, sz) = (self.position[xi] * scale(xi), self.position[zi]);
        let (ex, ez) = (end[xi] * scale(xi), end[zi]);
        let (dz, dx) = (ez - sz, ex - sx);
        let chord = (dz * dz + dx * dx).sqrt();
        let (cz, cx) = match (b.r, b.i.is_some() || b.k.is_some()) {
            (Some(_), true) => {
                return Err(self.err(alarm::ARC_R_AND_IJK, "arc with both R and I/K"))
            }
            (Some(r), false) => {
                if chord < ARC_TOLERANCE {
                    return Err(self.err(
                        alarm::ARC_RADIUS_TOO_SMALL,
                        "a full circle cannot be programmed with R",
                    ));
                }
                let half = chord / 2.0;
                if r.abs() + 1e-9 < half {
                    return Err(self.err(
                        alarm::ARC_RADIUS_TOO_SMALL,
                        format!("arc radius R{r} is smaller than half the chord ({half:.4})"),
                    ));
                }
                let h = (r * r - half * half).max(0.0).sqrt();
                // Left of the chord direction in the (Z right, X up) plane.
                let (lz, lx) = (-dx / chord, dz / chord);
                // CCW minor arc: centre on the left; CW: right; R < 0 (more than 180°) flips it.
                let side = if clockwise { -1.0 } else { 1.0 } * r.signum();
                (sz + dz / 2.0 + side * h * lz, sx + dx / 2.0 + side * h * lx)
            }
            (None, true) => {
                let (cz, cx) = (sz + b.k.unwrap_or(0.0), sx + b.i.unwrap_or(0.0));
                let r_start = ((sz - cz).powi(2) + (sx - cx).powi(2)).sqrt();
                let r_end = ((ez - cz).powi(2) + (ex - cx).powi(2)).sqrt();
                if r_start < ARC_TOLERANCE || (r_start - r_end).abs() > ARC_TOLERANCE {
                    return Err(self.err(
                        alarm::ARC_END_NOT_ON_CIRCLE,
                        format!("arc end point is not on the circle (radius {r_start:.4} at start, {r_end:.4} at end)"),
                    ));
                }
                (cz, cx)
            }
            (None, false) => {
                return Err(self.err(alarm::ARC_RADIUS_TOO_SMALL, "arc needs R or I/K"))
            }
        };
        let mut center = self.position.clone();
        center[xi] = cx / scale(xi);
        center[zi] = cz;
        Ok(center)
    }

    fn axis_index(&self, letter: char) -> Option<usize> {
        self.axes.iter().position(|&a| a == letter)
    }
}

fn integer(w: &Word) -> Option<i32> {
    (w.value.fract() == 0.0 && w.value.abs() < i32::MAX as f64).then_some(w.value as i32)
}

/// Interprets a whole program without running it: every command, or the first error.
pub fn check(
    dialect: Dialect,
    text: &str,
    axes: &[char],
    diameter: &[bool],
    start: &[f64],
) -> Result<Vec<Canon>, ProgramError> {
    let mut interp = Interpreter::new(dialect, text, axes, diameter, start);
    let mut out = Vec::new();
    while let Some(c) = interp.next_command()? {
        out.push(c);
    }
    Ok(out)
}
