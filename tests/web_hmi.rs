//! The operator's web HMI in a real browser: headless Debian chromium, driven by playwright-core
//! (`tests/hmi/panel.cjs`), loads a program, starts it twice and once at line 5 (block search),
//! jogs X with the panel's keys in JOG mode (held, and a step), watches the line and the part
//! count advance, is refused MDI in AUTO and an out-of-range override, reads the offset page and
//! the live ladder, and runs an MDI block in MDI mode. The screenshot, taken while the program
//! runs, is kept at `target/hmi/panel.png`. The page's commands go through the services' command
//! path: they come back as command events naming the page. Runs in scripts/test.sh's network
//! namespace, which also installs chromium and playwright-core.

use std::path::PathBuf;
use std::time::{Duration, Instant};

mod common;

use cnc::cell::Cell;
use cnc_msgs::msg::CommandEvent;
use cnc_runtime::dds::RosNode;
use cnc_runtime::topics;

const DOMAIN: u16 = 54;
const ADDRESS: &str = "127.0.0.1:18054";

#[test]
fn the_operator_runs_a_program_from_the_web_hmi_in_chromium() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let playwright = root.join("target/npm/node_modules/playwright-core");
    assert!(
        playwright.is_dir(),
        "{} missing: run the tests with scripts/test.sh, which installs it",
        playwright.display()
    );
    let mut cfg = common::sim_lathe(DOMAIN);
    cfg.hmi.web_address = ADDRESS.into();
    let parameter_file =
        std::env::temp_dir().join(format!("cnc_web_parameters_{}.yaml", std::process::id()));
    let _ = std::fs::remove_file(&parameter_file);
    cfg.machine.parameter_file = Some(parameter_file.clone());
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut ros = RosNode::new(&cfg.network, "lathe1", "web_hmi_test").expect("node");
    let events = ros
        .dds_subscription::<CommandEvent>(&topics::COMMAND_EVENTS)
        .expect("events");

    // The page is served once the bridge runs.
    let t0 = Instant::now();
    while std::net::TcpStream::connect(ADDRESS).is_err() {
        assert!(t0.elapsed() < Duration::from_secs(20), "web HMI not served");
        std::thread::sleep(Duration::from_millis(50));
    }
    let shots = root.join("target/hmi");
    std::fs::create_dir_all(&shots).expect("target/hmi");
    let screenshot = shots.join("panel.png");
    let _ = std::fs::remove_file(&screenshot);
    let mut browser = std::process::Command::new("node");
    browser
        .arg(root.join("tests/hmi/panel.cjs"))
        .arg(format!("http://{ADDRESS}/"))
        .arg(&screenshot)
        .env("PLAYWRIGHT_CORE", &playwright);
    let out = common::output_within(&mut browser, std::time::Duration::from_secs(300));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "browser test failed:\n{stdout}\n{stderr}"
    );

    // The screenshot is a PNG of a real page.
    let png = std::fs::read(&screenshot).expect("screenshot kept");
    assert!(
        png.starts_with(b"\x89PNG") && png.len() > 20_000,
        "{} bytes",
        png.len()
    );

    // Every button went through the command path and was recorded with the page as client.
    let mut seen = Vec::new();
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(5) {
        while let Ok(Some((e, _))) = events.take() {
            seen.push(e);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let from_page = |command: &str, accepted: bool| {
        seen.iter()
            .filter(|e| {
                e.client == "web@127.0.0.1" && e.command == command && e.accepted == accepted
            })
            .count()
    };
    // Events published before this subscriber matched may be missed; the late ones are not.
    assert!(from_page("set_mode", true) >= 1, "{seen:#?}");
    assert!(from_page("jog", true) >= 2, "{seen:#?}");
    assert!(
        seen.iter()
            .any(|e| e.command == "start_program" && e.detail == "O0005 at line 5"),
        "{seen:#?}"
    );
    assert!(from_page("set_overrides", false) >= 1, "{seen:#?}");
    assert!(from_page("mdi", true) >= 1, "{seen:#?}");
    assert!(from_page("set_parameter", true) >= 1, "{seen:#?}");
    assert!(from_page("acknowledge_alarm", true) >= 1, "{seen:#?}");
    // The written parameter waits in the file for the next start.
    let next = cfg
        .clone()
        .with_parameter_file()
        .expect("parameter file applies");
    assert_eq!(next.servo.lookahead, 12);
    let _ = std::fs::remove_file(&parameter_file);
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}
