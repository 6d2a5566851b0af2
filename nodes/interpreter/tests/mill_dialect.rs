//! The FANUC 0-M mill dialect where LinuxCNC cannot be the oracle (`tests/linuxcnc_oracle.rs`
//! names each difference): FANUC behaviour from the manual (`003`) and its inventory's
//! Appendix A, asserted on the canonical stream. Decision D47.

use cnc_interpreter::{trace, Canon, Dialect, Library, ProgramError, Setup};

const XYZ: [char; 3] = ['X', 'Y', 'Z'];

fn mill() -> Setup {
    let mut setup = Setup::new(&XYZ, &[false; 3], &[0.0; 3]);
    for (n, length, radius) in [(1, 100.0, 5.0), (2, 42.5, 3.0)] {
        let t = setup.offsets.tools.entry(n).or_default();
        t.z = length;
        t.radius = radius;
    }
    setup
}

fn run(text: &str) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(Dialect::FanucMill, text, mill())
}

/// The stream as trace lines without the source line: `RAPID X5.0000 Y5.0000 Z2.0000`.
fn lines(text: &str) -> Vec<String> {
    run(text)
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
        .iter()
        .map(|c| {
            let l = trace::line(&XYZ, c);
            l.split_once(' ').map_or(l.clone(), |(_, b)| b.to_string())
        })
        .collect()
}

fn alarm(text: &str) -> ProgramError {
    match run(text) {
        Ok(c) => panic!("no alarm for\n{text}\n{c:?}"),
        Err(e) => e,
    }
}

#[test]
fn g98_after_g99_moves_over_at_the_r_level_and_returns_to_the_initial_level() {
    let l = lines("G0 X0. Y0. Z20.\nG99 G81 X5. Y5. Z-5. R2. F100\nG98 X15.\nG80\nM30\n");
    assert_eq!(
        l[1..9],
        [
            "RAPID X5.0000 Y5.0000 Z20.0000",
            "RAPID X5.0000 Y5.0000 Z2.0000",
            "LINEAR X5.0000 Y5.0000 Z-5.0000 F100.0000",
            "RAPID X5.0000 Y5.0000 Z2.0000",
            // LinuxCNC would climb to Z20 on the way over; FANUC moves at the level it is at.
            "RAPID X15.0000 Y5.0000 Z2.0000",
            "LINEAR X15.0000 Y5.0000 Z-5.0000 F100.0000",
            "RAPID X15.0000 Y5.0000 Z20.0000",
            "M30",
        ]
    );
}

#[test]
fn tapping_reverses_the_spindle_at_the_bottom_and_back_at_r() {
    let l = lines("G0 X0. Y0. Z10.\nS500 M3\nG99 G84 X5. Y5. Z-8. R2. P300 F100\nG80\nM30\n");
    assert_eq!(
        l[4..11],
        [
            "RAPID X5.0000 Y5.0000 Z2.0000",
            "LINEAR X5.0000 Y5.0000 Z-8.0000 F100.0000",
            "DWELL 0.300",
            "M4",
            "LINEAR X5.0000 Y5.0000 Z2.0000 F100.0000",
            "M3",
            "M30",
        ]
    );
    // G74 left-hand: the other way round; G98 returns to the initial level after R.
    let l = lines("G0 X0. Y0. Z10.\nS500 M4\nG98 G74 X5. Y5. Z-8. R2. F100\nG80\nM30\n");
    assert_eq!(
        l[6..10],
        [
            "M3",
            "LINEAR X5.0000 Y5.0000 Z2.0000 F100.0000",
            "M4",
            "RAPID X5.0000 Y5.0000 Z10.0000",
        ]
    );
}

#[test]
fn fine_boring_orients_and_shifts_off_the_wall_before_leaving() {
    let l = lines("G0 X0. Y0. Z10.\nS800 M3\nG98 G76 X5. Y5. Z-8. R2. Q0.4 F80\nG80\nM30\n");
    assert_eq!(
        l[5..11],
        [
            "LINEAR X5.0000 Y5.0000 Z-8.0000 F80.0000",
            "M19",
            "RAPID X5.4000 Y5.0000 Z-8.0000",
            "RAPID X5.4000 Y5.0000 Z10.0000",
            "RAPID X5.0000 Y5.0000 Z10.0000",
            "M3",
        ]
    );
}

