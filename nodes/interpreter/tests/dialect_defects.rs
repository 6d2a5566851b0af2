//! The defects programs written independently of this project found (issue 21), one test
//! each, asserted on the canonical stream: locals in subprograms (D51), full circles and
//! helices under compensation, inch input (D53), G71 type I monotonicity (D54), non-ASCII
//! text inside a block (D55) and numbers without a decimal point (D52).

use cnc_interpreter::{trace, Canon, Dialect, ProgramError, Setup};

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

fn run(dialect: Dialect, text: &str, setup: Setup) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(dialect, text, setup)
}

/// The stream as trace lines without the source line.
fn lines_of(dialect: Dialect, text: &str, setup: Setup) -> Vec<String> {
    let letters = setup.axes.clone();
    run(dialect, text, setup)
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
        .iter()
        .map(|c| {
            let l = trace::line(&letters, c);
            l.split_once(' ').map_or(l.clone(), |(_, b)| b.to_string())
        })
        .collect()
}

fn mill_lines(text: &str) -> Vec<String> {
    lines_of(Dialect::FanucMill, text, mill())
}

fn moves(lines: &[String]) -> Vec<String> {
    lines
        .iter()
        .filter(|l| l.starts_with("RAPID") || l.starts_with("LINEAR") || l.starts_with("ARC"))
        .cloned()
        .collect()
}

// ------------------------------------------------------------------ D51: locals

#[test]
fn a_mill_subprogram_works_with_its_callers_locals_and_a_macro_call_opens_its_own() {
    // M98: the subprogram reads the caller's #7 and #24 and leaves #1 for it.
    let text = "O1000\n#7=2.\n#24=30.\nG00 X0 Y0\nM98 P2000\nG00 X#1\nM30\n\
                O2000\nG00 X#24 Y#7\n#1=12.\nM99\n";
    assert_eq!(
        moves(&mill_lines(text)),
        [
            "RAPID X0.0000 Y0.0000 Z0.0000",
            "RAPID X30.0000 Y2.0000 Z0.0000",
            "RAPID X12.0000 Y2.0000 Z0.0000"
        ]
    );
    // G65: the macro has only its arguments (A is #1); what it writes stays its own.
    let text = "O1000\n#7=2.\n#24=30.\nG00 X0 Y0\nG65 P2000 A5.\nG00 X[#1+1.]\nM30\n\
                O2000\nG00 X[#24+#1] Y[#7+1.]\n#1=12.\nM99\n";
    assert_eq!(
        moves(&mill_lines(text)),
        [
            "RAPID X0.0000 Y0.0000 Z0.0000",
            "RAPID X5.0000 Y1.0000 Z0.0000",
            "RAPID X1.0000 Y1.0000 Z0.0000"
        ]
    );
}

#[test]
fn a_subprograms_d_word_from_the_callers_local_compensates() {
    // The defect as seen: `D#7` in an M98 subprogram became no D, and the contour was cut
    // uncompensated without an alarm.
    let text = "O1000\n#7=1.\nG00 X-20. Y0\nM98 P2000\nM30\n\
                O2000\nG41 D#7 G01 X0 Y0 F500.\nY20.\nG40 X-20.\nM99\n";
    let l = moves(&mill_lines(text));
    // Offset 1 has radius 5: the wall is cut at X-5 (left of travel in +Y).
    assert!(
        l.iter().any(|m| m.starts_with("LINEAR X-5.0000 Y20.0000")),
        "{l:?}"
    );
}

#[test]
fn a_huaxing_subprogram_has_its_own_locals_as_the_manual_says() {
    // `000` §5.27.2: locals store data within one program; a subprogram's are its own.
    let text = "O1000\n#1=5\nG00 X100 Z50\nM98 P2000\nM30\nO2000\nG00 X[#1+10]\nM99\n";
    let l = lines_of(Dialect::HuaxingLathe, text, Setup::lathe([200.0, 100.0]));
    assert!(l.contains(&"RAPID X10.0000 Z50.0000".to_string()), "{l:?}");
}

// ------------------------------------------------------------------ closed elements under comp

/// The numbers after each letter of a trace line: `ARC_CCW X1 Y2 … CX3` → [('X',1), …].
fn fields(line: &str) -> Vec<(String, f64)> {
    line.split_whitespace()
        .skip(1)
        .filter_map(|w| {
            let at = w.find(|c: char| c == '-' || c.is_ascii_digit())?;
            Some((w[..at].to_string(), w[at..].parse().ok()?))
        })
        .collect()
}

fn field(line: &str, name: &str) -> f64 {
    fields(line)
        .into_iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v)
        .unwrap_or_else(|| panic!("{name} missing in {line}"))
}

