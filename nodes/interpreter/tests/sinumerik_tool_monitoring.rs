//! The 802D's tool monitoring beyond the manual's examples (`001` §9.13): by workpiece count
//! (decision D111) the limit disables the tool, a disabled tool cannot be selected until
//! RESETMON, and bad calls are alarms; by tool life (D122) the active edge's life goes down by
//! the cutting time the machine reports at the preprocessing stops around it.

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

/// A monitoring type beyond life and count is 17020; a count on an edge the offset page
/// lacks is 17190; SETPIECE beyond 32000 or on a second spindle, and RESETMON without its
/// state variable, are alarms.
#[test]
fn what_is_not_monitored_is_refused_with_its_alarm() {
    for (text, alarm) in [
        ("$TC_TP9[1]=4\n", 17020),
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

/// Runs `front` on a machine that answers its preprocessing stops, in turn, with the cutting
/// times `reports` (seconds); `at_stop` sees the program at each stop before the answer. The
/// commands it sent; every report must be taken.
fn on_machine(
    front: &mut cnc_interpreter::sinumerik::Sinumerik,
    reports: &[f64],
    mut at_stop: impl FnMut(&cnc_interpreter::sinumerik::Sinumerik),
) -> Vec<cnc_interpreter::Command> {
    use cnc_interpreter::{MachineTimers, Measurement};
    front.core.on_machine = true;
    let mut reports = reports.iter();
    let mut out = Vec::new();
    loop {
        match cnc_interpreter_core::next_command(front) {
            Ok(Some(c)) => out.push(c.command),
            Ok(None) if front.core.awaiting_machine() => {
                at_stop(front);
                let cutting = *reports
                    .next()
                    .expect("no more stops than the test's reports");
                let at = front.core.pos.clone();
                front
                    .core
                    .machine_result(Measurement {
                        triggered: true,
                        position: at.clone(),
                        rest: at,
                        timers: Some(MachineTimers {
                            cutting,
                            ..MachineTimers::default()
                        }),
                    })
                    .unwrap();
            }
            Ok(None) => break,
            Err(e) => panic!("alarm {e}"),
        }
    }
    assert_eq!(reports.next(), None, "every report taken");
    out
}

/// Tool life on the machine (D122): T1 D1 has 1 minute left, its prewarning at 0.5. The run's
/// first block, the change to T2 and the program's end are preprocessing stops; at each the
/// machine reports its cutting time, and T1 D1's life goes down by what was cut while it was
/// the active edge (40 s, then 30 s more: 6411, then 6413 and the tool disabled), while T2
/// D1, not monitored, keeps its own.
#[test]
fn the_active_edge_wears_by_the_cutting_time_the_machine_reports_at_each_stop() {
    use cnc_interpreter::sinumerik::Sinumerik;
    use cnc_interpreter::Command;
    let mut s = mill();
    s.offsets
        .tools
        .insert(21, cnc_interpreter_core::ToolOffset::default());
    for (key, v) in [
        ("$TC_TP9", 1.0),
        ("$TC_MOP11", 1.0),
        ("$TC_MOP2", 1.0),
        ("$TC_MOP1", 0.5),
    ] {
        let d = u32::from(key != "$TC_TP9");
        s.kept.insert(
            cnc_interpreter::sinumerik::monitor::kept_key(key, 1, d).unwrap(),
            v,
        );
    }
    let text = "T1 D1\nG1 X100 F150\nT2 D1\nG1 X0\nT1 D1\nG1 X50\nM30\n";
    let mut front = Sinumerik::new(text, s, Library::new());
    // The machine's cutting time at each stop: the run's start (T1 D1), the change to T2
    // after 40 s of cutting, the change back after 50 s more, M30 after 30 s more.
    let mut life = Vec::new();
    let out = on_machine(&mut front, &[100.0, 140.0, 190.0, 220.0], |f| {
        life.push(f.tool_datum("$TC_MOP2", 1, 1))
    });
    let stops = life.len();
    assert_eq!(stops, 4);
    // Before each stop's accounting: full, full, a third (40 s gone), a third (T2's 50 s are
    // not T1's).
    let third = 1.0 / 3.0;
    for (seen, want) in life.iter().zip([1.0, 1.0, third, third]) {
        assert!((seen - want).abs() < 1e-9, "{life:?}");
    }
    assert!(out.contains(&Command::ProgramEnd));
    assert_eq!(out.iter().filter(|c| **c == Command::Sync).count(), stops);
    // 40 s, then 30 s on T1 D1 (190 → 220): 1 − 70/60 min, below 0: disabled.
    let left = front.tool_datum("$TC_MOP2", 1, 1);
    assert!((left - (1.0 - 70.0 / 60.0)).abs() < 1e-9, "{left}");
    let shown: Vec<&str> = front.messages.iter().map(|m| m.1.as_str()).collect();
    assert_eq!(
        shown,
        [
            "6411 tool 1 has reached its prewarning limit with D = 1",
            "6413 tool 1 has reached its monitoring limit with D = 1"
        ]
    );
    assert_eq!(front.tool_datum("$TC_TP8", 1, 0) as i64 & 4, 4, "disabled");
    assert_eq!(
        front.tool_datum("$TC_MOP2", 2, 1),
        0.0,
        "T2 is not monitored"
    );
}

/// A check without the machine wears nothing (its stops report no cutting time), and RESETMON
/// sets the life back to its setpoint.
#[test]
fn a_check_wears_no_tool_and_resetmon_restores_the_life() {
    let text = "DEF INT STATE\n$TC_TP9[1]=1 $TC_MOP11[1,1]=5 $TC_MOP2[1,1]=2\nT1 D1\n\
                G1 X100 F100\nR1=$TC_MOP2[1,1]\nRESETMON(STATE,1,1,1)\nR2=$TC_MOP2[1,1]\nM30\n";
    let r = run(text).ok();
    assert_eq!((r.front.r(1), r.front.r(2)), (2.0, 5.0));
}

/// `$A_MONIFACT` (§9.13.2): the life clock's factor. T1 D1 cuts 30 s at the factor 1, then the
/// program sets 5 (a preprocessing stop: the 30 s are accounted at 1) and cuts 6 s more, which
/// take 30 s of life. It reads back, starts each program at 1.0, and 0 is refused.
#[test]
fn the_life_clock_factor_scales_what_is_cut_after_it_is_set() {
    use cnc_interpreter::sinumerik::Sinumerik;
    let text = "$TC_TP9[1]=1 $TC_MOP11[1,1]=10 $TC_MOP2[1,1]=10\nT1 D1\nR1=$A_MONIFACT\n\
                G1 X100 F200\n$A_MONIFACT=5\nG1 X120\nR2=$TC_MOP2[1,1] R3=$A_MONIFACT\nM30\n";
    let mut front = Sinumerik::new(text, mill(), Library::new());
    // The stops: T1 D1 (the first block after life monitoring came on), $A_MONIFACT=5 after
    // 30 s, the read of $TC_MOP2 after 6 s more, M30.
    on_machine(&mut front, &[0.0, 30.0, 36.0, 36.0], |_| {});
    assert_eq!(front.r(1), 1.0);
    // 10 min − 0.5 min (30 s at 1) − 0.5 min (6 s at 5).
    assert!((front.r(2) - 9.0).abs() < 1e-9, "{}", front.r(2));
    assert_eq!(front.r(3), 5.0);
    assert_eq!(run("$A_MONIFACT=0\n").alarm(), (17020, 1));
    assert_eq!(run("R1=$A_MONIFACT\nM30\n").ok().front.r(1), 1.0);
}