#[test]
fn back_boring_goes_down_shifted_and_bores_upwards() {
    let l = lines("G0 X0. Y0. Z10.\nS800 M3\nG98 G87 X5. Y5. Z-3. R-12. Q0.5 F60\nG80\nM30\n");
    assert_eq!(
        l[3..15],
        [
            "RAPID X5.0000 Y5.0000 Z10.0000",
            "M19",
            "RAPID X5.5000 Y5.0000 Z10.0000",
            "RAPID X5.5000 Y5.0000 Z-12.0000",
            "RAPID X5.0000 Y5.0000 Z-12.0000",
            "M3",
            "LINEAR X5.0000 Y5.0000 Z-3.0000 F60.0000",
            "M19",
            "RAPID X5.5000 Y5.0000 Z-3.0000",
            "RAPID X5.5000 Y5.0000 Z10.0000",
            "RAPID X5.0000 Y5.0000 Z10.0000",
            "M3",
        ]
    );
    let e = alarm("G0 Z10.\nG99 G87 X5. Y5. Z-3. R-12. Q0.5 F60\nM30\n");
    assert_eq!((e.line, e.text.contains("G98")), (2, true), "{e}");
}

#[test]
fn g86_and_g88_stop_the_spindle_and_restart_it_the_way_it_turned() {
    let l = lines("G0 X0. Y0. Z10.\nS800 M4\nG98 G86 X5. Y5. Z-8. R2. F80\nG80\nM30\n");
    assert_eq!(l[6..9], ["M5", "RAPID X5.0000 Y5.0000 Z10.0000", "M4"]);
    // G88: dwell, stop, a program stop for the manual retract, then out and on again.
    let l = lines("G0 X0. Y0. Z10.\nS800 M3\nG99 G88 X5. Y5. Z-8. R2. P1000 F80\nG80\nM30\n");
    assert_eq!(
        l[6..11],
        [
            "DWELL 1.000",
            "M5",
            "M0",
            "RAPID X5.0000 Y5.0000 Z2.0000",
            "M3"
        ]
    );
}

#[test]
fn hole_data_stay_until_g80_and_l0_only_stores_them() {
    // L0 stores the data without drilling; the next position drills with them.
    let l = lines("G0 X0. Y0. Z10.\nG98 G81 Z-4. R1. F90 L0\nX7.\nG85 X9.\nG80\nM30\n");
    assert_eq!(l[1], "RAPID X7.0000 Y0.0000 Z10.0000", "{l:?}");
    assert!(
        l.contains(&"LINEAR X9.0000 Y0.0000 Z1.0000 F90.0000".to_string()),
        "{l:?}"
    );
    // After G80 the data are gone.
    let e = alarm("G0 Z10.\nG81 X1. Z-4. R1. F90\nG80\nG81 X2.\nM30\n");
    assert_eq!((e.number, e.line), (10, 4), "{e}");
    // A group-01 code ends the cycle: this X moves, nothing drills.
    let l = lines("G0 Z10.\nG81 X1. Z-4. R1. F90\nG0 X3.\nX4.\nM30\n");
    assert_eq!(
        l[l.len() - 3..l.len() - 2],
        ["RAPID X4.0000 Y0.0000 Z10.0000"]
    );
}

#[test]
fn cycle_words_are_checked_with_their_line() {
    // FANUC P/S numbers (decision D49): 010 a code missing what it needs, 003 a value out
    // of its range, 009 a word where it may not be.
    for (text, number, line) in [
        ("G0 Z10.\nG81 X1. Z-4. F90\nM30\n", 10, 2),
        ("G0 Z10.\nG83 X1. Z-4. R1. Q0. F90\nM30\n", 3, 2),
        ("G0 Z10.\nG81 X1. Z-4. R-6. F90\nM30\n", 3, 2),
        ("G0 Z10.\nG81 X1. Z-4. R1. L2 K2. F90\nM30\n", 9, 2),
        ("G0 Z10.\nG81 X1. Z-4. R1. L2.5 F90\nM30\n", 3, 2),
        ("G0 Z10.\nG82 X1. Z-4. R1. P-5 F90\nM30\n", 3, 2),
        ("G0 Z10.\nG73 X1. Z-4. R1. F90\nM30\n", 10, 2),
        ("G0 Z10.\nG83 X1. Z-4. R1. Q0.000001 F90\nM30\n", 3, 2),
        ("G0 Z10.\nG81 X1. Z-4. R1. L1000 F90\nM30\n", 3, 2),
    ] {
        let e = alarm(text);
        assert_eq!((e.number, e.line), (number, line), "{text}: {e}");
    }
}