#[test]
fn a_full_circle_and_a_helix_under_cutter_compensation_are_cut_in_every_plane() {
    // (plane code, horizontal, vertical, normal axis, centre-offset letter of the horizontal)
    for (code, h, v, n, i) in [
        ("G17", "X", "Y", "Z", "I"),
        ("G18", "Z", "X", "Y", "K"),
        ("G19", "Y", "Z", "X", "J"),
    ] {
        // A bore of radius 30 finished inside with a radius-5 cutter (offset 1), then the
        // same as a helix going down 2 mm.
        let text = format!(
            "{code}\nG00 {h}0 {v}0 {n}5.\nG41 D1 G01 {h}30. {v}0 F500.\nG03 {h}30. {v}0 {i}-30.\n\
             G40 G01 {h}0 {v}0\nG41 D1 G01 {h}30. {v}0 {n}-1.\nG03 {h}30. {v}0 {n}-3. {i}-30.\n\
             G40 G01 {h}0 {v}0\nM30\n"
        );
        let l = moves(&mill_lines(&text));
        let arcs: Vec<&String> = l.iter().filter(|m| m.starts_with("ARC")).collect();
        assert_eq!(arcs.len(), 2, "{code}: {l:?}");
        for (arc, depth) in arcs.iter().zip([5.0, -3.0]) {
            // The entry ends on the offset circle (radius 25), and the circle runs round to
            // the offset of its own end point, as FANUC and LinuxCNC cut it (oracle 50–54).
            let k = l.iter().position(|m| m == *arc).unwrap();
            let before = &l[k - 1];
            let r0 = field(before, h).hypot(field(before, v));
            let r = field(arc, h).hypot(field(arc, v));
            assert!(
                (r0 - 25.0).abs() < 1e-4,
                "{code}: entry ends at radius {r0}: {before}"
            );
            assert!((r - 25.0).abs() < 1e-4, "{code}: radius {r} in {arc}");
            assert!((field(arc, h) - 25.0).abs() < 1e-4, "{code}: {arc}");
            assert!((field(arc, n) - depth).abs() < 1e-4, "{code}: {arc}");
        }
    }
}

#[test]
fn reference_point_codes_are_refused_under_cutter_compensation_like_g28() {
    // Found on the way: G30 under G41 ran its second move past the held element, out of
    // program order (a mutant of oracle program 36). G27, G29 and G30 now join G28 (D48).
    for code in ["G27 X0 Y0", "G28 Z30.", "G29 X0", "G30 Z30."] {
        let text = format!("G00 X0 Y0 Z30.\nG41 D1 G01 X10. F500.\nY10.\n{code}\nM30\n");
        let e = run(Dialect::FanucMill, &text, mill()).unwrap_err();
        assert_eq!((e.number, e.line), (10, 4), "{code}: {e}");
        assert!(e.text.contains("G40 first"), "{e}");
    }
}

// ------------------------------------------------------------------ D55: non-ASCII text

#[test]
fn a_non_ascii_character_inside_a_block_is_an_alarm_and_chinese_text_behind_it_a_comment() {
    let lathe = || Setup::lathe([200.0, 100.0]);
    for (text, what) in [
        ("G00 X100 Z50\nG00 X6é0 Z-3\nM30\n", "é inside a word"),
        (
            "G00 X100 Z50\nG01 X20\u{a0}Z-30 F100\nM30\n",
            "no-break space",
        ),
        ("G00 X100 Z50\nＧＧ00 X10\nM30\n", "full-width letters"),
        (
            "G00 X100 Z50\nG01 X20 Z-30é F100\nM30\n",
            "accent after a word",
        ),
        (
            "G00 X100 Z50\nG01 X20 é Z-30\nM30\n",
            "a letter that is no Chinese text",
        ),
    ] {
        for dialect in [Dialect::HuaxingLathe, Dialect::Gtc2eLathe] {
            let e = run(dialect, text, lathe()).unwrap_err();
            assert_eq!(e.line, 2, "{what}: {e}");
            assert!(e.text.contains("inside the block"), "{what}: {e}");
        }
    }
    let e = run(
        Dialect::FanucMill,
        "G00 X1. Y2.\nG01 X3.é Y4. F100\nM30\n",
        mill(),
    )
    .unwrap_err();
    assert_eq!((e.number, e.line), (9, 2), "{e}");
    // As the manuals print it: Chinese text after a space behind the block.
    let l = lines_of(
        Dialect::HuaxingLathe,
        "G00 X100 Z50\nN0020 G01 X80 Z40 F100      每 5mm 停 1 秒\nM30\n",
        lathe(),
    );
    assert!(
        l.contains(&"LINEAR X80.0000 Z40.0000 F100.0000".to_string()),
        "{l:?}"
    );
}

