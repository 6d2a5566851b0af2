//! Issue 28, must-show 1 without DDS: the simulated lathe with incremental encoders (a dog and
//! index marks per axis) and the motion core in one deterministic loop on a simulated clock.
//! From power-on: nothing knows where the slides are, a run is refused with alarm 224; the
//! reference return takes X, then Z, fast onto the dog, slow off it, to the first index mark;
//! each axis then stands on its reference point within one encoder count (0.001 mm), in the
//! machine's coordinates and in the simulator's; then a program's move runs to its end point.
//! A machine whose dog is missing ends its reference return with alarm 1094.

use std::path::Path;

mod common;

use cnc_io::node::sim_config;
use cnc_io::SimLathe;
use cnc_motion::motion::ReferenceInputs;
use cnc_motion::{Block, Command, FromLaunch, Motion, MotionConfig, MotionEvent, RunState};
use cnc_msgs::servo::ServoSetpoint;
use cnc_msgs::signals::{f, GImage, SignalTable, YImage};
use cnc_runtime::LaunchConfig;

/// One encoder count, mm.
const COUNT: f64 = 0.001;

/// `launch_configs/sim_lathe.yaml` with incremental encoders on both axes.
fn incremental_lathe(dog_length: f64) -> LaunchConfig {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("launch_configs/sim_lathe.yaml");
    let mut v: serde_yaml::Value =
        serde_yaml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for axis in v["machine"]["axes"].as_sequence_mut().unwrap() {
        axis["reference"] = serde_yaml::from_str(&format!(
            "{{ slow_feed: 300, grid: 5, dog_length: {dog_length} }}"
        ))
        .unwrap();
    }
    let text = serde_yaml::to_string(&v).unwrap();
    LaunchConfig::from_yaml_in(&text, Path::new("/tmp"), None).unwrap()
}

/// The machine and the control, ticked together.
struct Rig {
    sim: SimLathe,
    motion: Motion,
    feedback: cnc_msgs::servo::ServoFeedback,
    plc: GImage,
    period: f64,
    /// Per axis, the first and last tick its slide moved (more than 0.25 mm/s), as the
    /// simulator saw it.
    moved: Vec<Option<(usize, usize)>>,
    ticks: usize,
    alarms: Vec<u32>,
}

impl Rig {
    fn new(cfg: &LaunchConfig) -> Rig {
        let mut sim = SimLathe::new(sim_config(cfg), &cfg.power_on_slide());
        let feedback = sim.step(&ServoSetpoint::default(), &YImage::default(), 0.0);
        let n = cfg.machine.axes.len();
        let motion = Motion::new(MotionConfig::from_launch(cfg), &feedback.position[..n]);
        Rig {
            sim,
            motion,
            feedback,
            plc: GImage::released(),
            period: cfg.servo.period_ms / 1000.0,
            moved: vec![None; n],
            ticks: 0,
            alarms: Vec::new(),
        }
    }

    fn tick(&mut self) {
        let n = self.motion.commanded().len();
        self.motion.reference_inputs(ReferenceInputs {
            dog: self.feedback.reference_dog,
            marker: self.feedback.marker,
            marker_position: self.feedback.marker_position,
        });
        self.motion.overtravel_inputs(
            self.feedback.overtravel_plus,
            self.feedback.overtravel_minus,
        );
        let before = self.sim.position().to_vec();
        let mut sp = ServoSetpoint {
            enable: 1,
            axis_count: n as u32,
            ..ServoSetpoint::default()
        };
        let actual = self.feedback.position;
        sp.position[..n].copy_from_slice(self.motion.tick(Some(&actual[..n]), &self.plc));
        self.feedback = self.sim.step(&sp, &YImage::default(), self.period);
        self.ticks += 1;
        for (i, (a, b)) in before.iter().zip(self.sim.position()).enumerate() {
            if (a - b).abs() > 0.001 {
                let first = self.moved[i].map_or(self.ticks, |(f, _)| f);
                self.moved[i] = Some((first, self.ticks));
            }
        }
        for e in self.motion.take_events() {
            let MotionEvent::Alarm { number, .. } = e;
            self.alarms.push(number);
        }
    }

