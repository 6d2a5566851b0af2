//! Who may write each parameter and within which bounds (decisions D124): the one table the
//! launch config's reading, the parameter file's application and every write from the cell
//! (the bridge's `set_parameter`, the web panel's) go through.
//!
//! - **Builder only**: file paths, the dialect, the machine's geometry and kinematics, the
//!   drives' and the PLC's timing, the simulated machine's switches. Only the launch config
//!   sets them; a write from the cell is refused.
//! - **Cell**: the ratings' values (lowered only, [`crate::limits`]), a few settings of the
//!   run (dry run feed, the restart's approach, the look-ahead depth, the profile), and the
//!   monitors, which the cell may **tighten** down to a floor but never loosen beyond the
//!   builder's value (kept in `limits.monitors`).
//!
//! Every number, whoever writes it, lies within a range physics or the ratings give; a name the
//! table does not know is the builder's.

use crate::LaunchConfig;

/// Who may write a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Writer {
    /// The launch config only.
    Builder,
    /// The launch config, and the cell through `set_parameter` (stored in the parameter file).
    Cell,
}

/// The values a number may take: fixed, or from the config (its ratings).
#[derive(Clone, Copy)]
pub enum Range {
    Fixed(f64, f64),
    Of(fn(&LaunchConfig) -> (f64, f64)),
}

/// One row of the table. `pattern` names parameters as `parameters::list` does, `*` standing
/// for one part (an axis letter, a list index).
pub struct Rule {
    pub pattern: &'static str,
    pub writer: Writer,
    /// The range of a number, whoever writes it; `None`: not a number (the config's own rules
    /// decide its values).
    pub range: Option<Range>,
    /// A monitor: a write from the cell may only tighten it (a smaller value), from the
    /// builder's value down to the range's low end.
    pub monitor: bool,
    pub why: &'static str,
}

const fn builder(pattern: &'static str, range: Option<Range>, why: &'static str) -> Rule {
    Rule {
        pattern,
        writer: Writer::Builder,
        range,
        monitor: false,
        why,
    }
}

const fn cell(pattern: &'static str, range: Option<Range>, why: &'static str) -> Rule {
    Rule {
        pattern,
        writer: Writer::Cell,
        range,
        monitor: false,
        why,
    }
}

const fn monitor(pattern: &'static str, range: Range, why: &'static str) -> Rule {
    Rule {
        pattern,
        writer: Writer::Cell,
        range: Some(range),
        monitor: true,
        why,
    }
}

/// The fastest rated axis, mm/min: no feed of the machine's own choosing is faster.
fn feeds(cfg: &LaunchConfig) -> (f64, f64) {
    let fastest = cfg
        .limits
        .axes
        .values()
        .map(|a| a.max_velocity)
        .fold(1.0, f64::max);
    (1.0, fastest)
}

/// Up to the longest rated travel, mm.
fn distances(cfg: &LaunchConfig) -> (f64, f64) {
    let longest = cfg
        .limits
        .axes
        .values()
        .map(|a| a.max - a.min)
        .fold(1.0, f64::max);
    (0.0, longest)
}

/// Up to the machine's own queue.
fn lookahead(cfg: &LaunchConfig) -> (f64, f64) {
    (2.0, cfg.servo.queue_capacity as f64)
}

use Range::{Fixed, Of};

