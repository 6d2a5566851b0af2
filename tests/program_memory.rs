//! Issue 26: program memory is on disk, bounded, and memory is returned when programs are
//! deleted. Before the change, 120 loads of 4 MiB grew the cell to 2.9 GB, and none of it came
//! back after the programs were deleted. The cell runs as its own process (`cnc run`), so its
//! resident memory is read from `/proc/<pid>/status`; this test is its supervisor.

use std::path::{Path, PathBuf};
use std::time::Duration;

mod common;

use cnc_cell::client::CellClient;
use cnc_runtime::LaunchConfig;
use ros2_client::ServiceMapping;

const DOMAIN: u16 = 74;
const LOADS: usize = 120;

/// The simulated lathe with its program memory in `dir`, large enough for every load (the
/// default 64 MiB would refuse the 17th with alarm 70: that is the interpreter's unit test).
fn config(dir: &Path) -> PathBuf {
    common::sim_lathe_file(dir, "memory_lathe.yaml", DOMAIN, |v| {
        v["machine"]["program_directory"] = "programs".into();
        v["machine"]["program_capacity_kib"] = (1024u32 * 1024).into();
        v["machine"]["parameter_file"] = serde_yaml::Value::Null;
    })
}

/// Resident memory of process `pid` in MiB: total (`VmRSS`), its peak (`VmHWM`), and of it the
/// process's own heap (`RssAnon`) and shared memory (`RssShmem`: the iceoryx2 channels, counted
/// once per mapping).
struct Resident {
    total: f64,
    peak: f64,
    anon: f64,
    shmem: f64,
}

fn resident(pid: u32) -> Resident {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("status");
    let mib = |key: &str| {
        status
            .lines()
            .find(|l| l.starts_with(key))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|n| n.parse::<f64>().ok())
            .unwrap_or_else(|| panic!("{key} in /proc/{pid}/status"))
            / 1024.0
    };
    Resident {
        total: mib("VmRSS:"),
        peak: mib("VmHWM:"),
        anon: mib("RssAnon:"),
        shmem: mib("RssShmem:"),
    }
}

impl std::fmt::Display for Resident {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.0} MiB (heap {:.0}, shared {:.0})",
            self.total, self.anon, self.shmem
        )
    }
}

/// A program of just under 4 MiB (the services' limit), different for each `n`.
fn big_program(n: usize) -> String {
    let mut text = format!("O{:04}\n", n % 10_000);
    let mut i = 0;
    while text.len() < cnc_runtime::MAX_PROGRAM_BYTES - 64 {
        text.push_str(&format!("G01 X{}.{:03} Z-{}.5 F200\n", i % 300, n, i % 400));
        i += 1;
    }
    text.push_str("M30\n");
    text
}

#[test]
fn a_hundred_and_twenty_programs_of_4_mib_are_kept_on_disk_and_their_memory_returned() {
    let dir = std::env::temp_dir().join(format!("cnc_program_memory_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let config = config(&dir);
    let cfg = LaunchConfig::load(&config).expect("config");
    let cell = common::KillOnDrop(common::cnc_run(&config, &dir.join("cell.log")));
    let pid = cell.0.id();
    let mut client = CellClient::new(
        &cfg.network,
        "lathe1",
        "supervisor",
        ServiceMapping::Enhanced,
    )
    .expect("client")
    .with_timeout(Duration::from_secs(60));
    client.wait_ready(Duration::from_secs(60)).expect("ready");

    // Two loads and deletes first: buffers that are allocated once, for the largest program
    // that passes (shared-memory slots, DDS fragments), are the baseline, not a leak.
    for n in 0..2 {
        let r = client
            .load_program("warmup.nc", &big_program(n))
            .expect("load");
        assert!(r.accepted, "{}", r.message);
        let r = client.delete_program("warmup.nc").expect("delete");
        assert!(r.accepted, "{}", r.message);
    }
    let before = resident(pid);

    let mut on_disk = 0u64;
    for n in 0..LOADS {
        let name = format!("jobs/P{n:03}.nc");
        let text = big_program(n);
        let r = client.load_program(&name, &text).expect("load");
        assert!(r.accepted, "{name}: {}", r.message);
        on_disk += text.len() as u64;
    }
    let loaded = resident(pid);
    let programs_mib = on_disk as f64 / (1024.0 * 1024.0);
    let files: u64 = std::fs::read_dir(dir.join("programs/jobs"))
        .expect("the programs' folder")
        .map(|e| e.expect("entry").metadata().expect("metadata").len())
        .sum();
    assert_eq!(files, on_disk, "every program on disk, whole");
    let listed = client.list_programs().expect("list");
    assert_eq!(listed.names.len(), LOADS);

    for n in 0..LOADS {
        let name = format!("jobs/P{n:03}.nc");
        let r = client.delete_program(&name).expect("delete");
        assert!(r.accepted, "{name}: {}", r.message);
    }
    // The allocator may give pages back a moment after the free.
    std::thread::sleep(Duration::from_millis(500));
    let deleted = resident(pid);
    println!(
        "{LOADS} programs, {programs_mib:.0} MiB: resident {before} before, {loaded} loaded \
         (peak {:.0} MiB), {deleted} after deleting",
        loaded.peak.max(deleted.peak)
    );
    assert!(
        !dir.join("programs/jobs").exists(),
        "an emptied folder is removed"
    );
    // Loaded, the cell holds each program once (the interpreter's program memory): growth
    // well beyond the programs' own size would be copies kept per load.
    assert!(
        loaded.total - before.total < programs_mib + 128.0,
        "{loaded} with {programs_mib:.0} MiB of programs, {before} before"
    );
    // Deleted, what is left is what DDS may keep of the last requests (32 MiB a topic, D63).
    assert!(
        deleted.total - before.total < 64.0,
        "{deleted} after deleting every program, {before} before loading"
    );
    drop(cell);
    let _ = std::fs::remove_dir_all(&dir);
}
