//! Interpreter core tests on the manual's own example programs and on bad programs.

use cnc_interpreter::{Aux, Canon, Command, Dialect, ProgramError, Setup};

const AXES: [char; 2] = ['X', 'Z'];
const DIAMETER: [bool; 2] = [true, false];

fn check(
    d: Dialect,
    text: &str,
    axes: &[char],
    diameter: &[bool],
    start: &[f64],
) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(d, text, Setup::new(axes, diameter, start))
}

mod alarm {
    pub const DWELL_TIME: u32 = 1;
    pub const TOOL_NUMBER: u32 = 6;
    pub const UNDEFINED_CODE: u32 = 7;
    pub const GROUP_00_WITH_01: u32 = 8;
    pub const ABS_AND_INC_SAME_AXIS: u32 = 9;
    pub const TOO_MANY_M: u32 = 10;
    pub const ARC_RADIUS_TOO_SMALL: u32 = 11;
    pub const DATA_FORMAT: u32 = 13;
    pub const ARC_R_AND_IJK: u32 = 15;
    pub const FEED_OUT_OF_RANGE: u32 = 16;
    pub const ARC_END_NOT_ON_CIRCLE: u32 = 50;
}

fn fixture(name: &str) -> String {
    let path = format!(
        "{}/../../../shared/fixtures/000/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The fixture's program text after its header.
fn listing(text: &str) -> String {
    text.split("(--- listing as printed ---)")
        .nth(1)
        .expect("listing marker")
        .to_string()
}

/// Where a rapid, line or arc ends (threads are left out: these tests place contours).
fn end_of(c: &Command) -> Option<Vec<f64>> {
    match c {
        Command::Thread { .. } => None,
        other => other.end().map(<[f64]>::to_vec),
    }
}

fn assert_close(a: &[f64], b: &[f64]) {
    assert!(
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9),
        "{a:?} != {b:?}"
    );
}

#[test]
fn fixture_001_basic_program_visits_a_b_c_d() {
    let cmds = check(
        Dialect::IsoLathe,
        &listing(&fixture("001_basic_program_ABCD.nc")),
        &AXES,
        &DIAMETER,
        &[0.0, 0.0],
    )
    .unwrap();
    let ends: Vec<Vec<f64>> = cmds.iter().filter_map(|c| end_of(&c.command)).collect();
    // A=[X100,Z50], B=[X50,Z2], C=B+W-32, D=[X80, C.Z-20], back to A (header of the fixture).
    let expected = [
        [100.0, 50.0],
        [50.0, 2.0],
        [50.0, -30.0],
        [80.0, -50.0],
        [100.0, 50.0],
    ];
    assert_eq!(ends.len(), expected.len());
    for (e, x) in ends.iter().zip(expected) {
        assert_close(e, &x);
    }
    let aux: Vec<Aux> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Aux(a) = c.command {
                Some(a)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(
        aux,
        [
            Aux::M(10),
            Aux::T(1),
            Aux::S(600.0),
            Aux::M(3),
            Aux::M(8),
            Aux::T(1),
            Aux::S(0.0),
            Aux::M(5),
            Aux::M(9),
            Aux::M(11),
            Aux::M(30)
        ]
    );
    assert_eq!(
        cmds.last().map(|c| (&c.command, c.line)),
        Some((&Command::ProgramEnd, 16))
    );
    // The listing never selects G01: `W-32 F200` follows `G0 X50 Z2`, so by the modal rules of
    // `000` §5.1 it is a rapid although the comment says "cut"; F only sets the modal feed.
    assert!(cmds
        .iter()
        .all(|c| !matches!(c.command, Command::Linear { .. } | Command::Arc { .. })));
}

#[test]
fn fixture_010_arcs_have_the_stated_end_points_and_centres() {
    let cmds = check(
        Dialect::IsoLathe,
        &listing(&fixture("010_g02_g03_comprehensive_O0001.nc")),
        &AXES,
        &DIAMETER,
        &[0.0, 0.0],
    )
    .unwrap();
    let arcs: Vec<_> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Arc {
                end,
                center,
                clockwise,
                ..
            } = &c.command
            {
                Some((end.clone(), center.clone(), *clockwise))
            } else {
                None
            }
        })
        .collect();
    assert_eq!(arcs.len(), 2);
    // G03 U24 W-24 R15 from X0 Z0: ends at X24 Z-24; the centre is 15 mm (radius) from both ends.
    let (end, center, cw) = &arcs[0];
    assert_close(end, &[24.0, -24.0]);
    assert!(!cw);
    for p in [[0.0, 0.0], [12.0, -24.0]] {
        let r = ((center[0] / 2.0 - p[0]).powi(2) + (center[1] - p[1]).powi(2)).sqrt();
        assert!((r - 15.0).abs() < 1e-9, "radius {r}");
    }
    assert_close(center, &[0.0, -15.0]);
    // G02 X26 Z-31 R5.
    let (end, center, cw) = &arcs[1];
    assert_close(end, &[26.0, -31.0]);
    assert!(cw);
    for p in [[12.0, -24.0], [13.0, -31.0]] {
        let r = ((center[0] / 2.0 - p[0]).powi(2) + (center[1] - p[1]).powi(2)).sqrt();
        assert!((r - 5.0).abs() < 1e-9, "radius {r}");
    }
    // Final point: back to X40 Z5.
    let last = cmds.iter().rev().find_map(|c| end_of(&c.command)).unwrap();
    assert_close(&last, &[40.0, 5.0]);
}

