//! The run-time timers (`001` §9.12.1, fixture 080, decisions D121): a block that reads one
//! waits until the machine has run every block before it (a preprocessing stop, the `Sync`
//! command), then reads the timers the machine reported; without a machine they read 0.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Aux, Command, Library};
use cnc_interpreter_core::{next_command, MachineTimers, Measurement};
use support::*;

/// Commands until the program waits or ends; `Err` on an alarm (number, line).
fn commands(front: &mut Sinumerik) -> Result<Vec<Command>, (u32, u32)> {
    let mut out = Vec::new();
    loop {
        match next_command(front) {
            Ok(Some(c)) => out.push(c.command),
            Ok(None) => return Ok(out),
            Err(e) => return Err((e.number, e.line)),
        }
    }
}

/// The machine's report of the preprocessing stop: the axes where they stand, the timers.
fn report(front: &mut Sinumerik, at: [f64; 3], timers: MachineTimers) {
    front
        .core
        .machine_result(Measurement {
            triggered: true,
            position: at.to_vec(),
            rest: at.to_vec(),
            timers: Some(timers),
        })
        .expect("the machine's axes");
}

fn cutting(seconds: f64) -> MachineTimers {
    MachineTimers {
        cutting: seconds,
        ..MachineTimers::default()
    }
}

/// Fixture 080 after a cut of 100 mm at F600 (10 s), the limit R10 = 5 s, its placeholder a
/// move and the program's end.
fn f080_on_machine() -> Sinumerik {
    let text = format!(
        "G0 X0 Y0 Z10\nG1 X100 F600\n{}",
        filled("080", &["G0 X1 M30"])
    );
    let mut s = mill();
    s.kept.insert(10_000 + 10, 5.0);
    let mut front = Sinumerik::new(&text, s, Library::new());
    front.core.on_machine = true;
    front
}

#[test]
fn the_block_that_reads_the_cutting_time_waits_for_the_machine_and_jumps_on_its_report() {
    for (seconds, jumps) in [(10.2, true), (4.9, false)] {
        let mut front = f080_on_machine();
        let before = commands(&mut front).expect("no alarm");
        // The cut, then the preprocessing stop; nothing of N10 or after is read yet.
        assert!(matches!(before.last(), Some(Command::Sync)), "{before:?}");
        assert!(matches!(before[before.len() - 2], Command::Linear { .. }));
        assert!(front.core.awaiting_machine());
        assert!(commands(&mut front).expect("no alarm").is_empty());
        report(&mut front, [100.0, 0.0, 10.0], cutting(seconds));
        let after = commands(&mut front).expect("no alarm");
        assert!(!after.contains(&Command::Sync), "one stop for the block");
        let m0 = after.contains(&Command::Aux(Aux::M(0)));
        assert_eq!(m0, jumps, "{seconds} s: {after:?}");
        assert_eq!(front.message() == "刀具作用时间: 达到极限值", jumps);
        // Not reached: the block after the IF runs (its move to X1) and the program ends.
        let to_x1 = after
            .iter()
            .any(|c| matches!(c, Command::Rapid { end } if end[0] == 1.0));
        assert_eq!(to_x1, !jumps, "{after:?}");
    }
}

#[test]
fn one_stop_reads_every_timer_of_a_block_in_its_unit() {
    let mut front = Sinumerik::new(
        "G1 X10 F100\nR1=$AC_CUTTING_TIME R2=$AC_CYCLE_TIME R3=$AC_OPERATING_TIME \
         R4=$AN_POWERON_TIME\nR5=$AC_CYCLE_TIME\nM30\n",
        mill(),
        Library::new(),
    );
    front.core.on_machine = true;
    let before = commands(&mut front).expect("no alarm");
    assert_eq!(before.iter().filter(|c| **c == Command::Sync).count(), 1);
    report(
        &mut front,
        [10.0, 0.0, 0.0],
        MachineTimers {
            cutting: 6.0,
            cycle: 7.5,
            operating: 3600.0,
            power_on: 7200.0,
        },
    );
    // The next block reads a timer again: another stop, another report.
    let next = commands(&mut front).expect("no alarm");
    assert_eq!(next, [Command::Sync]);
    assert_eq!(
        [front.r(1), front.r(2), front.r(3), front.r(4)],
        [6.0, 7.5, 3600.0, 120.0]
    );
    report(
        &mut front,
        [10.0, 0.0, 0.0],
        MachineTimers {
            cycle: 8.0,
            ..MachineTimers::default()
        },
    );
    let rest = commands(&mut front).expect("no alarm");
    assert_eq!(front.r(5), 8.0);
    assert!(rest.contains(&Command::ProgramEnd), "{rest:?}");
    // The stop did not move the program's position.
    assert_eq!(front.core.pos, [10.0, 0.0, 0.0]);
}

#[test]
fn without_a_machine_the_timers_read_zero_and_the_setup_time_is_refused() {
    // A check: the stop is taken at once, the timers read as the run found them.
    let mut front = Sinumerik::new(
        "G1 X10 F100\nR1=$AC_CUTTING_TIME+1\nM30\n",
        mill(),
        Library::new(),
    );
    let out = commands(&mut front).expect("no alarm");
    assert!(out.contains(&Command::Sync) && out.contains(&Command::ProgramEnd));
    assert_eq!(front.r(1), 1.0);
    let mut front = Sinumerik::new("R1=$AN_SETUP_TIME\n", mill(), Library::new());
    assert_eq!(commands(&mut front), Err((12140, 1)));
    // A timer named in a comment only is not read: no stop.
    let mut front = Sinumerik::new("G1 X1 F100 ; $AC_CYCLE_TIME\nM30\n", mill(), Library::new());
    assert!(!commands(&mut front)
        .expect("no alarm")
        .contains(&Command::Sync));
}
