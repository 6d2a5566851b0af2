//! Issue 29, must-show 4: `cnc run <cell launch file>` runs two simulated lathes, the robot and
//! the cell supervisor in one process. The terminal shows the supervisor's view until the work
//! order is complete; each lathe's web panel, in headless Debian chromium, offers a machine
//! selector that opens the other's panel, where its parts count up. The file is the repository's
//! `launch_configs/cell_two_lathes.yaml` with this test's domain, ports and folders laid over it.
//! Runs in scripts/test.sh's network namespace, which also installs chromium and playwright-core.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

const DOMAIN: u16 = 85;
const PANELS: [&str; 2] = ["127.0.0.1:18185", "127.0.0.1:18186"];

#[test]
fn the_cell_launch_file_runs_two_lathes_robot_and_supervisor_shown_in_terminal_and_panels() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let playwright = root.join("target/npm/node_modules/playwright-core");
    assert!(
        playwright.is_dir(),
        "{} missing: run the tests with scripts/test.sh",
        playwright.display()
    );
    let dir = common::fresh_dir("cnc_cell_launch");
    let text = std::fs::read_to_string(root.join("launch_configs/cell_two_lathes.yaml"))
        .expect("cell_two_lathes.yaml");
    let mut v: serde_yaml::Value = serde_yaml::from_str(&text).expect("yaml");
    let cell = &mut v["cell"];
    cell["order"]["parts"] = 3.into();
    cell["order"]["program"] = root
        .join("examples/lathe/robot_part.nc")
        .display()
        .to_string()
        .into();
    cell["robot"]["swap_seconds"] = 1.0.into();
    cell["supervisor"]["records"] = dir.join("records/cell").display().to_string().into();
    let machines = cell["machines"].as_sequence_mut().expect("machines");
    for (k, m) in machines.iter_mut().enumerate() {
        m["config"] = root
            .join("launch_configs/sim_lathe.yaml")
            .display()
            .to_string()
            .into();
        let o = &mut m["override"];
        let ns = format!("lathe{}", k + 1);
        o["machine"]["namespace"] = ns.clone().into();
        for f in [
            "memory_file",
            "position_file",
            "parameter_file",
            "program_directory",
        ] {
            o["machine"][f] = dir.join(format!("{ns}_{f}")).display().to_string().into();
        }
        o["plc"]["memory_file"] = dir
            .join(format!("{ns}_plc.yaml"))
            .display()
            .to_string()
            .into();
        o["recorder"]["directory"] = dir
            .join(format!("records/{ns}"))
            .display()
            .to_string()
            .into();
        o["network"]["domain_id"] = DOMAIN.into();
        o["hmi"]["web_address"] = PANELS[k].into();
        // A loaded CI machine is not real-time: no alarms for late servo ticks.
        o["servo"]["late_warning_ms"] = 60000.0.into();
        o["servo"]["late_alarm_ticks"] = 1_000_000u32.into();
    }
    let file = dir.join("cell.yaml");
    std::fs::write(&file, serde_yaml::to_string(&v).expect("yaml")).expect("cell file");

    let mut child = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(&file)
        .stdout(Stdio::piped())
        .stderr(Stdio::from(
            std::fs::File::create(dir.join("cnc.log")).expect("log"),
        ))
        .spawn()
        .expect("cnc run");
    let stdout = child.stdout.take().expect("stdout");
    let lines = std::thread::spawn(move || {
        BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .inspect(|l| println!("cnc: {l}"))
            .collect::<Vec<String>>()
    });
    let mut child = common::KillOnDrop(child);
    let t0 = Instant::now();
    while PANELS
        .iter()
        .any(|a| std::net::TcpStream::connect(a).is_err())
    {
        assert!(t0.elapsed() < Duration::from_secs(60), "panels not served");
        std::thread::sleep(Duration::from_millis(100));
    }
    let mut browser = Command::new("node");
    browser
        .arg(root.join("tests/hmi/cell.cjs"))
        .arg(format!("http://{}/", PANELS[0]))
        .arg(format!("http://{}/", PANELS[1]))
        .env("PLAYWRIGHT_CORE", &playwright);
    let out = common::output_within(&mut browser, Duration::from_secs(300));
    println!("{}", String::from_utf8_lossy(&out.stdout));
    assert!(
        out.status.success(),
        "browser: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    // The order completes and `cnc run` ends by itself.
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.0.try_wait().expect("wait") {
            break s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(240),
            "the work order did not complete"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    let lines = lines.join().expect("stdout read");
    assert!(status.success(), "cnc run: {status}");
    let has = |s: &str| lines.iter().any(|l| l.contains(s));
    assert!(has("machine 'lathe1' running"), "{lines:?}");
    assert!(has("machine 'lathe2' running"), "{lines:?}");
    assert!(
        has("lathe1 producing: 1/3 parts") && has("lathe2 producing: 1/3 parts"),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.contains("lathe1 done: 3/3 parts") && l.contains("lathe2 done: 3/3 parts")),
        "{lines:?}"
    );
    assert!(has("work order 'demo' complete"), "{lines:?}");
    let bag = lines
        .iter()
        .find_map(|l| l.strip_prefix("supervisor's audit bag: "))
        .expect("the bag named");
    println!(
        "cnc audit verify: {}",
        common::cell_run::audit_verify(std::path::Path::new(bag))
    );
    let _ = std::fs::remove_dir_all(&dir);
}