#[test]
fn g44_subtracts_the_length_and_h0_or_g49_cancel() {
    let l = lines("G44 H2 G0 Z10.\nH1 Z10.\nH0 Z10.\nG43 H2 Z10.\nG49 Z10.\nM30\n");
    let z: Vec<&str> = l
        .iter()
        .map(|s| s.rsplit(' ').next().unwrap_or(""))
        .collect();
    assert_eq!(
        z[..5],
        ["Z-32.5000", "Z-90.0000", "Z10.0000", "Z52.5000", "Z10.0000"]
    );
    let e = alarm("G43 H201 Z10.\nM30\n");
    assert_eq!((e.number, e.line), (30, 1), "{e}");
}

#[test]
fn t_only_selects_the_tool_on_the_mill() {
    // No offset comes with T: the Z move is the programmed one.
    let l = lines("T1 M6\nG0 Z10.\nM30\n");
    assert_eq!(l[..3], ["T1", "M6", "RAPID X0.0000 Y0.0000 Z10.0000"]);
    assert_eq!(alarm("T100\nM30\n").number, 30);
}

#[test]
fn a_tape_runs_its_first_program_and_calls_the_others() {
    let tape = "%\nO1\nG0 X0. Y0. Z5.\nM98 P2 L2\nM30\nO2\nG91 G1 X10. F100\nM99\n%\n";
    let l = lines(tape);
    assert_eq!(
        l[..3],
        [
            "RAPID X0.0000 Y0.0000 Z5.0000",
            "LINEAR X10.0000 Y0.0000 Z5.0000 F100.0000",
            "LINEAR X20.0000 Y0.0000 Z5.0000 F100.0000",
        ]
    );
    // A program of the tape replaces a library program of the same number.
    let mut lib = Library::new();
    lib.insert(2, "O0002", "G0 X99.\nM99\n");
    let cmds = cnc_interpreter::check_with_library(Dialect::FanucMill, tape, mill(), lib).unwrap();
    assert_eq!(cmds[1].command.end(), Some(&[10.0, 0.0, 5.0][..]));
    // An error inside a subprogram names it.
    let e = alarm("O1\nM98 P3\nM30\nO3\nG1 X1. F-5\nM99\n");
    assert_eq!(e.program, "O0003", "{e}");
}

#[test]
fn a_one_shot_code_may_share_its_block_with_a_motion_code() {
    let l = lines("G0 X5. Y5. Z5.\nG53 G1 Z0. F100\nX7.\nM30\n");
    // G53 moves at rapid in machine coordinates; G01 stays modal for the next block.
    assert_eq!(
        l[1..3],
        [
            "RAPID X5.0000 Y5.0000 Z0.0000",
            "LINEAR X7.0000 Y5.0000 Z0.0000 F100.0000"
        ]
    );
}

#[test]
fn cutter_compensation_works_in_g19_which_linuxcnc_refuses() {
    // G19: Y across, Z up; G42 keeps the cutter right of a path going +Y at Z0, so below it.
    let l = lines("G19 G0 X5. Y-10. Z0.\nG42 D1 G1 Y0. F100\nY30.\nG40 Y40.\nM30\n");
    assert_eq!(
        l[1..4],
        [
            "LINEAR X5.0000 Y0.0000 Z-5.0000 F100.0000",
            "LINEAR X5.0000 Y30.0000 Z-5.0000 F100.0000",
            "LINEAR X5.0000 Y40.0000 Z0.0000 F100.0000",
        ]
    );
}

#[test]
fn d0_compensates_with_no_radius_and_d_is_modal() {
    let l = lines("G0 X-10. Y0.\nG41 D0 G1 X0. F100\nY10.\nG40 X-10.\nM30\n");
    assert_eq!(l[1], "LINEAR X0.0000 Y0.0000 Z0.0000 F100.0000");
    // D2 given in a block of its own is used by the G41 after it: radius 3.
    let l = lines("G0 X-10. Y0.\nD2\nG41 G1 X0. F100\nX20.\nG40 X30.\nM30\n");
    assert_eq!(l[1], "LINEAR X0.0000 Y3.0000 Z0.0000 F100.0000");
}

