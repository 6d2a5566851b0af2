//! Coupled motion, TRAILON/TRAILOF (`001` §9.3.25.1–2, fixture 046, decision D115), on a
//! mill with the manual's axes V and W (figure 9-37: two-sided machining).

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Library, Setup};
use support::*;

/// X Y Z and the second slide's V and W, all at zero.
fn five_axes() -> Setup {
    Setup::new(&['X', 'Y', 'Z', 'V', 'W'], &[false; 5], &[0.0; 5])
}

fn run5(text: &str) -> Run {
    run_with(text, five_axes(), Library::new())
}

#[test]
fn f046_v_follows_y_w_follows_z_reversed_and_v_adds_its_own_path() {
    let text = filled(
        "046",
        &["N10 G0 X10 Y0 Z30", "N140 G1 Z5 F100", "N210 G0 Y0"],
    );
    let r = run5(&text).ok();
    assert_eq!(
        r.ends(),
        [
            vec![10.0, 0.0, 30.0, 0.0, 0.0],
            // N120 G0 Z10: Z down 20, W (factor -1) the other way, up 20.
            vec![10.0, 0.0, 10.0, 0.0, 20.0],
            // N130 G0 Y20: V the same way as Y.
            vec![10.0, 20.0, 10.0, 20.0, 20.0],
            vec![10.0, 20.0, 5.0, 20.0, 25.0],
            // N200 G1 Y22 V25: V its own 25 plus Y's 22 coupled.
            vec![10.0, 22.0, 5.0, 47.0, 25.0],
            vec![10.0, 0.0, 5.0, 25.0, 25.0],
        ]
    );
}

#[test]
fn trailof_ends_the_coupling_and_the_status_variable_says_which_axis_follows() {
    let text = "TRAILON(V,Y)\nR1=$AA_COUP_ACT[V]\nR2=$AA_COUP_ACT[Y]\nG0 Y10\nR3=$AA_IW[V]\n\
                TRAILOF(V)\nR4=$AA_COUP_ACT[V]\nR5=$AA_IW[V]\nG0 Y0\nG0 V0\nM30\n";
    let r = run5(text).ok();
    assert_eq!([r.front.r(1), r.front.r(2), r.front.r(3)], [8.0, 0.0, 10.0]);
    // After TRAILOF, V stands at 10 and the program reads it there.
    assert_eq!([r.front.r(4), r.front.r(5)], [0.0, 10.0]);
    let ends: Vec<f64> = r.ends().iter().map(|e| e[3]).collect();
    // Y back to 0 moves V no more; V0 goes to machine 0.
    assert_eq!(ends, [10.0, 10.0, 0.0]);
}

#[test]
fn two_leaders_add_and_a_follower_passes_its_travel_on() {
    // V follows Y and Z; W follows V at -0.5.
    let text = "TRAILON(V,Y)\nTRAILON(V,Z,2)\nTRAILON(W,V,-0.5)\nG1 Y4 Z1 F100\nM30\n";
    let r = run5(text).ok();
    assert!(near(&r.end(), &[0.0, 4.0, 1.0, 6.0, -3.0]), "{:?}", r.end());
}

#[test]
fn a_coupling_that_cannot_be_made_is_an_alarm() {
    let cases: [(&str, u32); 6] = [
        ("TRAILON(V,V)\nM30\n", 14051),
        ("TRAILON(V,Q)\nM30\n", 14092),
        ("TRAILON(V,Y)\nTRAILON(Y,V)\nM30\n", 14051),
        ("TRAILON(V,X)\nTRAILON(V,Y)\nTRAILON(V,Z)\nM30\n", 14051),
        ("TRAILON(V)\nM30\n", 14051),
        // A circle of the leader's plane is not followed.
        ("TRAILON(V,Y)\nG2 X10 Y0 I5 J0 F100\nM30\n", 12140),
    ];
    for (text, number) in cases {
        let r = run5(text);
        let e = r
            .error
            .as_ref()
            .unwrap_or_else(|| panic!("no alarm for {text}"));
        assert_eq!(e.number, number, "{text}: {e:?}");
        assert!(r.moves().is_empty(), "{text}");
    }
}
