//! Issue 23, must-show 2: the 802D instructions the coverage table
//! (`docs/sinumerik_802d.md`) lists as running without a fixture that asserts them, each
//! asserted here on what it emits; and every instruction the table lists as not built,
//! asserted to stop with alarm 12140 and its reason.

use cnc_interpreter::sinumerik::{Sinumerik, NOT_BUILT, NOT_BUILT_G};
use cnc_interpreter::{Aux, Command, Library, Setup};
use cnc_interpreter_core::{next_command, ProgramError};

#[path = "support/sinumerik.rs"]
mod support;

fn mill() -> Setup {
    Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3])
}

fn run(text: &str) -> (Vec<Command>, Option<ProgramError>) {
    let mut front = Sinumerik::new(text, mill(), Library::new());
    let mut out = Vec::new();
    loop {
        match next_command(&mut front) {
            Ok(Some(c)) => out.push(c.command),
            Ok(None) => return (out, None),
            Err(e) => return (out, Some(e)),
        }
    }
}

fn ok(text: &str) -> Vec<Command> {
    let (out, e) = run(text);
    assert!(e.is_none(), "{e:?}\n{text}");
    out
}

fn ends(out: &[Command]) -> Vec<Vec<f64>> {
    out.iter()
        .filter_map(|c| c.end().map(<[f64]>::to_vec))
        .collect()
}

fn near(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6)
}

#[test]
fn g4_dwells_by_seconds_and_keeps_f() {
    let out = ok("G1 X1 F100\nG4 F2.5\nX2\n");
    assert!(out.contains(&Command::Dwell { seconds: 2.5 }), "{out:?}");
    // F2.5 of G4 is no feed: the next move still runs at F100.
    let last_feed = out.iter().rev().find_map(|c| match c {
        Command::Linear { feed, .. } => Some(*feed),
        _ => None,
    });
    assert_eq!(last_feed, Some(100.0), "{out:?}");
}

#[test]
fn g94_g95_switch_the_feed_unit_and_g60_g64_g9_the_path_mode() {
    let out = ok("G95 G1 X1 F0.2\nG94 X2 F300\nG64 X3\nG9 X4\nX5\n");
    assert!(out.contains(&Command::FeedMode { per_rev: true }));
    assert!(out.contains(&Command::FeedMode { per_rev: false }));
    let modes: Vec<bool> = out
        .iter()
        .filter_map(|c| match c {
            Command::PathMode { exact_stop } => Some(*exact_stop),
            _ => None,
        })
        .collect();
    // G60 at power-on, G64, then G9 for its block only (exact stop, then blending again).
    assert_eq!(modes.first(), Some(&true), "{modes:?}");
    assert!(
        modes.windows(3).any(|w| w == [false, true, false]),
        "{modes:?}"
    );
}

#[test]
fn g70_inch_geometry_and_g700_inch_feed() {
    let out = ok("G70 G1 X1 F100\nG700 X2 F10\nG71 X3\n");
    let e = ends(&out);
    assert!(
        near(&e[0], &[25.4, 0.0, 0.0]) && near(&e[1], &[50.8, 0.0, 0.0]),
        "{e:?}"
    );
    assert!(near(&e[2], &[3.0, 0.0, 0.0]));
    let feeds: Vec<f64> = out
        .iter()
        .filter_map(|c| match c {
            Command::Linear { feed, .. } => Some(*feed),
            _ => None,
        })
        .collect();
    // G70: F stays mm/min; G700: F10 in/min is 254 mm/min.
    assert!(
        (feeds[0] - 100.0).abs() < 1e-9 && (feeds[1] - 254.0).abs() < 1e-9,
        "{feeds:?}"
    );
}

#[test]
fn poles_g110_g111_g112_and_polar_moves() {
    let out = ok("G0 X10 Y10\nG111 X20 Y0\nG1 AP=90 RP=5 F100\nG110 AP=0 RP=10\nG1 AP=180 RP=10\n");
    let e = ends(&out);
    assert!(near(&e[1], &[20.0, 5.0, 0.0]), "{e:?}");
    // G110: the pole 10 along X from the last point (20,5): (30,5); AP=180 RP=10 → (20,5).
    assert!(near(&e[2], &[20.0, 5.0, 0.0]), "{e:?}");
}

