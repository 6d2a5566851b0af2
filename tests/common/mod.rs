//! What the cell tests share: the simulated lathe's launch config for one test.

use cnc_runtime::LaunchConfig;

/// `launch_configs/sim_lathe.yaml` in DDS `domain` (one per test, so tests never hear each
/// other), with no kept memory (part count and variables start empty) and no parameter file and no recorder
/// (`tests/recording.rs` tests that).
pub fn sim_lathe(domain: u16) -> LaunchConfig {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/launch_configs/sim_lathe.yaml");
    let text = std::fs::read_to_string(path).expect("sim_lathe.yaml");
    let mut cfg = LaunchConfig::from_yaml(&text).expect("sim_lathe.yaml parses");
    cfg.network.domain_id = Some(domain);
    cfg.plc.memory_file = None;
    cfg.machine.memory_file = None;
    cfg.machine.parameter_file = None;
    cfg.recorder.enabled = false;
    cfg.hmi.web_address = String::new();
    cfg
}
