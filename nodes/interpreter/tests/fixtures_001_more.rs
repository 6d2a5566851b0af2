//! More of the 802D manual's fixtures (`../shared/fixtures/001`, issue 23, must-show 1),
//! asserted against their headers as `fixtures_001_filled.rs` does (its placeholders filled,
//! every printed line kept), in a file of their own to keep that one readable.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::sinumerik::expr::Val;
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

/// The mill with cutting edges `entries` (T×10+D) on its offset page besides T1 D1.
fn with_edges(entries: &[u32]) -> cnc_interpreter::Setup {
    let mut s = mill();
    for e in entries {
        s.offsets.tools.insert(*e, Default::default());
    }
    s
}

/// 082 (§9.13.3): SETPIECE(2) takes 2 off T1 D1's remaining count, SETPIECE(1) 1 off T2
/// D2's; the second does not count T1 again. The counts are set where the manual has its
/// first placeholder, as the offset page's monitoring screen would have them.
#[test]
fn f082_setpiece_counts_the_edges_used_since_the_last_one() {
    let text = filled(
        "082",
        &[
            "N20 $TC_TP9[1]=2 $TC_MOP4[1,1]=10 $TC_TP9[2]=2 $TC_MOP4[2,2]=5",
            "G1 X50 F500",
            "G1 X20",
            "",
        ],
    );
    let r = run_with(&text, with_edges(&[22]), Library::new()).ok();
    assert_eq!(r.front.tool_datum("$TC_MOP4", 1, 1), 8.0);
    assert_eq!(r.front.tool_datum("$TC_MOP4", 2, 2), 4.0);
}

/// Fixture 083 or 084 on a mill that changes tools with M6, T1–T3 each with D1 counted
/// from 10: the first placeholder switches the counts on, the others machine.
fn three_counted_tools(number: &str) -> Run {
    let text = filled(
        number,
        &[
            "$TC_TP9[1]=2 $TC_MOP4[1,1]=10 $TC_TP9[2]=2 $TC_MOP4[2,1]=10 $TC_TP9[3]=2 $TC_MOP4[3,1]=10",
            "G1 X10 F500",
            "G1 X20",
            "G1 X30",
            "G0 X0",
            "G0 Y0",
        ],
    );
    let mut s = with_edges(&[21, 31]);
    s.tool_change_with_m6 = true;
    run_with(&text, s, Library::new()).ok()
}

/// 083 (§9.13.3): with M06 changes, one SETPIECE(1) after the spindle is emptied counts
/// every tool changed in since the last: T1, T2 and T3 each lose one.
#[test]
fn f083_setpiece_after_m06_counts_every_tool_changed_in() {
    let r = three_counted_tools("083");
    for t in 1..=3 {
        assert_eq!(r.front.tool_datum("$TC_MOP4", t, 1), 9.0, "T{t}");
    }
}

/// 084 (§9.13.3): a SETPIECE before each M06 counts only the tool in the spindle: T1 −1,
/// T2 −2, T3 −0.
#[test]
fn f084_setpiece_before_each_change_counts_each_tool_its_own() {
    let r = three_counted_tools("084");
    let left: Vec<f64> = (1..=3)
        .map(|t| r.front.tool_datum("$TC_MOP4", t, 1))
        .collect();
    assert_eq!(left, [9.0, 8.0, 10.0]);
}

/// 085 (§9.13.3): RESETMON(state,12,1,2) sets T12 D1's remaining count back to its setpoint
/// and reports 0; for a tool that does not exist, an edge it lacks, a tool without
/// monitoring and a type not active, the manual's −2, −1, −3 and −4.
#[test]
fn f085_resetmon_sets_the_count_back_and_says_why_not() {
    let run = |setting: &str| {
        let text = filled("085", &[setting, ""]);
        let r = run_with(&text, with_edges(&[121, 131]), Library::new()).ok();
        let state = match r.front.variable("STATE").map(|v| v.values[0].clone()) {
            Some(Val::Num(x)) => x,
            other => panic!("state: {other:?}"),
        };
        (state, r.front.tool_datum("$TC_MOP4", 12, 1))
    };
    assert_eq!(
        run("$TC_TP9[12]=2 $TC_MOP13[12,1]=50 $TC_MOP4[12,1]=3"),
        (0.0, 50.0)
    );
    assert_eq!(run("$TC_MOP13[12,1]=50 $TC_MOP4[12,1]=3"), (-3.0, 3.0));
    let other = |text: &str| {
        let r = run_with(text, with_edges(&[121, 131]), Library::new()).ok();
        match r.front.variable("STATE").map(|v| v.values[0].clone()) {
            Some(Val::Num(x)) => x,
            other => panic!("state: {other:?}"),
        }
    };
    let set = "DEF INT state\n$TC_TP9[12]=2 $TC_TP9[13]=2\n";
    assert_eq!(other(&format!("{set}RESETMON(state,14,1,2)\n")), -2.0);
    assert_eq!(other(&format!("{set}RESETMON(state,12,5,2)\n")), -1.0);
    assert_eq!(other(&format!("{set}RESETMON(state,12,1,1)\n")), -4.0);
    assert_eq!(other(&format!("{set}RESETMON(state,0)\n")), 0.0);
}

/// 086 (§9.13.3): the workpiece loop counts T7 down from 700 one part at a time (an M0 per
/// part); at 100 left the prewarning 6411 shows once; at 1 left the loop ends with the
/// manual's message and M0, and RESETMON sets the count back to 700 with state 0, and the
/// loop runs on.
#[test]
fn f086_the_piece_count_loop_warns_stops_and_starts_over() {
    let text = filled("086", &["", "G0 X0 ; 退回"]);
    let mut lib = Library::new();
    lib.insert_named("BEARBEIT", "BEARBEIT.SPF", "G1 X10 F2000\nG0 X0\nM17\n");
    let mut front = cnc_interpreter::sinumerik::Sinumerik::new(&text, with_edges(&[71]), lib);
    let mut stops = 0;
    let mut reset_seen = false;
    for _ in 0..200_000 {
        let c = cnc_interpreter_core::next_command(&mut front)
            .expect("no alarm")
            .expect("the loop does not end");
        if c.command == Command::Aux(Aux::M(0)) {
            stops += 1;
        }
        if front.message() == "刀具 T7 已磨损—请更换" && front.tool_datum("$TC_MOP4", 7, 1) == 700.0
        {
            reset_seen = true;
            break;
        }
    }
    assert!(reset_seen, "RESETMON never set T7 back");
    // 699 parts, each with its M0, and the M0 for the tool change.
    assert_eq!(stops, 700);
    let warnings: Vec<&str> = front
        .messages
        .iter()
        .map(|m| m.1.as_str())
        .filter(|m| m.starts_with("6411"))
        .collect();
    assert_eq!(
        warnings,
        ["6411 tool 7 has reached its prewarning limit with D = 1"]
    );
    // RESETMON's state was 0: the program went back to ANF, not to its ALARM branch.
    assert!(!front.messages.iter().any(|m| m.1.starts_with("故障")));
    // RESETMON cleared the prewarning bit (16) the 6411 set.
    assert_eq!(front.tool_datum("$TC_TP8", 7, 0), 0.0);
}