    fn run_until(&mut self, max_ticks: usize, mut done: impl FnMut(&Rig) -> bool) -> bool {
        for _ in 0..max_ticks {
            self.tick();
            if done(self) {
                return true;
            }
        }
        false
    }
}

fn rapid(seq: u64, run_id: u64, end: &[f64]) -> Block {
    Block {
        run_id,
        seq,
        line: 1,
        kind: Command::Rapid { end: end.to_vec() },
    }
}

#[test]
fn from_power_on_a_start_is_refused_the_axes_find_their_reference_points_then_a_move_runs() {
    let cfg = incremental_lathe(20.0);
    let home = cfg.home();
    let mut rig = Rig::new(&cfg);
    assert_eq!(rig.motion.referenced(), &[false, false]);
    // The encoders count from 0 at power-on; the slides stand 95 mm (X: diameter) before home.
    println!(
        "power-on: slides at {:?} (machine), encoders {:?}",
        rig.sim.position(),
        &rig.feedback.position[..2]
    );
    assert_eq!(&rig.feedback.position[..2], &[0.0, 0.0]);

    // A run is refused, and moves nothing.
    rig.motion.push(rapid(1, 7, &[150.0, 50.0]));
    rig.run_until(50, |_| false);
    assert_eq!(rig.alarms, [cnc_motion::alarm::REFERENCE_NOT_DONE]);
    assert!(
        rig.moved.iter().all(Option::is_none),
        "moved {:?}",
        rig.moved
    );
    // Under the alarm motion refuses a reference return, with the reason its shell raises as
    // warning 1095 (D68).
    let refused = rig
        .motion
        .reference_return()
        .expect_err("refused under an alarm");
    assert!(refused.contains("reset first"), "{refused}");
    assert!(!rig.motion.referencing());
    rig.motion.reset();
    rig.alarms.clear();
    rig.run_until(30, |_| false);

    // Reference return: X, then Z.
    let m = rig.motion.reference_return().expect("started");
    assert!(m.contains("X, Z"), "{m}");
    let mut saw_mref = false;
    let ok = rig.run_until(20_000, |r| {
        saw_mref |= r.motion.f_image().get(f::MREF);
        !r.motion.referencing()
    });
    assert!(ok, "the reference return did not end");
    assert!(saw_mref, "F4.5 MREF never on");
    assert!(rig.alarms.is_empty(), "alarms {:?}", rig.alarms);
    let (x, z) = (rig.moved[0].unwrap(), rig.moved[1].unwrap());
    println!("X moved in ticks {x:?}, Z in {z:?}");
    assert!(x.1 < z.0, "X first, then Z: {x:?} {z:?}");
    assert_eq!(rig.motion.referenced(), &[true, true]);
    assert_eq!(rig.motion.state(), RunState::Idle);
    // Let the drives settle on the point.
    rig.run_until(100, |_| false);
    let scale = [0.5, 1.0];
    for i in 0..2 {
        let machine = rig.motion.actual()[i] / scale[i];
        let slide = rig.sim.position()[i] / scale[i];
        println!(
            "axis {i}: machine {machine:.6}, simulator {slide:.6}, home {}",
            home[i]
        );
        assert!((machine - home[i]).abs() <= COUNT, "axis {i} at {machine}");
        assert!(
            (slide - home[i]).abs() <= COUNT,
            "axis {i} really at {slide}"
        );
    }
    assert!(rig.motion.f_image().get(f::zp(0)) && rig.motion.f_image().get(f::zp(2)));

    // Now a program's move runs, to where it says, in the machine's coordinates.
    rig.motion.push(rapid(1, 8, &[150.0, 50.0]));
    let ok = rig.run_until(5_000, |r| r.motion.done_seq() == 1);
    assert!(ok && rig.alarms.is_empty(), "alarms {:?}", rig.alarms);
    rig.run_until(100, |_| false);
    let at: Vec<f64> = rig
        .sim
        .position()
        .iter()
        .zip(scale)
        .map(|(p, s)| p / s)
        .collect();
    assert!(
        (at[0] - 150.0).abs() < COUNT && (at[1] - 50.0).abs() < COUNT,
        "{at:?}"
    );
}

