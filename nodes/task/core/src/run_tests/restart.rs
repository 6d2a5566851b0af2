//! Starting in mid-program and restarting an interrupted run (block search, D67; issue 45
//! item 5).

use super::*;

/// The program counts its runs in kept #200 and moves by the count: a restart that read #200
/// as the interrupted run left it would cut 1 mm further out.
const COUNTED: &str =
    "#200=#200+1\nG00 X[100+#200] Z20\nS500 M03\nG01 Z10 F3000\nG01 Z5\nG01 X120\nM05\nM30\n";

fn counted_core() -> RunCore {
    let mut c = core();
    assert!(command(&mut c, 1, load("count.nc", COUNTED)).accepted);
    c.plc_scanned();
    c.axes(&[200.0, 100.0]);
    c
}

#[test]
fn a_program_starts_at_a_line_with_its_preamble_then_the_rest_of_it() {
    let mut c = counted_core();
    let r = command(&mut c, 2, start("count.nc", "line 5"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("at line 5"), "{}", r.message);
    let sent = run_to_end(&mut c, 1001);
    // S500 M03, then the approach: X stays out at 200, Z over to 10, X to 102 and onto 101.
    let ends: Vec<&Vec<f64>> = sent
        .iter()
        .filter(|b| b.0 != MotionBlock::KIND_AUX && !b.1.is_empty())
        .map(|b| &b.1)
        .collect();
    assert_eq!(
        ends,
        [
            &vec![200.0, 10.0],
            &vec![102.0, 10.0],
            &vec![101.0, 10.0],
            &vec![101.0, 5.0],
            &vec![120.0, 5.0]
        ]
    );
    assert!(sent.iter().all(|b| b.2 >= 5), "{sent:?}");
    let refused = command(&mut c, 3, start("count.nc", "N999"));
    assert!(!refused.accepted && refused.message.contains("not found"));
    let refused = command(&mut c, 4, start("count.nc", "goto 3"));
    assert!(!refused.accepted);
}

#[test]
fn an_interrupted_run_restarts_at_its_block_with_the_variables_it_started_with() {
    // The uninterrupted run, for comparison.
    let mut whole = counted_core();
    assert!(command(&mut whole, 2, start("count.nc", "")).accepted);
    let full = run_to_end(&mut whole, 1001);
    assert_eq!(whole.memory().kept.get(&200), Some(&1.0));

    // The run that is interrupted: motion has finished 4 blocks, at line 4, when the power
    // goes (an emergency stop here; a kill leaves the same kept position).
    let mut first = counted_core();
    assert!(command(&mut first, 2, start("count.nc", "")).accepted);
    first.motion_status(status_at(1001, 0, 1, MotionStatus::STATE_RUNNING));
    first.step();
    assert!(blocks(&first.take_effects()).len() > 5);
    first.motion_status(status_at(1001, 4, 4, MotionStatus::STATE_RUNNING));
    first.step();
    let kept = first.position().cloned().expect("a kept position");
    assert_eq!(
        (kept.program.as_str(), kept.line, kept.block),
        ("count.nc", 4, 5)
    );
    assert!(kept.interrupted());
    assert_eq!(kept.kept_at_start.get(&200), None, "#200 before the run");
    let memory_after = first.memory().clone();
    assert_eq!(memory_after.kept.get(&200), Some(&1.0));

    // The cell restarts: memory and position as kept, the axes elsewhere.
    let fresh = || {
        let c = RunCore::new(
            Dialect::HuaxingLathe,
            Setup::lathe([200.0, 100.0]),
            memory_after.clone(),
            2000,
        );
        let mut c = c.with_kept_position(Some(kept.clone()));
        assert!(command(&mut c, 1, load("count.nc", COUNTED)).accepted);
        c.plc_scanned();
        c.axes(&[250.0, 150.0]);
        c
    };
    let mut again = fresh();
    let r = command(&mut again, 2, start("", "interrupted"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("block 5"), "{}", r.message);
    let rest = run_to_end(&mut again, 2001);
    // After the preamble, exactly the uninterrupted run's blocks from block 5 on: X101, not
    // X102 (the search ran with #200 as the interrupted run found it).
    assert!(rest.len() > full.len() - 4);
    assert_eq!(rest[rest.len() - (full.len() - 4)..], full[4..]);
    assert_eq!(again.memory().kept.get(&200), Some(&1.0));
    // Completed: nothing is left to restart.
    let r = command(&mut again, 3, start("", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("no interrupted program"),
        "{}",
        r.message
    );

    // Another program's name, or an edited program, is refused.
    let mut other = fresh();
    let r = command(&mut other, 2, start("part.nc", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("not part.nc"),
        "{}",
        r.message
    );
    assert!(command(&mut other, 3, load("count.nc", PART)).accepted);
    let r = command(&mut other, 4, start("count.nc", "interrupted"));
    assert!(!r.accepted && r.message.contains("edited"), "{}", r.message);
}

fn calling_core() -> RunCore {
    let mut c = core();
    assert!(command(&mut c, 1, load("main.nc", MAIN_CALLING)).accepted);
    assert!(command(&mut c, 2, load("O2000", SUB)).accepted);
    c.plc_scanned();
    c.axes(&[200.0, 100.0]);
    c
}

/// An interruption inside a subprogram restarts at the subprogram's interrupted block (not at
/// the main program's call line), and the rest is the uninterrupted run's; a restart after the
/// subprogram was edited is refused.
#[test]
fn an_interrupted_subprogram_restarts_at_its_block_and_an_edit_of_it_is_refused() {
    let mut whole = calling_core();
    assert!(command(&mut whole, 3, start("main.nc", "")).accepted);
    let full = run_to_end(&mut whole, 1001);

    // Interrupted with 5 blocks done: inside O2000 (its third move).
    let mut first = calling_core();
    assert!(command(&mut first, 3, start("main.nc", "")).accepted);
    first.motion_status(status_at(1001, 0, 1, MotionStatus::STATE_RUNNING));
    first.step();
    assert!(blocks(&first.take_effects()).len() > 6);
    first.motion_status(status_at(1001, 5, 3, MotionStatus::STATE_RUNNING));
    first.step();
    let kept = first.position().cloned().expect("a kept position");
    assert!(kept.interrupted() && kept.block == 6, "{kept:?}");

    let fresh = |sub: &str| {
        let c = RunCore::new(
            Dialect::HuaxingLathe,
            Setup::lathe([200.0, 100.0]),
            first.memory().clone(),
            2000,
        );
        let mut c = c.with_kept_position(Some(kept.clone()));
        assert!(command(&mut c, 1, load("main.nc", MAIN_CALLING)).accepted);
        assert!(command(&mut c, 2, load("O2000", sub)).accepted);
        c.plc_scanned();
        c.axes(&[250.0, 150.0]);
        c
    };
    let mut again = fresh(SUB);
    let r = command(&mut again, 3, start("", "interrupted"));
    assert!(r.accepted, "{}", r.message);
    assert!(r.message.contains("block 6"), "{}", r.message);
    let rest = run_to_end(&mut again, 2001);
    // After the preamble, the uninterrupted run's blocks from block 6 on: the subprogram is
    // not run again from its top.
    assert!(rest.len() >= full.len() - 5, "{rest:?}");
    assert_eq!(rest[rest.len() - (full.len() - 5)..], full[5..], "{rest:?}");

    // The subprogram edited since: refused, naming it.
    let mut edited = fresh(SUB_EDITED);
    let r = command(&mut edited, 3, start("", "interrupted"));
    assert!(
        !r.accepted && r.message.contains("O2000") && r.message.contains("edited"),
        "{}",
        r.message
    );
}
