//! The turn-mill lathe (`sim_turnmill`, decision D138) through the whole chain on the PLC rig
//! (`rig/mod.rs`): the Huaxing front end, motion's positioned spindle and its gearing, the
//! ladder's M19 handshake and the simulated spindle drive. The manual's fixture 004 as one
//! program: at every positioning's FIN the spindle stands at the angle the block asks for,
//! having turned only the way the block says, and in the three-axis G08 the slides follow
//! its angle.

mod common;
#[path = "rig/mod.rs"]
mod rig;

use cnc_msgs::signals::{f, g, SignalTable};
use rig::*;

/// The text of the Huaxing manual's fixture `number` (`../shared/fixtures/000`).
fn fixture(number: &str) -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/fixtures/000");
    let path = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(number))
        .unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    text.split("(--- listing as printed ---)")
        .nth(1)
        .unwrap()
        .to_string()
}

/// The spindle's degrees turned, signed, from the encoder's 0–360° readings.
struct Turned {
    degrees: f64,
    last: f64,
}

impl Turned {
    fn read(&mut self, angle: f64) -> f64 {
        self.degrees += (angle - self.last + 180.0).rem_euclid(360.0) - 180.0;
        self.last = angle;
        self.degrees
    }
}

/// Fixture 004 on the turn-mill, the spindle standing at 0° at power-on: M14.6 holds it there
/// (C0); G08 C100 turns +100° to 100°; C−750 turns −130° to 330°; H−750 −750° to 300°; the
/// three-axis G08 +100° to 40° while X moves U−10 and Z to 120 geared to its angle; G08.6
/// C120 holds it (M14.6), then +80° to 120°. M15 lets it go back to speed control. (Z's 20 mm
/// in 100° asks Z for 3600 mm/s² while the spindle ramps, more than its 1500: the slide trails
/// by up to 0.25 mm then, its drive's lag; how closely a geared move keeps to the spindle is
/// measured on fixture 015's gentler helix below.)
#[test]
fn fixture_004_turns_the_spindle_as_the_c_axis_each_block_asks() {
    let cfg = config("sim_turnmill");
    let z = cfg.axis_index("Z").unwrap();
    let program = format!(
        "G00 X200 Z100\n{}M15\nM30\n",
        fixture("004_spindle_c_axis_position_m14_g08")
    );
    let mut r = Rig::on(cfg, &program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let mut spindle = Turned {
        degrees: 0.0,
        last: r.fb.spindle_angle_deg,
    };
    let (mut fins, mut was_fin) = (Vec::new(), false);
    // The three-axis G08: Z and the spindle where it began, the slide's worst distance
    // from where the spindle's angle puts it.
    let (mut geared, mut worst) = (None::<(f64, f64)>, 0.0f64);
    let mut z_end = 0.0;
    let ok = r.run_until(60.0, |r| {
        let a = r.fb.spindle_angle_deg;
        let turned = spindle.read(a);
        let orienting = r.nc().get(f::MF) && r.nc().read_i32(f::M_CODE) == 19;
        let fin = r.gi.get(g::FIN) && orienting;
        if fin && !was_fin {
            fins.push((a, r.fb.spindle_rpm, turned, r.fb.position[z]));
        }
        was_fin = fin;
        let travel = r.nc().read_i32(f::ORIENT_ANGLE);
        if orienting && travel == 100_000 && fins.len() == 4 {
            let (z0, t0) = *geared.get_or_insert((r.fb.position[z], turned));
            let want = z0 + 20.0 * ((turned - t0) / 100.0).clamp(0.0, 1.0);
            worst = worst.max((r.fb.position[z] - want).abs());
        }
        z_end = r.motion.commanded_display()[z];
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!("at each FIN (angle, rpm, turned, Z): {fins:?}; Z off the spindle by {worst:.4}");
    let want = [
        (0.0, 0.0),
        (100.0, 100.0),
        (330.0, -30.0),
        (300.0, -780.0),
        (40.0, -680.0),
        (40.0, -680.0),
        (120.0, -600.0),
    ];
    assert_eq!(fins.len(), want.len(), "{fins:?}");
    for (k, ((angle, rpm, turned, _), (a, t))) in fins.iter().zip(want).enumerate() {
        assert!(
            (angle - a).abs() < 1e-6 && (turned - t).abs() < 1e-6 && *rpm == 0.0,
            "positioning {k}: {angle}° after {turned}° at {rpm} rpm, not {a}° after {t}°"
        );
    }
    assert!(geared.is_some(), "the three-axis G08 ran");
    assert!(
        (fins[4].3 - fins[3].3 - 20.0).abs() < 0.01,
        "Z to 120: {fins:?}"
    );
    assert_eq!(z_end, 120.0, "Z at 120");
    assert!(worst < 0.25, "Z off the spindle's angle by {worst} mm");
    assert_eq!(r.motion.commanded_display()[0], 190.0, "X by U−10");
    assert!(!r.bit("ORIENT_REQ"), "M15: speed control again");
}

/// Fixture 015's first listing on the turn-mill: C to 0 at 1000 r/min, the infeed, then three
/// turns of C at 800 r/min with Z feeding 4.5 mm from Z0: a 1.5 mm helix, which the slide keeps at
/// every servo tick within the 0.1 mm the rigid tap keeps (`plc_cell_mill.rs`), ending on its
/// length exactly with C back at 0°.
#[test]
fn fixture_015_cuts_three_turns_of_a_helix_with_c_and_z() {
    let cfg = config("sim_turnmill");
    let z = cfg.axis_index("Z").unwrap();
    let listing = fixture("015_g08_rotary_axis_examples");
    let part = listing.split(".....").next().unwrap();
    let program = format!("G00 X50 Z0\nG98 F100\n{part}M15\nM30\n");
    let mut r = Rig::on(cfg, &program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let mut spindle = Turned {
        degrees: 0.0,
        last: r.fb.spindle_angle_deg,
    };
    let (mut helix, mut worst, mut ends) = (None::<(f64, f64)>, 0.0f64, Vec::new());
    let ok = r.run_until(60.0, |r| {
        let turned = spindle.read(r.fb.spindle_angle_deg);
        let orienting = r.nc().get(f::MF) && r.nc().read_i32(f::M_CODE) == 19;
        let three_turns = orienting && r.nc().read_i32(f::ORIENT_ANGLE) == 1_080_000;
        match (helix, three_turns) {
            (None, true) => helix = Some((r.fb.position[z], turned)),
            (Some((z0, t0)), true) => {
                let want = z0 + 4.5 * ((turned - t0) / 1080.0).clamp(0.0, 1.0);
                worst = worst.max((r.fb.position[z] - want).abs());
            }
            (Some(_), false) => {
                helix = None;
                ends.push((r.fb.spindle_angle_deg, turned));
            }
            (None, false) => {}
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!("helix ends at {ends:?}: Z off the spindle's helix by at most {worst:.4} mm");
    assert_eq!(ends.len(), 1, "{ends:?}");
    assert!(
        ends[0].0.abs() < 1e-6 || (ends[0].0 - 360.0).abs() < 1e-6,
        "C at 0: {ends:?}"
    );
    assert_eq!(r.motion.commanded_display()[z], 4.5, "Z 4.5 mm on");
    assert!(worst < 0.1, "{worst} mm");
}

/// Issue 49, must-show 5: a turn-mill part on `sim_turnmill` in the cell over DDS, as a
/// supervisor runs it: turned; C indexed to 90°, turned on by 180° and back to 0° by G08.6; two
/// cross holes drilled at C0 and C180 with the live tool turning at 1400 r/min (M65 S1400,
/// G87, D143); a hexagon milled on the face by polar interpolation; four face holes and a side
/// hole tapped rigidly with the live tool (G84/G88 after M29). The `axes` topic shows C at
/// each stop and under polar interpolation, the live tool (A) at its speed and turning in the
/// taps, and the part is counted.
#[test]
fn a_turn_mill_part_runs_in_the_cell_with_c_on_the_axes_topic() {
    use cnc_cell::client::CellClient;
    use cnc_msgs::msg::MachineState;
    use std::time::Duration;
    let cfg = common::machine("sim_turnmill", 188);
    let cell = cnc::cell::Cell::start(&cfg).unwrap();
    let mut client = CellClient::new(
        &cfg.network,
        "turnmill1",
        "turnmill_supervisor",
        ros2_client::ServiceMapping::Enhanced,
    )
    .unwrap();
    client.wait_ready(Duration::from_secs(30)).unwrap();
    let mut program = String::from(
        "O0485\nG00 X60 Z5\nM03 S800\nG01 X50 Z0 F300\nZ-20\nG00 X60 Z5\nM05\n\
         M14.6\nG08 C90 F500\nG04 X1\nG08 H180 F500\nG04 X1\nG08.6 C0 F500\n\
         G00 X60 Z-10\nM65 S1400\nG87 Z-10 C0 X44 F300 M20\nH180 M20\nG00 X60 Z5\nM66\n\
         T0303\nG00 X40 Z0\nG00 C0\nG12.1\nG98\nG01 X30 F900\n",
    );
    // The hexagon of 30 mm across flats on the face, by polar interpolation.
    let h = 15.0 / 3f64.sqrt();
    for (u, v) in [
        (15.0, h),
        (0.0, 2.0 * h),
        (-15.0, h),
        (-15.0, -h),
        (0.0, -2.0 * h),
        (15.0, -h),
        (15.0, h),
    ] {
        program.push_str(&format!("G01 X{:.4} C{:.4}\n", 2.0 * u, v));
    }
    // Four face holes tapped rigidly by the live tool on C 0°, 90°, 180°, 270°, a side hole
    // at C45, then C back to speed control.
    program.push_str(
        "G01 X40 C0\nG13.1\nM29 S800\nG84 X20 C0 Z-10 P200 F1.25 M20\nH90 K3 M20\n\
         G00 X60 Z-10\nM29 S800\nG88 Z-10 C45 X30 F1\nG80\nG00 X100 Z50\nM15\nM30\n",
    );
    let r = client.load_program("o0485.nc", &program).unwrap();
    assert!(r.accepted, "{}", r.message);
    let r = client.start_program("o0485.nc").unwrap();
    assert!(r.accepted, "{}", r.message);
    let c_at = |c: &CellClient| {
        c.axes
            .as_ref()
            .and_then(|a| a.axes.iter().find(|x| x.name == "C"))
            .map(|x| x.actual_position)
    };
    let tool_at = |c: &CellClient| {
        c.axes
            .as_ref()
            .and_then(|a| a.axes.iter().find(|x| x.name == "A"))
            .map(|x| x.actual_position)
    };
    let (mut stops, mut c_angles, mut tool_angles) = (Vec::new(), Vec::new(), Vec::new());
    // The live tool at 1400 r/min turns 336° between two messages of the axes topic (every
    // tenth 4 ms tick): how often the topic showed it so.
    let (mut last_tool, mut spinning) = (None::<f64>, 0);
    // The `live_tool` topic: messages (by their stamps) that showed it at 1400 r/min, asked
    // and actual.
    let (mut at_speed, mut last_stamp) = (0, None);
    let (done, _) = client.wait_until(Duration::from_secs(90), |c| {
        if let Some(angle) = c_at(c) {
            for want in [90.0, 270.0] {
                if (angle - want).abs() < 1e-3 && !stops.contains(&want) {
                    stops.push(want);
                }
            }
            let tenth = (angle * 10.0).round() as i64;
            if !c_angles.contains(&tenth) {
                c_angles.push(tenth);
            }
        }
        if let Some(t) = &c.live_tool {
            let stamp = Some((t.stamp.sec, t.stamp.nanosec));
            let new = stamp != last_stamp;
            last_stamp = stamp;
            if new && t.commanded_rpm == 1400.0 && t.at_speed && (t.actual_rpm - 1400.0).abs() < 1.0
            {
                at_speed += 1;
            }
        }
        if let Some(angle) = tool_at(c) {
            if let Some(last) = last_tool.replace(angle) {
                let turned = (angle - last).rem_euclid(360.0);
                if (turned - 336.0).abs() < 0.5 {
                    spinning += 1;
                }
            }
            let whole = angle.round() as i64;
            if !tool_angles.contains(&whole) {
                tool_angles.push(whole);
            }
        }
        c.state
            .as_ref()
            .is_some_and(|s| s.execution == MachineState::PROGRAM_COMPLETED)
            && c.part_count.as_ref().is_some_and(|p| p.count == 1)
    });
    assert!(done, "state {:?}, alarms {:?}", client.state, client.alarms);
    assert_eq!(stops, [90.0, 270.0], "C on the axes topic at its stops");
    println!(
        "the axes topic showed C at {} angles and the live tool A at {} angles, {spinning} \
         times turning 336° from the last (1400 r/min); the live_tool topic {at_speed} times at \
         1400 r/min",
        c_angles.len(),
        tool_angles.len()
    );
    // Two cross holes of 8 mm at 300 mm/min, 1.6 s each, with the tool at speed.
    assert!(
        spinning > 20,
        "the live tool drilling at 1400 r/min: {spinning}"
    );
    assert!(
        at_speed > 20,
        "the live_tool topic at 1400 r/min: {at_speed}"
    );
    // The axes topic comes every tenth tick (40 ms): polar interpolation turns C through
    // hundreds of tenths of a degree, the taps the live tool through most of its turn.
    assert!(
        c_angles.len() > 100,
        "C under polar interpolation: {c_angles:?}"
    );
    assert!(
        tool_angles.len() > 50,
        "the live tool turning: {tool_angles:?}"
    );
    // C stands where the side hole left it; the live tool stands (where M66 stopped it, the
    // taps' turns undone), the same angle half a second later.
    let (back, _) = client.wait_until(Duration::from_secs(5), |c| {
        c_at(c).is_some_and(|a| (a - 45.0).abs() < 1e-3)
    });
    assert!(back, "C at 45°: {:?}", client.axes);
    let stood = tool_at(&client).expect("A on the axes topic");
    client.wait_until(Duration::from_millis(500), |_| false);
    let still = tool_at(&client).expect("A on the axes topic");
    assert!(
        (still - stood).abs() < 1e-6,
        "the live tool at {stood}°, then {still}°"
    );
    let live = client.live_tool.as_ref().expect("the live_tool topic");
    assert!(
        live.positioned && live.commanded_rpm == 0.0 && live.actual_rpm < 1e-6,
        "{live:?}"
    );
    drop(client);
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
}

/// One skip run (G31, D139) on the turn-mill whose simulated probe (its measuring input, the
/// skip input X11.5) switches with Z at or below −20: the latched Z and the rest of it, and
/// the Z where the program's `G00 Z10` after it ends (machine coordinates).
fn skip_run(keeps_actual: bool, skip: &str) -> (bool, f64, f64, f64) {
    let mut cfg = config("sim_turnmill");
    cfg.machine.skip_keeps_actual = keeps_actual;
    cfg.sim.probe = vec![cnc_runtime::config::ProbeTarget {
        min: vec![-1000.0, -1000.0],
        max: vec![1000.0, -20.0],
    }];
    let z = cfg.axis_index("Z").unwrap();
    let program = format!("G00 X40 Z10\n{skip}\nG00 Z10\nM30\n");
    let mut r = Rig::on(cfg, &program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let mut latched = None;
    let ok = r.run_until(60.0, |r| {
        if let Some(res) = r.motion.block_result() {
            latched = Some((res.triggered, res.position[z], res.rest[z]));
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    let (triggered, at, rest) = latched.expect("the skip's result");
    (triggered, at, rest, r.motion.commanded_display()[z])
}

/// Issue 49, must-show 4 (G31 on the rig): the skip input ends the move where Z crosses
/// −20, the latched point within one servo period's travel of it (F100: 0.0067 mm); with
/// B19.6 = 1 the program goes on from the actual point (`G00 Z10` ends at 10), with B19.6 = 0
/// the programmed end −50 is written over it (`G00 Z10` ends 30 mm further, at 40). `L`
/// selects the input active low: the move ends where it switches off, leaving the box.
#[test]
fn g31_ends_on_the_skip_input_and_b19_6_decides_the_coordinates() {
    let period = 100.0 / 60.0 * 0.004;
    for (keeps, end) in [(true, 10.0), (false, 40.0)] {
        let (triggered, at, rest, last) = skip_run(keeps, "G31 Z-50 F100");
        println!("B19.6 keeps {keeps}: latched Z {at}, stood at {rest}, then Z {last}");
        assert!(triggered, "the skip came");
        assert!((at + 20.0).abs() <= period, "latched at {at}");
        // Seen a tick or two after the edge, behind an 8 ms drive lag, then braked.
        assert!(rest < at && rest > at - 0.05, "braked just past it: {rest}");
        assert!(
            (last - end).abs() < 1e-9,
            "G00 Z10 ends at {last}, not {end}"
        );
    }
    // Active low (L): into the box first (it is on), then out of it: the skip is its falling
    // edge at Z −20 on the way back up.
    let (triggered, at, _, _) = skip_run(true, "G00 Z-30\nG31 Z0 L11.5 F100");
    assert!(
        triggered && (at + 20.0).abs() <= period,
        "falling edge at {at}"
    );
}

/// The distance of face point `p` from the polyline `path`.
fn off_path(p: (f64, f64), path: &[(f64, f64)]) -> f64 {
    path.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 {
                (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
        })
        .fold(f64::INFINITY, f64::min)
}

/// What a run in polar interpolation did at the servo rate.
struct PolarRun {
    ticks: u32,
    /// Worst distance of the X/C setpoints, and of the slides' actual X and the spindle's
    /// angle, from the face's path, mm.
    worst: f64,
    worst_actual: f64,
    /// Fastest C setpoint, °/s, and the slowest face speed at the slot's pole crossing.
    fastest_c: f64,
    slowest_near_pole: f64,
}

/// Runs `program` on the turn-mill rig to its end and measures every tick in polar
/// interpolation against the face's polyline `path` (cutter centre, mm).
fn polar_run(program: &str, path: &[(f64, f64)]) -> (Rig, PolarRun) {
    let mut r = Rig::on(config("sim_turnmill"), program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let face = |x: f64, c: f64| {
        let (s, co) = c.to_radians().sin_cos();
        (x / 2.0 * co, x / 2.0 * s)
    };
    let mut run = PolarRun {
        ticks: 0,
        worst: 0.0,
        worst_actual: 0.0,
        fastest_c: 0.0,
        slowest_near_pole: f64::INFINITY,
    };
    let mut last: Option<(f64, (f64, f64))> = None;
    let ok = r.run_until(120.0, |r| {
        match r.motion.contour_c() {
            Some(c) => {
                let x = r.motion.commanded_display()[0];
                let p = face(x, c);
                run.worst = run.worst.max(off_path(p, path));
                // The drives report X's slide (radius).
                let actual = face(2.0 * r.fb.position[0], r.fb.spindle_angle_deg);
                run.worst_actual = run.worst_actual.max(off_path(actual, path));
                if let Some((c0, p0)) = last {
                    run.fastest_c = run.fastest_c.max((c - c0).abs() / 0.004);
                    let speed = (p.0 - p0.0).hypot(p.1 - p0.1) / 0.004;
                    if (p.1 - 1.0).abs() < 1e-3 && p.0.abs() < 0.2 {
                        run.slowest_near_pole = run.slowest_near_pole.min(speed);
                    }
                }
                last = Some((c, p));
                run.ticks += 1;
            }
            None => last = None,
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    (r, run)
}

/// Issue 49, must-show 2: polar interpolation (G12.1, D141) through the planner, the drives
/// and the PLC at the servo rate. A hexagon of 30 mm across flats about the spindle's centre
/// and a slot that passes 1 mm from the pole, at F1200: every tick's X and C setpoints,
/// mapped back to the face, lie within 1 µm of the programmed contour; C never turns faster
/// than its 36,000°/min, and near the pole the feed drops (to what C's rate and acceleration
/// allow at 1 mm from it, 3.4 mm/s) rather than the path bending; the spindle, following C,
/// keeps the slide's actual point near the contour too; G13.1 and M15 end it.
#[test]
fn polar_interpolation_keeps_every_servo_tick_on_the_face_contour() {
    let c_rate = config("sim_turnmill").machine.c_axis.max_velocity / 60.0;
    let (a, h) = (15.0f64, 15.0 / 3f64.sqrt());
    let corners = [
        (a, h),
        (0.0, 2.0 * h),
        (-a, h),
        (-a, -h),
        (0.0, -2.0 * h),
        (a, -h),
        (a, h),
    ];
    let mut program = String::from("T0101\nG00 X40 Z5\nM14.6\nG00 C0\nG12.1\nG98\nG01 X30 F1200\n");
    let mut path = vec![(20.0, 0.0), (15.0, 0.0)];
    for (u, v) in corners {
        program.push_str(&format!("G01 X{:.4} C{:.4}\n", 2.0 * u, v));
        path.push(((2.0 * u * 1e4).round() / 2e4, (v * 1e4).round() / 1e4));
    }
    program.push_str("G01 X40 C1\nG01 X-40 C1\nG13.1\nM15\nM30\n");
    path.extend([(20.0, 1.0), (-20.0, 1.0)]);
    let (r, run) = polar_run(&program, &path);
    println!(
        "{} ticks in polar interpolation: setpoints at most {:.2e} mm off the face's contour, \
         the actual point {:.4} mm; C at most {:.1}°/s (limit {c_rate}), the slot at the pole at \
         {:.2} mm/s (F1200 = 20 mm/s)",
        run.ticks, run.worst, run.worst_actual, run.fastest_c, run.slowest_near_pole
    );
    assert!(run.ticks > 1000, "{}", run.ticks);
    assert!(run.worst <= 0.001, "{} mm off the contour", run.worst);
    assert!(
        run.fastest_c <= c_rate * (1.0 + 1e-9),
        "C at {}°/s",
        run.fastest_c
    );
    // At 1 mm from the pole C's 600°/s allow 10.5 mm/s: the feed is lowered, not the path.
    assert!(
        run.slowest_near_pole < 11.0,
        "{} mm/s at the pole",
        run.slowest_near_pole
    );
    assert!(
        run.worst_actual < 0.05,
        "the slide's actual point {} mm off",
        run.worst_actual
    );
    assert!(!r.bit("ORIENT_REQ"), "M15: speed control again");
}

/// Fixture 016 as printed on the turn-mill, after the live tool's end mill (T0303, radius 4,
/// tip 0) and M14.6: G00 C0, G12.1, and the rectangle X10…−20 (diameter) by C −10…10 with
/// G41 — the cutter's centre runs the rectangle 4 mm inside it, every servo tick within 1 µm.
#[test]
fn fixture_016_mills_its_rectangle_through_the_machine() {
    let program = format!(
        "T0303\nG00 X40 Z5\nM14.6\n{}M15\nM30\n",
        fixture("016_g12_1_polar_interpolation")
    );
    let r = 4.0;
    let path = [
        (20.0, 0.0),
        (15.0, 0.0),
        (5.0 - r, 0.0),
        (5.0 - r, 10.0 - r),
        (-10.0 + r, 10.0 - r),
        (-10.0 + r, -10.0 + r),
        (5.0 - r, -10.0 + r),
        (5.0 - r, 0.0),
        (15.0, 0.0),
    ];
    let (_, run) = polar_run(&program, &path);
    println!(
        "fixture 016: {} ticks, setpoints at most {:.2e} mm off the cutter's path, the actual \
         point {:.4} mm",
        run.ticks, run.worst, run.worst_actual
    );
    assert!(run.ticks > 500, "{}", run.ticks);
    assert!(run.worst <= 0.001, "{} mm off the cutter's path", run.worst);
}

/// Issue 49, must-show 3 for G14 (D142): fixture 017 as printed on the turn-mill — G14.4 taps
/// Z0 → −10 at 1 mm a turn with the live tool (A) at 500 r/min, dwells 2 s, comes back. At
/// every servo tick the tap's setpoints keep Z on the tool's angle by the pitch (the line
/// gears them), and the slide's actual Z keeps to the tool drive's actual angle within the
/// 0.1 mm the rigid taps keep (`plc_cell_mill.rs`); the tool turns ten turns in and ten out.
#[test]
fn fixture_017_taps_with_the_live_tool_geared_at_every_tick() {
    let cfg = config("sim_turnmill");
    let z = cfg.axis_index("Z").unwrap();
    let program = fixture("017_g14_4_flying_cutter_tapping");
    let mut r = Rig::on(cfg, &program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let (mut worst_set, mut worst_actual, mut deepest, mut most_turned) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut start: Option<(f64, f64)> = None;
    let ok = r.run_until(60.0, |r| {
        let (zs, a_set) = (
            r.motion.commanded_display()[z],
            r.motion.live_tool_setpoint(),
        );
        if start.is_none() && r.motion.commanded_display()[0] == 0.0 && zs == 0.0 && r.t > 0.5 {
            start = Some((r.fb.position[z], r.fb.live_tool_angle));
        }
        if let Some((z0, a0)) = start {
            // At X0 and below Z0 the tap is in its thread: Z = −(turns) × 1 mm (until the
            // rapid away from it starts).
            if r.motion.commanded_display()[0] == 0.0 && zs <= 0.0 {
                worst_set = worst_set.max((zs + a_set / 360.0).abs());
                let want = z0 - (r.fb.live_tool_angle - a0) / 360.0;
                worst_actual = worst_actual.max((r.fb.position[z] - want).abs());
            }
            deepest = deepest.min(r.fb.position[z]);
            most_turned = most_turned.max(r.fb.live_tool_angle - a0);
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!(
        "G14.4: setpoints off the pitch by at most {worst_set:.2e} mm, the actual Z off the tool's \
         actual angle by {worst_actual:.2e} mm; deepest Z {deepest:.4}, {most_turned:.1}° turned"
    );
    assert!(start.is_some(), "the tap started at X0 Z0");
    assert!(worst_set < 1e-9, "setpoints {worst_set} mm off the pitch");
    assert!(
        worst_actual < 0.1,
        "the slide {worst_actual} mm off the tool's angle"
    );
    assert!((deepest + 10.0).abs() < 0.01, "to Z−10: {deepest}");
    assert!(
        (most_turned - 3600.0).abs() < 1.0,
        "ten turns: {most_turned}°"
    );
    assert_eq!(r.motion.commanded_display()[z], 100.0);
    assert!(
        r.motion.live_tool_setpoint().abs() < 1e-9,
        "the tool back at 0°"
    );
}

/// Issue 49, must-show 3 (D142): rigid tapping on the turn-mill, face and side, through the
/// rig. M29 S800 makes the live tool the tapping spindle; G84 taps four face holes at X20 on
/// C 0°, 90°, 180°, 270° from Z5 to Z−10 at 1.25 mm a turn, G88 a side hole at Z−10, C45 from
/// X60 to X30 at 1 mm. At every servo tick of a tap the drilling axis's actual position keeps
/// to the live tool drive's actual angle by the pitch within the 0.1 mm the rigid taps keep
/// (`plc_cell_mill.rs`), the setpoints exactly; at each hole's bottom C stands at its angle.
#[test]
fn rigid_taps_face_and_side_keep_the_slide_on_the_live_tools_angle() {
    let cfg = config("sim_turnmill");
    let (x, z) = (cfg.axis_index("X").unwrap(), cfg.axis_index("Z").unwrap());
    let program = "T0101\nG00 X60 Z5\nM14.6\nG00 C0\nM29 S800\n\
                   G84 X20 C0 Z-10 P500 F1.25 M20\nH90 K3 M20\nG00 X60 Z-10\nM29 S800\n\
                   G88 Z-10 C45 X30 F1\nG80\nG00 X100 Z50\nM15\nM30\n";
    let mut r = Rig::on(cfg, program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let (mut worst_set, mut worst_actual) = (0.0f64, 0.0f64);
    let mut bottoms: Vec<(f64, f64)> = Vec::new();
    let (mut last_a, mut rising) = (0.0f64, false);
    let ok = r.run_until(120.0, |r| {
        let set = r.motion.commanded_display();
        let a_set = r.motion.live_tool_setpoint();
        let a = r.fb.live_tool_angle;
        let tapping = a_set.abs() > 1e-9;
        if set[x] == 20.0 && tapping {
            // Face: Z = 5 − 1.25 × turns.
            worst_set = worst_set.max((set[z] - (5.0 - 1.25 * a_set / 360.0)).abs());
            worst_actual = worst_actual.max((r.fb.position[z] - (5.0 - 1.25 * a / 360.0)).abs());
        }
        if set[z] == -10.0 && set[x] != 20.0 && tapping {
            // Side: X (diameter) = 60 − 2 × 1 × turns.
            worst_set = worst_set.max((set[x] - (60.0 - 2.0 * a_set / 360.0)).abs());
            let x_dia = 2.0 * r.fb.position[x];
            worst_actual = worst_actual.max((x_dia - (60.0 - 2.0 * a / 360.0)).abs());
        }
        // A hole's bottom: where the tool's setpoint turns back.
        if rising && a_set < last_a {
            bottoms.push((r.fb.spindle_angle_deg, last_a));
        }
        if a_set != last_a {
            rising = a_set > last_a;
        }
        last_a = a_set;
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!(
        "rigid taps: setpoints off the pitch by {worst_set:.2e} mm, the actual slide off the \
         tool's actual angle by {worst_actual:.2e} mm; C and the tool at each bottom {bottoms:?}"
    );
    assert!(worst_set < 1e-9, "setpoints {worst_set} mm off");
    assert!(
        worst_actual < 0.1,
        "the slide {worst_actual} mm off the tool's angle"
    );
    let angles: Vec<f64> = bottoms.iter().map(|b| (b.0 * 1e3).round() / 1e3).collect();
    assert_eq!(angles, [0.0, 90.0, 180.0, 270.0, 45.0], "{bottoms:?}");
    for (k, want) in [4320.0, 4320.0, 4320.0, 4320.0, 5400.0].iter().enumerate() {
        assert!((bottoms[k].1 - want).abs() < 1e-6, "hole {k}: {bottoms:?}");
    }
    assert!(!r.bit("ORIENT_REQ"), "M15");
}

/// Issue 49, must-show 5's cross holes (D143): the live tool in speed mode drills. M65 S1500
/// turns it; G87 drills four cross holes at Z−10 from X60 to X30 on C 0°, 90°, 180°, 270°
/// (H90 K3) at F60 mm/min, clamped by M20; M66 stops it. Through motion, the PLC and the
/// simulated drives: at every servo tick the slide feeds into a hole the tool's drive turns
/// at 1500 r/min (its actual speed, by its encoder) and C stands at the hole's angle; no
/// slide moves before the tool is at speed; after M66 and at the end the tool stands.
#[test]
fn cross_holes_are_drilled_with_the_live_tool_turning_at_its_speed() {
    let cfg = config("sim_turnmill");
    let (x, z) = (cfg.axis_index("X").unwrap(), cfg.axis_index("Z").unwrap());
    let program = "T0101\nG98\nG00 X60 Z5\nM14.6\nG00 C0\nM65 S1500\nG00 Z-10\n\
                   G87 Z-10 C0 X30 F60 M20\nH90 K3 M20\nG00 X60 Z5\nM66\nG00 X100 Z50\nM15\nM30\n";
    let mut r = Rig::on(cfg, program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let (mut feeding, mut slowest, mut fastest) = (0usize, f64::MAX, 0.0f64);
    let mut holes: Vec<f64> = Vec::new();
    let mut moved_before_speed = false;
    let mut last_x = f64::NAN;
    let ok = r.run_until(120.0, |r| {
        let set = r.motion.commanded_display();
        let rpm = r.fb.live_tool_rpm;
        if r.motion.live_tool_rpm() > 0.0 && r.motion.live_tool_rpm() < 1500.0 && set[z] != 5.0 {
            moved_before_speed = true;
        }
        // Feeding into a hole: X between the hole's top and bottom, going in.
        if set[z] == -10.0 && set[x] < 60.0 - 1e-6 && set[x] > 30.0 && set[x] < last_x {
            feeding += 1;
            slowest = slowest.min(rpm);
            fastest = fastest.max(rpm);
            let c = (r.fb.spindle_angle_deg * 1e3).round() / 1e3;
            if !holes.contains(&c) {
                holes.push(c);
            }
        }
        last_x = set[x];
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!(
        "G87 with the live tool: {feeding} ticks feeding, its drive at {slowest:.3}…{fastest:.3} \
         r/min, C at {holes:?}"
    );
    // 15 mm of X (radius) at 60 mm/min is 15 s a hole: four holes, 15,000 ticks.
    assert!(feeding > 14_000, "{feeding} ticks");
    assert!(
        (slowest - 1500.0).abs() < 0.01 && (fastest - 1500.0).abs() < 0.01,
        "the tool at {slowest}…{fastest} r/min"
    );
    assert_eq!(holes, [0.0, 90.0, 180.0, 270.0]);
    assert!(!moved_before_speed, "a slide moved while the tool ran up");
    assert_eq!(r.motion.live_tool_rpm(), 0.0, "M66");
    assert!(r.fb.live_tool_rpm.abs() < 1e-6, "{}", r.fb.live_tool_rpm);
}

/// D143's stop through the standard ladder: the door opened while the live tool drills. The
/// ladder raises the door alarm (A3.0), holds the feed (*SP) and stops the live tool by
/// *SSTP (G29.6, B09.5 = 0): its drive brakes to a stand within its time constant while the
/// slide stands; closing the door does not restart it, reset does not either (the tool stays
/// standing: reset stops speed mode).
#[test]
fn the_door_opened_while_the_live_tool_drills_stops_it_through_the_ladder() {
    let cfg = config("sim_turnmill");
    let x = cfg.axis_index("X").unwrap();
    let program =
        "T0101\nG98\nG00 X60 Z-10\nM14.6\nG00 C0\nM65 S2000\nG87 Z-10 C0 X30 F30\nM66\nM30\n";
    let mut r = Rig::on(cfg, program, None);
    r.run_until(0.1, |_| false);
    r.started = true;
    let drilling = r.run_until(20.0, |r| r.motion.commanded_display()[x] < 55.0);
    assert!(drilling, "the drill in the hole");
    assert!(
        (r.fb.live_tool_rpm - 2000.0).abs() < 0.01,
        "{}",
        r.fb.live_tool_rpm
    );
    r.sim.devices.door_forced_open = true;
    let opened = r.t;
    assert!(
        r.run_until(0.1, |r| r.message("A3.0").is_some()),
        "door alarm"
    );
    assert!(!r.gi.get(g::SSTP_N), "*SSTP low");
    // The alarm within a scan or two (30 ms), 2000 r/min of 2500 in 0.239 s (0.19 s), the
    // drive's 12 ms lag and its last r/min (60 ms): 0.3 s.
    let stood = r.run_until(0.5, |r| {
        r.motion.live_tool_rpm() == 0.0 && r.fb.live_tool_rpm.abs() < 1.0
    });
    let after = r.t - opened;
    assert!(stood, "the tool still at {} r/min", r.fb.live_tool_rpm);
    assert!(after < 0.3, "stood after {after:.3} s");
    let held = r.motion.commanded_display();
    r.sim.devices.door_forced_open = false;
    r.run_until(1.0, |_| false);
    assert_eq!(r.motion.commanded_display(), held, "the slide stands");
    assert!(
        r.fb.live_tool_rpm.abs() < 1e-6,
        "the tool stands: {}",
        r.fb.live_tool_rpm
    );
    r.motion.reset();
    r.run_until(1.0, |_| false);
    assert_eq!(r.motion.live_tool_rpm(), 0.0, "reset ends speed mode");
    println!(
        "the door open: the live tool stood after {after:.3} s, the slide at X{:.3}",
        held[x]
    );
}
