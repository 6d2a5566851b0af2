//! The loops that keep the machine's time run in real time when the system allows it, and the
//! cell runs on, saying why, when it does not (issue 27).

mod common;

use std::time::{Duration, Instant};

use cnc::cell::Cell;

/// Scheduling policy and real-time priority of this process's thread named `name`, from
/// `/proc/self/task/*/stat` (fields 41 and 40).
fn thread_policy(name: &str) -> Option<(u32, u32)> {
    for task in std::fs::read_dir("/proc/self/task").ok()?.flatten() {
        let comm = std::fs::read_to_string(task.path().join("comm")).unwrap_or_default();
        if comm.trim() != name {
            continue;
        }
        let stat = std::fs::read_to_string(task.path().join("stat")).ok()?;
        // Fields after the command name in parentheses; field 3 is the first of them.
        let rest = stat.rsplit_once(')')?.1;
        let fields: Vec<&str> = rest.split_whitespace().collect();
        let rt_priority = fields.get(40 - 3)?.parse().ok()?;
        let policy = fields.get(41 - 3)?.parse().ok()?;
        return Some((policy, rt_priority));
    }
    None
}

#[test]
fn the_servo_thread_runs_under_sched_fifo_with_locked_memory() {
    let cfg = common::sim_lathe(63);
    let cell = Cell::start(&cfg).unwrap();
    // The servo thread enters real time once the drives answered.
    let t0 = Instant::now();
    let mut seen = None;
    while t0.elapsed() < Duration::from_secs(30) {
        seen = thread_policy("servo");
        if seen.is_some_and(|(policy, _)| policy == libc::SCHED_FIFO as u32) {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(
        seen,
        Some((libc::SCHED_FIFO as u32, cfg.realtime.servo_priority as u32)),
        "servo thread (policy, priority) as the kernel reports it"
    );
    let locked = cnc_runtime::realtime::locked_kb();
    assert!(locked > 0, "VmLck {locked} kB");
}

/// Without the privilege (no CAP_SYS_NICE or CAP_IPC_LOCK, RLIMIT_RTPRIO 0), `cnc run` says why
/// and still runs the part. The sim lathe's config with the servo-lateness alarms off
/// (`common::sim_lathe_file`): an ordinary thread on a loaded CI machine is late by tens of ms,
/// which would stop the cycle with alarm 1093, as it should on a real machine.
#[test]
fn without_the_privilege_the_cell_says_why_and_runs_anyway() {
    let home = std::env::temp_dir().join(format!("cnc_realtime_{}", std::process::id()));
    std::fs::create_dir_all(&home).unwrap();
    let config = common::sim_lathe_file(&home, "lathe.yaml", 64, |_| {});
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/lathe/demo_shaft.nc");
    let out = std::process::Command::new("setpriv")
        .args([
            "--inh-caps=-sys_nice,-ipc_lock",
            "--bounding-set=-sys_nice,-ipc_lock",
            "--",
            "prlimit",
            "--rtprio=0",
            "--memlock=65536",
            "--",
            env!("CARGO_BIN_EXE_cnc"),
            "run",
            config.to_str().expect("utf-8 path"),
            "--program",
            program,
            "--cycles",
            "1",
        ])
        .env("HOME", &home)
        .env("ROS_DOMAIN_ID", "64")
        .env_remove("XDG_DATA_HOME")
        .env_remove("RUST_LOG")
        .output()
        .expect("setpriv runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let _ = std::fs::remove_dir_all(&home);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("servo loop: runs as an ordinary thread: SCHED_FIFO 80 refused"),
        "{stderr}"
    );
    assert!(stderr.contains("memory not locked"), "{stderr}");
    assert!(stdout.contains("cycles done 1"), "{stdout}");
    assert!(stdout.contains("servo loop (ordinary thread)"), "{stdout}");
}
