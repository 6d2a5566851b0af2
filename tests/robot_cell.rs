//! Issue 29, the robot: one arm tends two lathes of one cell (`lathe1`, `lathe2`, each a full
//! controller of its own nodes, here in one process and one DDS domain) through their public
//! interface only. A supervisor's client runs each machine's first part; the robot then swaps
//! parts and starts cycles until it has loaded two into each (`common::robot_tends`, whose
//! observer judges safety from the machines' own `robot_handshake`).

mod common;

use cnc::cell::Cell;

#[test]
fn one_robot_tends_two_lathes_and_never_enters_one_that_is_not_safe() {
    let lathe1 = common::sim_lathe(82);
    let mut lathe2 = lathe1.clone();
    lathe2.machine.namespace = "lathe2".into();
    let cells = [
        Cell::start(&lathe1).expect("lathe1 starts"),
        Cell::start(&lathe2).expect("lathe2 starts"),
    ];
    let inside = common::robot_tends(&lathe1.network, &["lathe1", "lathe2"], 2);
    assert!(
        inside >= 4,
        "the observer saw the robot inside {inside} times"
    );
    for c in cells {
        let (_, failed) = c.stop();
        assert!(failed.is_empty(), "{failed:?}");
    }
}