#[test]
fn ct_continues_tangentially_and_cip_passes_its_point() {
    let out = ok("G1 X0 Y0 F100\nX10\nCT X20 Y10\nG1 X0 Y0\nCIP X20 Y0 I1=10 J1=10\n");
    let arcs: Vec<(Vec<f64>, bool)> = out
        .iter()
        .filter_map(|c| match c {
            Command::Arc {
                center, clockwise, ..
            } => Some((center.clone(), *clockwise)),
            _ => None,
        })
        .collect();
    // Tangent to +X at (10,0) and ending at (20,10): the quarter about (10,10), CCW.
    assert!(
        near(&arcs[0].0, &[10.0, 10.0, 0.0]) && !arcs[0].1,
        "{arcs:?}"
    );
    // Through (10,10) from (0,0) to (20,0): the upper half about (10,0), clockwise.
    assert!(near(&arcs[1].0, &[10.0, 0.0, 0.0]) && arcs[1].1, "{arcs:?}");
}

#[test]
fn spindle_words_go_out_before_the_move_and_m2_ends() {
    let out = ok("S800 M3 G1 X5 F100\nM5\nM2\n");
    let s = out.iter().position(|c| *c == Command::Aux(Aux::S(800.0)));
    let m3 = out.iter().position(|c| *c == Command::Aux(Aux::M(3)));
    let mv = out.iter().position(|c| c.end().is_some());
    assert!(s < mv && m3 < mv && s.is_some() && m3.is_some(), "{out:?}");
    assert_eq!(out.last(), Some(&Command::ProgramEnd));
}

#[test]
fn every_instruction_not_built_stops_with_12140_and_its_reason() {
    for (name, reason) in NOT_BUILT {
        let (_, e) = run(&format!("G0 X1\n{name}\n"));
        let e = e.unwrap_or_else(|| panic!("{name} ran"));
        assert_eq!((e.number, e.line), (12140, 2), "{name}: {e}");
        assert!(e.text.contains(reason), "{name}: {e}");
    }
    for (g, reason) in NOT_BUILT_G {
        let (_, e) = run(&format!("G0 X1\nG{g} X1\n"));
        let e = e.unwrap_or_else(|| panic!("G{g} ran"));
        assert_eq!((e.number, e.line), (12140, 2), "G{g}: {e}");
        assert!(e.text.contains(reason), "G{g}: {e}");
    }
}

#[test]
fn proc_names_the_program_in_its_first_block_only() {
    let out = ok("; header comment\nPROC RAHMEN\nDEF REAL LEN=4\nG0 X=LEN\nM2\n");
    assert_eq!(
        out.iter().filter_map(|c| c.end()).next_back(),
        Some(&[4.0, 0.0, 0.0][..])
    );
    let (_, e) = run("G0 X1\nPROC RAHMEN\n");
    let e = e.expect("PROC after a move");
    assert_eq!((e.number, e.line), (12080, 2), "{e}");
    let (_, e) = run("PROC RAHMEN(REAL LEN)\n");
    let e = e.expect("PROC with parameters");
    assert_eq!((e.number, e.line), (12140, 1), "{e}");
    let (_, e) = run("PROC\n");
    assert_eq!(e.map(|e| e.number), Some(12080));
}

/// `CALL NAME` (§9.1.6) calls, without parameters, the program or cycle whose name the
/// variable holds; a name that is neither is 14011, a variable that does not exist 12550.
#[test]
fn call_runs_the_program_a_variable_names() {
    let mut lib = Library::new();
    lib.insert_named("SEITE", "SEITE.SPF", "G1 X7 F100\nRET\n");
    let text = "DEF STRING[12] NEXT\nNEXT=\"seite\"\nCALL NEXT\nG0 X1\nM2\n";
    let r = support::run_with(text, mill(), lib.clone()).ok();
    assert_eq!(
        ends(&r.out),
        [vec![7.0, 0.0, 0.0], vec![1.0, 0.0, 0.0]],
        "{:?}",
        r.out
    );
    let r = support::run_with(
        "DEF STRING[12] NEXT\nNEXT=\"NOSUCH\"\nCALL NEXT\n",
        mill(),
        lib,
    );
    assert_eq!(r.alarm(), (14011, 3), "{:?}", r.error);
    let (_, e) = run("CALL NOVAR\n");
    assert_eq!(e.map(|e| e.number), Some(12550));
}

