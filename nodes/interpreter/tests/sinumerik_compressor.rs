//! COMPCAD/COMPOF and STOPFIFO/STARTFIFO (`001` §9.3.20, the address table; fixture 041,
//! decisions D119): the interpreter hands motion the compressor's and the buffer's switches
//! around the program's lines, which it leaves as written (motion compresses them).

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::Command;
use support::*;

#[test]
fn f041_switches_the_compressor_and_fills_the_buffer_around_its_lines() {
    let text = filled("041", &["N67 X44.326 Z32.196"]);
    let r = run(&text).ok();
    let at = |want: &Command| r.out.iter().position(|c| c == want);
    let on = at(&Command::Compressor { on: true }).expect("COMPCAD");
    let fill = at(&Command::Fifo { fill: true }).expect("STOPFIFO");
    let off = at(&Command::Compressor { on: false }).expect("COMPOF");
    let lines: Vec<usize> = r
        .out
        .iter()
        .enumerate()
        .filter(|(_, c)| matches!(c, Command::Linear { .. }))
        .map(|(k, _)| k)
        .collect();
    // N60–N67: eight lines at F10000 between the switches, as written.
    assert_eq!(lines.len(), 8);
    assert!(on < fill && fill < lines[0] && *lines.last().unwrap() < off);
    assert_eq!(
        r.out[lines[1]],
        Command::Linear {
            end: vec![41.365, 6.0, 32.5],
            feed: 10_000.0
        }
    );
    // SOFT before it: the jerk-limited profile.
    assert!(at(&Command::Profile { jerk_limited: true }).is_some_and(|k| k < on));
}

#[test]
fn nothing_inside_a_stopfifo_section_may_wait_for_the_machine() {
    for (text, line) in [
        ("STOPFIFO\nG1 F100 X10\nMEAS=1 X20\n", 3),
        ("STOPFIFO\nG1 F100 Z10 FXS[Z1]=1\n", 2),
    ] {
        let r = run(&format!("{text}M30\n"));
        assert_eq!(r.alarm(), (12140, line), "{text}: {:?}", r.error);
    }
    run("STOPFIFO\nG1 F100 X10\nSTARTFIFO\nMEAS=1 X20\nM30\n").ok();
}