/// The table. Ratings (`min`, `max`, `max_velocity`, `max_acceleration`, `max_jerk`) are
/// further held to the `limits` section ([`crate::limits`]).
pub const RULES: &[Rule] = &[
    builder(
        "machine.dialect",
        None,
        "the control's language is the machine's",
    ),
    builder("machine.position_file", None, "a file path"),
    builder("machine.msg_file", None, "a file path"),
    builder(
        "machine.msg_file_kib",
        None,
        "the message file's size (10, 100, 1024)",
    ),
    builder(
        "machine.decimal_point",
        None,
        "how numbers are read changes the cut",
    ),
    builder("machine.tool_post", None, "geometry"),
    builder("machine.arc_plane.*", None, "geometry"),
    builder(
        "machine.tool_change_macro",
        None,
        "what the tool change runs",
    ),
    builder(
        "machine.tool_change_with_m6",
        None,
        "how the tool changer works",
    ),
    builder("machine.spindle_c_axis", None, "what the machine is"),
    builder("machine.c_axis.*", None, "what the spindle's drive can do"),
    builder("machine.live_tool.*", None, "what the machine is"),
    builder("machine.skip_input", None, "the machine's wiring"),
    builder(
        "machine.skip_keeps_actual",
        None,
        "where a program goes on after a skip",
    ),
    builder(
        "machine.reference_order.*",
        None,
        "the order the axes home in",
    ),
    builder("machine.external_drives.*", None, "a file path"),
    builder("machine.axes.*.diameter", None, "geometry"),
    builder("machine.axes.*.home", None, "geometry"),
    builder("machine.axes.*.reference", None, "the axis's encoder"),
    builder("machine.axes.*.second_reference", None, "geometry"),
    builder("machine.axes.*.fixed_points.*", None, "geometry"),
    builder(
        "machine.axes.*.overtravel",
        None,
        "the axis's limit switches",
    ),
    builder(
        "machine.axes.*.drive_lag",
        Some(Fixed(0.0, 1.0)),
        "the drive's time constant, s",
    ),
    cell("machine.axes.*.min", None, "a rating: narrowed only"),
    cell("machine.axes.*.max", None, "a rating: narrowed only"),
    cell(
        "machine.axes.*.max_velocity",
        None,
        "a rating: lowered only",
    ),
    cell(
        "machine.axes.*.max_acceleration",
        None,
        "a rating: lowered only",
    ),
    cell("machine.axes.*.max_jerk", None, "a rating: lowered only"),
    monitor(
        "machine.axes.*.following_error",
        Fixed(0.01, 100.0),
        "a monitor, mm",
    ),
    monitor(
        "machine.axes.*.in_position",
        Fixed(0.000_1, 1.0),
        "a monitor, mm",
    ),
    monitor(
        "machine.contour_tolerance",
        Fixed(0.000_1, 1.0),
        "the contour's tolerance, mm",
    ),
    cell(
        "machine.restart.retract",
        None,
        "the restart's retract direction",
    ),
    cell(
        "machine.restart.approach_feed",
        Some(Of(feeds)),
        "a feed, mm/min, up to the fastest rating",
    ),
    cell(
        "machine.restart.clearance",
        Some(Of(distances)),
        "a distance, mm, up to the longest travel",
    ),
    monitor(
        "servo.tolerance",
        Fixed(0.000_1, 10.0),
        "the path's tolerance, mm",
    ),
    monitor(
        "servo.late_alarm_ticks",
        Fixed(1.0, u32::MAX as f64),
        "a monitor, servo ticks",
    ),
    monitor(
        "servo.late_warning_ms",
        Fixed(1.0, 3_600_000.0),
        "a monitor, ms",
    ),
    monitor(
        "servo.feedback_lost_ticks",
        Fixed(1.0, 1_000.0),
        "a monitor, servo ticks",
    ),
    cell(
        "servo.dry_run_feed",
        Some(Of(feeds)),
        "a feed, mm/min, up to the fastest rating",
    ),
    cell(
        "servo.lookahead",
        Some(Of(lookahead)),
        "blocks planned ahead",
    ),
    cell("servo.profile", None, "the speed profile's shape"),
    builder("servo.period_ms", None, "the drives' cycle"),
    builder("servo.queue_capacity", None, "motion's memory"),
    builder(
        "servo.drive_queue_ms",
        Some(Fixed(0.0, 1_000.0)),
        "the drives' setpoint queue, ms",
    ),
    builder("servo.drive_trace", None, "a file the drives write"),
    builder("plc.*", None, "the PLC's program and timing"),
    builder("sim.*", None, "the simulated machine's switches"),
];