#[test]
fn machine_data_stop_with_12140() {
    let (_, e) = run("$MA_FIX_POINT_POS[0]=1\n");
    let e = e.expect("refused");
    assert_eq!((e.number, e.line), (12140, 1), "{e}");
}

/// 063 (§9.8, D107) as printed: H functions go to the PLC with their values, before the
/// block's move, at most three in a block; `H5` is H0=5.0.
#[test]
fn f063_h_functions_carry_their_values_to_the_plc_before_the_move() {
    let text = support::fixture("063");
    let r = support::run_with(&text, support::mill(), Library::new()).ok();
    let h = |address, value| Command::Aux(Aux::H { address, value });
    let shown: Vec<&Command> = r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Aux(Aux::H { .. }) | Command::Rapid { .. }))
        .collect();
    assert_eq!(
        shown,
        [
            &h(1, 1.987),
            &h(2, 978.123),
            &h(3, 4.0),
            &h(99, -8978.234),
            &Command::Rapid {
                end: vec![71.3, 0.0, 0.0]
            },
            &h(0, 5.0),
        ]
    );
    for (bad, number) in [
        ("H1=1 H2=2 H3=3 H4=4\n", 14750),
        ("H10000=1\n", 17020),
        ("R1=1/0 H1=R1\n", 14051),
    ] {
        let (_, e) = run(bad);
        let e = e.unwrap_or_else(|| panic!("{bad} ran"));
        assert_eq!((e.number, e.line), (number, 1), "{bad}: {e}");
    }
}

#[test]
fn g74_takes_the_axes_named_to_their_reference_points_at_rapid() {
    let mut s = mill();
    s.reference = vec![-10.0, 20.0, 150.0];
    let text = "G0 X5 Y6 Z7\nTRANS X100\nN10 G74 X1=0 Z1=0\nG0 X1\n";
    let mut front = Sinumerik::new(text, s, Library::new());
    let mut out = Vec::new();
    while let Some(c) = next_command(&mut front).unwrap() {
        out.push(c.command);
    }
    let ends: Vec<&[f64]> = out.iter().filter_map(|c| c.end()).collect();
    // Machine X and Z at their reference points, Y where it was, whatever the frame.
    assert_eq!(ends[1], [-10.0, 6.0, 150.0]);
    assert!(matches!(
        out.iter().filter(|c| c.end().is_some()).nth(1),
        Some(Command::Rapid { .. })
    ));
    // Programming goes on in the frame: X1 is machine X101.
    assert_eq!(ends[2], [101.0, 6.0, 150.0]);
    let (_, e) = run("G74\n");
    assert_eq!(e.map(|e| e.number), Some(12080));
}

#[test]
fn offn_widens_the_compensated_offset_and_past_the_centre_changes_its_side() {
    // T1 D1 of radius 5; the contour runs up X0 with G41 (the cutter left of it, on −X).
    // OFFN adds to the radius; a negative OFFN beyond the radius puts the path on the other
    // side (§9.15, D96).
    let s = support::with_edge(11, 5.0);
    let program = |offn: &str, extra: &str| {
        format!(
            "T1 D1\nG0 X-20 Y0 Z5\n{offn}\nG1 G41 X0 Y0 F500\n{extra}Y40\nX40\nG40 X60 Y60\nM2\n"
        )
    };
    let start = |text: &str| -> Vec<f64> {
        let mut front = Sinumerik::new(text, s.clone(), Library::new());
        let mut out = Vec::new();
        while let Some(c) = next_command(&mut front).unwrap_or_else(|e| panic!("{e:?}")) {
            out.push(c.command);
        }
        // The start-up move ends perpendicular to the first contour element at Y0.
        ends(&out)[1].clone()
    };
    for (offn, x) in [
        ("", -5.0),
        ("OFFN=2", -7.0),
        ("OFFN=-7", 2.0),
        ("OFFN=-5", 0.0),
    ] {
        let end = start(&program(offn, ""));
        assert!(near(&end, &[x, 0.0, 5.0]), "{offn}: {end:?}");
    }
    // Modal until changed; the same value again under compensation is no change.
    assert!(near(
        &start(&program("OFFN=2", "OFFN=2\n")),
        &[-7.0, 0.0, 5.0]
    ));
    let (_, e) = run("OFFN=1EX6\nM2\n");
    assert_eq!(e.map(|e| e.number), Some(17020));
}