#[test]
fn cutter_compensation_alarms_name_the_block() {
    let cases = [
        // Start-up in an arc block (P/S 034).
        ("G0 X0. Y0.\nG41 D1 G2 X10. Y0. R5. F100\nM30\n", 2, "arc"),
        // Cancel in an arc block.
        (
            "G0 X0. Y0.\nG41 D1 G1 X10. F100\nY10.\nG40 G3 X0. Y20. R10.\nM30\n",
            4,
            "arc",
        ),
        // Plane change under compensation (P/S 037).
        ("G0 X0. Y0.\nG41 D1 G1 X10. F100\nG18\nM30\n", 3, "plane"),
        // Reference return, machine coordinates and canned cycles need G40 first.
        ("G0 X0. Y0.\nG41 D1 G1 X10. F100\nG28 Z0.\nM30\n", 3, "G28"),
        ("G0 X0. Y0.\nG41 D1 G1 X10. F100\nG53 Z0.\nM30\n", 3, "G53"),
        (
            "G0 X0. Y0. Z10.\nG41 D1 G1 X10. F100\nG81 X20. Z-5. R2.\nM30\n",
            3,
            "canned cycle",
        ),
        // A step smaller than the cutter radius between two inner corners: the offset line
        // would run backwards (interference, P/S 041), seen when block 5 shows the corner.
        (
            "G0 X-10. Y0.\nG41 D1 G1 X0. Y0. F100\nX20.\nY4.\nX40.\nY20.\nG40 X50.\nM30\n",
            5,
            "interference",
        ),
        // G41 on top of G41.
        (
            "G0 X0. Y0.\nG41 D1 G1 X10. F100\nG42 X20.\nM30\n",
            3,
            "G40 first",
        ),
    ];
    for (program, line, text) in cases {
        let e = alarm(program);
        assert_eq!(e.line, line, "{e} for\n{program}");
        assert!(e.text.contains(text), "{e} for\n{program}");
    }
}

#[test]
fn while_loops_nest_and_a_goto_may_leave_them() {
    // Two nested loops; the inner one is left by GOTO on its second lap of the third outer.
    let l = lines(
        "#1 = 0\nWHILE [#1 LT 3] DO1\n#2 = 0\nWHILE [#2 LT 2] DO2\n\
         IF [[#1 EQ 2] AND [#2 EQ 1]] GOTO 9\nG1 X#1 Y#2 F100\n#2 = #2 + 1\nEND2\n\
         #1 = #1 + 1\nEND1\nN9 G0 Z5.\nM30\n",
    );
    let xy: Vec<&str> = l.iter().map(|s| s.as_str()).collect();
    assert_eq!(
        xy[..6],
        [
            "LINEAR X0.0000 Y0.0000 Z0.0000 F100.0000",
            "LINEAR X0.0000 Y1.0000 Z0.0000 F100.0000",
            "LINEAR X1.0000 Y0.0000 Z0.0000 F100.0000",
            "LINEAR X1.0000 Y1.0000 Z0.0000 F100.0000",
            "LINEAR X2.0000 Y0.0000 Z0.0000 F100.0000",
            "RAPID X2.0000 Y0.0000 Z5.0000",
        ]
    );
    // A false condition at the start skips the body; DO without WHILE loops until a GOTO.
    let l = lines("WHILE [1 GT 2] DO1\nG1 X9. F100\nEND1\n#5 = 0\nDO3\n#5 = #5 + 1\nIF [#5 GE 4] GOTO 7\nEND3\nN7 G1 X#5 F100\nM30\n");
    assert_eq!(l[0], "LINEAR X4.0000 Y0.0000 Z0.0000 F100.0000");
}

#[test]
fn g65_passes_arguments_by_the_table_and_repeats_with_l() {
    // A=#1, B=#2, X=#24, Y=#25; locals are the macro's own. L2 runs it twice in one call:
    // the second pass sees what the first left in #24.
    let text = "%\nO1000\n#1 = 99\nG65 P9010 A2. B-3. X10. Y[4 * 2] L2\nG1 X#1 F100\nM30\n\
                O9010\nG1 X[#24 + #1] Y[#25 + #2] F200\n#24 = #24 + 1\nM99\n%\n";
    let l = lines(text);
    assert_eq!(
        l[..3],
        [
            "LINEAR X12.0000 Y5.0000 Z0.0000 F200.0000",
            "LINEAR X13.0000 Y5.0000 Z0.0000 F200.0000",
            // The caller's #1 is untouched by the macro's.
            "LINEAR X99.0000 Y5.0000 Z0.0000 F100.0000",
        ]
    );
}

