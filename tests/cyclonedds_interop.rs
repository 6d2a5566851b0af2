//! Interop with Eclipse Cyclone DDS (PyPI `cyclonedds`): `tests/interop/cyclone_peer.py` joins the
//! cell's domain, reads spindle, part_count and alarms with types built from the .msg files, and
//! calls the services with the rmw_cyclonedds mapping. `scripts/test.sh` creates the Python
//! environment (`target/venv`); without it this test fails, it does not skip.

mod common;

/// Runs `tests/interop/<script>` against a cell in `domain`; returns its output after checking
/// it passed.
fn run_peer(script: &str, domain: u16) -> String {
    common::peer_against_cell(&common::sim_lathe(domain), script)
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
