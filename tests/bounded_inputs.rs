//! Issue 26 end to end: every request is answered or refused, and nothing a client sends takes
//! the machine outside what it is rated for. The cell runs in this process; the clients are
//! Eclipse Cyclone DDS peers (`tests/interop/`), a DDS implementation nobody here wrote.

mod common;

/// The two tests' cells run one after the other, not side by side in this process: with both
/// at once on a loaded CI machine the burst's PLC was twice silent for half a second (alarm
/// 1092) while motion ticked on, a cause not found (decisions D41; its alarm now says how long).
static ONE_CELL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_cell_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    ONE_CELL.lock().unwrap_or_else(|e| e.into_inner())
}

/// 2,000 service requests in a burst while a program runs: each gets one reply, answered or
/// refused ("busy" when a service's queue is full), counted by the peer; the program still
/// runs to its end. Before the change, 1,885 of 2,000 got no answer at all.
#[test]
fn a_burst_of_two_thousand_requests_is_each_answered_or_refused() {
    let _alone = one_cell_at_a_time();
    common::peer_against_cell(&common::sim_lathe(70), "burst_peer.py");
}

/// Every service and the client input topic with random, extreme and non-finite values: every
/// request answered, every refusal with its reason (naming the parameter or the override), no
/// commanded position outside the rated travel, no spindle speed above its rating, and no
/// node of the cell fails (a panic would be an error at stop).
#[test]
fn fuzzed_services_and_inputs_never_take_the_machine_outside_its_ratings() {
    let _alone = one_cell_at_a_time();
    let mut cfg = common::sim_lathe(72);
    // Allowed, so the fuzzed commands reach the machine instead of stopping at the door.
    cfg.hmi.allowed_clients = Some(vec!["*".into()]);
    // A parameter file, so every written value is checked (and kept for the next start).
    let dir = std::env::temp_dir().join(format!("cnc_fuzz_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    cfg.machine.parameter_file = Some(dir.join("parameters.yaml"));
    common::peer_against_cell(&cfg, "fuzz_peer.py");
    // What was written still loads: the machine starts again on it.
    let written = cnc_runtime::parameters::load_file(&dir.join("parameters.yaml")).unwrap();
    cnc_runtime::parameters::apply(common::sim_lathe(72), &written).expect("written values apply");
    let _ = std::fs::remove_dir_all(&dir);
}