// ------------------------------------------------------------------ D54: G71 type I

/// A G71 over a contour whose X goes back from `back_x` after X60 (a pocket when below 60).
fn g71(ns_z: &str, back_x: &str) -> String {
    format!(
        "G00 X100 Z5\nG71 U1 R0.5\nG71 P10 Q20 U0.4 W0.1 F100\nN10 G01 X40{ns_z}\nZ-10\n\
         X60 Z-20\nX{back_x} Z-30\nX70 Z-40\nN20 X80\nM30\n"
    )
}

#[test]
fn a_g71_type_one_contour_with_a_pocket_is_refused_within_the_contour_tolerance() {
    let lathe = |tol: f64| {
        let mut s = Setup::lathe([200.0, 100.0]);
        s.contour_tolerance = tol;
        s
    };
    // A pocket of 5 mm (radius): alarm 47 on the cycle's line, with the way out named.
    let e = run(Dialect::HuaxingLathe, &g71("", "50"), lathe(0.05)).unwrap_err();
    assert_eq!((e.number, e.line), (47, 3), "{e}");
    assert!(e.text.contains("type II"), "{e}");
    // The same contour as type II (Z in the ns block) is roughed.
    assert!(run(Dialect::HuaxingLathe, &g71(" W0", "50"), lathe(0.05)).is_ok());
    // 0.03 mm back (X59.94 as a diameter) is within GS#33 = 0.05, not within 0.01.
    assert!(run(Dialect::HuaxingLathe, &g71("", "59.94"), lathe(0.05)).is_ok());
    let e = run(Dialect::HuaxingLathe, &g71("", "59.94"), lathe(0.01)).unwrap_err();
    assert_eq!(e.number, 47, "{e}");
}

// ------------------------------------------------------------------ D52: decimal points

#[test]
fn mill_numbers_without_a_decimal_point_count_thousandths_unless_the_machine_says_calculator() {
    let text = "G00 X50 Y20. Z0\nG01 X50. F100\nG04 X1500\nG02 X50. Y0 R10. \
                \nG91 G00 X10\nM30\n";
    let l = mill_lines(text);
    assert_eq!(l[0], "RAPID X0.0500 Y20.0000 Z0.0000", "{l:?}");
    assert_eq!(l[1], "LINEAR X50.0000 Y20.0000 Z0.0000 F100.0000", "{l:?}");
    // G04 X counts milliseconds; F is a feed as written.
    assert_eq!(l[2], "DWELL 1.500", "{l:?}");
    assert_eq!(l[4], "RAPID X50.0100 Y0.0000 Z0.0000", "{l:?}");
    // The machine parameter (FANUC's DPI): calculator type reads X50 as 50 mm.
    let mut calc = mill();
    calc.calculator_decimal_point = Some(true);
    let l = lines_of(Dialect::FanucMill, "G00 X50 Y20 Z0\nM30\n", calc);
    assert_eq!(l[0], "RAPID X50.0000 Y20.0000 Z0.0000");
    // In a canned cycle K counts repeats; in a G18 arc it is a length.
    let l = moves(&mill_lines(
        "G00 X0 Y0 Z10.\nG91 G99 G81 X10. Z-5. R-8. K3 F100\nG80 G90\nM30\n",
    ));
    assert_eq!(
        l.iter().filter(|m| m.starts_with("LINEAR")).count(),
        3,
        "{l:?}"
    );
    // G65 arguments of lengths count thousandths too; a decimal point means mm.
    let l = moves(&mill_lines(
        "O1\nG65 P2 X30 Y30.\nM30\nO2\nG00 X#24 Y#25\nM99\n",
    ));
    assert_eq!(l[0], "RAPID X0.0300 Y30.0000 Z0.0000", "{l:?}");
}

// ------------------------------------------------------------------ D53: inch input

/// The canonical stream's numbers, for comparing two programs that should move alike.
fn numbers(lines: &[String]) -> Vec<(String, Vec<(String, f64)>)> {
    lines
        .iter()
        .map(|l| {
            let kind = l.split_whitespace().next().unwrap_or("").to_string();
            (kind, fields(l))
        })
        .collect()
}

