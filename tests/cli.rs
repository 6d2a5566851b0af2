//! The `cnc` binary as a user runs it: `run --program --cycles` exits 0 when the cycles complete
//! and non-zero on an alarm. The domain comes from `ROS_DOMAIN_ID` (the launch config names none).

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// `cnc` with `args` from the repository's folder: whether it succeeded, and its stdout
/// followed by its stderr.
fn cnc(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

/// Runs `cnc run` on the program; the run must end by itself within 120 s (a hang fails
/// here instead of passing as a non-zero exit).
fn run_program(domain: &str, name: &str, text: &str, cycles: &str) -> (bool, String) {
    run_program_with(domain, name, text, cycles, |_, _| {})
}

/// [`run_program`], calling `during` with the process id and the time since the start while
/// the run goes on.
fn run_program_with(
    domain: &str,
    name: &str,
    text: &str,
    cycles: &str,
    mut during: impl FnMut(u32, Duration),
) -> (bool, String) {
    let dir = std::env::temp_dir().join(format!("cnc_cli_{}_{domain}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    // The launch config file, its kept memory and recordings in this test's own folder.
    let config = dir.join("sim_lathe.yaml");
    std::fs::copy(
        concat!(env!("CARGO_MANIFEST_DIR"), "/launch_configs/sim_lathe.yaml"),
        &config,
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("run")
        .arg(&config)
        .arg("--program")
        .arg(&path)
        .args(["--cycles", cycles])
        .env("ROS_DOMAIN_ID", domain)
        .stdout(Stdio::from(
            std::fs::File::create(dir.join("out.txt")).unwrap(),
        ))
        .stderr(Stdio::from(
            std::fs::File::create(dir.join("err.txt")).unwrap(),
        ))
        .spawn()
        .unwrap();
    // A hung run is a failure, not a hung test suite.
    let started = Instant::now();
    let deadline = started + Duration::from_secs(120);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        during(child.id(), started.elapsed());
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            let out = std::fs::read_to_string(dir.join("out.txt")).unwrap_or_default();
            panic!("cnc run did not end within 120 s:\n{out}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let text = format!(
        "{}{}",
        std::fs::read_to_string(dir.join("out.txt")).unwrap_or_default(),
        std::fs::read_to_string(dir.join("err.txt")).unwrap_or_default()
    );
    (status.success(), text)
}

#[test]
fn run_exits_zero_after_its_cycles() {
    let (ok, out) = run_program(
        "45",
        "two.nc",
        "G00 X100 Z20\nS500 M03\nG01 Z10 F3000\nM05\nM30\n",
        "2",
    );
    assert!(ok, "{out}");
    assert!(
        out.contains("DDS domain 45"),
        "ROS_DOMAIN_ID not honoured:\n{out}"
    );
    assert!(out.contains("cycles done 2"), "{out}");
    // The line of each completed cycle shows its part counted.
    assert!(out.contains("parts 1 | cycles done 1"), "{out}");
    assert!(out.contains("parts 2 | cycles done 2"), "{out}");
    assert!(
        out.contains("servo loop (") && out.contains("round trip"),
        "no servo statistics at exit:\n{out}"
    );
}

#[test]
fn run_exits_nonzero_on_an_alarm_with_number_and_line() {
    let (ok, out) = run_program(
        "46",
        "bad.nc",
        "G00 X100 Z20\nG01 Z10 F3000\nG02 X120 Z-20 R5\nM30\n",
        "1",
    );
    assert!(!ok, "{out}");
    assert!(out.contains("alarm 11") && out.contains("line 3"), "{out}");
}

/// A cell whose whole process stands still for 0.7 s at a time (a busy host's stolen time, a
/// debugger, `kill -STOP`) runs its cycles on: the PLC that had no chance to scan is not taken
/// as silent (alarm 1092, decisions D41), and neither DDS's nor iceoryx2's waits end their node
/// when the continued process's `epoll_wait` returns `EINTR`.
#[test]
fn a_process_that_stands_still_runs_on() {
    let mut frozen = Vec::new();
    let (ok, out) = run_program_with(
        "44",
        "still.nc",
        "G00 X100 Z20\nS500 M03\nG01 Z-50 F600\nG00 Z20\nM05\nM30\n",
        "2",
        |pid, elapsed| {
            let due = Duration::from_millis(3000 + 2500 * frozen.len() as u64);
            if frozen.len() < 5 && elapsed >= due {
                let pid = pid as libc::pid_t;
                // SAFETY: signals to our own child, which is still running (not yet waited for).
                unsafe { libc::kill(pid, libc::SIGSTOP) };
                std::thread::sleep(Duration::from_millis(700));
                unsafe { libc::kill(pid, libc::SIGCONT) };
                frozen.push(elapsed);
            }
        },
    );
    assert!(
        frozen.len() >= 3,
        "the run ended before three stops:\n{out}"
    );
    assert!(ok, "{out}");
    assert!(out.contains("cycles done 2"), "{out}");
    assert!(!out.contains("1092"), "the PLC taken as silent:\n{out}");
    // Motion saw the stops: its longest tick interval is one of them.
    let max_interval = out
        .lines()
        .find_map(|l| l.split("min/p50/p99/max ").nth(1))
        .and_then(|v| v.split(['/', ';']).nth(3))
        .and_then(|v| v.trim().parse::<f64>().ok());
    assert!(
        max_interval.is_some_and(|us| us > 600_000.0),
        "no stop in the servo statistics ({max_interval:?}):\n{out}"
    );
}

#[test]
fn simulate_prints_the_cycle_time_and_draws_the_part() {
    let dir = std::env::temp_dir().join(format!("cnc_sim_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("part.svg");
    let program = dir.join("shaft.nc");
    // 100 mm at 600 mm/min: 10 s of feed plus rapids and accelerations.
    std::fs::write(&program, "G00 X50 Z5\nG01 Z-95 F600\nG00 X100\nM30\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("simulate")
        .arg(&program)
        .arg("--svg")
        .arg(&svg)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let seconds: f64 = stdout
        .lines()
        .find_map(|l| {
            l.strip_prefix("cycle time: ")?
                .strip_suffix(" s")?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("no cycle time line: {stdout}"));
    assert!(seconds > 10.0 && seconds < 13.0, "{seconds}");
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.starts_with("<svg") && picture.contains("class=\"part\""));
    assert!(picture.contains("class=\"feed\"") && picture.contains("class=\"rapid\""));
    // A bad program: the alarm with its line, non-zero exit, no cycle time.
    std::fs::write(&program, "G00 X50\nG02 X60 Z-10 R1\nM30\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("simulate")
        .arg(&program)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("line 2"), "{err}");
}

#[test]
fn check_uses_the_offset_page_of_the_launch_config() {
    // Fixture 053 (G42 with T1): the config's offset 1 has nose radius 0.4, tip 3.
    let program = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/fixtures/000/053_tnrc_outer_G42.nc"
    );
    let (ok, text) = cnc(&["check", program, "--trace"]);
    assert!(ok && text.contains("no alarm"), "{text}");
    // The start-up move ends off the programmed X26 Z131, and outer corners get R0.4 arcs.
    assert!(!text.contains("LINEAR X26.0000 Z131.0000"), "{text}");
    assert!(text.contains("CX29.2000 CZ128.6000"), "{text}");

    // A bad offset page is refused when the config is loaded.
    let dir = std::env::temp_dir().join(format!("cnc_cfg_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/launch_configs/sim_lathe.yaml"
    ))
    .unwrap()
    .replace("{ radius: 0.4, tip: 3 }", "{ radius: 0.4, tip: 12 }");
    let bad = dir.join("bad.yaml");
    std::fs::write(&bad, cfg).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["check", program, "--config"])
        .arg(&bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("machine.tools[1]"),
        "{err}"
    );
}

#[test]
fn plc_check_reports_the_standard_program_and_refuses_a_bad_one() {
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "plc-check",
            "nodes/plc/programs/lathe_standard.plc",
            "--rungs",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains(" steps, "), "{text}");
    assert!(text.contains("RD.NOT ESTOP_OK | WRT ESTOP"), "{text}");
    let bad = std::env::temp_dir().join(format!("cnc_bad_{}.plc", std::process::id()));
    std::fs::write(&bad, "RD X0.0\nAND.STK\nEND1\nEND2\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("plc-check")
        .arg(&bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("line 2: AND.STK needs two stack entries"),
        "{err}"
    );
    let _ = std::fs::remove_file(&bad);
}

#[test]
fn the_802d_manuals_cycle_examples_run_as_printed_on_the_built_in_mill() {
    // Fixtures 092–117 (§10), each a whole listing as the manual prints it, on the built-in
    // sim_mill_802d: its offset page holds the tools they call (T20 D1 is entry 201), its Z
    // travel their clearance heights, and 107's subprogram comes from the listing itself
    // (the transfer format, D95). The cycles of 100 and 101 stop with M0 for the operator.
    // Two listings cannot run as printed, each stopped with its alarm: 103 has a line `.`
    // where the manual leaves the machining out, 117 passes DP and never defines it.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/fixtures/001");
    let mut listings: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            name.ends_with(".mpf") && ("092".."118").contains(&&name[..3])
        })
        .collect();
    listings.sort();
    assert_eq!(listings.len(), 26);
    for path in listings {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let listing = path.to_string_lossy();
        let (ok, text) = cnc(&["simulate", "--config", "sim_mill_802d", &listing]);
        let expected_alarm = match &name[..3] {
            "103" => Some("alarm 12080 at line 12"),
            "117" => Some("alarm 12550 at line 11: DP is not defined"),
            _ => None,
        };
        match expected_alarm {
            Some(alarm) => assert!(!ok && text.contains(alarm), "{name}: {text}"),
            None => {
                assert!(ok && text.contains("cycle time: "), "{name}: {text}");
                let stops = ["100", "101"].contains(&&name[..3]);
                assert_eq!(text.contains("program stops: 1,"), stops, "{name}: {text}");
            }
        }
    }
}

/// Issue 46 item 4: `cnc check` starts with the tool the machine holds: given by
/// `--tool-in-spindle` (or the config's `machine.tool_in_spindle`); without one, a program
/// that selects an edge of the tool in the spindle is refused with 17190.
#[test]
fn check_starts_with_the_tool_in_the_spindle() {
    let dir = std::env::temp_dir().join(format!("cnc_cli_spindle_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let config = std::fs::read_to_string(format!("{root}/launch_configs/sim_mill_802d.yaml"))
        .unwrap()
        .replace("tool_change_with_m6: false", "tool_change_with_m6: true");
    let config_path = dir.join("m6.yaml");
    std::fs::write(&config_path, config).unwrap();
    let program = dir.join("EDGE.MPF");
    std::fs::write(&program, "D1\nG0 X0 Y0 Z10\nM30\n").unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "check",
            program.to_str().unwrap(),
            "--config",
            config_path.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        cnc(&a)
    };
    let (ok, text) = args(&[]);
    assert!(!ok && text.contains("17190"), "{text}");
    let (ok, text) = args(&["--tool-in-spindle", "1"]);
    assert!(ok, "{text}");
    let (ok, text) = args(&["--tool-in-spindle", "40000"]);
    assert!(!ok, "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 49 (D138): `cnc check --trace` and `cnc simulate` on the turn-mill prove a C-axis
/// program without the machine: the trace names C's angle, way and speed; the simulation turns
/// the spindle as the simulated drive positions it, so three turns of C with Z geared to it
/// take their time and keep every axis within its velocity and acceleration. Polar
/// interpolation and a live tool tap show C and the live tool in the trace.
#[test]
fn check_and_simulate_show_the_turn_mills_c_axis() {
    let dir = std::env::temp_dir().join(format!("cnc_cli_turnmill_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("c_axis.nc");
    std::fs::write(
        &program,
        "G00 X50 Z0\nG98 F100\nM14.6\nG08 C90 F1000\nG01 U-1.5\nG08 H1080 Z4.5 F800\nM15\nM30\n",
    )
    .unwrap();
    let path = program.to_string_lossy();
    let (ok, text) = cnc(&["check", "--config", "sim_turnmill", "--trace", &path]);
    assert!(ok, "{text}");
    assert!(
        text.contains("ROTARY X50.0000 Z0.0000 C90.0000 A0.0000 TO90.000 Plus S1000.0"),
        "{text}"
    );
    assert!(
        text.contains("ROTARY X48.5000 Z4.5000 C1170.0000 A0.0000 BY1080.000 Incremental S800.0"),
        "{text}"
    );
    let (ok, text) = cnc(&["simulate", "--config", "sim_turnmill", &path]);
    assert!(ok, "{text}");
    let number = |key: &str| -> f64 {
        let line = text.lines().find(|l| l.starts_with(key)).expect(key);
        line[key.len()..]
            .trim()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    // Three turns at 800 r/min are 0.225 s; C to 90° and the infeed come on top.
    assert!(number("cycle time:") > 0.225 + 0.1, "{text}");
    assert!(number("max axis velocity / limit:") <= 1.0 + 1e-6, "{text}");
    assert!(
        number("max axis acceleration / limit:") <= 1.0 + 1e-6,
        "{text}"
    );
    let (ok, text) = cnc(&["check", &path]);
    assert!(
        !ok && text.contains("alarm 74 at line 3"),
        "sim_lathe: {text}"
    );
    // Polar interpolation, a live tool tap and a cross hole (D141, D142, D143): the trace shows
    // C in degrees on the face's lines, the live tool's A turning with the tap and its speed
    // for the drilling; simulate runs them.
    let face = dir.join("face.nc");
    std::fs::write(
        &face,
        "T0303\nG00 X40 Z0\nM14.6\nG00 C0\nG12.1\nG98\nG01 X30 F600\nG01 C15\nG13.1\n\
         G00 X0 Z5\nG14.4 Z-5 R500 F1\nG00 X60 Z-5\nM65 S1200\nG87 Z-5 C90 X40 F200\nM66\n\
         G00 X100\nM15\nM30\n",
    )
    .unwrap();
    let face = face.to_string_lossy();
    let (ok, text) = cnc(&["check", "--config", "sim_turnmill", "--trace", &face]);
    assert!(ok, "{text}");
    // The line to C15 at X30 (radius 15) ends at 45° and X 2·√(15² + 15²).
    let end = format!("LINEAR X{:.4} Z0.0000 C45.0000", 60.0 / 2f64.sqrt());
    assert!(
        text.contains("C_CONTOUR_ON") && text.contains(&end),
        "{text}"
    );
    assert!(
        text.contains("LINEAR X0.0000 Z-5.0000 C45.0000 A3600.0000"),
        "{text}"
    );
    // A cross hole with the live tool turning (D143): its speed, the hole at C90, the stop.
    for want in [
        "LIVE_TOOL S1200.0",
        "ROTARY X60.0000 Z-5.0000 C90.0000 A0.0000 TO90.000 Plus",
        "LINEAR X40.0000 Z-5.0000 C90.0000 A0.0000 F200.0000",
        "LIVE_TOOL_STOP",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }
    let (ok, text) = cnc(&["simulate", "--config", "sim_turnmill", &face]);
    assert!(ok, "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}