/// §9.6.7 "补偿号的更换" (D105): a new edge (D) or OFFN under compensation changes the
/// radius along the next move in the plane, from the old at its start to the new at its
/// end, and holds after it; carried by an arc it is refused (12140), and one that would put
/// the path past the contour (changing sides) is the compensation-direction alarm 10752.
#[test]
fn a_new_edge_or_offn_under_compensation_changes_the_radius_along_the_next_line() {
    let mut s = support::with_edge(11, 5.0);
    s.offsets.tools.insert(
        12,
        cnc_interpreter_core::ToolOffset {
            radius: 3.0,
            ..Default::default()
        },
    );
    // Up X0 with G41 (the cutter on −X) from Y0 to Y40, then along +X at Y40.
    let program = |change: &str, up: &str| {
        format!("T1 D1\nG0 X-20 Y0 Z5\nG1 G41 X0 Y0 F500\n{change}\n{up}\nX40\nG40 X60 Y60\nM2\n")
    };
    let run_ends = |text: &str| -> Result<Vec<Vec<f64>>, (u32, u32)> {
        let mut front = Sinumerik::new(text, s.clone(), Library::new());
        let mut out = Vec::new();
        loop {
            match next_command(&mut front) {
                Ok(Some(c)) => out.push(c.command),
                Ok(None) => return Ok(ends(&out)),
                Err(e) => return Err((e.number, e.line)),
            }
        }
    };
    for (change, at_start, at_end) in [
        ("D2", -5.0, -3.0),
        ("OFFN=3", -5.0, -8.0),
        ("OFFN=0", -5.0, -5.0),
    ] {
        let ends = run_ends(&program(change, "Y40")).unwrap_or_else(|e| panic!("{change}: {e:?}"));
        // The start-up move ends normal to the first element at the old radius; the line up
        // ends at the new one, and the element along X40 is offset by it.
        assert!(near(&ends[1], &[at_start, 0.0, 5.0]), "{change}: {ends:?}");
        let up = ends.iter().find(|e| (e[1] - 40.0).abs() < 1e-6).unwrap();
        assert!(near(up, &[at_end, 40.0, 5.0]), "{change}: {ends:?}");
        let r = -at_end;
        assert!(
            ends.iter().any(|e| near(e, &[40.0, 40.0 + r, 5.0])),
            "{change}: {ends:?}"
        );
    }
    // Carried by an arc: refused with the reason; past the contour: 10752.
    assert_eq!(
        run_ends(&program("D2", "G2 X0 Y40 I0 J20")).unwrap_err(),
        (12140, 5)
    );
    assert_eq!(
        run_ends(&program("OFFN=-10", "Y40")).unwrap_err(),
        (10752, 4)
    );
}

#[test]
fn a_line_waiting_for_its_second_ang_block_at_the_end_or_return_is_an_alarm() {
    // §9.5.2: `ANG=` alone makes the line wait for the block with the end point; a program
    // ending or returning first would lose it.
    for (text, line) in [
        ("F100\nG1 X10 Y10\nN20 ANG=30\nM2\n", 4),
        ("F100\nG1 X10 Y10\nN20 ANG=30\nM30\n", 4),
        ("F100\nG1 X10 Y10\nN20 ANG=30\nRET\n", 4),
    ] {
        let (out, e) = run(text);
        let e = e.unwrap_or_else(|| panic!("{text} ran: {out:?}"));
        assert_eq!((e.number, e.line), (12080, line), "{text}: {e:?}");
        assert!(e.text.contains("ANG"), "{}", e.text);
    }
    // Completed before the end, it runs.
    ok("F100\nG1 X10 Y10\nN20 ANG=30\nN30 X60 Y20 ANG=-45\nM2\n");
}

