//! Interop with Eclipse Cyclone DDS (PyPI `cyclonedds`): `tests/interop/cyclone_peer.py` joins the
//! cell's domain, reads spindle, part_count and alarms with types built from the .msg files, and
//! calls the services with the rmw_cyclonedds mapping. `scripts/test.sh` creates the Python
//! environment (`target/venv`); without it this test fails, it does not skip.

use std::path::PathBuf;
use std::process::Command;

mod common;

use cnc::cell::Cell;

#[test]
fn cyclone_dds_peer_reads_topics_and_calls_services() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let python = std::env::var("CNC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root.join("target/venv/bin/python"));
    assert!(
        python.exists(),
        "{} missing: run scripts/test.sh, which creates the venv with cyclonedds",
        python.display()
    );
    let cfg = common::sim_lathe(43);
    let cell = Cell::start(&cfg).unwrap();
    let out = Command::new(&python)
        .arg(root.join("tests/interop/cyclone_peer.py"))
        .args(["--domain", "43"])
        // Cyclone on loopback only, like the cell.
        .env("CYCLONEDDS_URI", "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" multicast=\"true\"/></Interfaces></General></Domain></CycloneDDS>")
        .output()
        .unwrap();
    let (_, errors) = cell.stop();
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "Cyclone DDS peer failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("part_count 0 -> 1"), "{stdout}");
    assert!(errors.is_empty(), "{errors:?}");
}
