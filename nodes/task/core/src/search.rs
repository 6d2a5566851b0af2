//! Block search and restart: a program started at a block in mid-program (issue 28; decisions
//! D67). The search runs the program from its top through the interpreter without motion
//! ("with calculation", 802D `001` §6.5; FANUC program restart, `003` part 2), so variables,
//! jumps, subprogram levels, offsets, the modal codes and the position are rebuilt exactly as
//! an uninterrupted run would have them at the block. What the machine must be given before
//! that block, it is given first: the tool, the spindle speed and direction and the coolant
//! (the last of each that the skipped part programmed), then an approach to where the block
//! starts, the retract axis first, as the machine's config says.

use cnc_interpreter_core::{Fault, Turn};

use cnc_interpreter::interpreter::MAX_CHECK_COMMANDS;
use cnc_interpreter::{Aux, Canon, Command, Dialect, Interpreter, ProgramError, Setup};

/// Where a program starts.
#[derive(Debug, Clone, PartialEq)]
pub enum SearchTarget {
    /// The first command the program makes at or after this line of the main program (the
    /// calling line for a called program's commands), in the order the program runs.
    Line(u32),
    /// The main program's block numbered `N`.
    Sequence(u32),
    /// The main program's line that begins with this label (`NAME:`).
    Label(String),
    /// The program's `n`-th canonical command (from 1), where a run was interrupted: the
    /// kept program position (decisions D64, D67).
    Block(u64),
}

impl SearchTarget {
    /// Reads the start the operator or the supervisor asks for: empty (the top), `line 12`,
    /// `N120`, `label NAME` or `block 57`.
    pub fn parse(text: &str) -> Result<Option<SearchTarget>, String> {
        let t = text.trim();
        let number = |s: &str| -> Result<u64, String> {
            s.trim()
                .parse::<u64>()
                .ok()
                .filter(|n| *n > 0 && *n <= u64::from(u32::MAX))
                .ok_or_else(|| format!("block search {t:?}: {s:?} is not a number from 1"))
        };
        if t.is_empty() {
            return Ok(None);
        }
        let target = if let Some(n) = t.strip_prefix("line ") {
            SearchTarget::Line(number(n)? as u32)
        } else if let Some(n) = t.strip_prefix("block ") {
            SearchTarget::Block(number(n)?)
        } else if let Some(name) = t.strip_prefix("label ") {
            let name = name.trim();
            if name.is_empty()
                || name.len() > 32
                || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                return Err(format!("block search: label {name:?} is not a label name"));
            }
            SearchTarget::Label(name.to_string())
        } else if let Some(n) = t.strip_prefix(['N', 'n']) {
            SearchTarget::Sequence(number(n)? as u32)
        } else {
            return Err(format!(
                "block search {t:?}: give `line L`, `N<number>`, `label NAME` or `block B`"
            ));
        };
        Ok(Some(target))
    }
}

/// How the machine approaches the restart point (the launch config's `machine.restart`).
#[derive(Debug, Clone, PartialEq)]
pub struct Approach {
    /// The axis that takes the tool away from the work (lathe X, mill Z), by index.
    pub retract_axis: usize,
    /// Away from the work is the axis's positive direction.
    pub retract_positive: bool,
    /// The last leg, onto the restart point, runs at this feed (mm/min): the tool may arrive
    /// in the cut.
    pub feed: f64,
    /// The last leg's length (mm): the retract axis comes at rapid to this distance from the
    /// point, then at the approach feed.
    pub clearance: f64,
    /// Where the retract axis must stand for an M06 tool change (a mill's second reference
    /// point, `003` §6.2); `None`: the tool changes where the axes stand (a lathe's turret).
    pub tool_change_at: Option<f64>,
}

impl Approach {
    /// The usual approach on `machine`: a mill (with Y) retracts Z upwards and changes tools
    /// at Z's second reference point, a lathe retracts X outwards; 500 mm/min onto the point.
    pub fn default_for(machine: &Setup) -> Approach {
        let mill = machine.axes.contains(&'Y');
        let letter = if mill { 'Z' } else { 'X' };
        let retract_axis = machine.axes.iter().position(|&a| a == letter).unwrap_or(0);
        Approach {
            retract_axis,
            retract_positive: true,
            feed: DEFAULT_APPROACH_FEED,
            clearance: DEFAULT_CLEARANCE,
            tool_change_at: machine
                .second_reference
                .get(retract_axis)
                .copied()
                .filter(|_| mill),
        }
    }
}

/// The approach's last leg, mm/min, unless the config says otherwise.
pub const DEFAULT_APPROACH_FEED: f64 = 500.0;
/// The approach's last leg, mm, unless the config says otherwise.
pub const DEFAULT_CLEARANCE: f64 = 1.0;

