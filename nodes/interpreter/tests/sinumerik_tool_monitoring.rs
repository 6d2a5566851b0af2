//! The 802D's tool monitoring by workpiece count beyond the manual's examples (`001` §9.13,
//! decision D111): the limit disables the tool, a disabled tool cannot be selected until
//! RESETMON, tool life is refused rather than not counted, and bad calls are alarms.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter::Library;
use support::*;

const COUNTED: &str = "$TC_TP9[1]=2 $TC_MOP13[1,1]=2 $TC_MOP4[1,1]=2 $TC_MOP3[1,1]=1\n";

/// Two parts on a count of 2: the first reaches the prewarning (6411), the second the limit
/// (6413) and the tool is disabled, so selecting T1 again is alarm 17190 at its line.
#[test]
fn the_limit_disables_the_tool_and_t_cannot_select_it_again() {
    let text = format!("T1 D1\n{COUNTED}G1 X10 F500\nSETPIECE(1)\nSETPIECE(1)\nT0\nT1\nM30\n");
    let r = run(&text);
    assert_eq!(r.alarm(), (17190, 7), "{:?}", r.error);
    let shown: Vec<&str> = r.front.messages.iter().map(|m| m.1.as_str()).collect();
    assert_eq!(
        shown,
        [
            "6411 tool 1 has reached its prewarning limit with D = 1",
            "6413 tool 1 has reached its monitoring limit with D = 1"
        ]
    );
    assert_eq!(r.front.tool_datum("$TC_MOP4", 1, 1), 0.0);
    // Disabled (4) and prewarned (16).
    assert_eq!(r.front.tool_datum("$TC_TP8", 1, 0), 20.0);
}

/// RESETMON sets the count back and enables the tool: T1 runs again.
#[test]
fn resetmon_enables_a_disabled_tool() {
    let text = format!(
        "DEF INT STATE\nT1 D1\n{COUNTED}SETPIECE(2)\nT0\nRESETMON(STATE,1)\nT1\nR1=$TC_MOP4[1,1]\nR2=$TC_TP8[1]\nM30\n"
    );
    let r = run(&text).ok();
    assert_eq!(r.front.r(1), 2.0);
    // In the spindle (bit 0), neither disabled nor prewarned.
    assert_eq!(r.front.r(2), 1.0);
}

/// Tool life (type 1) needs the path time motion measures and is not built: 12140, not a
/// monitoring that never counts. A count on an edge the offset page lacks is 17190; SETPIECE
/// beyond 32000 or on a second spindle, and RESETMON without its state variable, are alarms.
#[test]
fn what_is_not_monitored_is_refused_with_its_alarm() {
    for (text, alarm) in [
        ("$TC_TP9[1]=1\n", 12140),
        ("$TC_MOP4[1,2]=5\n", 17190),
        ("$TC_MOP4[1]=5\n", 12550),
        ("T1 D1\nSETPIECE(32001)\n", 17020),
        ("T1 D1\nSETPIECE(1,2)\n", 17020),
        ("RESETMON(1,1)\n", 14051),
    ] {
        let r = run(text);
        assert_eq!(r.alarm().0, alarm, "{text}: {:?}", r.error);
    }
}

/// Without count monitoring active ($TC_TP9 0) SETPIECE leaves the count alone.
#[test]
fn setpiece_counts_only_monitored_tools() {
    let r = run_with(
        "T1 D1\n$TC_MOP4[1,1]=5\nSETPIECE(3)\nM30\n",
        mill(),
        Library::new(),
    )
    .ok();
    assert_eq!(r.front.tool_datum("$TC_MOP4", 1, 1), 5.0);
}
