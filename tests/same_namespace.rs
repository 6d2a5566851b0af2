//! Issue 29: two controllers started with the same namespace and domain on one host. The
//! second refuses to start, saying why, before it opens any channel or DDS participant; the
//! first is not disturbed: it goes on answering and runs a part to its end. Both run as their
//! own processes (`cnc run`), as they would on a host.

use std::time::{Duration, Instant};

mod common;

use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_runtime::LaunchConfig;
use ros2_client::ServiceMapping;

const DOMAIN: u16 = 75;
const PART: &str = "O0001\nG00 X60 Z5\nS600 M03\nG01 X50 F3000\nZ-5\nG00 X60\nM05\nM30\n";

#[test]
fn a_second_controller_with_the_same_namespace_is_refused_and_the_first_runs_on() {
    let dir = common::fresh_dir("cnc_same_ns");
    let config = common::sim_lathe_file(&dir, "lathe.yaml", DOMAIN, |_| {});
    let cfg = LaunchConfig::load(&config).expect("config");
    let mut first = common::KillOnDrop(common::cnc_run(&config, &dir.join("first.log")));
    let mut client = CellClient::new(
        &cfg.network,
        "lathe1",
        "supervisor",
        ServiceMapping::Enhanced,
    )
    .expect("client");
    client
        .wait_ready(Duration::from_secs(60))
        .expect("the first is ready");
    let r = client.load_program("part.nc", PART).expect("load");
    assert!(r.accepted, "{}", r.message);

    // The second: same config, same host. It must end on its own, refused.
    let mut second = common::cnc_run(&config, &dir.join("second.log"));
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = second.try_wait().expect("wait") {
            break s;
        }
        if t0.elapsed() > Duration::from_secs(30) {
            let _ = second.kill();
            let _ = second.wait();
            panic!("the second controller did not refuse to start");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let said = std::fs::read_to_string(dir.join("second.log")).unwrap_or_default();
    println!("the second said: {said}");
    assert!(!status.success(), "the second exited with success");
    assert!(
        said.contains("machine lathe1 (DDS domain 75) already runs on this host")
            && said.contains(&format!("process {}", first.0.id())),
        "{said}"
    );

    // The first is undisturbed: still running, ready, and it makes a part.
    assert!(
        first.0.try_wait().expect("wait").is_none(),
        "the first ended"
    );
    client.poll();
    let before = client.part_count.as_ref().map_or(0, |p| p.count);
    let r = client.start_program("part.nc").expect("start");
    assert!(r.accepted, "{}", r.message);
    let t0 = Instant::now();
    loop {
        client.poll();
        let done = client
            .state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED);
        let counted = client.part_count.as_ref().map_or(0, |p| p.count) > before;
        if done && counted {
            break;
        }
        assert!(
            client.alarms.as_ref().is_none_or(|a| a.alarms.is_empty()),
            "an alarm on the first: {:?}",
            client.alarms
        );
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "the part did not end"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(client);
    drop(first);
    let _ = std::fs::remove_dir_all(&dir);
}