#[test]
fn system_variables_read_positions_offsets_and_modal_state() {
    let l = lines(
        "G10 L2 P2 X100. Y50. Z-10.\nG55 G1 X5. Y6. F300\n\
         #100 = #5001 + #5002\n#101 = #5021\n#102 = #4001 * 100 + #4003\n\
         #103 = #5242 + #2001 + #2202\n#5241 = 200\n#2001 = 7\n\
         G1 X#100 Y#101 Z#102\nG1 X#103\nG43 H1 Z0.\nM30\n",
    );
    // #5001 + #5002 = 5 + 6 (work), #5021 = 105 (machine X), G01 and G90 give 190, G55's
    // Y zero 50 + H1's length 100 + D2's radius 3 give 153. G55's Z zero is -10.
    // #5241 has moved G55's X zero to 200 before the moves.
    assert_eq!(
        l[1], "LINEAR X211.0000 Y155.0000 Z180.0000 F300.0000",
        "{l:?}"
    );
    assert_eq!(
        l[2], "LINEAR X353.0000 Y155.0000 Z180.0000 F300.0000",
        "{l:?}"
    );
    // #2001 = 7 made H1's length 7.
    assert_eq!(
        l[3], "LINEAR X353.0000 Y155.0000 Z-3.0000 F300.0000",
        "{l:?}"
    );
}

#[test]
fn g91_g10_l2_adds_to_the_work_offset_that_g90_replaces() {
    // FANUC 0-M: G10 in G91 is an increment to the stored offset; LinuxCNC always replaces.
    let l = lines(
        "G10 L2 P1 X37.5 Y-12.25 Z7.5\nG91 G10 L2 P1 X2.5 Y-0.75\n\
         G90 G54 G0 X0. Y0. Z0.\nG10 L2 P1 X1. Y2. Z3.\nG0 X0. Y0. Z0.\nM30\n",
    );
    assert_eq!(l[0], "RAPID X40.0000 Y-13.0000 Z7.5000", "{l:?}");
    assert_eq!(l[1], "RAPID X1.0000 Y2.0000 Z3.0000", "{l:?}");
}

#[test]
fn common_variables_500_to_999_are_kept_for_the_next_program() {
    let mut it = cnc_interpreter::Interpreter::new(
        Dialect::FanucMill,
        "#500 = 12.5\n#999 = -1\n#100 = 3\nM30\n",
        mill(),
    );
    while let Ok(Some(_)) = it.next_command() {}
    let kept = it.memory().kept;
    assert_eq!(kept.get(&500), Some(&12.5));
    assert_eq!(kept.get(&999), Some(&-1.0));
    // #100–#199 are cleared at power-off (A.3).
    assert_eq!(kept.get(&100), None);
}

#[test]
fn g27_checks_g29_returns_and_g60_approaches_from_one_side() {
    // G28 through X10 Y5 to the reference point (0, 0, 0); G29 back through the same
    // intermediate point to X30 Y20.
    let l = lines("G0 X10. Y5. Z20.\nG28 X10. Y5.\nG29 X30. Y20.\nG27 X0. Y0.\nM30\n");
    assert_eq!(
        l[1..6],
        [
            "RAPID X10.0000 Y5.0000 Z20.0000",
            "RAPID X0.0000 Y0.0000 Z20.0000",
            "RAPID X10.0000 Y5.0000 Z20.0000",
            "RAPID X30.0000 Y20.0000 Z20.0000",
            // G27 to the reference point: there, so no alarm.
            "RAPID X0.0000 Y0.0000 Z20.0000",
        ]
    );
    // G27 to a point that is not the reference point: P/S 092 on its line.
    let e = alarm("G0 X10.\nG27 X5.\nM30\n");
    assert_eq!((e.number, e.line), (92, 2), "{e}");
    // G29 with no G28 before it.
    assert_eq!(alarm("G29 X5.\nM30\n").number, 10);
    // G60: each moving axis stops 1 mm short and comes the last millimetre from below.
    let l = lines("G0 X10. Y10.\nG60 X-5. Y10.\nM30\n");
    assert_eq!(
        l[1..3],
        [
            "RAPID X-6.0000 Y10.0000 Z0.0000",
            "RAPID X-5.0000 Y10.0000 Z0.0000"
        ]
    );
}

#[test]
fn m06_needs_the_tool_axis_at_the_second_reference_point() {
    let mut setup = mill();
    setup.second_reference = vec![0.0, 0.0, 150.0];
    let run = |text: &str| cnc_interpreter::check(Dialect::FanucMill, text, setup.clone());
    // Z is at 0, the tool change position is Z150: a machine alarm, before the change.
    let e = run("T2\nM06\nM30\n").unwrap_err();
    assert_eq!((e.number, e.line), (1006, 2), "{e}");
    // G91 G30 Z0 takes Z there (only Z moves); then M06 changes the tool.
    let c = run("G0 X20. Y10.\nG91 G30 Z0.\nT2 M06\nM30\n").expect("tool change at G30");
    let text: Vec<String> = c.iter().map(|c| trace::line(&XYZ, c)).collect();
    assert!(
        text.iter()
            .any(|l| l.ends_with("RAPID X20.0000 Y10.0000 Z150.0000")),
        "{text:?}"
    );
    assert!(text.iter().any(|l| l.ends_with(" M6")), "{text:?}");
    // A third reference point is not configured.
    assert_eq!(run("G30 P3 Z0.\nM30\n").unwrap_err().number, 3);
}

