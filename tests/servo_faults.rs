//! Killing the io process (the drives) stops the motion node's output within 3 servo ticks:
//! from the third tick without feedback the setpoints carry `enable` 0 and no longer move.
//! Runs io as its own process (`cnc node io`) and motion in this one, on DDS domain 47 and
//! their own iceoryx2 instance.

use std::process::{Child, Command};
use std::time::{Duration, Instant};

use cnc_msgs::servo::{ServoFeedback, ServoSetpoint};
use cnc_runtime::shm::{channel, instance, ShmNode};
use cnc_runtime::{LaunchConfig, Shutdown};

const DOMAIN: u16 = 47;

/// Kills the child if the test ends early.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn killing_io_stops_the_motion_output_within_three_ticks() {
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/launch_configs/sim_lathe.yaml"
    ))
    .expect("sim_lathe.yaml");
    // The default of 3 ticks, a namespace of its own, a domain of its own.
    let text = base
        .replace("namespace: lathe1", "namespace: faults")
        .replace("feedback_lost_ticks: 25", "feedback_lost_ticks: 3")
        .replace("memory_file: state/lathe1_memory.yaml", "")
        .replace(
            "interfaces: [127.0.0.1]",
            &format!("interfaces: [127.0.0.1]\n  domain_id: {DOMAIN}"),
        );
    let dir = std::env::temp_dir().join(format!("cnc_faults_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("faults.yaml");
    std::fs::write(&path, &text).unwrap();
    let cfg = LaunchConfig::load(&path).expect("config");
    assert_eq!(cfg.servo.feedback_lost_ticks, 3);

    let io = Killed(
        Command::new(env!("CARGO_BIN_EXE_cnc"))
            .args(["node", "io"])
            .arg(&path)
            .spawn()
            .expect("cnc node io"),
    );
    let inst = instance(&cfg.machine.namespace, DOMAIN);
    let shutdown = Shutdown::default();
    let (c, i, s) = (cfg.clone(), inst.clone(), shutdown.clone());
    let motion = std::thread::spawn(move || cnc_motion::node::run(c, i, s));

    // Watch what motion sends and what the drives answer.
    let shm = ShmNode::new(&inst, "fault_watch").expect("iceoryx2");
    let setpoints = shm
        .receiver::<ServoSetpoint>(channel::SETPOINT, false)
        .expect("setpoints");
    let feedback = shm
        .receiver::<ServoFeedback>(channel::FEEDBACK, false)
        .expect("feedback");
    let mut seen: Vec<ServoSetpoint> = Vec::new();
    let mut last_answered = 0u64;
    let watch = |until: Instant, seen: &mut Vec<ServoSetpoint>, last: &mut u64| {
        while Instant::now() < until {
            while let Ok(Some(sp)) = setpoints.latest() {
                if seen.last().is_none_or(|l| l.seq < sp.seq) {
                    seen.push(sp);
                }
            }
            while let Ok(Some(fb)) = feedback.latest() {
                *last = (*last).max(fb.seq);
            }
            std::thread::sleep(Duration::from_micros(500));
        }
    };
    // The loop runs with the drives answering.
    let start = Instant::now();
    while last_answered < 100 && start.elapsed() < Duration::from_secs(60) {
        watch(
            Instant::now() + Duration::from_millis(100),
            &mut seen,
            &mut last_answered,
        );
    }
    assert!(last_answered >= 100, "the drives never answered");

    drop(io); // SIGKILL: the drives are gone
    watch(
        Instant::now() + Duration::from_millis(500),
        &mut seen,
        &mut last_answered,
    );
    shutdown.request();
    motion.join().expect("motion thread").expect("motion node");

    // The setpoint answered last is L; L+1 is computed with its answer, L+2 and L+3 are the
    // first and second ticks without one, L+4 the third: from there the servo is off.
    let cut = last_answered + 4;
    let after: Vec<&ServoSetpoint> = seen.iter().filter(|s| s.seq >= cut).collect();
    assert!(
        after.len() > 10,
        "motion kept ticking: {} setpoints",
        after.len()
    );
    assert!(
        after.iter().all(|s| s.enable == 0),
        "enabled after the third tick without feedback: {:?}",
        after.iter().find(|s| s.enable != 0).map(|s| s.seq)
    );
    assert!(after.windows(2).all(|w| w[0].position == w[1].position));
    // The setpoints before were enabled: the fault, not a start-up state, switched them off.
    assert!(seen.iter().any(|s| s.seq < cut && s.enable == 1));
    let _ = std::fs::remove_dir_all(&dir);
}
