//! Travel to a fixed stop, FXS/FXST/FXSW and `$AA_FXS` (`001` §9.3.23, fixtures 044/045,
//! decisions D118): the selection with its move, the setting data, the wait for the machine,
//! the deselection, and the alarms.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Command, Library};
use cnc_interpreter_core::{next_command, Measurement};
use support::*;

/// The fixed stop selections of a program's commands: (axis, on, torque, window).
fn selections(out: &[Command]) -> Vec<(u8, bool, f64, f64)> {
    out.iter()
        .filter_map(|c| match c {
            Command::FixedStop {
                axis,
                on,
                torque,
                window,
            } => Some((*axis, *on, *torque, *window)),
            _ => None,
        })
        .collect()
}

/// Fixture 044 with its template line made the manual's G1 G94 and a feed, from Z200.
#[test]
fn f044_selects_z1_with_its_torque_and_window_in_the_block_of_its_move() {
    let text = format!("G0 X0 Z200\n{}M30\n", filled("044", &["N10 G1 G94 F100"]));
    let r = run(&text).ok();
    assert_eq!(selections(&r.out), vec![(2, true, 12.3, 2.0)]);
    // The selection goes right before its move: the line to X250 Z100 at F100.
    let k = r
        .out
        .iter()
        .position(|c| matches!(c, Command::FixedStop { .. }))
        .expect("the selection");
    assert_eq!(
        r.out[k + 1],
        Command::Linear {
            end: vec![250.0, 0.0, 100.0],
            feed: 100.0
        }
    );
}

/// Fixture 045's four alternatives of N20, each a program of its own: the setting data's
/// torque and window (the machine data's 5 % and 1 mm) where FXST or FXSW is not written.
#[test]
fn f045_each_alternative_takes_the_setting_data_for_what_it_leaves_out() {
    let text = fixture("045");
    let alternatives: Vec<&str> = text.lines().filter(|l| l.starts_with("N20")).collect();
    assert_eq!(alternatives.len(), 4);
    let expected = [(5.0, 1.0), (12.3, 1.0), (12.3, 2.0), (5.0, 2.0)];
    for (line, (torque, window)) in alternatives.iter().zip(expected) {
        let r = run(&format!("G0 X0 Z200\nN10 G1 G94 F100\n{line}\nM30\n")).ok();
        assert_eq!(
            selections(&r.out),
            vec![(0, true, torque, window)],
            "{line}"
        );
    }
}

/// On the machine the program waits after the selection's move: where it ended is the
/// machine's to say. `$AA_FXS` reads 1 at the stop, 0 after the deselection, whose move
/// starts where the axis stopped.
#[test]
fn the_program_reads_on_from_where_the_axis_met_its_stop() {
    let text = "G0 X0 Z200\nG1 G94 F100 Z50 FXS[Z1]=1 FXST[Z1]=20\nR1=$AA_FXS[Z1]\n\
                G1 X10 Z150 FXS[Z1]=0\nR2=$AA_FXS[Z1]\nM30\n";
    let mut front = Sinumerik::new(text, mill(), Library::new());
    front.core.on_machine = true;
    let mut out = Vec::new();
    while let Some(c) = next_command(&mut front).expect("no alarm") {
        out.push(c.command);
    }
    assert!(front.core.awaiting_machine());
    assert_eq!(selections(&out), vec![(2, true, 20.0, 1.0)]);
    // Before the result $AA_FXS would read 3 (selected).
    assert_eq!(
        front.core.fixed_stops[2],
        cnc_interpreter_core::measure::FixedStop::Selected
    );
    front
        .core
        .machine_result(Measurement {
            triggered: true,
            position: vec![0.0, 0.0, 95.0],
            rest: vec![0.0, 0.0, 95.0],
            timers: None,
        })
        .expect("the machine's axes");
    let mut rest = Vec::new();
    while let Some(c) = next_command(&mut front).expect("no alarm") {
        rest.push(c.command);
    }
    assert_eq!(front.r(1), 1.0);
    assert_eq!(front.r(2), 0.0);
    assert_eq!(
        selections(&rest),
        vec![(2, false, 100.0, 1.0)],
        "the deselection"
    );
    assert_eq!(
        rest[1],
        Command::Linear {
            end: vec![10.0, 0.0, 150.0],
            feed: 100.0
        }
    );
}

#[test]
fn what_cannot_travel_to_a_stop_is_an_alarm_with_its_number() {
    for (text, alarm, line) in [
        // Selected and deselected with a move in the block; the selected axis moves.
        ("G1 F100 FXS[Z1]=1\n", 12080, 1),
        ("G1 F100 X10 FXS[Z1]=1\n", 12080, 1),
        ("G1 F100 FXS[Z1]=0\n", 12080, 1),
        // Values.
        ("G1 F100 Z10 FXS[Z1]=2\n", 17020, 1),
        ("FXST[Z1]=0\n", 17020, 1),
        ("FXST[Z1]=120\n", 17020, 1),
        ("FXSW[Z1]=0\n", 17020, 1),
        ("G1 F100 Z10 FXS[Q1]=1\n", 14092, 1),
        ("G1 F100 Z10 X5 FXS[Z1]=1 FXS[X1]=1\n", 12060, 1),
        // A G1 line; not with a measurement.
        ("G0 Z10 FXS[Z1]=1\n", 12140, 1),
        ("G1 F100 Z10 FXS[Z1]=1 MEAS=1\n", 12080, 1),
        // At the stop the axis moves only with its deselection; no second selection.
        ("G1 F100 Z10 FXS[Z1]=1\nG1 Z20\n", 12080, 2),
        ("G1 F100 Z10 FXS[Z1]=1\nG1 Z5 FXS[Z1]=1\n", 12080, 2),
        // Nothing may hold the move back: no chamfer or rounding at either end.
        ("G1 F100 Z10 FXS[Z1]=1 RND=2\nX5\n", 12140, 1),
        ("G1 F100 X10 RND=2\nZ10 FXS[Z1]=1\n", 12140, 2),
    ] {
        let r = run(&format!("{text}M30\n"));
        assert_eq!(r.alarm(), (alarm, line), "{text}: {:?}", r.error);
    }
    // Another axis may move while one is clamped.
    run("G1 F100 Z10 FXS[Z1]=1\nG1 X20\nG1 Z30 FXS[Z1]=0\nM30\n").ok();
}