#[test]
fn a_rotary_axis_cannot_move_under_cutter_compensation() {
    let setup = Setup::new(&['X', 'Y', 'Z', 'A'], &[false; 4], &[0.0; 4]);
    let e = cnc_interpreter::check(
        Dialect::FanucMill,
        "G0 X-10. Y0.\nG41 D0 G1 X0. F100\nX10. A30.\nG40 X20.\nM30\n",
        setup,
    )
    .unwrap_err();
    assert_eq!(e.line, 3, "{e}");
    assert!(e.text.contains("A cannot move"), "{e}");
}

#[test]
fn modal_information_names_the_codes_in_force() {
    let text = "G0 X0. Y-10. Z20.\nG56 G61 G44 H1 Z20.\nG42 D1 G1 X5. Y0. F100\n\
                #500 = #4007 * 100 + #4008\n#501 = #4001\nG40 G1 X10.\n\
                G99 G83 Z-5. R2. Q2. F50 L0\n#502 = #4009 * 100 + #4010\nG80\n\
                G18 G91\n#503 = #4002 * 100 + #4003\n#504 = #4014 * 100 + #4015\nM30\n";
    let mut it = cnc_interpreter::Interpreter::new(Dialect::FanucMill, text, mill());
    while let Ok(Some(_)) = it.next_command() {}
    let kept = it.memory().kept;
    let got: Vec<f64> = (500..=504)
        .map(|n| kept.get(&n).copied().unwrap_or(-1.0))
        .collect();
    // G42 G44, G01, G83 G99, G18 G91, G56 G61.
    assert_eq!(got, [4244.0, 1.0, 8399.0, 1891.0, 5661.0]);
}

/// Under cutter compensation a block's moves wait for the next block (to know the corner);
/// M and S functions of the blocks in between still come out in program order: after the
/// moves of the block before them, before those of the block after.
#[test]
fn m_and_s_between_compensated_blocks_keep_their_place() {
    let text = "O1\nG17 G90 G0 X-20. Y-20. Z5. S1000 M3\nG1 Z-5. F300\nG41 D1 G1 X0 Y0\n\
        Y40.\nX40.\nM8\nY0\nS800 X0\nG40 G1 X-20. Y-20.\nM30\n";
    let out = run(text).unwrap();
    let at = |pred: &dyn Fn(&Canon) -> bool| out.iter().position(pred).unwrap();
    let m8 = at(&|c| c.command == cnc_interpreter::Command::Aux(cnc_interpreter::Aux::M(8)));
    let s800 = at(&|c| c.command == cnc_interpreter::Command::Aux(cnc_interpreter::Aux::S(800.0)));
    let last_of = |line: u32| {
        out.iter()
            .rposition(|c| c.line == line && c.command.end().is_some())
            .unwrap()
    };
    let first_of = |line: u32| {
        out.iter()
            .position(|c| c.line == line && c.command.end().is_some())
            .unwrap()
    };
    // M8 (line 7) after X40's moves (line 6), before Y0's (line 8).
    assert!(last_of(6) < m8 && m8 < first_of(8), "{out:?}");
    // S800 in the X0 block (line 9) before its move, after Y0's.
    assert!(last_of(8) < s800 && s800 < first_of(9), "{out:?}");
}