#[test]
fn m30_counts_the_part_in_the_total_and_actual_counters() {
    use cnc_interpreter_core::FrontEnd;
    // §9.12.2, D82: $AC_TOTAL_PARTS, $AC_REQUIRED_PARTS, $AC_ACTUAL_PARTS are kept entries
    // 11000–11002 of the machine's memory. A subprogram's M2 returns and counts nothing.
    let counters = |total: f64, required: f64, actual: f64, text: &str| -> [f64; 3] {
        let mut s = mill();
        s.kept
            .extend([(11_000, total), (11_001, required), (11_002, actual)]);
        let mut lib = Library::new();
        lib.insert_named("SUB1", "SUB1.SPF", "G0 X2\nM2\n");
        let mut front = Sinumerik::new(text, s, lib);
        while next_command(&mut front)
            .unwrap_or_else(|e| panic!("{e:?}"))
            .is_some()
        {}
        let get = |k| front.core().common.get(&k).copied().unwrap_or(0.0);
        [get(11_000), get(11_001), get(11_002)]
    };
    assert_eq!(
        counters(7.0, 0.0, 2.0, "G0 X1\nSUB1\nM30\n"),
        [8.0, 0.0, 3.0]
    );
    assert_eq!(counters(7.0, 5.0, 3.0, "G0 X1\nM2\n"), [8.0, 5.0, 4.0]);
    // Reaching the required count starts the actual count again.
    assert_eq!(counters(7.0, 5.0, 4.0, "G0 X1\nM2\n"), [8.0, 5.0, 0.0]);
    assert_eq!(counters(999_999_999.0, 0.0, 0.0, "M30\n"), [0.0, 0.0, 1.0]);
}

/// 031 (§9.3.10) on `launch_configs/sim_mill_802d.yaml`: G75 FP=1 takes Z to fixed point 1,
/// FP=2 X and Y to fixed point 2 (the tool change position), at rapid in machine
/// coordinates whatever the offsets; FP defaults to 1; a point the machine data lacks, an FP
/// outside 1…4 and FP without G75 stop the block (D102).
#[test]
fn f031_g75_approaches_the_fixed_points_of_the_machine_data() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../launch_configs/sim_mill_802d.yaml"
    );
    let file: serde_yaml::Value =
        serde_yaml::from_str(&std::fs::read_to_string(path).unwrap()).expect("sim_mill_802d");
    let machine: cnc_machine::MachineConfig =
        serde_yaml::from_value(file["machine"].clone()).expect("its machine section");
    let mut setup = cnc_interpreter::setup::of_machine(&machine, &machine.home());
    // A work offset and a frame, which G75 ignores.
    setup
        .offsets
        .work
        .insert(0, [('X', 100.0), ('Z', -50.0)].into_iter().collect());
    let fixture = std::fs::read_dir(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/fixtures/001"
    ))
    .unwrap()
    .map(|e| e.unwrap().path())
    .find(|p| p.file_name().unwrap().to_string_lossy().starts_with("031"))
    .unwrap();
    let text = format!(
        "G54 TRANS Y7\nG0 X1 Y2 Z3\n{}",
        std::fs::read_to_string(fixture).unwrap()
    );
    let mut front = Sinumerik::new(&text, setup.clone(), Library::new());
    let mut out = Vec::new();
    while let Some(c) = next_command(&mut front).unwrap() {
        out.push(c.command);
    }
    let rapids: Vec<&[f64]> = out
        .iter()
        .filter_map(|c| match c {
            Command::Rapid { end } => Some(end.as_slice()),
            _ => None,
        })
        .collect();
    let fp = machine.fixed_points();
    // X1 Y2 Z3 in G54 + TRANS: machine X101 Y9 Z−47; then Z to FP 1, then X and Y to FP 2.
    assert_eq!(rapids[0], [101.0, 9.0, -47.0]);
    assert_eq!(rapids[1], [101.0, 9.0, fp[2][0]]);
    assert_eq!(rapids[2], [fp[0][1], fp[1][1], fp[2][0]]);
    assert_eq!(rapids[2], [450.0, 350.0, 350.0]);
    // FP omitted: fixed point 1.
    let mut f = Sinumerik::new("G0 X20\nG75 X1=0\n", setup.clone(), Library::new());
    let mut ends = Vec::new();
    while let Some(c) = next_command(&mut f).unwrap() {
        ends.extend(c.command.end().map(<[f64]>::to_vec));
    }
    assert_eq!(ends, [vec![20.0, 0.0, 150.0], vec![0.0, 0.0, 150.0]]);
    for (bad, number) in [
        ("G75 FP=3 Z1=0\n", 17020),
        ("G75 FP=5 Z1=0\n", 17020),
        ("G75 FP=1.5 Z1=0\n", 17020),
        ("G75 FP=1\n", 12080),
        ("G1 X10 F100 FP=1\n", 12080),
    ] {
        let mut f = Sinumerik::new(bad, setup.clone(), Library::new());
        let e = loop {
            match next_command(&mut f) {
                Ok(Some(_)) => {}
                Ok(None) => panic!("{bad} ran"),
                Err(e) => break e,
            }
        };
        assert_eq!((e.number, e.line), (number, 1), "{bad}: {e:?}");
    }
}