#[test]
fn incremental_mode_and_u_w_words() {
    let cmds = check(
        Dialect::IsoLathe,
        "G00 X10 Z10\nG91 G01 X5 Z-2 F100\nG90 U4 W1\nM30\n",
        &AXES,
        &DIAMETER,
        &[0.0, 0.0],
    )
    .unwrap();
    let ends: Vec<_> = cmds.iter().filter_map(|c| end_of(&c.command)).collect();
    assert_close(&ends[1], &[15.0, 8.0]);
    assert_close(&ends[2], &[19.0, 9.0]);
}

#[test]
fn full_circle_with_i_k_and_dwell_forms() {
    let cmds = check(
        Dialect::IsoLathe,
        "G01 X20 Z0 F100\nG02 I-5\nG04 P1500\nG04 X2\nG04 U3 P500\n",
        &AXES,
        &DIAMETER,
        &[20.0, 0.0],
    )
    .unwrap();
    assert!(
        matches!(&cmds[1].command, Command::Arc { end, center, .. } if end == &vec![20.0, 0.0] && center == &vec![10.0, 0.0])
    );
    let dwells: Vec<f64> = cmds
        .iter()
        .filter_map(|c| {
            if let Command::Dwell { seconds } = c.command {
                Some(seconds)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(dwells, [1.5, 2.0, 0.5]);
}

#[test]
fn unknown_g_code_on_line_3_stops_before_it() {
    let text = "G00 X50 Z5\nG01 Z-10 F100\nG07.5 X60\nG01 X70\n";
    let mut interp = cnc_interpreter::Interpreter::new(
        Dialect::IsoLathe,
        text,
        Setup::new(&AXES, &DIAMETER, &[100.0, 50.0]),
    );
    let mut lines = vec![];
    let err = loop {
        match interp.next_command() {
            Ok(Some(c)) => lines.push(c.line),
            Ok(None) => panic!("program must not end normally"),
            Err(e) => break e,
        }
    };
    assert_eq!(lines, [1, 2]);
    assert_eq!((err.number, err.line), (alarm::UNDEFINED_CODE, 3));
    assert!(err.text.contains("G7.5"), "{}", err.text);
    // Nothing after the bad line, ever.
    assert!(interp.next_command().is_err());
}

#[test]
fn program_errors_carry_number_and_line() {
    let cases: &[(&str, u32, u32)] = &[
        (
            "G00 X10\nG02 X20 Z-50 R5 F100\n",
            alarm::ARC_RADIUS_TOO_SMALL,
            2,
        ),
        (
            "G01 X10 Z0 F100\nG02 X10 Z0 R5\n",
            alarm::ARC_RADIUS_TOO_SMALL,
            2,
        ),
        (
            "G01 X10 Z0 F100\nG02 X20 Z-5 I3 K0\n",
            alarm::ARC_END_NOT_ON_CIRCLE,
            2,
        ),
        (
            "G01 X10 Z0 F100\nG02 X20 Z-5 R10 I3\n",
            alarm::ARC_R_AND_IJK,
            2,
        ),
        (
            "G01 X10 Z0 F100\nG02 X20 Z-5\n",
            alarm::ARC_RADIUS_TOO_SMALL,
            2,
        ),
        ("G01 X10\n", alarm::FEED_OUT_OF_RANGE, 1),
        ("M3 M8 M10 M5\n", alarm::TOO_MANY_M, 1),
        ("M77\n", alarm::UNDEFINED_CODE, 1),
        ("G00 Y10\n", alarm::UNDEFINED_CODE, 1),
        ("G00 X10 U5\n", alarm::ABS_AND_INC_SAME_AXIS, 1),
        ("G04 G01 X10 F100\n", alarm::GROUP_00_WITH_01, 1),
        ("G00 X10 X20\n", alarm::DATA_FORMAT, 1),
        ("\n\nG01 X1 F-5\n", alarm::FEED_OUT_OF_RANGE, 3),
        ("T12.5\n", alarm::TOOL_NUMBER, 1),
        ("G04 P-100000000\n", alarm::DWELL_TIME, 1),
        ("G01 X1 F100 $\n", alarm::DATA_FORMAT, 1),
    ];
    for &(text, number, line) in cases {
        let e = check(Dialect::IsoLathe, text, &AXES, &DIAMETER, &[0.0, 0.0]).unwrap_err();
        assert_eq!((e.number, e.line), (number, line), "{text:?}: {e}");
    }
}

#[test]
fn arbitrary_bytes_never_panic() {
    // A small deterministic mutation run; the fuzz target of issue 3 goes further.
    let base = "O0001\nN10 G00 X100 Z50;\nN20 M3 S600\nN30 G01 X50 Z2 F200\nN40 G02 U10 W-5 R8\nN50 G03 X60 Z-20 I5 K-3\nN60 G04 P100\nM30\n";
    let bytes = base.as_bytes();
    let mut state: u64 = 0x9e3779b97f4a7c15;
    for _ in 0..3000 {
        let mut b = bytes.to_vec();
        for _ in 0..3 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let pos = (state % b.len() as u64) as usize;
            b[pos] = (state >> 32) as u8;
        }
        let text = String::from_utf8_lossy(&b);
        if let Err(e) = check(Dialect::IsoLathe, &text, &AXES, &DIAMETER, &[0.0, 0.0]) {
            assert!(e.line >= 1 && e.number > 0, "{e}");
        }
    }
}

#[test]
fn endless_or_runaway_programs_end_in_an_alarm() {
    let hx = |text: &str| {
        cnc_interpreter::check(Dialect::HuaxingLathe, text, Setup::lathe([100.0, 50.0]))
            .unwrap_err()
    };
    // A GOTO loop that moves, one that never moves, and cycles with absurd step counts.
    let e = cnc_interpreter::interpreter::check_limited(
        Dialect::HuaxingLathe,
        "N10 G0 X1\nN20 G0 X2\nGOTO10\n",
        Setup::lathe([100.0, 50.0]),
        cnc_interpreter::Library::new(),
        1000,
    )
    .unwrap_err();
    assert_eq!(e.number, 20, "{e}");
    let e = hx("N10 #1=1\nGOTO10\n");
    assert_eq!((e.number, e.line), (20, 2), "{e}");
    let e = hx("G0 X100 Z10\nG71 U0.00001 R1\nG71 P1 Q2 U0 W0\nN1 G0 X0\nN2 G1 Z-10000\n");
    assert_eq!((e.number, e.line), (13, 3), "{e}");
    let e = hx("G0 X100 Z5\nG75 R1\nG75 X0 Z-9000 P1 Q1 F10\n");
    assert_eq!((e.number, e.line), (13, 3), "{e}");
    // PLC inputs are not wired to the interpreter: reading one is an alarm, not a made-up 0.
    let e = hx("#1=#1002\n");
    assert_eq!((e.number, e.line), (20, 1), "{e}");
}

/// Issue 45 item 10: a feed below the least increment is an alarm, not a move that never ends.
#[test]
fn a_feed_below_the_least_increment_is_an_alarm() {
    for text in [
        "G98 G01 X10 Z5 F0.0000000000000000001\nM30\n",
        "G99 G01 X10 Z5 F0.0001\nM30\n",
    ] {
        let e = cnc_interpreter::check(Dialect::HuaxingLathe, text, Setup::lathe([100.0, 50.0]))
            .unwrap_err();
        assert_eq!(e.line, 1, "{e}");
        assert!(e.text.contains("out of range (min 0.001)"), "{e}");
    }
    assert!(cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G98 G01 X10 Z5 F0.001\nM30\n",
        Setup::lathe([100.0, 50.0])
    )
    .is_ok());
}

/// Issue 45 item 10: two million blank lines read once are no endless loop; a loop that
/// comes back over the same text without a move still is one.
#[test]
fn a_long_stretch_of_blank_lines_is_no_endless_loop() {
    let text = format!("G0 X10 Z5\n{}G0 X20\nM30\n", "\n".repeat(2_000_000));
    let cmds = cnc_interpreter::check(Dialect::HuaxingLathe, &text, Setup::lathe([100.0, 50.0]))
        .expect("runs to its end");
    assert_eq!(cmds.last().map(|c| c.line), Some(2_000_003));
    let e = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        &format!("N10 #1=1\n{}GOTO10\n", "\n".repeat(1000)),
        Setup::lathe([100.0, 50.0]),
    )
    .unwrap_err();
    assert_eq!(e.number, 20, "{e}");
}

