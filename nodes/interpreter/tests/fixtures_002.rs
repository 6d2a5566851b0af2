//! The GTC2E manual's example programs (`../shared/fixtures/002/`), run with the
//! `gtc2e-lathe` dialect and checked against what each header and the manual state.
//!
//! Moves are compared as trace lines (`cnc check --trace` format, numbers without trailing
//! zeros, no source line), X in diameter, machine coordinates. The start point is X200 Z100
//! unless the manual's figure gives another.

use cnc_interpreter::{trace, Canon, Command, Dialect, ProgramError, Setup};

const HOME: [f64; 2] = [200.0, 100.0];

fn fixture(name: &str) -> String {
    let path = format!(
        "{}/../../../shared/fixtures/002/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn run_setup(text: &str, setup: Setup) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(Dialect::Gtc2eLathe, text, setup)
}

fn run(text: &str, start: [f64; 2]) -> Vec<Canon> {
    run_setup(text, Setup::lathe(start)).unwrap_or_else(|e| panic!("{e}"))
}

/// `1.5000` → `1.5`, `100.0000` → `100`.
fn trim_number(word: &str) -> String {
    let split = word
        .find(|c: char| c.is_ascii_digit() || c == '-')
        .unwrap_or(word.len());
    let (head, num) = word.split_at(split);
    if num.contains('.') && num.parse::<f64>().is_ok() {
        let t = num.trim_end_matches('0').trim_end_matches('.');
        format!("{head}{t}")
    } else {
        word.to_string()
    }
}

/// The stream as trace lines without the source line: `RAPID X181 Z100`.
fn lines(cmds: &[Canon]) -> Vec<String> {
    cmds.iter()
        .map(|c| {
            let l = trace::line(&['X', 'Z'], c);
            let body = l.split_once(' ').map(|(_, b)| b).unwrap_or("");
            body.split(' ')
                .map(trim_number)
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect()
}

fn last_position(cmds: &[Canon]) -> [f64; 2] {
    cmds.iter()
        .rev()
        .find_map(|c| c.command.end().map(|e| [e[0], e[1]]))
        .expect("a move")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

#[test]
fn fixture_001_g00_absolute_incremental_and_mixed() {
    let cmds = run(&fixture("001_g00_rapid.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "RAPID X60 Z110",
            "RAPID X140 Z110",
            "RAPID X140 Z100",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_002_003_g01_absolute_and_incremental_cut_the_same_path() {
    // A = X90 Z100 (the incremental version starts there).
    let a = [90.0, 100.0];
    let expected = [
        "RAPID X40 Z80",
        "LINEAR X40 Z60 F120",
        "LINEAR X60 Z50 F120",
        "LINEAR X60 Z0 F80",
        "M2",
        "END",
    ];
    assert_eq!(
        lines(&run(&fixture("002_g01_absolute_fig4_2.nc"), a)),
        expected
    );
    assert_eq!(
        lines(&run(&fixture("003_g01_incremental_fig4_2.nc"), a)),
        expected
    );
}

#[test]
fn fixture_004_four_arc_forms_reach_d_around_the_same_centre() {
    // Four alternative single blocks, each run alone from C = X40 Z60.
    let text = fixture("004_g02_arc_variants_fig4_3.nc");
    let variants: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('('))
        .filter(|l| l.contains("G2"))
        .collect();
    assert_eq!(variants.len(), 4);
    for v in variants {
        let cmds = run(&format!("{v}\nM2\n"), [40.0, 60.0]);
        assert_eq!(
            lines(&cmds)[0],
            "ARC_CW X60 Z50 CX60 CZ60 F80 PLANE ZX",
            "{v}"
        );
    }
}

#[test]
fn fixtures_005_to_007_g33_threads_metric_taper_and_inch() {
    let straight = lines(&run(&fixture("005_g33_straight_thread.nc"), HOME));
    assert_eq!(straight[0], "THREAD X200 Z70 LEAD1.5 Q0");
    // 1:6 taper: U10 (diameter) over W-30.
    let taper = lines(&run(&fixture("006_g33_taper_thread.nc"), HOME));
    assert_eq!(taper[0], "THREAD X210 Z70 LEAD3 Q0");
    // E10.2 = 10½ threads per inch: lead 25.4 / 10.5 mm.
    let cmds = run(&fixture("007_g33_inch_thread.nc"), HOME);
    match &cmds[0].command {
        Command::Thread { end, lead, .. } => {
            assert!(close(*lead, 25.4 / 10.5), "lead {lead}");
            assert!(close(end[1], 70.0));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn fixture_008_g76_passes_at_u19_u1975_u20_with_the_g31_retract() {
    let cmds = run(&fixture("008_g76_thread_cycle.nc"), HOME);
    let mut expected = vec!["RAPID X181 Z100".to_string()];
    // Each pass: thread to 8 mm before the end (Z58), retract X by 3 while threading to Z50,
    // Z back to the start, X back to the infeed point.
    for x in [181.0, 180.25, 180.0] {
        if x != 181.0 {
            expected.push(format!("RAPID X{x} Z100"));
        }
        expected.push(format!("THREAD X{x} Z58 LEAD1.5 Q0"));
        expected.push(format!("THREAD X{} Z50 LEAD1.5 Q0", x + 3.0));
        expected.push(format!("RAPID X{} Z100", x + 3.0));
        expected.push(format!("RAPID X{x} Z100"));
    }
    expected.extend(["RAPID X200 Z100", "M2", "END"].map(String::from));
    assert_eq!(lines(&cmds), expected);
}

#[test]
fn fixture_009_g74_taps_in_reverses_and_taps_out() {
    let cmds = run(&fixture("009_g74_tapping_cycle.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "RAPID X0 Z100",
            "M3",
            "THREAD X0 Z50 LEAD1.5 Q0",
            "M5",
            "M4",
            "THREAD X0 Z100 LEAD1.5 Q0",
            "M5",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_010_g24_triangles_from_b_b1_b2() {
    let cmds = run(&fixture("010_g24_taper_cycle_fig4_4.nc"), HOME);
    let mut expected = vec!["RAPID X40 Z100".to_string()];
    // B -> C at F, C -> A -> B at G00; B1 = X32, B2 = X24, the same triangle shifted.
    for b in [40, 32, 24] {
        if b != 40 {
            expected.push(format!("LINEAR X{b} Z100 F150"));
        }
        expected.push(format!("LINEAR X{} Z45 F150", b + 10));
        expected.push(format!("RAPID X{} Z100", b + 10));
        expected.push(format!("RAPID X{b} Z100"));
    }
    expected.extend(["RAPID X70 Z100", "M2", "END"].map(String::from));
    assert_eq!(lines(&cmds), expected);
}

#[test]
fn fixture_011_g77_rectangles_from_a_a1_a2() {
    let cmds = run(&fixture("011_g77_cylinder_cycle_fig4_5.nc"), HOME);
    let cuts: Vec<String> = lines(&cmds)
        .into_iter()
        .filter(|l| l.starts_with("LINEAR"))
        .collect();
    // A = X40 cuts X34; U-4 makes A1 = X36 cutting X30; X32 makes A2 = X32 cutting X26.
    assert_eq!(
        cuts,
        [
            "LINEAR X34 Z50 F150",
            "LINEAR X30 Z50 F150",
            "LINEAR X26 Z50 F150"
        ]
    );
    let l = lines(&cmds);
    assert!(l.contains(&"RAPID X36 Z100".to_string()) && l.contains(&"RAPID X32 Z100".to_string()));
    assert_eq!(last_position(&cmds), [60.0, 100.0]);
}

#[test]
fn fixture_012_g83_drills_to_c_e_g_with_the_dwell() {
    let cmds = run(&fixture("012_g83_drill_cycle_fig4_6.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "RAPID X0 Z100",
            "RAPID X0 Z65",
            "LINEAR X0 Z40 F20",
            "DWELL 1",
            "RAPID X0 Z65",
            "LINEAR X0 Z60 F20",
            "LINEAR X0 Z35 F20",
            "DWELL 1",
            "RAPID X0 Z60",
            "LINEAR X0 Z55 F20",
            "LINEAR X0 Z30 F20",
            "DWELL 1",
            "RAPID X0 Z55",
            "RAPID X0 Z100",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_013_g75_grooves_from_a_a1_a2() {
    let cmds = run(&fixture("013_g75_grooving_cycle_fig4_7.nc"), HOME);
    let l = lines(&cmds);
    // A = X70, B = X60, C = X60 Z47.5; A1 = X62 (B1 = X52); A2 = X54 (B2 = X44).
    for (a, b) in [(70, 60), (62, 52), (54, 44)] {
        assert!(l.contains(&format!("LINEAR X{b} Z47.5 F30")), "{l:?}");
        assert!(l.contains(&format!("RAPID X{a} Z47.5")), "{l:?}");
        assert!(l.contains(&format!("RAPID X{a} Z100")), "{l:?}");
    }
    assert_eq!(l.iter().filter(|x| x.starts_with("LINEAR")).count(), 8);
}

#[test]
fn fixture_014_g22_g80_runs_the_body_three_times() {
    let cmds = run(&fixture("014_g22_g80_program_loop.nc"), HOME);
    let infeeds = lines(&cmds)
        .iter()
        .filter(|l| l.starts_with("LINEAR") && l.ends_with("Z20 F200"))
        .count();
    assert_eq!(infeeds, 3);
    // Each pass X −6 (diameter): X = start − 68, Z = start − 80.
    assert_eq!(last_position(&cmds), [200.0 - 68.0, 100.0 - 80.0]);
}

#[test]
fn fixture_015_g04_dwells_5_5_s() {
    let cmds = run(&fixture("015_g04_dwell.nc"), HOME);
    assert_eq!(lines(&cmds), ["DWELL 5.5", "M2", "END"]);
}

#[test]
fn fixture_016_g26_returns_both_axes_together_after_m65() {
    let cmds = run(&fixture("016_g26_return_to_start.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        ["LINEAR X150 Z350 F150", "RAPID X200 Z100", "M2", "END"]
    );
}

#[test]
fn fixture_017_g31_g76_then_g25_g61_g60() {
    let cmds = run(&fixture("017_g31_g76_g25_g61_g60.nc"), HOME);
    let l = lines(&cmds);
    // G31 U5 W6: retract X by 5 starting 6 mm before the end of W-30.
    assert!(l.contains(&"THREAD X49 Z76 LEAD2 Q0".to_string()), "{l:?}");
    assert!(l.contains(&"THREAD X54 Z70 LEAD2 Q0".to_string()), "{l:?}");
    assert!(l.contains(&"THREAD X48 Z76 LEAD2 Q0".to_string()), "{l:?}");
    // G25 stores where the tool is after the second pass (X48 Z100, decision D29); G61
    // returns there X first (M52), G60 to the start of the G61 block, X200 Z150.
    let tail: Vec<&str> = l.iter().rev().take(7).rev().map(String::as_str).collect();
    assert_eq!(
        tail,
        [
            "RAPID X200 Z150",
            "RAPID X48 Z150",
            "RAPID X48 Z100",
            "RAPID X200 Z100",
            "RAPID X200 Z150",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_018_g54_shifts_g56_shifts_back_g26_returns() {
    // Offset group 1 as the manual describes it (X −20, Z −50); group 3 undoes it.
    let mut setup = Setup::lathe(HOME);
    setup
        .offsets
        .work
        .insert(0, [('X', -20.0), ('Z', -50.0)].into_iter().collect());
    setup
        .offsets
        .work
        .insert(2, [('X', 20.0), ('Z', 50.0)].into_iter().collect());
    let cmds = run_setup(&fixture("018_g54_g56_offsets.nc"), setup).unwrap();
    let l = lines(&cmds);
    // Under G54 the programmed X5 Z8 and X10 Z10 lie 20 and 50 mm from their unshifted
    // places; after G56 the shift is gone and G26 returns to the start point.
    assert_eq!(l[0], "RAPID X-15 Z-42", "{l:?}");
    assert_eq!(l[1], "LINEAR X-10 Z-40 F200", "{l:?}");
    assert_eq!(last_position(&cmds), HOME);
}

#[test]
fn fixture_019_gang_mode_t5_does_not_index_the_turret() {
    let cmds = run(&fixture("019_g50_g51_turret_modes.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "T1",
            "LINEAR X20 Z100 F100",
            "LINEAR X0 Z100 F100",
            "T2",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_020_g96_ends_at_the_programmed_speed_at_x0() {
    let cmds = run(&fixture("020_g96_constant_surface_speed.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "RAPID X50 Z100",
            "S100",
            "S180",
            "LINEAR X0 Z100 F100",
            "M2",
            "END"
        ]
    );
}

#[test]
fn fixture_021_g41_runs_compensated() {
    // The geometry is checked in tests/nose_comp.rs; here: it runs and ends at the start.
    let mut setup = Setup::lathe(HOME);
    setup.front_tool_post = true;
    let cmds = run_setup(&fixture("021_g41_nose_radius_comp.nc"), setup).unwrap();
    assert_eq!(last_position(&cmds), HOME);
}

#[test]
fn fixture_022_m97_jumps_m98_calls_twice_m20_ends_the_cycle() {
    let cmds = run(&fixture("022_m97_m98_m99_subroutine.nc"), HOME);
    assert_eq!(
        lines(&cmds),
        [
            "M3",
            "DWELL 1",
            "M8",
            "LINEAR X190 Z100 F100",
            "LINEAR X190 Z80 F100",
            "LINEAR X180 Z80 F100",
            "LINEAR X180 Z60 F100",
            "M5",
            "M9",
            "END"
        ]
    );
}

#[test]
fn fixture_023_taper_shaft_diameters_and_return() {
    // Start X50 Z100: U-32 reaches X18, the chamfer X20.
    let cmds = run(
        &fixture("023_part_fig4_8_taper_shaft_incremental.nc"),
        [50.0, 100.0],
    );
    let l = lines(&cmds);
    for d in [
        "LINEAR X20 Z89",
        "LINEAR X23 Z75",
        "LINEAR X25 Z74",
        "LINEAR X32.8 Z45",
        "LINEAR X32.8 Z38",
    ] {
        assert!(l.iter().any(|x| x.starts_with(d)), "{d} missing: {l:?}");
    }
    assert_eq!(last_position(&cmds), [50.0, 100.0]);
}

#[test]
fn fixture_024_grooves_with_tool_changes() {
    let cmds = run(&fixture("024_part_fig4_9_grooves_toolchange.nc"), HOME);
    let l = lines(&cmds);
    let t: Vec<&String> = l.iter().filter(|x| x.starts_with('T')).collect();
    assert_eq!(t, ["T1", "T2", "T1"]);
    for cut in [
        "LINEAR X30 Z78.5 F150",
        "LINEAR X30 Z18.5 F150",
        "LINEAR X25 Z57.5 F30",
        "LINEAR X25 Z36 F30",
        "LINEAR X25 Z33.5 F30",
        "LINEAR X30 Z31 F30",
    ] {
        assert!(l.contains(&cut.to_string()), "{cut} missing: {l:?}");
    }
    assert_eq!(last_position(&cmds), HOME);
}

#[test]
fn fixture_025_profile_arcs_r15_r25_r25_r15_and_thread() {
    let cmds = run(&fixture("025_part_fig4_10_profile_and_thread.nc"), HOME);
    // Arc radii from start to centre, X as radius.
    let mut start = HOME;
    let mut radii = Vec::new();
    for c in &cmds {
        match &c.command {
            Command::Arc { end, center, .. } => {
                let r = (((start[0] - center[0]) / 2.0).powi(2) + (start[1] - center[1]).powi(2))
                    .sqrt();
                radii.push((r * 1000.0).round() / 1000.0);
                start = [end[0], end[1]];
            }
            Command::Rapid { end } | Command::Linear { end, .. } | Command::Thread { end, .. } => {
                start = [end[0], end[1]]
            }
            _ => {}
        }
    }
    assert_eq!(radii, [15.0, 25.0, 25.0, 15.0]);
    let l = lines(&cmds);
    // Profile U sum −14 then U14: X back to the start; W sum −130 then W126: Z 4 short.
    assert!(l.contains(&"RAPID X200 Z-30".to_string()), "{l:?}");
    assert!(l.contains(&"RAPID X200 Z96".to_string()), "{l:?}");
    // Thread passes at X159 and X158.75 (U-41, then U-0.25), lead 1.5 over W-15.
    assert!(
        l.contains(&"THREAD X159 Z81 LEAD1.5 Q0".to_string()),
        "{l:?}"
    );
    assert!(
        l.contains(&"THREAD X158.75 Z81 LEAD1.5 Q0".to_string()),
        "{l:?}"
    );
    assert_eq!(last_position(&cmds), HOME);
}