/// G450/G451 (§9.6.5, D103): outside a contour run clockwise with G41 (cutter radius 5), G450
/// rounds each outer corner with an arc of the cutter's radius around it; G451 extends the
/// offset lines to where they cross (5 mm out on each side of a right angle) and keeps the
/// arc only where the contour turns by 100° or more (the 135° turn at X40 Y0 here).
#[test]
fn g451_meets_outer_corners_at_the_intersection_up_to_a_turn_of_100_degrees() {
    let program = |corner: &str| {
        format!(
            "T1 D1\nG0 G17 X-20 Y-10 Z0\nG1 F300\n{corner} G41 X0 Y0\nY30\nX40\nY0\nX20 Y20\nG40 X20 Y50\nM2\n"
        )
    };
    let run_corner = |corner: &str| {
        let mut f = Sinumerik::new(
            &program(corner),
            support::with_edge(11, 5.0),
            Library::new(),
        );
        let mut out = Vec::new();
        while let Some(c) = next_command(&mut f).unwrap() {
            out.push(c.command);
        }
        out
    };
    let arcs = |out: &[Command]| -> Vec<Vec<f64>> {
        out.iter()
            .filter_map(|c| match c {
                Command::Arc { center, .. } => Some(center[..2].to_vec()),
                _ => None,
            })
            .collect()
    };
    // G450: arcs around the three outer corners X0 Y30, X40 Y30, X40 Y0.
    let g450 = run_corner("G450");
    assert_eq!(
        arcs(&g450),
        [vec![0.0, 30.0], vec![40.0, 30.0], vec![40.0, 0.0]]
    );
    // G451: the right-angled corners at the crossings, the 135° one still an arc.
    let g451 = run_corner("G451");
    assert_eq!(arcs(&g451), [vec![40.0, 0.0]]);
    let corners: Vec<Vec<f64>> = ends(&g451).into_iter().map(|e| e[..2].to_vec()).collect();
    for want in [[-5.0, 35.0], [45.0, 35.0]] {
        assert!(
            corners.iter().any(|c| near(c, &want)),
            "{want:?} in {corners:?}"
        );
    }
    // The turn from Y down to X20 Y20 (135°) keeps the arc: nothing after the start point is
    // placed out at the far crossing of the two offsets.
    let far = corners[1..].iter().any(|c| c[0] > 46.0 || c[1] < -6.0);
    assert!(!far, "{corners:?}");
    // The manual's contour (fixture 061: lines and arcs) under G451: the same end, the line
    // to arc corners met at the crossings too, so fewer corner arcs than under G450.
    let text = support::fixture("061");
    let count_arcs = |text: &str| {
        let r = support::run_with(text, support::mill(), Library::new()).ok();
        (
            r.out
                .iter()
                .filter(|c| matches!(c, Command::Arc { .. }))
                .count(),
            r.end(),
        )
    };
    let (with_circles, end) = count_arcs(&text);
    let (with_crossings, end_451) = count_arcs(&text.replace("G450", "G451"));
    assert_eq!(end, end_451);
    assert!(
        with_crossings < with_circles,
        "{with_crossings} vs {with_circles}"
    );
}