/// The state a stream of commands leaves the machine in, as the PLC and motion see it: the
/// last of each modal code. A restart gives the machine these before the restart block.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Collected {
    /// Where the last move ended: the restart block starts there.
    pub position: Option<Vec<f64>>,
    pub feed_per_rev: Option<bool>,
    pub exact_stop: Option<bool>,
    /// The acceleration profile: jerk-limited or not.
    pub jerk_limited: Option<bool>,
    /// The drives' feedforward: on or off.
    pub feedforward: Option<bool>,
    /// Acceleration overrides, the last per axis.
    pub accelerations: Vec<(u8, f64)>,
    /// The last T: on a lathe the turret's station, on a mill the tool put ready.
    pub tool: Option<i32>,
    /// The tool the last M06 put in a mill's spindle (the T before it).
    pub loaded: Option<i32>,
    pub speed: Option<f64>,
    /// M03, M04, M05, M19 or a spindle position (an incremental one as M05: where it
    /// left the spindle is not known before the machine runs; D100).
    pub spindle: Option<Aux>,
    /// M07, M08 or M09.
    pub coolant: Option<i32>,
    /// M41–M44.
    pub gear: Option<i32>,
}

impl Collected {
    /// Takes one more command of the skipped part. Other M codes (stops, chuck, tailstock,
    /// the part counter) are events or handshakes whose effect stays on the machine: they are
    /// not given again (decisions D67).
    pub fn take(&mut self, c: &Command) {
        if let Some(end) = c.end() {
            self.position = Some(end.to_vec());
        }
        match *c {
            Command::FeedMode { per_rev } => self.feed_per_rev = Some(per_rev),
            Command::PathMode { exact_stop } => self.exact_stop = Some(exact_stop),
            Command::Profile { jerk_limited } => self.jerk_limited = Some(jerk_limited),
            Command::Feedforward { on } => self.feedforward = Some(on),
            Command::Acceleration { axis, percent } => {
                self.accelerations.retain(|(a, _)| *a != axis);
                self.accelerations.push((axis, percent));
            }
            Command::Aux(Aux::T(t)) => self.tool = Some(t),
            Command::Aux(Aux::S(s)) => self.speed = Some(s),
            Command::Aux(Aux::Orient {
                way: Turn::Incremental,
                ..
            }) => {
                self.spindle = Some(Aux::M(5));
            }
            Command::Aux(orient @ Aux::Orient { .. }) => self.spindle = Some(orient),
            Command::Aux(Aux::M(m)) => match m {
                3 | 4 | 5 | 19 => self.spindle = Some(Aux::M(m)),
                7..=9 => self.coolant = Some(m),
                41..=44 => self.gear = Some(m),
                6 => self.loaded = self.tool,
                _ => {}
            },
            _ => {}
        }
    }

    /// What the machine is given before the restart block, from `here`: tool (a mill's tool
    /// change at its change position), gear range, speed, spindle, coolant, then the approach (retract axis away from the work, the other
    /// axes, the retract axis onto the point at the approach feed) and the modes the block
    /// runs in. Each command is on `line` of the restart block.
    pub fn preamble(&self, here: &[f64], approach: &Approach, line: u32, main: u32) -> Vec<Canon> {
        let mut out = Vec::new();
        let mut push = |command| {
            out.push(Canon {
                line,
                main_line: main,
                command,
            })
        };
        let mut here = here.to_vec();
        let r = approach.retract_axis.min(here.len().saturating_sub(1));
        if let Some(t) = self.loaded {
            // A mill changes tools with the tool axis at its change position.
            let elsewhere = |h: &f64| here.get(r).is_some_and(|x| x != h);
            if let Some(h) = approach.tool_change_at.filter(elsewhere) {
                here[r] = h;
                push(Command::Rapid { end: here.clone() });
            }
            push(Command::Aux(Aux::T(t)));
            push(Command::Aux(Aux::M(6)));
        }
        if let Some(t) = self.tool.filter(|t| self.loaded != Some(*t)) {
            push(Command::Aux(Aux::T(t)));
        }
        for m in [self.gear].into_iter().flatten() {
            push(Command::Aux(Aux::M(m)));
        }
        if let Some(s) = self.speed {
            push(Command::Aux(Aux::S(s)));
        }
        if let Some(a) = self.spindle {
            push(Command::Aux(a));
        }
        if let Some(m) = self.coolant {
            push(Command::Aux(Aux::M(m)));
        }
        if let Some(target) = self
            .position
            .as_ref()
            .filter(|t| t.len() == here.len() && **t != here)
        {
            let away = if approach.retract_positive {
                here[r].max(target[r])
            } else {
                here[r].min(target[r])
            };
            push(Command::FeedMode { per_rev: false });
            push(Command::PathMode { exact_stop: true });
            let mut at = here.to_vec();
            if at[r] != away {
                at[r] = away;
                push(Command::Rapid { end: at.clone() });
            }
            let mut over = target.clone();
            over[r] = away;
            if over != at {
                push(Command::Rapid { end: over.clone() });
            }
            // Rapid to the clearance short of the point, then the approach feed.
            if (away - target[r]).abs() > approach.clearance {
                let sign = if approach.retract_positive { 1.0 } else { -1.0 };
                over[r] = target[r] + sign * approach.clearance;
                push(Command::Rapid { end: over.clone() });
            }
            if over != *target {
                push(Command::Linear {
                    end: target.clone(),
                    feed: approach.feed,
                });
            }
        }
        push(Command::FeedMode {
            per_rev: self.feed_per_rev.unwrap_or(false),
        });
        push(Command::PathMode {
            exact_stop: self.exact_stop.unwrap_or(false),
        });
        if let Some(jerk_limited) = self.jerk_limited {
            push(Command::Profile { jerk_limited });
        }
        if let Some(on) = self.feedforward {
            push(Command::Feedforward { on });
        }
        for &(axis, percent) in &self.accelerations {
            push(Command::Acceleration { axis, percent });
        }
        out
    }
}

