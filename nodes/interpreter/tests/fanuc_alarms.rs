//! The FANUC 0-M P/S alarms for program errors (`003` inventory Appendix A.4), each raised
//! by a program with the number and the line the alarm names. Decision D49 records which
//! check raises which number where the appendix names only the family.

use cnc_interpreter::{check_with_library, Dialect, Library, ProgramError, Setup};

fn mill(axes: &[char]) -> Setup {
    let mut setup = Setup::new(axes, &vec![false; axes.len()], &vec![0.0; axes.len()]);
    for (n, length, radius) in [(1, 100.0, 5.0), (2, 42.5, 3.0), (9, 10.0, 5000.0)] {
        let t = setup.offsets.tools.entry(n).or_default();
        t.z = length;
        t.radius = radius;
    }
    setup
}

fn alarm_on(axes: &[char], text: &str) -> ProgramError {
    let library = Library::new();
    match check_with_library(Dialect::FanucMill, text, mill(axes), library) {
        Ok(c) => panic!("no alarm for\n{text}\n{c:?}"),
        Err(e) => e,
    }
}

#[test]
fn every_listed_program_alarm_is_raised_with_its_number_and_line() {
    let xyz = ['X', 'Y', 'Z'];
    let cases: &[(u32, &str, u32)] = &[
        (3, "G0 X1000000.\nM30\n", 1),
        (4, "G0 X10. 5\nM30\n", 1),
        (5, "G0 X0.\nG1 X F100\nM30\n", 2),
        (6, "G0 X--5\nM30\n", 1),
        (7, "G0 X1.2.3\nM30\n", 1),
        (9, "G0 X0.\nG0 X1. ?\nM30\n", 2),
        (9, "G0 B5.\nM30\n", 1),
        (10, "G0 X0.\nG12 X5.\nM30\n", 2),
        (11, "G0 X0.\nG1 X10.\nM30\n", 2),
        (20, "G0 X0. Y0.\nG2 X10. Y0. I3. J0. F100\nM30\n", 2),
        (29, "G0 X-10. Y0.\nG41 D9 G1 X0. F100\nM30\n", 2),
        (30, "G43 H201 Z10.\nM30\n", 1),
        (
            33,
            "G0 X-10. Y0.\nG41 D1 G1 X0. Y0. F100\nX10.\nG3 X-6. Y0. I-8. J0.\nG40 X-20.\nM30\n",
            4,
        ),
        (34, "G0 X0. Y0.\nG41 D1 G2 X10. Y0. R5. F100\nM30\n", 2),
        (37, "G0 X0. Y0.\nG41 D1 G1 X10. F100\nG18\nM30\n", 3),
        (
            41,
            "G0 X-10. Y0.\nG41 D1 G1 X0. Y0. F100\nX20.\nY4.\nX40.\nY20.\nG40 X50.\nM30\n",
            5,
        ),
        (76, "G0 X0.\nG65 A1.\nM30\n", 2),
        // Line 2 of O0002, the subprogram that calls itself once too often.
        (77, "%\nO0001\nM98 P2\nM30\nO0002\nM98 P2\nM99\n%\n", 2),
        (78, "G0 X0.\nM98 P4321\nM30\n", 2),
        (92, "G0 X10.\nG27 X5.\nM30\n", 2),
        (112, "#1 = 1\n#2 = #1 / 0\nM30\n", 2),
        (114, "#1 = \nM30\n", 1),
        (115, "#1 = #40\nM30\n", 1),
        (116, "#5001 = 3\nM30\n", 1),
        (118, "#1 = [1 + [2 * 3]\nM30\n", 1),
        (119, "#1 = SQRT[-4]\nM30\n", 1),
        (124, "#1 = 0\nWHILE [#1 LT 3] DO1\n#1 = #1 + 1\nM30\n", 2),
        (126, "WHILE [1 EQ 1] DO4\nEND4\nM30\n", 1),
        (126, "G0 X0.\nEND2\nM30\n", 2),
        (128, "G0 X0.\nGOTO 900\nM30\n", 2),
        (129, "%\nO0001\nG65 P2 G1\nM30\nO0002\nM99\n%\n", 3),
        (3012, "G0 X0.\n#3000 = 12 (TOOL BROKEN)\nM30\n", 2),
    ];
    for &(number, text, line) in cases {
        let e = alarm_on(&xyz, text);
        assert_eq!((e.number, e.line), (number, line), "{e} for\n{text}");
        assert!(!e.text.is_empty());
    }
    // P/S 021: a plane that names an axis the machine lacks (an X-Z machine in G17).
    let e = alarm_on(&['X', 'Z'], "G17 G2 X10. Z0. R5. F100\nM30\n");
    assert_eq!((e.number, e.line), (21, 1), "{e}");
}