/// D126: the Huaxing manual (§5.11) gives no feed for the chamfer or rounding it inserts, and
/// the FANUC family's do not either; they are cut at the feed of the block that carries the
/// L or D word (the block entering the corner), as FANUC controls cut ,C and ,R, unlike the
/// 802D (the block leaving it).
#[test]
fn a_huaxing_chamfer_takes_the_feed_of_the_block_that_commands_it() {
    let cmds = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G98 G01 Z-10 L2 F100\nX40 F200\nM30\n",
        Setup::lathe([20.0, 5.0]),
    )
    .unwrap();
    let feeds: Vec<f64> = cmds
        .iter()
        .filter_map(|c| match c.command {
            cnc_interpreter::Command::Linear { feed, .. } => Some(feed),
            _ => None,
        })
        .collect();
    assert_eq!(
        feeds,
        [100.0, 100.0, 200.0],
        "the line, the chamfer, the next line"
    );
}

/// Chamfer L and corner rounding D in G01 (`000` §5.11, decision D31).
#[test]
fn chamfer_and_corner_rounding_in_g01() {
    let hx = |t: &str| {
        let cmds =
            cnc_interpreter::check(Dialect::HuaxingLathe, t, Setup::lathe([20.0, 5.0])).unwrap();
        cnc_interpreter::trace::format(&AXES, &cmds)
    };
    // Line-line chamfer L2: the Z cut stops 2 mm short, the chamfer ends 2 mm up the face.
    assert_eq!(
        hx("G01 Z-10 L2 F100\nX40\nM30\n"),
        "L1 LINEAR X20.0000 Z-8.0000 F100.0000\n\
         L1 LINEAR X24.0000 Z-10.0000 F100.0000\n\
         L2 LINEAR X40.0000 Z-10.0000 F100.0000\n\
         L3 M30\nL3 END\n"
    );
    // Rounding D2 of a right angle: an arc of radius 2 tangent to both lines.
    assert_eq!(
        hx("G01 Z-10 D2 F100\nX40\nM30\n"),
        "L1 LINEAR X20.0000 Z-8.0000 F100.0000\n\
         L1 ARC_CW X24.0000 Z-10.0000 CX24.0000 CZ-8.0000 F100.0000 PLANE ZX\n\
         L2 LINEAR X40.0000 Z-10.0000 F100.0000\n\
         L3 M30\nL3 END\n"
    );
    // An M code after the motion of the chamfered block stays after its line.
    let t = hx("G01 Z-10 L2 F100 M09\nX40\nM30\n");
    let order: Vec<&str> = t.lines().map(|l| l.split_once(' ').unwrap().1).collect();
    assert_eq!(order[0], "LINEAR X20.0000 Z-8.0000 F100.0000");
    assert_eq!(order[1], "LINEAR X24.0000 Z-10.0000 F100.0000");
    assert_eq!(order[2], "M9", "{t}");
    // Line-arc: the chamfer ends on the arc 2 mm from the corner; the arc keeps its centre.
    let cmds = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G01 Z-10 L2 F100\nG02 X40 Z-20 R10\nM30\n",
        Setup::lathe([20.0, 5.0]),
    )
    .unwrap();
    let ends: Vec<Vec<f64>> = cmds.iter().filter_map(|c| end_of(&c.command)).collect();
    let q2 = &ends[1];
    let (dz, dr) = (q2[1] + 10.0, q2[0] / 2.0 - 10.0);
    assert!(((dz * dz + dr * dr).sqrt() - 2.0).abs() < 1e-9, "{q2:?}");
    match &cmds[2].command {
        Command::Arc { end, center, .. } => {
            assert_close(end, &[40.0, -20.0]);
            let r = |p: &[f64]| {
                ((p[0] / 2.0 - center[0] / 2.0).powi(2) + (p[1] - center[1]).powi(2)).sqrt()
            };
            assert!((r(q2) - 10.0).abs() < 1e-9 && (r(end) - 10.0).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // Too long for the lines: alarm 119 on the chamfer's block; L and D together: alarm 12;
    // a collinear corner and a chamfer before a rapid are left alone.
    let e = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G01 Z-10 L20 F100\nX40\nM30\n",
        Setup::lathe([20.0, 5.0]),
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (119, 1), "{e}");
    let e = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G01 Z-10 L2 D2 F100\nX40\nM30\n",
        Setup::lathe([20.0, 5.0]),
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (12, 1), "{e}");
    assert!(hx("G01 Z-10 L2 F100\nZ-20\nM30\n").starts_with("L1 LINEAR X20.0000 Z-10.0000"));
    assert!(hx("G01 Z-10 L2 F100\nG00 X40\nM30\n").starts_with("L1 LINEAR X20.0000 Z-10.0000"));
}