/// A program found at its restart block.
#[derive(Debug)]
pub struct Restart {
    /// Commands of the program before the restart block (run without motion).
    pub skipped: u64,
    /// What the skipped part left the machine in.
    pub collected: Collected,
    /// What the machine is given first ([`Collected::preamble`]).
    pub preamble: Vec<Canon>,
    /// The restart block's first command.
    pub first: Canon,
}

/// The main-program line where `target` is, for a sequence number or a label.
fn target_line(text: &str, target: &SearchTarget) -> Option<u32> {
    let mut lines = text.lines().zip(1u32..);
    match target {
        SearchTarget::Line(l) => Some(*l),
        SearchTarget::Sequence(n) => lines
            .find(|(l, _)| cnc_interpreter_core::text::line_number(l) == Some(*n))
            .map(|(_, i)| i),
        SearchTarget::Label(name) => lines
            .find(|(l, _)| {
                l.trim_start()
                    .strip_prefix(name.as_str())
                    .is_some_and(|rest| rest.starts_with(':'))
            })
            .map(|(_, i)| i),
        SearchTarget::Block(_) => None,
    }
}

/// Runs `interp` (a program `text` of `dialect`, at machine position `here`) without motion
/// up to `target`, and says what the restart needs. An alarm in the skipped part, or a
/// target the program never reaches, is an error with the control's alarm number: nothing is
/// started.
pub fn search(
    dialect: Dialect,
    interp: &mut Interpreter,
    text: &str,
    target: &SearchTarget,
    here: &[f64],
    approach: &Approach,
) -> Result<Restart, ProgramError> {
    let not_found = |what: String| {
        ProgramError::new(
            dialect.alarm(Fault::TargetNotFound),
            0,
            format!("block search: {what} not found before the program end"),
        )
    };
    let line = match target {
        SearchTarget::Block(_) => None,
        SearchTarget::Line(0) => return Err(not_found("line 0".into())),
        t => Some(target_line(text, t).ok_or_else(|| not_found(describe(t)))?),
    };
    interp.set_searching(true);
    let found = run_to(interp, (target, line), here, approach, &not_found);
    interp.set_searching(false);
    found
}

/// The search's run: commands up to the target, collected.
fn run_to(
    interp: &mut Interpreter,
    (target, line): (&SearchTarget, Option<u32>),
    here: &[f64],
    approach: &Approach,
    not_found: &dyn Fn(String) -> ProgramError,
) -> Result<Restart, ProgramError> {
    let mut collected = Collected::default();
    let mut skipped: u64 = 0;
    loop {
        let Some(c) = interp.next_command()? else {
            return Err(not_found(describe(target)));
        };
        let hit = match (target, line) {
            (SearchTarget::Block(n), _) => skipped + 1 == *n,
            (_, Some(l)) => c.main_line >= l,
            _ => false,
        };
        if hit {
            let preamble = collected.preamble(here, approach, c.line, c.main_line);
            return Ok(Restart {
                skipped,
                collected,
                preamble,
                first: c,
            });
        }
        if c.command == Command::ProgramEnd || skipped as usize >= MAX_CHECK_COMMANDS {
            return Err(not_found(describe(target)));
        }
        collected.take(&c.command);
        skipped += 1;
    }
}

fn describe(t: &SearchTarget) -> String {
    match t {
        SearchTarget::Line(l) => format!("line {l}"),
        SearchTarget::Sequence(n) => format!("N{n}"),
        SearchTarget::Label(name) => format!("label {name}"),
        SearchTarget::Block(b) => format!("block {b}"),
    }
}

#[cfg(test)]
#[path = "search_tests.rs"]
mod tests;
