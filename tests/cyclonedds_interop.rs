//! Interop with Eclipse Cyclone DDS (PyPI `cyclonedds`): `tests/interop/cyclone_peer.py` joins the
//! cell's domain, reads spindle, part_count and alarms with types built from the .msg files, and
//! calls the services with the rmw_cyclonedds mapping. `scripts/test.sh` creates the Python
//! environment (`target/venv`); without it this test fails, it does not skip.

mod common;

use cnc::cell::Cell;

/// Runs `tests/interop/<script>` with the venv's Python against a cell in `domain`; returns
/// its output after checking it passed.
fn run_peer(script: &str, domain: u16) -> String {
    let cfg = common::sim_lathe(domain);
    let cell = Cell::start(&cfg).unwrap();
    let out = common::cyclone_peer(script, domain);
    let (_, errors) = cell.stop();
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{script} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(errors.is_empty(), "{errors:?}");
    stdout
}

#[test]
fn cyclone_dds_peer_reads_topics_and_calls_services() {
    let stdout = run_peer("cyclone_peer.py", 43);
    assert!(stdout.contains("part_count 0 -> 1"), "{stdout}");
}

/// The robot handshake from outside: cycle complete, door, chuck, clear, next cycle, and
/// refusals with their reasons.
#[test]
fn cyclone_dds_robot_does_the_load_handshake() {
    let stdout = run_peer("robot_peer.py", 53);
    assert!(
        stdout.contains("ok   next cycle started by the robot"),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "ok   door close with the robot inside refused: door close refused: robot not clear"
        ),
        "{stdout}"
    );
}