/// §9.6.7 (D104): G42 after G41 (or G41 again) without G40: the last element of the old
/// compensation ends normal to its end point, a line goes to the next element's offset
/// start on the new side, normal to it, and compensation goes on there.
#[test]
fn g41_to_g42_or_g41_again_ends_normal_and_starts_normal_without_g40() {
    let program = |again: &str| {
        format!(
            "T1 D1\nG0 X-20 Y-10 Z0\nG1 F300 G41 X0 Y0\nY30\n{again} X40\nY0\nG40 X60 Y-10\nM2\n"
        )
    };
    let corners = |again: &str| {
        let mut f = Sinumerik::new(&program(again), support::with_edge(11, 5.0), Library::new());
        let mut out = Vec::new();
        while let Some(c) = next_command(&mut f).unwrap() {
            out.push(c.command);
        }
        assert!(
            !out.iter().any(|c| matches!(c, Command::Arc { .. })) || again == "G41",
            "{out:?}"
        );
        ends(&out)
            .into_iter()
            .map(|e| [e[0], e[1]])
            .collect::<Vec<_>>()
    };
    // Up X0 on the left (X−5) to Y30, normal there; then on the right of the way to X40
    // (Y25), from its start normal to it (X0 Y25); the corner at X40 Y30 is inside on the
    // right (X35 Y25); G40 from the last element's end.
    let switched = corners("G42");
    let want = [
        [-5.0, 30.0],
        [0.0, 25.0],
        [35.0, 25.0],
        [35.0, 0.0],
        [60.0, -10.0],
    ];
    for w in want {
        assert!(
            switched.iter().any(|c| near(c, &w)),
            "{w:?} in {switched:?}"
        );
    }
    let at = |p: [f64; 2]| switched.iter().position(|c| near(c, &p)).unwrap();
    assert!(at([-5.0, 30.0]) + 1 == at([0.0, 25.0]), "{switched:?}");
    // G41 again: normal at X−5 Y30, then to X0 Y35, the left of the way to X40.
    let again = corners("G41");
    let at = |p: [f64; 2]| again.iter().position(|c| near(c, &p));
    let (end, start) = (at([-5.0, 30.0]), at([0.0, 35.0]));
    assert!(end.is_some() && start == end.map(|e| e + 1), "{again:?}");
}

/// 039 (§9.3.18, D108): ACC[X]=80 gives motion X's acceleration at 80 % before the next move,
/// ACC[S]=50 the spindle's at 50 % (its axis number `SPINDLE_AXIS`), ACC[X]=100 back to the
/// rated; out of 1…200 % 17020; an axis or spindle the machine lacks 14092.
#[test]
fn f039_acc_overrides_the_acceleration_of_an_axis_and_of_the_spindle() {
    let text = support::filled("039", &["N30 G1 X100 F1000"]);
    let r = support::run_with(&text, support::mill(), Library::new()).ok();
    let acc: Vec<&Command> = r
        .out
        .iter()
        .filter(|c| matches!(c, Command::Acceleration { .. } | Command::Linear { .. }))
        .collect();
    assert_eq!(
        acc,
        [
            &Command::Acceleration {
                axis: 0,
                percent: 80.0
            },
            &Command::Acceleration {
                axis: cnc_msgs::canon::SPINDLE_AXIS,
                percent: 50.0
            },
            &Command::Linear {
                end: vec![100.0, 0.0, 0.0],
                feed: 1000.0
            },
            &Command::Acceleration {
                axis: 0,
                percent: 100.0
            },
        ]
    );
    for (bad, number) in [
        ("ACC[S]=0.5\n", 17020),
        ("ACC[S2]=50\n", 14092),
        ("ACC[X]=0\n", 17020),
        ("ACC[Z]=201\n", 17020),
        ("ACC[A]=50\n", 14092),
    ] {
        let (_, e) = run(bad);
        let e = e.unwrap_or_else(|| panic!("{bad} ran"));
        assert_eq!((e.number, e.line), (number, 1), "{bad}: {e}");
    }
}

/// DC, ACP and ACN on a rotary axis (§9.2.1, D109): the angle modulo 360° reached the
/// shortest way, turning positive or negative, from wherever the axis stands (turns
/// included); on a linear axis they are refused.
#[test]
fn dc_acp_acn_position_a_rotary_axis_by_its_way() {
    let setup = cnc_interpreter::Setup::new(&['X', 'Y', 'Z', 'A'], &[false; 4], &[0.0; 4]);
    let text = "G0 A370\nA=DC(45)\nA=ACP(10)\nA=ACN(350)\nA=DC(340)\nA=ACP(340)\nG91 A=ACN(340)\n";
    let r = support::run_with(text, setup, Library::new()).ok();
    let a: Vec<f64> = r.moves().iter().map(|c| c.end().unwrap()[3]).collect();
    // 370 (10°) → 45 the short way up: 405; → ACP 10: 730; → ACN 350: 710; → DC 340 (from
    // 350): 700; → ACP 340 (already there): 700; → ACN 340 (there): 700, G91 or not.
    assert_eq!(a, [370.0, 405.0, 730.0, 710.0, 700.0, 700.0, 700.0]);
    let (_, e) = run("X=DC(10)\n");
    assert_eq!(e.map(|e| e.number), Some(12080));
}

