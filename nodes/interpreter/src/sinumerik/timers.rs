//! The run-time timers (`001` §9.12.1, decisions D121): `$AC_CUTTING_TIME`, `$AC_CYCLE_TIME`
//! and `$AC_OPERATING_TIME` in seconds, `$AN_POWERON_TIME` in minutes, as the machine counts
//! them. They are main-run variables: a block that reads one waits until every block before
//! it has run on the machine (a preprocessing stop), then reads them as the machine reported
//! them. Without a machine (a check, a simulation, a block search) they read as the run found
//! them: 0.

use cnc_interpreter_core::{Fault, MachineTimers};

use super::expr::EvalError;
use super::lex::strip_comment;

/// A timer's value from the machine's report.
type Reading = fn(&MachineTimers) -> f64;

/// The timers a program can read, each with its value from the machine's report
/// (`$AN_SETUP_TIME` is refused: see [`timer`]).
const TIMERS: [(&str, Reading); 4] = [
    ("$AC_CUTTING_TIME", |t| t.cutting),
    ("$AC_CYCLE_TIME", |t| t.cycle),
    ("$AC_OPERATING_TIME", |t| t.operating),
    ("$AN_POWERON_TIME", |t| t.power_on / 60.0),
];

/// Whether a line reads a run-time timer (outside its comment), so that it must wait for the
/// machine before it runs.
pub fn reads_timer(line: &str) -> bool {
    // Most blocks name no system variable: one scan for `$` decides them.
    line.contains('$') && {
        let upper = strip_comment(line).to_ascii_uppercase();
        TIMERS.iter().any(|(name, _)| upper.contains(name))
    }
}

/// The value of timer `name` in `t`; `None` if `name` is no timer.
pub fn timer(t: &MachineTimers, name: &str) -> Option<Result<f64, EvalError>> {
    // Minutes since the control last started with its default values: a time kept across
    // power-off, which this controller does not keep.
    if name == "$AN_SETUP_TIME" {
        return Some(Err(EvalError::new(
            Fault::NotSupported,
            "$AN_SETUP_TIME (the time since the last start with default values) is not kept \
             by this controller",
        )));
    }
    TIMERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, value)| Ok(value(t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_reads_a_timer_only_outside_its_comment() {
        assert!(reads_timer("N10 IF $AC_CUTTING_TIME>=R10 GOTOF WZZEIT"));
        assert!(reads_timer("r1=$an_poweron_time"));
        assert!(!reads_timer("G1 X10 ; $AC_CYCLE_TIME"));
        assert!(!reads_timer("R1=$AC_TOTAL_PARTS"));
    }

    #[test]
    fn timers_read_in_their_units() {
        let t = MachineTimers {
            cutting: 1.5,
            cycle: 2.5,
            operating: 3.5,
            power_on: 120.0,
        };
        let v = |n: &str| timer(&t, n).unwrap().unwrap();
        assert_eq!(
            [
                v("$AC_CUTTING_TIME"),
                v("$AC_CYCLE_TIME"),
                v("$AC_OPERATING_TIME"),
                v("$AN_POWERON_TIME")
            ],
            [1.5, 2.5, 3.5, 2.0]
        );
        assert_eq!(
            timer(&t, "$AN_SETUP_TIME").unwrap().unwrap_err().fault,
            Fault::NotSupported
        );
        assert!(timer(&t, "$AC_TOTAL_PARTS").is_none());
    }
}