#[test]
fn a_missing_dog_ends_the_reference_return_on_the_overtravel_switch_or_within_the_travel() {
    // A dog of length 0 is never seen pressed: X runs on to its + overtravel switch (alarm
    // 40); on a machine whose switches are out of reach, the travel guard stops it (1094).
    for (switches, alarm) in [
        (None, cnc_motion::alarm::OVERTRAVEL_PLUS),
        (Some([-1e6, 1e6]), cnc_motion::alarm::REFERENCE_FAILED),
    ] {
        let mut cfg = incremental_lathe(20.0);
        cfg.machine.axes[0].reference.as_mut().unwrap().dog_length = 1e-9;
        cfg.machine.axes[0].overtravel = switches;
        let mut rig = Rig::new(&cfg);
        rig.motion.reference_return().expect("started");
        let ended = rig.run_until(200_000, |r| !r.motion.referencing());
        assert!(ended);
        assert_eq!(rig.alarms, [alarm], "switches {switches:?}");
        assert_eq!(rig.motion.referenced(), &[false, false]);
    }
}

/// The same through the whole cell on DDS (runs in scripts/test.sh's network namespace): a
/// supervisor's start is refused with alarm 224 after power-on; in HOME mode cycle start
/// returns X and Z to their reference points, `axes.homed` turns true and the positions are
/// the configured ones within one encoder count; back in AUTO the part runs to its end.
#[test]
fn the_cell_powers_up_unreferenced_and_runs_a_part_after_its_reference_return() {
    use cnc::cell::Cell;
    use cnc_cell::client::CellClient;
    use cnc_msgs::msg::MachineState;
    use cnc_runtime::config::ReferenceEntry;
    use std::time::{Duration, Instant};

    let mut cfg = common::sim_lathe(78);
    for a in &mut cfg.machine.axes {
        a.reference = Some(ReferenceEntry {
            positive: true,
            fast_feed: None,
            slow_feed: 300.0,
            grid: 5.0,
            dog_length: 20.0,
            power_on: None,
        });
    }
    let home = cfg.home();
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut c = common::ready_client(&cfg, "supervisor", Duration::from_secs(30));
    let part = "O0001\nG00 X150 Z50\nS600 M03\nG01 X140 Z40 F2000\nG00 X180 Z80\nM05\nM30\n";
    assert!(c.load_program("part.nc", part).expect("load").accepted);
    let wait_axes =
        |c: &mut CellClient, what: &str, ok: &dyn Fn(&cnc_msgs::msg::AxisState) -> bool| {
            common::wait(c, Duration::from_secs(90), what, |c| {
                c.axes.as_ref().is_some_and(ok)
            })
        };
    wait_axes(&mut c, "axes state", &|a| a.axes.iter().all(|x| !x.homed));
    // The machine left WAIT (ready_client) only after the PLC's first scan as well: before
    // it the PLC's interface holds the emergency stop, and motion would refuse the reference
    // return (1095).

    // Power-on: the start is refused with the alarm number.
    let r = c.start_program("part.nc").expect("start");
    println!("start before the reference return: {}", r.message);
    assert!(!r.accepted && r.message.contains("224"), "{}", r.message);

    // HOME mode, cycle start: the reference return.
    common::set_mode(&mut c, MachineState::MODE_HOME);
    let t0 = Instant::now();
    let r = c.start_program("").expect("start");
    assert!(r.accepted, "{}", r.message);
    wait_axes(&mut c, "reference return", &|a| {
        a.axes.iter().all(|x| x.homed)
    });
    println!("reference return took {:.1} s", t0.elapsed().as_secs_f64());
    // Settled on the reference points.
    std::thread::sleep(Duration::from_millis(300));
    c.poll();
    let axes = c.axes.clone().expect("axes");
    for (x, h) in axes.axes.iter().zip(&home) {
        println!("{}: {:.4} (reference point {h})", x.name, x.actual_position);
        assert!(
            (x.actual_position - h).abs() <= COUNT,
            "{} at {}",
            x.name,
            x.actual_position
        );
    }

    // AUTO: the part runs.
    common::set_mode(&mut c, MachineState::MODE_AUTO);
    let r = c.start_program("part.nc").expect("start");
    assert!(r.accepted, "{}", r.message);
    common::wait(&mut c, Duration::from_secs(60), "part", |c| {
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
    });
    std::thread::sleep(Duration::from_millis(300));
    c.poll();
    let end: Vec<f64> = c
        .axes
        .as_ref()
        .unwrap()
        .axes
        .iter()
        .map(|x| x.actual_position)
        .collect();
    assert!(
        (end[0] - 180.0).abs() < 0.005 && (end[1] - 80.0).abs() < 0.005,
        "{end:?}"
    );
    drop(c);
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}