/// A program sets a work zero through #5220–#5325 (`000` §6.2): the moves after it shift.
#[test]
fn system_variables_set_the_work_zero_offsets() {
    let cmds = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "G54 G00 X50 Z10\n#5222=-100\nG00 X50 Z10\n#5222=#0\nM30\n",
        Setup::lathe([200.0, 100.0]),
    )
    .unwrap();
    let ends: Vec<Vec<f64>> = cmds.iter().filter_map(|c| end_of(&c.command)).collect();
    assert_close(&ends[0], &[50.0, 10.0]);
    assert_close(&ends[1], &[50.0, -90.0]);
    let e = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "#5221=999999\nM30\n",
        Setup::lathe([200.0, 100.0]),
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (20, 1), "{e}");
}

/// The Huaxing M codes that go to the PLC (`000` §4.1, decision D6): those that start something
/// before the block's motion, those that stop something after it, each with its number.
#[test]
fn huaxing_plc_m_codes_go_out_before_or_after_the_motion() {
    let before = "G01 X98 F100 M03\nX97 M04\nX96 M06\nX95 M08\nX94 M10\nX93 M12\nX92 M14\n\
                  X91 M17\nX90 M18\nX89 M19\nX88 M20\nX87 M22\nX86 M32\nX85 M41\nX84 M42\n\
                  X83 M43\nX82 M44\nX81 M63\nX80 M64\nX79 M56\nM30\n";
    let after = "G01 X98 F100 M05\nX97 M09\nX96 M11\nX95 M13\nX94 M15\nX93 M21\nX92 M23\n\
                 X91 M33\nX90 M65\nX89 M48\nX88 M00\nM30\n";
    for (text, m_first) in [(before, true), (after, false)] {
        let cmds = cnc_interpreter::check(Dialect::HuaxingLathe, text, Setup::lathe([100.0, 0.0]))
            .unwrap_or_else(|e| panic!("{e}"));
        for line in 1..text.lines().count() as u32 {
            let of_line: Vec<&Command> = cmds
                .iter()
                .filter(|c| c.line == line)
                .map(|c| &c.command)
                .collect();
            let m_at = of_line
                .iter()
                .position(|c| matches!(c, Command::Aux(Aux::M(_))))
                .unwrap_or_else(|| panic!("line {line}: no M code in {of_line:?}"));
            let move_at = of_line
                .iter()
                .position(|c| matches!(c, Command::Linear { .. }))
                .unwrap_or_else(|| panic!("line {line}: no move in {of_line:?}"));
            assert_eq!(m_at < move_at, m_first, "line {line}: {of_line:?}");
            // The number goes out as written.
            let written: i32 = text
                .lines()
                .nth(line as usize - 1)
                .unwrap()
                .rsplit('M')
                .next()
                .unwrap()
                .trim()
                .parse()
                .unwrap();
            assert_eq!(of_line[m_at], &Command::Aux(Aux::M(written)));
        }
    }
}

