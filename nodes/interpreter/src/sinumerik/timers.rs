//! The run-time timers (`001` §9.12.1, decisions D121): `$AC_CUTTING_TIME`, `$AC_CYCLE_TIME`
//! and `$AC_OPERATING_TIME` in seconds, `$AN_POWERON_TIME` in minutes, as the machine counts
//! them. They are main-run variables: a block that reads one waits until every block before
//! it has run on the machine (a preprocessing stop), then reads them as the machine reported
//! them. Without a machine (a check, a simulation, a block search) they read as the run found
//! them: 0.

use cnc_interpreter_core::{Fault, MachineTimers};

use super::expr::EvalError;
use super::lex::strip_comment;

/// The timers a program can read (`$AN_SETUP_TIME` is refused: see [`timer`]).
const TIMERS: [&str; 4] = [
    "$AC_CUTTING_TIME",
    "$AC_CYCLE_TIME",
    "$AC_OPERATING_TIME",
    "$AN_POWERON_TIME",
];

/// Whether a line reads a run-time timer (outside its comment), so that it must wait for the
/// machine before it runs.
pub fn reads_timer(line: &str) -> bool {
    // Most blocks name no system variable: one scan for `$` decides them.
    line.contains('$') && {
        let upper = strip_comment(line).to_ascii_uppercase();
        TIMERS.iter().any(|t| upper.contains(t))
    }
}

/// The value of timer `name` in `t`; `None` if `name` is no timer.
pub fn timer(t: &MachineTimers, name: &str) -> Option<Result<f64, EvalError>> {
    Some(Ok(match name {
        "$AC_CUTTING_TIME" => t.cutting,
        "$AC_CYCLE_TIME" => t.cycle,
        "$AC_OPERATING_TIME" => t.operating,
        "$AN_POWERON_TIME" => t.power_on / 60.0,
        // Minutes since the control last started with its default values: a time kept across
        // power-off, which this controller does not keep.
        "$AN_SETUP_TIME" => {
            return Some(Err(EvalError::new(
                Fault::NotSupported,
                "$AN_SETUP_TIME (the time since the last start with default values) is not \
                 kept by this controller",
            )))
        }
        _ => return None,
    }))
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