/// 077–079 (§9.11.4, D110): MAIN calls BOHRUNG (079, its placeholders filled) on the CF card
/// (D:) and, in 078, on the USB device (G:, the name printed with a trailing space); the
/// external program runs where the call stands and MAIN goes on after its M17.
#[test]
fn f077_to_f079_extcall_runs_bohrung_from_the_external_drive() {
    let bohrung = support::filled("079", &["N030 X=10 Z=-5", "N040 X20", "", ""]);
    for (main, drive) in [("077", 'D'), ("078", 'G')] {
        let text = support::filled(main, &["N020 G0 X0 Y0 Z5", "N040 G0 Z50"]);
        let mut lib = Library::new();
        let name = format!("{drive}:\\EXTERNE_UP\\BOHRUNG");
        lib.insert_named(&name, &name, &bohrung);
        let r = support::run_with(&text, support::mill(), lib).ok();
        assert_eq!(
            r.ends(),
            [
                vec![0.0, 0.0, 5.0],
                vec![10.0, 0.0, -5.0],
                vec![20.0, 0.0, -5.0],
                vec![20.0, 0.0, 50.0]
            ],
            "{main}"
        );
    }
    // Not on a drive, or no drive named: 14011 with the reason.
    for bad in ["EXTCALL(\"D:\\NONE\")\n", "EXTCALL(\"BOHRUNG\")\n"] {
        let (_, e) = run(bad);
        let e = e.unwrap_or_else(|| panic!("{bad} ran"));
        assert_eq!((e.number, e.line), (14011, 1), "{bad}: {e}");
    }
}

/// G54–G59 are the 1st–6th settable offsets and G507–G554 the 7th–54th (§9.2.10), each
/// shifting by its own values from the offset page; G500 takes none; G53 suppresses the active
/// one for its block only (non-modal), and the next block is in the offset again.
#[test]
fn settable_offsets_shift_by_their_own_values_and_g53_suppresses_them_for_one_block() {
    let mut s = mill();
    // Offset k (0 = G54) shifts X by 10·(k+1), Y by −(k+1), Z by 100·(k+1).
    for k in 0..54u8 {
        let f = f64::from(k + 1);
        s.offsets.work.insert(
            k,
            [('X', 10.0 * f), ('Y', -f), ('Z', 100.0 * f)]
                .into_iter()
                .collect(),
        );
    }
    let codes: Vec<u32> = (54..=59).chain(507..=554).collect();
    let mut text = String::new();
    for g in &codes {
        text.push_str(&format!("G{g} G0 X1 Y2 Z3\n"));
    }
    text.push_str("G53 X1 Y2 Z3\nX1 Y2 Z3\nG500 X1 Y2 Z3\nM30\n");
    let mut front = Sinumerik::new(&text, s, Library::new());
    let mut e = Vec::new();
    while let Some(c) = next_command(&mut front).unwrap() {
        e.extend(c.command.end().map(<[f64]>::to_vec));
    }
    assert_eq!(e.len(), codes.len() + 3, "{e:?}");
    for (k, g) in codes.iter().enumerate() {
        let f = (k + 1) as f64;
        assert_eq!(e[k], [1.0 + 10.0 * f, 2.0 - f, 3.0 + 100.0 * f], "G{g}");
    }
    // G53: machine coordinates for its block; the next block in G554 again; G500: none.
    let f = codes.len() as f64;
    let n = codes.len();
    assert_eq!(e[n], [1.0, 2.0, 3.0], "G53");
    assert_eq!(
        e[n + 1],
        [1.0 + 10.0 * f, 2.0 - f, 3.0 + 100.0 * f],
        "after G53"
    );
    assert_eq!(e[n + 2], [1.0, 2.0, 3.0], "G500");
}