/// G66/G67 (`003` Part 2 §8.4, D129): a drilling macro called after every positioning move of
/// a hole pattern, as shops write them; the G66 block itself moves nothing (its Z and R are
/// arguments), the macro's own moves do not call it again, and G67 ends the calls.
#[test]
fn g66_calls_its_macro_after_every_move_block_until_g67() {
    let text = "%\nO1000\nG90 G0 X0. Y0. Z50.\n\
                G66 P9110 Z-8. R2. F120.\n\
                X10. Y10.\nX30.\nM8\nG91 Y20.\nG90 G67\nX0. Y0.\nM30\n\
                O9110\n(DRILL ONE HOLE AT THE CURRENT XY)\n\
                G90 G0 Z#18\nG1 Z#26 F#9\nG0 Z#18\nM99\n%\n";
    let l = lines(text);
    assert_eq!(
        l[..15],
        [
            "RAPID X0.0000 Y0.0000 Z50.0000",
            // G66 moved nothing; the first hole: the move, then the macro.
            "RAPID X10.0000 Y10.0000 Z50.0000",
            "RAPID X10.0000 Y10.0000 Z2.0000",
            "LINEAR X10.0000 Y10.0000 Z-8.0000 F120.0000",
            "RAPID X10.0000 Y10.0000 Z2.0000",
            // X30.: the macro's moves left the tool at R; the next move starts there.
            "RAPID X30.0000 Y10.0000 Z2.0000",
            "RAPID X30.0000 Y10.0000 Z2.0000",
            "LINEAR X30.0000 Y10.0000 Z-8.0000 F120.0000",
            "RAPID X30.0000 Y10.0000 Z2.0000",
            // M8 moves nothing and calls nothing.
            "M8",
            // G91 Y20.: an incremental move calls it too (the macro's G90 is modal: the
            // caller is in G90 after it, as on the control).
            "RAPID X30.0000 Y30.0000 Z2.0000",
            "RAPID X30.0000 Y30.0000 Z2.0000",
            "LINEAR X30.0000 Y30.0000 Z-8.0000 F120.0000",
            "RAPID X30.0000 Y30.0000 Z2.0000",
            // After G67 the move is only a move.
            "RAPID X0.0000 Y0.0000 Z2.0000",
        ],
        "{l:#?}"
    );
    assert_eq!(l[15], "M30", "{l:#?}");
}

#[test]
fn g66_counts_l_its_arguments_follow_the_table_and_its_errors_are_p_s_alarms() {
    // L2: the macro runs twice after each move; its locals are set again for each call.
    let text = "%\nO1000\nG66 P9120 L2 A1.\nG0 X5.\nG67\nM30\nO9120\n\
                G1 Y#1 F100\n#1 = #1 + 1\nM99\n%\n";
    let l = lines(text);
    assert_eq!(
        l[..4],
        [
            "RAPID X5.0000 Y0.0000 Z0.0000",
            "LINEAR X5.0000 Y1.0000 Z0.0000 F100.0000",
            "LINEAR X5.0000 Y2.0000 Z0.0000 F100.0000",
            "M30",
        ],
        "{l:#?}"
    );
    // G04's X is a time, G92's a position set: neither calls the macro.
    let l = lines("%\nO1000\nG66 P9130\nG4 X1.\nG92 X0.\nG67\nM30\nO9130\nM5\nM99\n%\n");
    assert!(!l.iter().any(|c| c == "M5"), "{l:#?}");
    // P missing: P/S 076; an address that is no argument (G, N, O, P, L excepted): P/S 129;
    // a macro not in memory: P/S 078; a second G66 before G67: P/S 077.
    assert_eq!(alarm("G66 Z1.\nM30\n").number, 76);
    assert_eq!(
        alarm("%\nO1\nG66 P9000 G1\nM30\nO9000\nM99\n%\n").number,
        129
    );
    assert_eq!(alarm("G66 P9999\nM30\n").number, 78);
    let twice = "%\nO1\nG66 P9000\nG66 P9000\nM30\nO9000\nM99\n%\n";
    let e = alarm(twice);
    assert_eq!((e.number, e.line), (77, 4), "{e}");
    // G67 with no modal call is nothing to cancel.
    assert_eq!(
        lines("G67\nG0 X1.\nM30\n")[0],
        "RAPID X1.0000 Y0.0000 Z0.0000"
    );
}