/// The lathe as shipped (absolute encoders), in the rig.
fn absolute_lathe() -> LaunchConfig {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("launch_configs/sim_lathe.yaml");
    LaunchConfig::load(&path).unwrap()
}

/// Display position of axis `i` as the simulator has it.
fn slide(rig: &Rig, i: usize) -> f64 {
    let scale = [0.5, 1.0];
    rig.sim.position()[i] / scale[i]
}

#[test]
fn a_held_jog_moves_at_its_feed_and_stops_within_200_ms_of_the_last_request() {
    let mut rig = Rig::new(&absolute_lathe());
    let start = slide(&rig, 0);
    // X+ at 600 mm/min (diameter), the request repeated every 40 ms for one second.
    for k in 0..250 {
        if k % 10 == 0 {
            rig.motion.jog(0, true, 600.0, None).expect("jog");
        }
        rig.tick();
    }
    let moved = slide(&rig, 0) - start;
    println!("one second of X+ jog at 600 mm/min: {moved:.3} mm");
    assert!((moved - 10.0).abs() < 0.5, "{moved}");
    // Another axis is refused while X moves.
    assert!(rig.motion.jog(1, true, 600.0, None).is_err());
    // The requests stop: the slide stands within 200 ms (50 ticks) of the last one (at tick
    // 240, 10 ticks ago).
    let mut still_after = None;
    for t in 0..100 {
        let before = slide(&rig, 0);
        rig.tick();
        // Standing: less than 0.25 mm/s (the drive's lag settles after that).
        if (slide(&rig, 0) - before).abs() < COUNT && !rig.motion.jogging() {
            still_after = Some(10 + t + 1);
            break;
        }
    }
    let ticks = still_after.expect("the jog did not stop");
    println!("stopped {} ms after the last request", ticks * 4);
    assert!(ticks * 4 <= 200, "{ticks} ticks");
    assert!(rig.alarms.is_empty(), "{:?}", rig.alarms);
}

