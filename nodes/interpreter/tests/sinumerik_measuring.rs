//! Measuring with the touch probe, MEAS/MEAW (`001` §9.3.12, fixture 032, decisions D116):
//! the measuring line, the wait for the machine's result, `$AC_MEA[1]`, `$AA_MM`/`$AA_MW`
//! under offsets and frames, and the alarms.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Command, Library, Setup};
use cnc_interpreter_core::{next_command, Measurement};
use support::*;

/// A mill without tools (machine Z is the probe's tip), G54 shifted by (100, 50, −20).
fn mill_g54() -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0, 0.0, 100.0]);
    let g54 = s.offsets.work.entry(0).or_default();
    g54.insert('X', 100.0);
    g54.insert('Y', 50.0);
    g54.insert('Z', -20.0);
    s
}

/// A program on the machine: the commands up to the first wait for a measurement.
struct OnMachine {
    front: Sinumerik,
}

impl OnMachine {
    fn new(text: &str) -> Self {
        let mut front = Sinumerik::new(text, mill_g54(), Library::new());
        front.core.on_machine = true;
        OnMachine { front }
    }

    /// Commands until the program waits or ends; `Err` on an alarm (number, line).
    fn commands(&mut self) -> Result<Vec<Command>, (u32, u32)> {
        let mut out = Vec::new();
        loop {
            match next_command(&mut self.front) {
                Ok(Some(c)) => out.push(c.command),
                Ok(None) => return Ok(out),
                Err(e) => return Err((e.number, e.line)),
            }
        }
    }

    fn machine_result(&mut self, triggered: bool, position: [f64; 3], rest: [f64; 3]) {
        self.front
            .core
            .machine_result(Measurement {
                triggered,
                position: position.to_vec(),
                rest: rest.to_vec(),
                timers: None,
            })
            .expect("a result of the machine's axes");
    }
}

fn probe_of(c: &Command) -> (Vec<f64>, f64, bool, bool) {
    match c {
        Command::Probe {
            end,
            feed,
            rising,
            stop,
        } => (end.clone(), *feed, *rising, *stop),
        other => panic!("not a measuring move: {other:?}"),
    }
}

/// Fixture 032 with its `..` line filled, on a machine whose probe switches where the test
/// says.
fn f032() -> String {
    filled("032", &["G0 Z50 M30"])
}

#[test]
fn f032_measures_along_its_line_and_waits_for_the_machine() {
    let mut m = OnMachine::new(&format!("G54\n{}", f032()));
    let out = m.commands().expect("no alarm");
    // The measuring line in machine coordinates (G54 shifts X by 100, Z by −20), at F4000,
    // the rising edge, delete distance to go; nothing after it yet.
    let (end, feed, rising, stop) = probe_of(out.last().expect("a command"));
    assert_eq!(end, vec![400.0, 0.0, -60.0]);
    assert_eq!((feed, rising, stop), (4000.0, true, true));
    assert!(m.front.core.awaiting_machine());
    assert!(m.commands().expect("still waiting").is_empty());
    // The probe switched at machine X250 Z−20 (work X150 Z0) and the axes rested a little
    // further on.
    m.machine_result(true, [250.0, 0.0, -20.0], [250.4, 0.0, -20.1]);
    let rest = m.commands().expect("no alarm");
    assert_eq!(m.front.r(5), 150.0);
    assert_eq!(m.front.r(6), 0.0);
    // N30's values, then the filled line: G0 Z50 from the rest position, M30.
    assert_eq!(rest[0].end(), Some(&[250.4, 0.0, 30.0][..]));
    assert!(rest
        .iter()
        .all(|c| !matches!(c, Command::Aux(cnc_interpreter::Aux::M(0)))));
}

#[test]
fn f032_jumps_to_its_error_label_when_the_probe_does_not_switch() {
    let mut m = OnMachine::new(&f032());
    m.commands().expect("no alarm");
    m.machine_result(false, [300.0, 0.0, -40.0], [300.0, 0.0, -40.0]);
    let rest = m.commands().expect("no alarm");
    assert_eq!(
        rest.first(),
        Some(&Command::Aux(cnc_interpreter::Aux::M(0))),
        "MEASERR: M0"
    );
    // R5 and R6 were not written.
    assert_eq!((m.front.r(5), m.front.r(6)), (0.0, 0.0));
}