/// M29 rigid tapping (`003` §6.4, inventory A.1 "rigid if M29 S_ precedes it, F = pitch × S";
/// D130): the spindle holds its angle in position control, and each G84 hole is a tap in
/// locked to the spindle at the pitch F/S, the dwell, and a tap out turning the other way —
/// the canonical taps motion runs for the 802D's CYCLE84. G80 ends it: the next G84 is the
/// floating one again.
#[test]
fn m29_makes_g84_and_g74_tap_rigidly_at_the_pitch_f_over_s_until_g80() {
    let l = lines(
        "G90 G0 X0. Y0. Z30.\nM29 S500\nG98 G84 X10. Y10. Z-12. R3. P200 F750.\n\
         X20.\nG80\nM29 S400\nG99 G74 X30. Z-6. R2. F400.\nG80\nM30\n",
    );
    assert_eq!(
        l[..16],
        [
            "RAPID X0.0000 Y0.0000 Z30.0000",
            "S500.0",
            // M29: position control where the spindle stands.
            "SPINDLE_POSITION 0.000 Incremental",
            "RAPID X10.0000 Y10.0000 Z30.0000",
            "RAPID X10.0000 Y10.0000 Z3.0000",
            // F750 / S500: a 1.5 mm pitch, in turning M03's way, out the other.
            "TAP X10.0000 Y10.0000 Z-12.0000 LEAD1.5000 S500.0",
            "DWELL 0.200",
            "TAP X10.0000 Y10.0000 Z3.0000 LEAD-1.5000 S500.0",
            "RAPID X10.0000 Y10.0000 Z30.0000",
            // The second hole taps rigidly too.
            "RAPID X20.0000 Y10.0000 Z30.0000",
            "RAPID X20.0000 Y10.0000 Z3.0000",
            "TAP X20.0000 Y10.0000 Z-12.0000 LEAD1.5000 S500.0",
            "DWELL 0.200",
            "TAP X20.0000 Y10.0000 Z3.0000 LEAD-1.5000 S500.0",
            "RAPID X20.0000 Y10.0000 Z30.0000",
            "S400.0",
        ],
        "{l:#?}"
    );
    // G74 (left hand) at F400/S400 = 1 mm: in turning M04's way; G99 ends at R.
    assert_eq!(
        l[16..22],
        [
            "SPINDLE_POSITION 0.000 Incremental",
            "RAPID X30.0000 Y10.0000 Z30.0000",
            "RAPID X30.0000 Y10.0000 Z2.0000",
            "TAP X30.0000 Y10.0000 Z-6.0000 LEAD-1.0000 S400.0",
            "TAP X30.0000 Y10.0000 Z2.0000 LEAD1.0000 S400.0",
            "M30",
        ],
        "{l:#?}"
    );
    // G95: F is the pitch itself.
    let l = lines("G0 X0. Y0. Z5.\nG95 M29 S300\nG84 Z-4. R1. F1.25\nG80\nM30\n");
    assert!(
        l.contains(&"TAP X0.0000 Y0.0000 Z-4.0000 LEAD1.2500 S300.0".to_string()),
        "{l:#?}"
    );
    // After G80 a G84 is the floating tap: feed moves with the spindle reversed.
    let l = lines("G0 X0. Y0. Z5.\nM29 S300\nG80\nM3\nG84 Z-4. R1. F300.\nG80\nM30\n");
    assert!(!l.iter().any(|c| c.starts_with("TAP")), "{l:#?}");
    assert!(l.contains(&"M4".to_string()), "{l:#?}");
}

#[test]
fn rigid_tapping_refuses_what_it_cannot_tap() {
    // No S for M29, no F for the pitch, and M03 after M29 (the spindle left position control).
    let e = alarm("M29\nM30\n");
    assert_eq!((e.number, e.line), (10, 1), "{e}");
    let e = alarm("M29 S500\nG84 X1. Z-5. R2.\nM30\n");
    assert_eq!((e.number, e.line), (10, 2), "{e}");
    assert!(e.text.contains("F"), "{e}");
    let e = alarm("M29 S500\nM3\nG84 X1. Z-5. R2. F500.\nM30\n");
    assert_eq!((e.number, e.line), (10, 3), "{e}");
    assert!(e.text.contains("M29 S again"), "{e}");
}

/// G63 tapping mode (`003` §3.4 "until G64 or G63"; D131): until G61 or G64 every linear move
/// is a tap in a floating holder, cut as a thread of the pitch F/S so the overrides stay out
/// and the feed holds to the spindle (as the 802D's G63, D93); rapids stay rapids.
#[test]
fn g63_cuts_linear_moves_as_taps_at_f_over_s_until_g64() {
    let l = lines(
        "G0 X5. Y5. Z5. S600 M3\nG63 G1 Z-10. F600.\nM4\nZ5.\nG0 X15.\nG64 G1 Z0. F100.\nM30\n",
    );
    assert_eq!(
        l[3..9],
        [
            "THREAD X5.0000 Y5.0000 Z-10.0000 LEAD1.0000 Q0.000",
            "M4",
            // Out on the same lead, the spindle reversed.
            "THREAD X5.0000 Y5.0000 Z5.0000 LEAD1.0000 Q0.000",
            "RAPID X15.0000 Y5.0000 Z5.0000",
            // G64 ends the tapping mode (and blends again).
            "BLENDING",
            "LINEAR X15.0000 Y5.0000 Z0.0000 F100.0000",
        ],
        "{l:#?}"
    );
    // Without S there is no pitch; an arc is no tap.
    assert_eq!(alarm("G63 G1 Z-5. F100.\nM30\n").number, 10);
    let e = alarm("S500 M3\nG63 G1 X1. F500.\nG2 X2. R1.\nM30\n");
    assert_eq!((e.number, e.line), (10, 3), "{e}");
}
