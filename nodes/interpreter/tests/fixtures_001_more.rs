//! More of the 802D manual's fixtures (`../shared/fixtures/001`, issue 23, must-show 1),
//! asserted against their headers as `fixtures_001_filled.rs` does (its placeholders filled,
//! every printed line kept), in a file of their own to keep that one readable.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::{Aux, Command, Library};
use support::*;

/// 037 (§9.3.16): G64 lets N10, N20 and the filled blocks run on without a stop between them
/// (the path mode goes to motion as blending before N10's move), G60 at N180 switches back
/// to exact stop before its move.
#[test]
fn f037_g64_blends_from_n10_and_g60_stops_exactly_from_n180() {
    let text = filled(
        "037",
        &["N10 G64 G1 X50 F500", "N20 Y30", "N30 X0", "N180 G60 Y0"],
    );
    let r = run_with(&text, mill(), Library::new()).ok();
    let shown: Vec<String> = r
        .out
        .iter()
        .filter_map(|c| match c {
            Command::PathMode { exact_stop } => Some(format!("exact {exact_stop}")),
            Command::Linear { end, .. } => Some(format!("X{} Y{}", end[0], end[1])),
            _ => None,
        })
        .collect();
    let from = shown.iter().position(|s| s == "exact false").expect("G64");
    assert_eq!(
        shown[from..],
        [
            "exact false",
            "X50 Y0",
            "X50 Y30",
            "X0 Y30",
            "exact true",
            "X0 Y0"
        ],
        "{shown:?}"
    );
}

/// 081 (§9.12.2): `IF $AC_TOTAL_PARTS==R15 GOTOF SIST` — with the count equal to R15 the
/// jump skips the placeholder to SIST: the message, then M0; with R15 another number the
/// program goes on to the placeholder line (12080 as printed).
#[test]
fn f081_the_part_count_reached_jumps_to_the_message_and_m0() {
    let text = fixture("081");
    let mut s = mill();
    // $AC_TOTAL_PARTS is kept entry 11000 (D82): 7 parts made, R15 = 7.
    s.kept.insert(11_000, 7.0);
    s.kept.insert(10_015, 7.0);
    let r = run_with(&text, s.clone(), Library::new()).ok();
    assert_eq!(
        r.front.messages.last().map(|m| m.1.as_str()),
        Some("达到额定工件数")
    );
    assert!(r.out.contains(&Command::Aux(Aux::M(0))), "{:?}", r.out);
    s.kept.insert(10_015, 8.0);
    let r = run_with(&text, s, Library::new());
    assert_eq!(r.alarm(), (12080, line_of(&text, "...")));
}