/// Modal and one-shot G codes whose effect is a canonical command or a position: G09/G61/G64
/// path modes, G98/G99 feed modes, G05 three-point arcs, G18, G28 reference return, G52 local
/// and G50.x coordinate settings.
#[test]
fn huaxing_modal_codes_reach_the_canonical_stream() {
    let text = "G18 G00 X100 Z50\nG61 G01 X90 F100\nG64 X80\nG09 X70\nG99 G01 X60 F0.2\n\
                G98 G01 X50 F100\nG05 X50 Z30 I5 K-10\nG52 Z-10\nG00 X40 Z0\nG52 Z10\n\
                G50.3 U0 W0\nG28 U0 W0\nM30\n";
    let cmds = cnc_interpreter::check(Dialect::HuaxingLathe, text, Setup::lathe([100.0, 50.0]))
        .unwrap_or_else(|e| panic!("{e}"));
    let has = |line: u32, f: &dyn Fn(&Command) -> bool| {
        cmds.iter().any(|c| c.line == line && f(&c.command))
    };
    assert!(has(2, &|c| *c == Command::PathMode { exact_stop: true }));
    assert!(has(3, &|c| *c == Command::PathMode { exact_stop: false }));
    // G09 stops this block only: exact stop before its move, blending after.
    assert!(has(4, &|c| *c == Command::PathMode { exact_stop: true }));
    assert!(has(5, &|c| *c == Command::FeedMode { per_rev: true }));
    assert!(has(6, &|c| *c == Command::FeedMode { per_rev: false }));
    assert!(
        has(7, &|c| matches!(c, Command::Arc { .. })),
        "G05 three-point arc"
    );
    // G52 Z-10 shifts the work zero: Z0 is machine Z−10 (G52 Z10 shifts it back).
    assert!(has(
        9,
        &|c| matches!(c, Command::Rapid { end } if (end[1] + 10.0).abs() < 1e-9)
    ));
    // G28 U0 W0 goes to the reference point (the setup's start, X100 Z50).
    assert!(has(
        12,
        &|c| matches!(c, Command::Rapid { end } if (end[0] - 100.0).abs() < 1e-9
        && (end[1] - 50.0).abs() < 1e-9)
    ));
}