#[test]
fn an_increment_moves_exactly_its_step_and_a_jog_stops_at_the_soft_limit() {
    let mut rig = Rig::new(&absolute_lathe());
    for (axis, positive, step) in [
        (0, true, 0.001),
        (0, false, 0.1),
        (1, false, 1.0),
        (1, true, 10.0),
    ] {
        let start = slide(&rig, axis);
        rig.motion
            .jog(axis, positive, 1000.0, Some(step))
            .expect("increment");
        assert!(rig.run_until(5_000, |r| !r.motion.jogging()));
        rig.run_until(50, |_| false);
        let moved = slide(&rig, axis) - start;
        let want = if positive { step } else { -step };
        println!("axis {axis} increment {want}: moved {moved:.4}");
        assert!((moved - want).abs() <= COUNT / 2.0, "{moved} for {want}");
    }
    // Z+ held toward its soft limit (max 100 + from the config) stops on it.
    let max = absolute_lathe().machine.axes[1].max;
    for k in 0..10_000 {
        if k % 10 == 0 {
            rig.motion.jog(1, true, 6000.0, None).expect("jog");
        }
        rig.tick();
        if slide(&rig, 1) > max + COUNT {
            panic!("past the soft limit: {}", slide(&rig, 1));
        }
        if k > 2_000 {
            break;
        }
    }
    rig.run_until(100, |r| !r.motion.jogging());
    println!(
        "Z held toward +: stands at {:.4} (soft limit {max})",
        slide(&rig, 1)
    );
    assert!((slide(&rig, 1) - max).abs() < 0.01);
}