/// The rule of parameter `name` (a name the table does not know is the builder's).
pub fn rule(name: &str) -> &'static Rule {
    const UNKNOWN: Rule = builder("", None, "not in the table: the builder's");
    RULES
        .iter()
        .find(|r| matches(r.pattern, name))
        .unwrap_or(&UNKNOWN)
}

/// Whether `name` is one of the parameters `pattern` names: part by part, `*` for any one
/// part; a pattern ending in `*` also takes deeper names (`sim.*` for `sim.probe.0.min`).
fn matches(pattern: &str, name: &str) -> bool {
    let mut p = pattern.split('.');
    let mut n = name.split('.');
    loop {
        match (p.next(), n.next()) {
            (None, None) => return true,
            (Some("*"), Some(_)) if pattern.ends_with(".*") && p.clone().next().is_none() => {
                return true
            }
            (Some(a), Some(b)) if a == "*" || a == b => continue,
            _ => return false,
        }
    }
}

/// A number as a message shows it: plain when short, else in exponent form (a refusal must not
/// print a 300-digit number back).
pub fn show(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 12 {
        plain
    } else {
        format!("{v:.3e}")
    }
}

impl Range {
    pub fn bounds(&self, cfg: &LaunchConfig) -> (f64, f64) {
        match self {
            Fixed(lo, hi) => (*lo, *hi),
            Of(f) => f(cfg),
        }
    }
}

/// Checks a number `v` of parameter `name` against its range (any writer).
pub fn check_range(cfg: &LaunchConfig, name: &str, v: f64) -> Result<(), String> {
    if !v.is_finite() {
        return Err(format!("{name}: not a finite number"));
    }
    if let Some(range) = rule(name).range {
        let (lo, hi) = range.bounds(cfg);
        if !(lo..=hi).contains(&v) {
            return Err(format!(
                "{name} = {} outside {}..{} ({})",
                show(v),
                show(lo),
                show(hi),
                rule(name).why
            ));
        }
    }
    Ok(())
}

/// Whether the cell may write `name` = `v` (a number, or `None`: not a number or null), given
/// the builder's value of a monitor (`builder_value`): the refusal names the rule.
pub fn check_cell_write(
    cfg: &LaunchConfig,
    name: &str,
    v: Option<f64>,
    builder_value: Option<f64>,
) -> Result<(), String> {
    let r = rule(name);
    if r.writer == Writer::Builder {
        return Err(format!(
            "{name} is the machine builder's ({}): set in the launch config only",
            r.why
        ));
    }
    if let Some(v) = v {
        check_range(cfg, name, v)?;
    }
    if r.monitor {
        let Some(v) = v else {
            return Err(format!("{name}: a monitor is written as a number"));
        };
        let limit = builder_value.unwrap_or(f64::INFINITY);
        if v > limit {
            return Err(format!(
                "{name} = {} would loosen a monitor beyond the builder's {} (the cell may only tighten it)",
                show(v),
                show(limit)
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_take_one_part_per_star_and_a_tail_after_a_final_star() {
        assert!(matches("machine.axes.*.min", "machine.axes.X.min"));
        assert!(!matches("machine.axes.*.min", "machine.axes.X.max"));
        assert!(!matches("machine.axes.*.min", "machine.axes.X.min.0"));
        assert!(matches("sim.*", "sim.probe.0.min"));
        assert!(matches("machine.arc_plane.*", "machine.arc_plane.1"));
        assert_eq!(rule("machine.axes.Z.drive_lag").writer, Writer::Builder);
        assert_eq!(rule("machine.axes.Z.max_velocity").writer, Writer::Cell);
        assert_eq!(rule("machine.something_new").writer, Writer::Builder);
    }

    #[test]
    fn a_huge_number_is_shown_short() {
        assert_eq!(show(1e308), "1.000e308");
        assert_eq!(show(0.05), "0.05");
        assert_eq!(show(12000.0), "12000");
    }
}
