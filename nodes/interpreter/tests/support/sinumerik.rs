//! What the tests of the 802D manual's example programs share: the fixture's text, the
//! simulated mill, a run to the end or the first alarm, and comparisons.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Command, Library, Setup};
use cnc_interpreter_core::{next_command, ProgramError, ToolOffset};

pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/fixtures/001")
}

/// The fixture's text below its header (`; ---- program text as printed below ----`).
pub fn fixture(number: &str) -> String {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir())
        .expect("fixtures 001")
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(number))
        })
        .collect();
    paths.sort();
    let text = std::fs::read_to_string(&paths[0]).expect("fixture text");
    match text.split_once("; ---- program text as printed below ----\n") {
        Some((_, body)) => body.to_string(),
        None => text,
    }
}

/// The simulated 802D mill: X Y Z at zero, tool T1 D1 of 10 mm radius and 50 mm length.
pub fn mill() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    s.offsets.tools.insert(
        11,
        ToolOffset {
            z: 50.0,
            radius: 10.0,
            ..ToolOffset::default()
        },
    );
    s
}

/// The mill with one cutting edge (`entry` T·10+D) of `radius` and length 0: machine Z is
/// the cutter's tip.
pub fn with_edge(entry: u32, radius: f64) -> Setup {
    let mut s = mill();
    s.offsets.tools.insert(
        entry,
        ToolOffset {
            radius,
            ..ToolOffset::default()
        },
    );
    s
}

/// A line the manual prints as a placeholder (`...`, `…`, `X... Y...`, a line of dots).
pub fn placeholder(line: &str) -> bool {
    let code = line.split(';').next().unwrap_or("").trim();
    code.contains("...")
        || code.contains('…')
        || (!code.is_empty() && code.bytes().all(|b| b == b'.'))
}

/// The fixture with its placeholder lines replaced by `fills`, one each, in order (an
/// empty fill leaves an empty line, so line numbers stay the manual's).
pub fn filled(number: &str, fills: &[&str]) -> String {
    let text = fixture(number);
    let holes = text.lines().filter(|l| placeholder(l)).count();
    assert_eq!(holes, fills.len(), "{number}: {holes} placeholder lines");
    let mut fills = fills.iter();
    let mut out = String::new();
    for line in text.lines() {
        if placeholder(line) {
            out.push_str(fills.next().copied().unwrap_or(""));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// The line (1-based) of the fixture text that starts with `block` (`N90`).
pub fn line_of(text: &str, block: &str) -> u32 {
    text.lines()
        .position(|l| l.trim_start().starts_with(block))
        .map(|i| i as u32 + 1)
        .unwrap_or_else(|| panic!("no block {block}"))
}

pub struct Run {
    pub front: Sinumerik,
    pub out: Vec<Command>,
    /// The program line of each command of `out`.
    pub lines: Vec<u32>,
    pub error: Option<ProgramError>,
}

pub fn run_with(text: &str, setup: Setup, library: Library) -> Run {
    let mut front = Sinumerik::new(text, setup, library);
    let mut out = Vec::new();
    let mut lines = Vec::new();
    let error = loop {
        match next_command(&mut front) {
            Ok(Some(c)) => {
                lines.push(c.line);
                out.push(c.command);
            }
            Ok(None) => break None,
            Err(e) => break Some(e),
        }
        assert!(out.len() < 100_000, "runaway program");
    };
    Run {
        front,
        out,
        lines,
        error,
    }
}

pub fn run(text: &str) -> Run {
    run_with(text, mill(), Library::new())
}

impl Run {
    pub fn ok(self) -> Run {
        assert!(self.error.is_none(), "{:?}", self.error);
        self
    }
    pub fn alarm(&self) -> (u32, u32) {
        let e = self.error.as_ref().expect("an alarm");
        (e.number, e.line)
    }
    pub fn moves(&self) -> Vec<&Command> {
        self.out.iter().filter(|c| c.end().is_some()).collect()
    }
    /// Every move's end point, in order.
    pub fn ends(&self) -> Vec<Vec<f64>> {
        self.out
            .iter()
            .filter_map(|c| c.end().map(<[f64]>::to_vec))
            .collect()
    }
    pub fn end(&self) -> Vec<f64> {
        self.moves()
            .last()
            .and_then(|c| c.end())
            .expect("a move")
            .to_vec()
    }
}

pub fn near(a: &[f64], b: &[f64]) -> bool {
    within(a, b, 1e-3)
}

pub fn within(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
}

pub fn arc(c: &Command) -> (Vec<f64>, Vec<f64>, bool) {
    match c {
        Command::Arc {
            end,
            center,
            clockwise,
            ..
        } => (end.clone(), center.clone(), *clockwise),
        other => panic!("not an arc: {other:?}"),
    }
}