/// The moves and dwells of `cmds` as short text: `R x z` rapid, `F x z` feed, `D s` dwell,
/// `M n` aux M.
fn moves(cmds: &[Canon]) -> Vec<String> {
    cmds.iter()
        .filter_map(|c| match &c.command {
            Command::Rapid { end } => Some(format!("R{} {}", end[0], end[1])),
            Command::Linear { end, .. } => Some(format!("F{} {}", end[0], end[1])),
            Command::Dwell { seconds } => Some(format!("D{seconds}")),
            Command::Aux(Aux::M(m)) => Some(format!("M{m}")),
            _ => None,
        })
        .collect()
}

#[test]
fn g83_g87_drilling() {
    let hx = |text: &str| check(Dialect::HuaxingLathe, text, &AXES, &DIAMETER, &[50.0, 5.0]);
    // G83 J0 at X0 from Z5 to Z-5: pecks of 4 mm, back off 1, dwell 0.5 s, out to Z5.
    let cmds = hx("G83 X0 Z-5 Q4. R1 P500 F80\nM30\n").unwrap();
    assert_eq!(
        moves(&cmds),
        ["R0 5", "F0 1", "R0 2", "F0 -3", "R0 -2", "F0 -5", "D0.5", "R0 5", "M30"]
    );
    // J1 leaves the hole after each peck and comes back to R short of the depth reached.
    let cmds = hx("G83 X0 Z-5 Q4. R1 J1 F80\nM30\n").unwrap();
    assert_eq!(
        moves(&cmds),
        ["R0 5", "F0 1", "R0 5", "R0 2", "F0 -3", "R0 5", "R0 -2", "F0 -5", "R0 5", "M30"]
    );
    // Q is modal: the next block with a position drills again with the same pecks; Q0 drills
    // straight; without a decimal point Q counts 0.0001 mm increments (D12).
    let cmds = hx("G83 X0 Z-3 Q20000 F80\nZ-1\nZ-2 Q0\nM30\n").unwrap();
    assert_eq!(
        moves(&cmds),
        [
            "R0 5", "F0 3", "R0 4", "F0 1", "R0 2", "F0 -1", "R0 0", "F0 -3", "R0 5", "F0 3",
            "R0 4", "F0 1", "R0 2", "F0 -1", "R0 5", "F0 -2", "R0 5", "M30"
        ]
    );
    // K2 with an incremental hole position: two holes 10 mm apart; M20 clamps after
    // positioning, M21 unclamps at the end of each hole.
    let cmds = hx("G00 X60 Z-10\nG87 W-5 X40 K2 M20 F50\nM30\n").unwrap();
    assert_eq!(
        moves(&cmds),
        [
            "R60 -10", "R60 -15", "M20", "F40 -15", "R60 -15", "M21", "R60 -20", "M20", "F40 -20",
            "R60 -20", "M21", "M30"
        ]
    );
    // Errors, on the line of the drilling block.
    for (bad, number) in [
        ("G83 X0 F80", 23),           // no hole bottom
        ("G83 X0 Z-5 K0 F80", 13),    // repeat count below 1
        ("G83 X0 Z-5 J2 F80", 13),    // J is 0 or 1
        ("G83 X0 C90 Z-5 F80", 74),   // no C axis on this lathe (D138)
        ("G83 X0 Z-5 M20 M8 F80", 7), // one clamp code
    ] {
        let e = hx(&format!("G00 X0 Z5\n{bad}\nM30\n")).unwrap_err();
        assert_eq!((e.number, e.line), (number, 2), "{bad}: {e}");
    }
    // With nose compensation on, the cycle is refused (D45).
    let mut setup = Setup::new(&AXES, &DIAMETER, &[50.0, 5.0]);
    setup.offsets.tools.insert(
        1,
        cnc_interpreter::setup::ToolOffset {
            radius: 0.4,
            tip: 3,
            ..Default::default()
        },
    );
    let e = cnc_interpreter::check(
        Dialect::HuaxingLathe,
        "T0101\nG42 G01 X40 Z2 F100\nG83 X0 Z-5 F80\nM30\n",
        setup,
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (42, 3), "{e}");
}