/// Jog through the cell's `jog` service (runs in scripts/test.sh's network namespace): refused
/// in AUTO; in JOG mode a held jog moves at its feed; the client then disappears and the axis
/// stands soon after its last request (dead man), measured on the `axes` topic's time stamps
/// (177–196 ms on an idle machine); an increment moves exactly its step.
#[test]
fn a_robot_jogs_through_the_jog_service_and_its_disappearance_stops_the_axis() {
    use cnc::cell::Cell;
    use cnc_cell::client::CellClient;
    use cnc_msgs::msg::MachineState;
    use cnc_msgs::srv::{Jog, JogRequest};
    use std::time::{Duration, Instant};

    let cfg = common::sim_lathe(79);
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut watch = common::ready_client(&cfg, "jog_watch", Duration::from_secs(30));
    let x = |c: &CellClient| {
        c.axes
            .as_ref()
            .map_or(f64::NAN, |a| a.axes[0].actual_position)
    };
    let request = |direction: i8, feed: f64, increment: f64| JogRequest {
        axis: "X".into(),
        direction,
        feed,
        increment,
    };
    let mut robot = common::ready_client(&cfg, "robot", Duration::from_secs(30));
    let robot_jog = robot.service::<Jog>("jog").expect("jog client");
    let jog = |client: &cnc_cell::client::ServiceClient<Jog>, direction, feed, increment| {
        client
            .call(request(direction, feed, increment))
            .expect("jog answered")
    };
    // The service is discovered once; the first call may wait for it.
    let r = jog(&robot_jog, 1, 1200.0, 0.0);
    assert!(!r.accepted && r.message.contains("AUTO"), "{}", r.message);
    common::set_mode(&mut robot, MachineState::MODE_JOG);

    // Held for one second: a request every 50 ms.
    watch.poll();
    let start = x(&watch);
    let t0 = Instant::now();
    let mut last_request = t0;
    while t0.elapsed() < Duration::from_secs(1) {
        let r = jog(&robot_jog, 1, 1200.0, 0.0);
        assert!(r.accepted, "{}", r.message);
        last_request = Instant::now();
        std::thread::sleep(Duration::from_millis(50));
        watch.poll();
    }
    // The robot is gone: no more requests, its participant closed. The axes samples of the
    // next second, by motion's time stamps: the first at the final position is an upper bound
    // of when X stood (samples come every 40 ms).
    let last_request_wall =
        std::time::SystemTime::now() - Instant::now().saturating_duration_since(last_request);
    drop(robot_jog);
    drop(robot);
    let mut samples: Vec<(std::time::SystemTime, f64)> = Vec::new();
    let gone = Instant::now();
    while gone.elapsed() < Duration::from_secs(1) {
        watch.poll();
        if let Some(a) = watch.axes.as_ref() {
            let t =
                std::time::UNIX_EPOCH + Duration::new(a.stamp.sec.max(0) as u64, a.stamp.nanosec);
            if samples.last().is_none_or(|(s, _)| *s != t) {
                samples.push((t, a.axes[0].actual_position));
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let end = samples.last().expect("axes samples").1;
    let stood = samples
        .iter()
        .find(|(_, x)| (x - end).abs() < 1e-4)
        .map(|(t, _)| *t)
        .expect("a sample at the end");
    let stop_ms = stood
        .duration_since(last_request_wall)
        .unwrap_or_default()
        .as_secs_f64()
        * 1000.0;
    let moved = x(&watch) - start;
    println!(
        "held jog: X moved {moved:.2} mm in {:.2} s; stood {stop_ms:.0} ms after the last request",
        last_request.duration_since(t0).as_secs_f64()
    );
    assert!(moved > 15.0 && moved < 25.0, "{moved}");
    // The 200 ms bound is asserted on the simulated clock (the rig test above). Here, on the
    // wall clock of a machine that may be busy, the figure is printed, and only a stop that
    // does not come within half a second fails: a loaded CI measured 200 ms once.
    assert!(
        stop_ms <= 500.0,
        "stood {stop_ms:.0} ms after the last request"
    );

    // An increment of 0.1 mm (diameter) from the watcher's own client.
    std::thread::sleep(Duration::from_millis(300));
    watch.poll();
    let before = x(&watch);
    let watch_jog = watch.service::<Jog>("jog").expect("jog client");
    let r = jog(&watch_jog, -1, 600.0, 0.1);
    assert!(r.accepted, "{}", r.message);
    std::thread::sleep(Duration::from_millis(800));
    watch.poll();
    let step = x(&watch) - before;
    println!("increment -0.1: moved {step:.4}");
    drop(watch_jog);
    assert!((step + 0.1).abs() <= COUNT, "{step}");
    drop(watch);
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}

#[test]
fn an_axis_on_its_overtravel_switch_stops_with_the_alarm_and_jogs_off_it_only_the_other_way() {
    // The + switch of X at 220 (diameter), inside the soft limit, as a misadjusted dog would be.
    let mut cfg = absolute_lathe();
    let max = cfg.machine.axes[0].max;
    cfg.machine.axes[0].overtravel = Some([-5.0, 220.0]);
    assert!(max > 225.0, "X max {max}");
    let mut rig = Rig::new(&cfg);
    let mut k = 0;
    while rig.alarms.is_empty() && k < 5_000 {
        if k % 10 == 0 {
            let _ = rig.motion.jog(0, true, 3000.0, None);
        }
        rig.tick();
        k += 1;
    }
    assert_eq!(rig.alarms, [cnc_motion::alarm::OVERTRAVEL_PLUS]);
    rig.run_until(50, |_| false);
    let stood = slide(&rig, 0);
    println!("X ran onto its + switch at 220: stands at {stood:.3}");
    assert!(
        (220.0..221.0).contains(&stood),
        "on the switch, past it by the stop: {stood}"
    );
    assert!(!rig.motion.jogging());
    // Reset: X+ is still refused, and so is a program; X− moves it off the switch.
    rig.motion.reset();
    rig.alarms.clear();
    rig.run_until(5, |_| false);
    let refused = rig.motion.jog(0, true, 600.0, Some(1.0)).unwrap_err();
    assert!(refused.contains("overtravel"), "{refused}");
    rig.motion.push(rapid(1, 9, &[150.0, 50.0]));
    rig.run_until(10, |_| false);
    assert_eq!(rig.alarms, [cnc_motion::alarm::OVERTRAVEL_PLUS]);
    rig.motion.reset();
    rig.alarms.clear();
    rig.run_until(5, |_| false);
    rig.motion
        .jog(0, false, 600.0, Some(2.0))
        .expect("jog off the switch");
    assert!(rig.run_until(2_000, |r| !r.motion.jogging()));
    rig.run_until(50, |_| false);
    assert!(!rig.motion.overtravel_pressed());
    assert!(rig.alarms.is_empty(), "{:?}", rig.alarms);
    rig.motion
        .jog(0, true, 600.0, Some(0.5))
        .expect("X+ again, off the switch");
}

/// Asks the web panel at `address` for a jog of X and returns its reply frame.
fn panel_jog(address: &str, direction: i8, increment: f64) -> serde_json::Value {
    use std::time::{Duration, Instant};
    let url = format!("ws://{address}/ws");
    let t0 = Instant::now();
    let (mut ws, _) = loop {
        match tungstenite::connect(url.as_str()) {
            Ok(c) => break c,
            Err(e) if t0.elapsed() < Duration::from_secs(10) => {
                println!("panel not there yet: {e}");
                std::thread::sleep(Duration::from_millis(200));
            }
            Err(e) => panic!("no panel at {address}: {e}"),
        }
    };
    let request = serde_json::json!({"id": 41, "op": "jog", "axis": "X",
        "direction": direction, "feed": 3000.0, "increment": increment});
    ws.send(tungstenite::Message::text(request.to_string()))
        .expect("request sent");
    while t0.elapsed() < Duration::from_secs(20) {
        if let Ok(tungstenite::Message::Text(t)) = ws.read() {
            let v: serde_json::Value = serde_json::from_str(&t).unwrap();
            if v["type"] == "reply" && v["id"] == 41 {
                return v;
            }
        }
    }
    panic!("no reply from the panel");
}

/// Overtravel through the cell (runs in scripts/test.sh's network namespace): a robot holds
/// X+ until X runs onto its switch; the alarm comes, `axes` shows X on its + switch, and a jog
/// is refused until the reset; then X+ is refused by name, through ROS 2 and through the web
/// panel alike — motion refuses it, and its reason is the answer (issue 47) — and X− takes it
/// off the switch.
#[test]
fn the_cell_stops_an_axis_on_its_overtravel_switch_and_lets_it_off_the_other_way() {
    use cnc::cell::Cell;
    use cnc_cell::client::CellClient;
    use cnc_msgs::msg::MachineState;
    use cnc_msgs::srv::{Jog, JogRequest};
    use std::time::{Duration, Instant};

    let mut cfg = common::sim_lathe(80);
    cfg.machine.axes[0].overtravel = Some([-5.0, 220.0]);
    let panel = "127.0.0.1:18780";
    cfg.hmi.web_address = panel.into();
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut c = common::ready_client(&cfg, "robot", Duration::from_secs(30));
    common::set_mode(&mut c, MachineState::MODE_JOG);
    let jog = c.service::<Jog>("jog").expect("jog client");
    let ask = |direction: i8, increment: f64| {
        jog.call(JogRequest {
            axis: "X".into(),
            direction,
            feed: 3000.0,
            increment,
        })
        .expect("jog answered")
    };
    let x_switch = |c: &CellClient| c.axes.as_ref().map_or(0, |a| a.axes[0].overtravel);
    let alarm_40 = |c: &CellClient| {
        c.alarms
            .as_ref()
            .is_some_and(|a| a.alarms.iter().any(|x| x.number == 40))
    };
    let t0 = Instant::now();
    while !alarm_40(&c) {
        let _ = ask(1, 0.0);
        std::thread::sleep(Duration::from_millis(50));
        c.poll();
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "no overtravel alarm"
        );
    }
    common::wait(
        &mut c,
        Duration::from_secs(5),
        "axes do not show the switch",
        |c| x_switch(c) == 1,
    );
    let r = ask(-1, 1.0);
    println!("jog during the alarm: {}", r.message);
    assert!(!r.accepted && r.message.contains("reset"), "{}", r.message);
    assert!(c.reset().expect("reset").accepted);
    std::thread::sleep(Duration::from_millis(300));
    c.poll();
    let r = ask(1, 0.5);
    println!("X+ on the switch after reset: {}", r.message);
    assert!(
        !r.accepted && r.message.contains("overtravel"),
        "{}",
        r.message
    );
    let reply = panel_jog(panel, 1, 0.5);
    println!("X+ from the panel: {reply}");
    assert_eq!(reply["accepted"], false);
    assert!(
        reply["message"]
            .as_str()
            .is_some_and(|m| m.contains("X is on its + overtravel switch")),
        "{reply}"
    );
    let r = ask(-1, 2.0);
    assert!(r.accepted, "{}", r.message);
    common::wait(&mut c, Duration::from_secs(5), "still on the switch", |c| {
        x_switch(c) == 0
    });
    std::thread::sleep(Duration::from_millis(300));
    c.poll();
    let x = c
        .axes
        .as_ref()
        .map_or(f64::NAN, |a| a.axes[0].actual_position);
    println!("off the switch at X {x:.3}");
    assert!(x < 220.0, "{x}");
    assert!(ask(1, 0.5).accepted);
    drop(jog);
    drop(c);
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}

/// Issue 28 end to end, the handwheel through the cell (D72): the external handwheel's
/// switches and the wheel's detents come over `sim/input` (as a networked pendant would, each
/// through the bridge's authority and audit), the io node's drives report the wheel's counter
/// with every feedback, the standard ladder turns the switches into G18 HS1 and G19 MP1, and
/// the motion node moves X 0.01 mm of diameter a detent at ×10, as `axes` shows.
#[test]
fn the_cell_moves_the_axis_the_handwheel_selects_by_its_detents() {
    use cnc::cell::Cell;
    use cnc_cell::client::CellClient;
    use cnc_msgs::msg::{MachineState, SimInput};
    use cnc_runtime::dds::RosNode;
    use cnc_runtime::topics;
    use std::time::{Duration, Instant};

    let cfg = common::sim_lathe(81);
    let cell = Cell::start(&cfg).expect("cell starts");
    let mut c = common::ready_client(&cfg, "robot", Duration::from_secs(30));
    common::set_mode(&mut c, MachineState::MODE_HANDWHEEL);
    let mut panel = RosNode::new(&cfg.network, "lathe1", "pendant").expect("pendant node");
    let keys = panel
        .dds_publisher::<SimInput>(&topics::SIM_INPUT)
        .expect("sim/input publisher");
    let x_actual = |c: &CellClient| c.axes.as_ref().map(|a| a.axes[0].actual_position);
    // Stands: two samples 200 ms apart agree.
    let settled = |c: &mut CellClient| {
        let mut last = None;
        loop {
            std::thread::sleep(Duration::from_millis(200));
            c.poll();
            let now = x_actual(c);
            if now.is_some() && now == last {
                return now.unwrap_or(f64::NAN);
            }
            last = now;
        }
    };
    let detent = |clockwise: bool| {
        keys.publish(SimInput {
            input: SimInput::HANDWHEEL_DETENT,
            value: clockwise,
        })
        .expect("detent sent");
        std::thread::sleep(Duration::from_millis(20));
    };
    let switches = || {
        for input in [SimInput::HANDWHEEL_SELECT_X, SimInput::HANDWHEEL_X10] {
            keys.publish(SimInput { input, value: true })
                .expect("switch sent");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let start = settled(&mut c);
    // What is sent before the pendant's writer is matched is lost: set the switches and turn
    // a detent until X moves.
    let t0 = Instant::now();
    while settled(&mut c) == start {
        switches();
        detent(true);
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "X never moved; alarms {:?}, state {:?}",
            c.alarms,
            c.state
        );
    }
    let from = settled(&mut c);
    for _ in 0..20 {
        detent(true);
    }
    for _ in 0..5 {
        detent(false);
    }
    let to = settled(&mut c);
    println!(
        "handwheel through the cell: X from {from:.4} to {to:.4} for 20 detents + and 5 − at ×10"
    );
    assert!(((to - from) - 0.15).abs() < 1e-6, "{from} → {to}");
    drop(keys);
    drop(panel);
    drop(c);
    let (_, failed) = cell.stop();
    assert!(failed.is_empty(), "nodes failed: {failed:?}");
}