#[test]
fn an_inch_program_moves_the_machine_as_its_metric_twin_within_a_micrometre() {
    // The same part twice: millimetres, and inches (every length divided by 25.4). Lines,
    // arcs by R and by I/J, a full circle under cutter compensation (radius in mm from the
    // offset page), a canned cycle with R and Q, a work offset written by G10 and a local
    // system by G52, feeds in units per minute, and positions read back by #5001.
    let metric = "G21 G90 G17 G54\nG10 L2 P1 X25.4 Y-12.7 Z0\nG52 X5.08\nG00 X0 Y0 Z10.\n\
                  G01 Z-1. F254.\nG41 D1 X50.8 Y0\nG03 X50.8 Y0 I-50.8 J0\nG40 G01 X0 Y0\n\
                  G02 X25.4 Y25.4 R25.4 F508.\nG00 Z10.\nG99 G83 X12.7 Y12.7 Z-6.35 R2.54 Q1.27 F127.\n\
                  G80\n#1 = #5001 * 2\nG00 X#1\nM30\n";
    let inch = "G20 G90 G17 G54\nG10 L2 P1 X1. Y-.5 Z0\nG52 X.2\nG00 X0 Y0 Z.3937008\n\
                G01 Z-.0393701 F10.\nG41 D1 X2. Y0\nG03 X2. Y0 I-2. J0\nG40 G01 X0 Y0\n\
                G02 X1. Y1. R1. F20.\nG00 Z.3937008\nG99 G83 X.5 Y.5 Z-.25 R.1 Q.05 F5.\n\
                G80\n#1 = #5001 * 2\nG00 X#1\nM30\n";
    let (m, i) = (numbers(&mill_lines(metric)), numbers(&mill_lines(inch)));
    assert_eq!(m.len(), i.len(), "{m:?}\n{i:?}");
    for ((km, fm), (ki, fi)) in m.iter().zip(&i) {
        assert_eq!(km, ki);
        assert_eq!(fm.len(), fi.len(), "{km}");
        for ((n, a), (_, b)) in fm.iter().zip(fi) {
            assert!((a - b).abs() < 1e-3, "{km} {n}: metric {a}, inch {b}");
        }
    }
    // The last move: #5001 read in inches under G20, so the inch program goes to the same
    // machine point.
    assert!(m.len() > 20, "{m:?}");
}

#[test]
fn the_lathe_manuals_have_no_inch_input_so_g20_is_their_undefined_code_alarm() {
    // D53: Huaxing's G21 is a conditional jump, GTC2E knows inches only as threads per inch.
    for (dialect, number) in [(Dialect::HuaxingLathe, 7), (Dialect::Gtc2eLathe, 15)] {
        let e = run(
            dialect,
            "G00 X50 Z5\nG20\nG00 X10\nM30\n",
            Setup::lathe([200.0, 100.0]),
        )
        .unwrap_err();
        assert_eq!((e.number, e.line), (number, 2), "{dialect:?}: {e}");
    }
}

#[test]
fn variables_read_and_write_offsets_and_positions_in_the_programs_unit() {
    // Offset 1 is 100 mm long; under G20 #2001 reads 3.937 inches and #5221 writes inches.
    let l = mill_lines("G20\n#1 = #2001\n#5221 = 1.\nG00 X#1 Y0 Z0\nM30\n");
    let x = field(&l[0], "X");
    // X#1 is 3.937 inches in G54, whose X zero is now 1 inch: 25.4 + 100 mm.
    assert!((x - 125.4).abs() < 1e-6, "{l:?}");
}

#[test]
fn a_stop_code_in_a_block_with_motion_acts_after_it() {
    // D56 (D6): the return, then the spindle stop.
    let l = mill_lines("G00 X0 Y0 Z0\nS1000 M3\nG30 Z30. M5\nM30\n");
    let at = |s: &str| l.iter().position(|x| x == s).unwrap_or(usize::MAX);
    assert!(at("M5") > at("RAPID X0.0000 Y0.0000 Z30.0000"), "{l:?}");
}

#[test]
fn a_full_circle_under_tool_nose_compensation_is_cut_on_the_lathe() {
    // Huaxing G42 (nose radius 0.4, tip 3 on offset 1): a full circle in Z-X by I/K after a
    // G01 start-up; before the fix it was dropped without a word.
    let mut setup = Setup::lathe([200.0, 100.0]);
    setup.offsets.tools.insert(
        1,
        cnc_interpreter::setup::ToolOffset {
            radius: 0.4,
            tip: 3,
            ..Default::default()
        },
    );
    let text =
        "T0101\nG00 X100 Z20\nG42 G01 X80 Z10 F100\nG02 X80 Z10 I-10 K0\nG40 G01 X100 Z20\nM30\n";
    let l = moves(&lines_of(Dialect::HuaxingLathe, text, setup));
    assert!(l.iter().any(|m| m.starts_with("ARC")), "{l:?}");
}