/// G99.1 (`000` §5.25, D132): feed per revolution whose next cut waits for the encoder's Z
/// pulse: that one cut goes to motion locked to the encoder from the index (start angle 0), at
/// F along the path; the rapid before it and the cuts after it are G99's own.
#[test]
fn g99_1_starts_its_next_cut_on_the_encoder_z_pulse_and_leaves_g99() {
    let text = "G98 G00 X40 Z2\nM03 S500\nG99.1 F0.2\nG00 Z1\nG01 Z-30\nX60 Z-40\nG01 Z-50\nM30\n";
    let c = check(
        Dialect::HuaxingLathe,
        text,
        &AXES,
        &DIAMETER,
        &[100.0, 50.0],
    )
    .unwrap();
    let kinds: Vec<&Command> = c.iter().map(|c| &c.command).collect();
    // G99.1 selects feed per revolution once.
    assert_eq!(
        kinds
            .iter()
            .filter(|k| matches!(k, Command::FeedMode { per_rev: true }))
            .count(),
        1,
        "{kinds:#?}"
    );
    let threads: Vec<(f64, f64, Vec<f64>)> = c
        .iter()
        .filter_map(|c| match &c.command {
            Command::Thread {
                end,
                lead,
                start_angle,
            } => Some((*lead, *start_angle, end.to_vec())),
            _ => None,
        })
        .collect();
    // Only the first cut after G99.1, Z2 → Z-30: a straight cut, so the lead is F.
    assert_eq!(threads.len(), 1, "{kinds:#?}");
    let (lead, angle, end) = &threads[0];
    assert!((lead - 0.2).abs() < 1e-12 && *angle == 0.0, "{threads:?}");
    assert_close(end, &[40.0, -30.0]);
    // The taper after it and the last cut are G99 cuts.
    assert!(
        c.iter()
            .any(|c| matches!(&c.command, Command::Linear { .. })),
        "{kinds:#?}"
    );
    // A taper as the indexed cut: F along the path, so its lead along Z (the longer slide
    // travel: 10 mm of Z against 10 mm of X diameter, 5 mm of slide) is F × 10 / √125.
    let c = check(
        Dialect::HuaxingLathe,
        "G00 X40 Z2\nM03 S500\nG99.1 F0.2\nG01 X50 Z-8\nM30\n",
        &AXES,
        &DIAMETER,
        &[100.0, 50.0],
    )
    .unwrap();
    let lead = c
        .iter()
        .find_map(|c| match &c.command {
            Command::Thread { lead, .. } => Some(*lead),
            _ => None,
        })
        .expect("the indexed cut");
    assert!((lead - 0.2 * 10.0 / 125f64.sqrt()).abs() < 1e-12, "{lead}");
    // An arc cannot start on the pulse; G98 before the cut cancels the wait.
    let e = check(
        Dialect::HuaxingLathe,
        "G00 X40 Z2\nG99.1 F0.2\nG02 X50 Z-3 R5\nM30\n",
        &AXES,
        &DIAMETER,
        &[100.0, 50.0],
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (alarm::UNDEFINED_CODE, 3), "{e}");
    let c = check(
        Dialect::HuaxingLathe,
        "G00 X40 Z2\nG99.1 F0.2\nG98 F100\nG01 Z-30\nM30\n",
        &AXES,
        &DIAMETER,
        &[100.0, 50.0],
    )
    .unwrap();
    assert!(!c
        .iter()
        .any(|c| matches!(c.command, Command::Thread { .. })));
}