/// Without a machine (`cnc check`, a simulation) the probe is taken as switching at the
/// line's end (D116): the program is read along its main path.
#[test]
fn f032_checked_without_a_machine_reads_its_main_path() {
    let r = run_with(&f032(), mill_g54(), Library::new()).ok();
    assert_eq!(r.front.r(5), 300.0);
    assert_eq!(r.front.r(6), -40.0);
    assert!(!r
        .out
        .iter()
        .any(|c| matches!(c, Command::Aux(cnc_interpreter::Aux::M(0)))));
}

#[test]
fn meaw_and_the_falling_edge_and_the_two_coordinate_systems_under_a_frame() {
    // G54 and a frame: TRANS X10, then ROT RPL=90 (the frame turns work X onto machine Y).
    let text = "G54 G17\nTRANS X10\nAROT RPL=90\nMEAW=-1 G1 X20 Y0 F200\n\
                R1=$AA_MM[X] R2=$AA_MM[Y] R3=$AA_MW[X] R4=$AA_MW[Y] R7=$AC_MEA[1]\nM30\n";
    let mut m = OnMachine::new(text);
    let out = m.commands().expect("no alarm");
    let (end, _, rising, stop) = probe_of(out.last().expect("a command"));
    // Work X20 Y0 under the frame: machine X 100 + 10, Y 50 + 20 (Z stays at 100).
    assert!(near(&end, &[110.0, 70.0, 100.0]), "{end:?}");
    assert_eq!((rising, stop), (false, false));
    m.machine_result(true, [110.0, 62.5, 100.0], [110.0, 70.0, 100.0]);
    m.commands().expect("no alarm");
    assert_eq!((m.front.r(1), m.front.r(2)), (110.0, 62.5));
    // Back through the frame: 12.5 along the rotated X, nothing across it.
    assert!((m.front.r(3) - 12.5).abs() < 1e-9, "{}", m.front.r(3));
    assert!(m.front.r(4).abs() < 1e-9, "{}", m.front.r(4));
    assert_eq!(m.front.r(7), 1.0);
    // The table's spelling $AC_MEAS reads the same status.
    let r = run("MEAS=1 G1 X5 F100\nR1=$AC_MEAS[1]\nM30\n").ok();
    assert_eq!(r.front.r(1), 1.0);
}

#[test]
fn a_probe_that_did_not_switch_leaves_the_last_measured_values() {
    let text = "MEAS=1 G1 Z50 F100\nR1=$AA_MM[Z]\nMEAS=1 G1 Z0\nR2=$AA_MM[Z] R3=$AC_MEA[1]\nM30\n";
    let mut m = OnMachine::new(text);
    m.commands().expect("no alarm");
    m.machine_result(true, [0.0, 0.0, 60.0], [0.0, 0.0, 59.8]);
    m.commands().expect("no alarm");
    m.machine_result(false, [0.0, 0.0, -20.0], [0.0, 0.0, -20.0]);
    m.commands().expect("no alarm");
    assert_eq!(
        (m.front.r(1), m.front.r(2), m.front.r(3)),
        (60.0, 60.0, 0.0)
    );
}

#[test]
fn what_cannot_be_measured_is_an_alarm_with_its_number() {
    for (text, alarm, line) in [
        // Measuring input 1's edges are +1 and −1.
        ("MEAS=2 G1 X10 F100\n", 17020, 1),
        // A measuring job needs a move.
        ("G1 F100\nMEAS=1\n", 12080, 2),
        // One job per block.
        ("MEAS=1 MEAW=1 G1 X10 F100\n", 12080, 1),
        // A straight G1 line only.
        ("MEAS=1 G2 X10 Y0 CR=5 F100\n", 12140, 1),
        ("MEAS=1 G0 X10\n", 12140, 1),
        // Not under radius compensation.
        ("T1 D1\nG1 G41 X10 Y10 F100\nMEAS=1 X20\n", 12140, 3),
        // No chamfer into the unknown, nor one waiting for it.
        ("MEAS=1 G1 X10 F100 CHF=1\nX20\n", 12140, 1),
        ("G1 X10 F100 CHF=1\nMEAS=1 Y20\n", 12140, 2),
        // Nothing measured yet.
        ("R1=$AA_MW[X]\n", 12550, 1),
        ("R1=$AC_MEA[2]\n", 17020, 1),
        // MEAS is the control's own name.
        ("DEF REAL MEAS\n", 12080, 1),
    ] {
        let r = run(&format!("{text}M30\n"));
        assert_eq!(r.alarm(), (alarm, line), "{text}: {:?}", r.error);
    }
}
