use super::*;
use cnc_interpreter::Setup;

const LATHE: Dialect = Dialect::HuaxingLathe;

fn lathe_here() -> Vec<f64> {
    vec![200.0, 100.0]
}

fn found(text: &str, target: SearchTarget) -> Result<Restart, ProgramError> {
    let mut interp = Interpreter::new(LATHE, text, Setup::lathe([200.0, 100.0]));
    search(
        LATHE,
        &mut interp,
        text,
        &target,
        &lathe_here(),
        &Approach::default_for(&Setup::lathe([0.0, 0.0])),
    )
}

const PART: &str = "O0001\n\
    T0101\n\
    G99 S800 M03\n\
    M08\n\
    N40 G00 X52 Z2\n\
    G01 Z-30 F0.2\n\
    X60\n\
    M09\n\
    M05\n\
    M30\n";

#[test]
fn targets_read_as_the_operator_writes_them() {
    assert_eq!(SearchTarget::parse("  "), Ok(None));
    assert_eq!(
        SearchTarget::parse("line 12"),
        Ok(Some(SearchTarget::Line(12)))
    );
    assert_eq!(
        SearchTarget::parse("N0120"),
        Ok(Some(SearchTarget::Sequence(120)))
    );
    assert_eq!(
        SearchTarget::parse("label LAB1"),
        Ok(Some(SearchTarget::Label("LAB1".into())))
    );
    assert_eq!(
        SearchTarget::parse("block 57"),
        Ok(Some(SearchTarget::Block(57)))
    );
    for bad in [
        "line 0",
        "line -3",
        "line 99999999999",
        "N",
        "label a:b",
        "goto 3",
        "block x",
    ] {
        assert!(SearchTarget::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn a_line_a_sequence_number_and_a_label_find_the_same_kind_of_restart() {
    // Line 6 is `G01 Z-30`: the tool, S800 M03, M08 and G99 come first, then the approach:
    // X out to 200 (already there), Z over to 2, X down to 53 (the clearance, 1 mm of
    // diameter) and onto 52 at the approach feed.
    let r = found(PART, SearchTarget::Line(6)).unwrap();
    assert_eq!(r.first.line, 6);
    assert_eq!(r.skipped, 6);
    let cmds: Vec<Command> = r.preamble.iter().map(|c| c.command.clone()).collect();
    assert_eq!(
        cmds,
        vec![
            Command::Aux(Aux::T(1)),
            Command::Aux(Aux::S(800.0)),
            Command::Aux(Aux::M(3)),
            Command::Aux(Aux::M(8)),
            Command::FeedMode { per_rev: false },
            Command::PathMode { exact_stop: true },
            Command::Rapid {
                end: vec![200.0, 2.0]
            },
            Command::Rapid {
                end: vec![53.0, 2.0]
            },
            Command::Linear {
                end: vec![52.0, 2.0],
                feed: DEFAULT_APPROACH_FEED
            },
            Command::FeedMode { per_rev: true },
            Command::PathMode { exact_stop: false },
        ]
    );
    assert!(r.preamble.iter().all(|c| c.line == 6));
    // N40 is line 5, whose rapid is the first command after the M08.
    let n = found(PART, SearchTarget::Sequence(40)).unwrap();
    assert_eq!((n.first.line, n.skipped), (5, 5));
    let x60 = found(PART, SearchTarget::Line(7)).unwrap();
    assert_eq!(x60.collected.position, Some(vec![52.0, -30.0]));
}

#[test]
fn a_label_is_the_line_that_begins_with_it() {
    // No dialect built so far writes labels (the 802D does); the search finds their line.
    let text = "G00 X50\nMARK_2: G01 X40\n  MARK: G00 X60\nM30\n";
    let line = |name: &str| target_line(text, &SearchTarget::Label(name.into()));
    assert_eq!(line("MARK"), Some(3));
    assert_eq!(line("MARK_2"), Some(2));
    assert_eq!(line("MAR"), None);
}

#[test]
fn a_tool_retracted_below_the_point_goes_out_first_and_the_restart_point_is_reached_last() {
    // The operator left the tool at X30 Z-10 (inside the part's diameter): X goes out to 52
    // first (the larger of here and the point), then Z, then nothing more (X is at 52).
    let mut interp = Interpreter::new(LATHE, PART, Setup::lathe([200.0, 100.0]));
    let r = search(
        LATHE,
        &mut interp,
        PART,
        &SearchTarget::Line(6),
        &[30.0, -10.0],
        &Approach::default_for(&Setup::lathe([0.0, 0.0])),
    )
    .unwrap();
    let moves: Vec<&Command> = r
        .preamble
        .iter()
        .map(|c| &c.command)
        .filter(|c| c.end().is_some())
        .collect();
    assert_eq!(
        moves,
        vec![
            &Command::Rapid {
                end: vec![52.0, -10.0]
            },
            &Command::Rapid {
                end: vec![52.0, 2.0]
            },
        ]
    );
}

#[test]
fn a_target_the_program_never_reaches_is_refused_with_the_alarm_and_nothing_runs() {
    for target in [
        SearchTarget::Line(40),
        SearchTarget::Sequence(41),
        SearchTarget::Block(1000),
    ] {
        let e = found(PART, target.clone()).unwrap_err();
        assert_eq!(e.number, LATHE.alarm(Fault::TargetNotFound), "{target:?}");
        assert!(e.text.contains("not found"), "{e}");
    }
    // An alarm in the skipped part is the program's alarm, with its line.
    let bad = "G00 X50 Z5\nG01 X40 Z0 F0.2 Q\nG00 X60\nM30\n";
    let e = found(bad, SearchTarget::Line(3)).unwrap_err();
    assert_eq!(e.line, 2);
}

#[test]
fn main_lines_name_the_calling_line_inside_a_subprogram() {
    // Line 2 calls O0002 twice; its moves are on the subprogram's lines 2 and 3 but on the
    // main program's line 2.
    let mut lib = cnc_interpreter::Library::new();
    lib.insert(2, "O0002", "O0002\nG01 U-2 F0.1\nG00 U2\nM99\n");
    let main = "G00 X50 Z5\nM98 P20002\nG00 X80\nM30\n";
    let mut interp =
        Interpreter::with_library(LATHE, main, Setup::lathe([200.0, 100.0]), lib.clone());
    let mut seen = Vec::new();
    while let Some(c) = interp.next_command().unwrap() {
        seen.push((c.line, c.main_line));
    }
    assert_eq!(
        &seen[..6],
        &[(1, 1), (2, 2), (3, 2), (2, 2), (3, 2), (3, 3)]
    );
    // Line 3 of the main program is found after the calls, not in the subprogram's line 3.
    let mut interp = Interpreter::with_library(LATHE, main, Setup::lathe([200.0, 100.0]), lib);
    let r = search(
        LATHE,
        &mut interp,
        main,
        &SearchTarget::Line(3),
        &lathe_here(),
        &Approach::default_for(&Setup::lathe([0.0, 0.0])),
    )
    .unwrap();
    assert_eq!(r.skipped, 5);
    assert_eq!(
        r.first.command,
        Command::Rapid {
            end: vec![80.0, 5.0]
        }
    );
}

/// A positioned spindle is given again before the restart block; one left by an incremental
/// SPOS stands with M5, its angle not known before the machine runs (D100).
#[test]
fn the_restart_gives_the_last_spindle_position_and_an_incremental_one_as_m5() {
    let orient = |degrees, way| Command::Aux(Aux::Orient { degrees, way });
    for (skipped, want) in [
        (
            vec![Command::Aux(Aux::M(3)), orient(45.0, Turn::Minus)],
            orient(45.0, Turn::Minus),
        ),
        (
            vec![
                orient(45.0, Turn::Shortest),
                orient(-90.0, Turn::Incremental),
            ],
            Command::Aux(Aux::M(5)),
        ),
        (
            vec![orient(45.0, Turn::Shortest), Command::Aux(Aux::M(4))],
            Command::Aux(Aux::M(4)),
        ),
    ] {
        let mut c = Collected::default();
        for k in &skipped {
            c.take(k);
        }
        let approach = Approach::default_for(&Setup::lathe([0.0, 0.0]));
        let spindle: Vec<Command> = c
            .preamble(&lathe_here(), &approach, 9, 9)
            .into_iter()
            .map(|p| p.command)
            .filter(|k| matches!(k, Command::Aux(Aux::M(_) | Aux::Orient { .. })))
            .collect();
        assert_eq!(spindle, [want], "{skipped:?}");
    }
}

/// A block search runs SETPIECE without counting (`001` §9.13.3): the pieces were counted when
/// the program ran up to there; the same program run from its top counts them once.
#[test]
fn setpiece_does_not_count_during_a_block_search() {
    use cnc_interpreter::sinumerik::monitor::kept_key;
    let text = "T1 D1\nSETPIECE(1)\nG1 X10 F500\nM30\n";
    let mut setup = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    setup.offsets.tools.insert(11, Default::default());
    let count = kept_key("$TC_MOP4", 1, 1).unwrap();
    setup.kept.insert(kept_key("$TC_TP9", 1, 0).unwrap(), 2.0);
    setup.kept.insert(count, 10.0);
    let dialect = Dialect::Sinumerik802d;
    let mut searched = Interpreter::new(dialect, text, setup.clone());
    search(
        dialect,
        &mut searched,
        text,
        &SearchTarget::Line(3),
        &[0.0; 3],
        &Approach::default_for(&setup),
    )
    .expect("line 3 found");
    while searched.next_command().unwrap().is_some() {}
    assert_eq!(searched.memory().kept.get(&count), Some(&10.0));
    let mut whole = Interpreter::new(dialect, text, setup);
    while whole.next_command().unwrap().is_some() {}
    assert_eq!(whole.memory().kept.get(&count), Some(&9.0));
}
