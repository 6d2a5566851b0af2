//! Issue 47: the boundaries ARCHITECTURE.md states, enforced by Cargo. Each pure crate's
//! normal dependency tree (`cargo tree -e normal`, features resolved for that crate alone, as
//! `cargo build -p` resolves them) must not reach the transports, the runtime or the clock's
//! and threads' crates: then no code in it can use them, whatever its author meant.

use std::process::Command;

/// The crates of `package`'s normal dependency tree.
fn tree(package: &str) -> Vec<String> {
    let out = Command::new(env!("CARGO"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tree",
            "-p",
            package,
            "-e",
            "normal",
            "--prefix",
            "none",
            "--offline",
        ])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {package}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(String::from)
        .collect()
}

const TRANSPORTS: [&str; 5] = ["ros2-client", "rustdds", "iceoryx2", "cnc_runtime", "smol"];

#[test]
fn the_pure_cores_cannot_reach_dds_iceoryx2_or_the_runtime() {
    for package in [
        "cnc_machine",
        "cnc_interpreter_core",
        "cnc_interpreter",
        "cnc_task_core",
        "cnc_motion_core",
    ] {
        let crates = tree(package);
        assert!(crates.iter().any(|c| c == package), "{package}: {crates:?}");
        let reached: Vec<&String> = crates
            .iter()
            .filter(|c| TRANSPORTS.contains(&c.as_str()))
            .collect();
        assert!(reached.is_empty(), "{package} reaches {reached:?}");
    }
}
