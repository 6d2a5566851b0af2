//! The 802D mill's spindle and axes through the whole chain on the PLC rig (`rig/mod.rs`):
//! SPOS positioned by the ladder and the simulated drive (D100), rigid tapping with the slide
//! locked to the spindle (D101), FFWON's following error (D106), H functions with HF (D107).

#[path = "rig/mod.rs"]
mod rig;

use cnc_msgs::signals::{f, g, SignalTable};
use cnc_plc::memory::Retained;
use rig::*;

/// The simulated 802D mill at power-up running `program`, its cycle started.
fn mill(program: &str) -> Rig {
    let cfg = config("sim_mill_802d");
    let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
    let mut r = Rig::on(cfg, program, Some(&kept));
    r.run_until(0.1, |_| false);
    r.started = true;
    r
}

/// The text of the 802D manual's fixture `number` (`../shared/fixtures/001`).
fn fixture(number: &str) -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/fixtures/001");
    let path = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(number))
        .unwrap();
    std::fs::read_to_string(path).unwrap()
}

/// The spindle's angle unwrapped: the degrees it has turned, signed, from the encoder's
/// 0–360° readings (less than half a turn between two of them).
struct Turned {
    degrees: f64,
    last: f64,
}

impl Turned {
    fn from(angle: f64) -> Turned {
        Turned {
            degrees: 0.0,
            last: angle,
        }
    }

    fn read(&mut self, angle: f64) -> f64 {
        let mut d = (angle - self.last).rem_euclid(360.0);
        if d > 180.0 {
            d -= 360.0;
        }
        self.last = angle;
        self.degrees += d;
        self.degrees
    }
}

/// SPOS through the whole chain (D100): the 802D front end, motion's M19 with the stop
/// position in F30–F35, the ladder copying it to Y8–Y13 with the strobe, the simulated drive
/// positioning and holding, the ladder's FIN on SPINDLE_ORIENTED. At each FIN the spindle
/// stands at its angle, having turned only the way the program asked.
#[test]
fn spos_positions_the_simulated_spindle_each_way_through_the_ladder() {
    let program = "SPOS=14.3\nS800 M3\nG0 X10\nSPOS=ACN(300)\nG0 X20\nSPOS=IC(-720.5)\n\
                   SPOS=ACP(290)\nM3\nG0 X30\nM30\n";
    let mut r = mill(program);
    // At each M19's FIN: (angle, rpm, degrees turned so far).
    let mut spindle = Turned::from(r.fb.spindle_angle_deg);
    let mut fins = Vec::new();
    let mut was_fin = false;
    let ok = r.run_until(120.0, |r| {
        let a = r.fb.spindle_angle_deg;
        let turned = spindle.read(a);
        let fin = r.gi.get(g::FIN) && r.nc().get(f::MF) && r.nc().read_i32(f::M_CODE) == 19;
        if fin && !was_fin {
            fins.push((a, r.fb.spindle_rpm, turned));
        }
        was_fin = fin;
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!("{fins:?} at {:.2} s", r.t);
    assert_eq!(fins.len(), 4, "{fins:?}");
    let angles: Vec<f64> = fins.iter().map(|f| f.0).collect();
    let want = [14.3, 300.0, (300.0 - 720.5f64).rem_euclid(360.0), 290.0];
    for (got, want) in angles.iter().zip(want) {
        assert!((got - want).abs() < 1e-6, "{angles:?}");
    }
    assert!(
        fins.iter().all(|f| f.1 == 0.0),
        "standing at each FIN: {fins:?}"
    );
    // IC(−720.5): two turns and half a degree back; ACP(290) from 299.5: 350.5° forward.
    assert!((fins[2].2 - fins[1].2 + 720.5).abs() < 1e-6, "{fins:?}");
    assert!((fins[3].2 - fins[2].2 - 350.5).abs() < 1e-6, "{fins:?}");
    // M3 turns it again: the position control let go.
    assert!(r.fb.spindle_rpm > 700.0, "{}", r.fb.spindle_rpm);
}

/// Rigid tapping through the whole chain (D101): G331 sends the tap's travel to the ladder as
/// a positioning with its speed, the simulated drive turns the spindle through it, and the
/// slide follows the spindle's angle at every servo tick, within what its drive lag and the
/// setpoint's one period ahead allow; the tap ends exactly at its depth with the spindle
/// standing, and G332 brings it out turning the other way.
#[test]
fn g331_and_g332_tap_with_the_slide_locked_to_the_simulated_spindle() {
    let z = config("sim_mill_802d").axis_index("Z").unwrap();
    let program =
        "G0 X10 Y10 Z5\nSPOS=0\nG331 Z-25 K0.8 S600\nG4 F0.5\nG332 Z5 K0.8\nG0 Z50\nM30\n";
    let mut r = mill(program);
    // Unwrapped spindle angle; while a tap runs, the slide's distance from where the spindle
    // puts it (0.8 mm a turn from where the tap began).
    let mut spindle = Turned::from(r.fb.spindle_angle_deg);
    let mut tap: Option<(f64, f64)> = None;
    let (mut worst, mut ends, mut deepest) = (0.0f64, Vec::new(), f64::INFINITY);
    let mut rising = 0usize;
    let ok = r.run_until(120.0, |r| {
        let turned = spindle.read(r.fb.spindle_angle_deg);
        let slide = r.fb.position[z];
        deepest = deepest.min(slide);
        let orienting = r.nc().get(f::MF) && r.nc().read_i32(f::M_CODE) == 19;
        let tapping = orienting && r.nc().bytes[f::ORIENT_WAY] == 3;
        match (tap, tapping) {
            (None, true) => {
                tap = Some((slide, turned));
                rising += 1;
            }
            (Some((z0, t0)), true) => {
                let sign = if rising == 1 { -1.0 } else { 1.0 };
                let want = z0 + sign * (turned - t0).abs() / 360.0 * 0.8;
                worst = worst.max((slide - want).abs());
            }
            (Some(_), false) => {
                tap = None;
                ends.push((slide, r.fb.spindle_rpm, turned));
            }
            (None, false) => {}
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    println!("taps end at {ends:?}, slide off the spindle's helix by at most {worst:.4} mm");
    assert_eq!(ends.len(), 2, "{ends:?}");
    // Down 30 mm and back: 37.5 turns each way, the spindle standing at each end.
    let length = ends[0].0 - ends[1].0;
    assert!((length + 30.0).abs() < 1e-3, "{ends:?}");
    assert!(ends.iter().all(|e| e.1 == 0.0), "{ends:?}");
    assert!((ends[0].2 - 37.5 * 360.0).abs() < 1e-3, "{ends:?}");
    assert!(ends[1].2.abs() < 1e-3, "back where it began: {ends:?}");
    // The slide never went below the depth, and kept to the spindle within its lag.
    assert!(deepest >= ends[0].0 - 1e-3, "{deepest} below {}", ends[0].0);
    assert!(worst < 0.1, "{worst}");
}

/// Fixture 040 (§9.3.19, D106) through motion and the simulated drives: FFWON before a
/// move at F900 takes the following error (an axis's distance from its commanded position,
/// which a drive with an 8 ms lag makes 0.105 mm on X at 13.1 mm/s) to almost nothing; the same
/// program with FFWOF keeps it. The template's placeholders filled: the move and one back.
#[test]
fn f040_ffwon_takes_the_following_error_to_almost_nothing() {
    let text = fixture("040")
        .replace("N20 G1 X... Y... Z... F900", "N20 G1 X200 Y100 Z100 F900")
        .replace("\n...\n", "\nN30 X0 Y0 Z150\n")
        + "M30\n";
    let worst = |text: &str| {
        let mut r = mill(text);
        let mut worst = 0.0f64;
        let ok = r.run_until(120.0, |r| {
            for (c, a) in r.motion.commanded().iter().zip(&r.fb.position) {
                worst = worst.max((c - a).abs());
            }
            r.program_done()
        });
        assert!(ok, "program did not finish; events {:?}", r.events);
        worst
    };
    let with = worst(&text);
    let without = worst(&text.replace("N10 FFWON", "N10 FFWOF"));
    println!("largest following error: {with:.5} mm with FFWON, {without:.5} mm without");
    // X runs at 15 mm/s × 200/229 = 13.1 mm/s: 8 ms behind is 0.105 mm.
    assert!(without > 0.09, "{without}");
    assert!(with < without / 10.0, "{with} vs {without}");
}

/// Fixture 039's `ACC[S]=50` (§9.3.18, D108) reaches the spindle drive: the spindle takes
/// twice as long to reach its speed as without it.
#[test]
fn f039_acc_s_halves_the_spindles_acceleration() {
    let text = fixture("039").replace("\n...\n", "\nN30 S1000 M3\nN40 G4 F3\n") + "M30\n";
    // How long the spindle takes from turning (10 rpm) to 990 rpm.
    let ramp = |text: &str| {
        let mut r = mill(text);
        let (mut began, mut reached) = (None, None);
        let ok = r.run_until(60.0, |r| {
            let rpm = r.fb.spindle_rpm;
            if began.is_none() && rpm >= 10.0 {
                began = Some(r.t);
            }
            if reached.is_none() && rpm >= 990.0 {
                reached = Some(r.t);
            }
            r.program_done()
        });
        assert!(ok, "program did not finish; events {:?}", r.events);
        reached.expect("990 rpm reached") - began.expect("the spindle turned")
    };
    let half = ramp(&text);
    let rated = ramp(&text.replace("N20 ACC[S]=50", "N20"));
    println!("10 to 990 rpm in {half:.3} s with ACC[S]=50, {rated:.3} s without");
    assert!((half / rated - 2.0).abs() < 0.05, "{half} vs {rated}");
}

/// Fixture 063's H functions (§9.8, D107) through motion and the standard ladder: each goes
/// to the PLC with the HF strobe, its address in F40 and its value in F44–F51, and the ladder
/// gives FIN once settled, so the program runs to its end.
#[test]
fn f063_h_functions_reach_the_ladder_with_hf_and_get_fin() {
    let text = fixture("063") + "M30\n";
    let mut r = mill(&text);
    let mut seen = Vec::new();
    let mut was = false;
    let ok = r.run_until(30.0, |r| {
        let hf = r.nc().get(f::HF);
        if hf && !was {
            let mut v = [0u8; 8];
            v.copy_from_slice(&r.nc().bytes[f::H_VALUE..f::H_VALUE + 8]);
            seen.push((r.nc().read_i32(f::H_ADDRESS), f64::from_le_bytes(v)));
        }
        was = hf;
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    assert_eq!(
        seen,
        [
            (1, 1.987),
            (2, 978.123),
            (3, 4.0),
            (99, -8978.234),
            (0, 5.0)
        ]
    );
}

/// Fixture 032 (§9.3.12, D116) through the interpreter, motion and the simulated probe: the
/// measuring line N10 from the mill's home (X0 Z150; no tool is selected on the fresh
/// machine, so work and machine coordinates are one) meets a wall the probe finds at X200,
/// where the line is at Z 150 − 190·⅔. The axes brake there (the rest of the line dropped), R5/R6 get the work
/// position of the edge, and the program goes on from where they stopped. Without the wall
/// the probe never switches and the program stops at MEASERR's M0 at the line's end.
#[test]
fn f032_meas_finds_the_wall_brakes_there_and_the_program_reads_the_edge() {
    let text = fixture("032").replace("\n..\n", "\nN40 G0 X=R5-10 Z100\nM30\n");
    let wall = cnc_runtime::config::ProbeTarget {
        min: vec![200.0, -100.0, -100.0],
        max: vec![400.0, 100.0, 200.0],
    };
    let probed = |wall: Option<cnc_runtime::config::ProbeTarget>| {
        let mut cfg = config("sim_mill_802d");
        cfg.sim.probe = wall.into_iter().collect();
        let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
        let mut r = Rig::on(cfg, &text, Some(&kept));
        r.run_until(0.1, |_| false);
        r.started = true;
        let mut furthest = 0.0f64;
        r.run_until(30.0, |r| {
            furthest = furthest.max(r.fb.position[0]);
            r.program_done() || r.motion.state() == cnc_motion::RunState::Hold
        });
        (r, furthest)
    };
    let (r, furthest) = probed(Some(wall));
    assert!(r.program_done(), "the program ran to its end");
    let kept = r.stream.interpreter().memory().kept;
    let z_at_wall = 150.0 - 190.0 * 2.0 / 3.0;
    assert!((kept[&10_005] - 200.0).abs() < 1e-6, "R5 {}", kept[&10_005]);
    assert!(
        (kept[&10_006] - z_at_wall).abs() < 1e-6,
        "R6 {}",
        kept[&10_006]
    );
    // Braked within detection and the jerk-limited stop from F4000 (under 4 mm), not at the
    // line's end at X300.
    assert!(
        furthest > 200.0 && furthest < 204.0,
        "furthest X {furthest}"
    );
    let end = r.motion.commanded_display();
    assert!(
        (end[0] - 190.0).abs() < 1e-9 && (end[2] - 100.0).abs() < 1e-9,
        "{end:?}"
    );
    println!(
        "R5 {} R6 {:.4}, furthest X {furthest:.3}",
        kept[&10_005], kept[&10_006]
    );

    let (r, furthest) = probed(None);
    assert!(!r.program_done());
    assert_eq!(r.motion.state(), cnc_motion::RunState::Hold, "MEASERR: M0");
    let end = r.motion.commanded_display();
    assert!((end[0] - 300.0).abs() < 1e-9, "the whole line: {end:?}");
    assert!(furthest <= 300.0 + 1e-9, "{furthest}");
    let kept = r.stream.interpreter().memory().kept;
    assert_eq!(kept.get(&10_005), None, "R5 not written");
}

/// Fixture 080 (§9.12.1, D121) through the interpreter and motion on the simulated mill: a
/// cut of 100 mm at F600, then the fixture's check of the cutting time against R10. The block
/// that reads `$AC_CUTTING_TIME` waits until the cut has run, then reads what motion counted:
/// the cut's 10 s and its ramps, not the rapid before it. Over a limit of 5 s the program
/// jumps to WZZEIT and holds at its M0; under a limit of 20 s it runs on to its end.
#[test]
fn f080_reads_the_cutting_time_the_machine_counted_and_jumps_on_it() {
    let run = |limit: f64| {
        let text = format!(
            "R10={limit}\nG0 X0 Y0 Z100\nG1 X100 F600\nR1=$AC_CUTTING_TIME R2=$AC_CYCLE_TIME\n{}",
            fixture("080").replace("\n...\n", "\nG0 X1\nM30\n")
        );
        let mut r = mill(&text);
        r.run_until(40.0, |r| {
            r.program_done() || r.motion.state() == cnc_motion::RunState::Hold
        });
        r
    };
    let r = run(5.0);
    assert_eq!(r.motion.state(), cnc_motion::RunState::Hold, "WZZEIT: M0");
    let kept = r.stream.interpreter().memory().kept;
    let (cutting, cycle) = (kept[&10_001], kept[&10_002]);
    assert!((10.0..10.3).contains(&cutting), "cutting {cutting}");
    // The rapid of 50 mm at 12 m/min takes 0.25 s at the least.
    assert!(
        cycle > cutting + 0.25,
        "the rapid counts in the cycle: {cycle}"
    );
    assert!((r.motion.commanded_display()[0] - 100.0).abs() < 1e-9);
    println!("$AC_CUTTING_TIME {cutting:.3} s, $AC_CYCLE_TIME {cycle:.3} s");

    let r = run(20.0);
    assert!(
        r.program_done(),
        "under the limit the program runs to its end"
    );
    assert!((r.motion.commanded_display()[0] - 1.0).abs() < 1e-9);
}

/// Tool life through the interpreter and motion on the simulated mill (§9.13.2, D122): T1 D1
/// has 0.1 min (6 s) of life; a cut of 100 mm at F600 takes 10 s, so reading `$TC_MOP2` after
/// it (a preprocessing stop) finds the life used up by the cutting time motion counted, the
/// tool disabled (`$TC_TP8` bit 2), and the program's end accounts nothing more.
#[test]
fn tool_life_wears_by_the_cutting_time_motion_counted() {
    let text = "$TC_TP9[1]=1 $TC_MOP11[1,1]=0.1 $TC_MOP2[1,1]=0.1\nT1 D1\nG0 X0 Y0 Z100\n\
                G1 X100 F600\nR1=$TC_MOP2[1,1]\nG0 Z120\nM30\n";
    let mut r = mill(text);
    r.run_until(40.0, |r| r.program_done());
    assert!(r.program_done(), "the program runs to its end");
    let kept = r.stream.interpreter().memory().kept;
    let key =
        |name: &str, d: u32| cnc_interpreter::sinumerik::monitor::kept_key(name, 1, d).unwrap();
    let seen = kept[&10_001];
    let cut = (0.1 - seen) * 60.0;
    assert!((10.0..10.3).contains(&cut), "R1 {seen}: {cut} s cut");
    assert_eq!(
        kept[&key("$TC_MOP2", 1)],
        seen,
        "M30 accounts no more cutting"
    );
    assert_eq!(kept[&key("$TC_TP8", 0)] as i64 & 4, 4, "T1 disabled");
    println!("$TC_MOP2[1,1] {seen:.5} min after {cut:.3} s of cutting");
}

/// Fixture 091 (§9.15, D117) through motion and the simulated drives on the 802D mill with
/// its optional fourth axis as C and T1 D1 the fixture's cutter (radius 10.123): the program
/// runs as printed to its M2, back at X25 Z50 C120 (T1's length along Z), and while the
/// cutter is at the groove's base the developed position of its centre (C·r and the Y
/// slide's offset from C's centre) stays within OFFN − R of the groove's centre line, the
/// Y slide reaching that offset on both walls of the axial section.
#[test]
fn f091_tracyl_cuts_the_hook_slot_on_the_four_axis_mill() {
    let path = format!(
        "{}/launch_configs/sim_mill_802d.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap().replace(
        "    # - { name: A, min: -99999.0, max: 99999.0, home: 0.0, max_velocity: 10800.0, max_acceleration: 3600.0 }",
        "    - { name: C, min: -99999.0, max: 99999.0, home: 0.0, max_velocity: 10800.0, max_acceleration: 3600.0 }",
    );
    let mut cfg = cnc_runtime::LaunchConfig::from_yaml(&text).unwrap();
    assert_eq!(
        cfg.machine.axes.len(),
        4,
        "the C axis line is in sim_mill_802d.yaml"
    );
    let length = {
        let t1 = cfg.machine.tools.get_mut(&11).unwrap();
        t1.radius = 10.123;
        t1.z
    };
    let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
    let mut r = Rig::on(cfg, &fixture("091"), Some(&kept));
    r.run_until(0.1, |_| false);
    r.started = true;
    let inside = 12.4 - 10.123;
    let base = 17.5 + length;
    let (mut worst, mut wall_minus, mut wall_plus) = (0.0f64, 0.0f64, 0.0f64);
    let ok = r.run_until(600.0, |r| {
        let p = &r.fb.position;
        if (p[0] - base).abs() < 1e-3 && p[2] <= 1.0 {
            let y = p[3].to_radians() * 17.5 + (p[1] - 60.0);
            let z = p[2];
            let seg = |q: f64, lo: f64, hi: f64, across: f64| {
                ((lo - q).max(0.0).max(q - hi)).hypot(across)
            };
            let d = seg(z, -30.0, 1.0, y - 70.0).min(seg(y, 20.0, 70.0, z + 30.0));
            worst = worst.max(d);
            if z > -25.0 {
                wall_minus = wall_minus.min(p[1] - 60.0);
                wall_plus = wall_plus.max(p[1] - 60.0);
            }
        }
        r.program_done()
    });
    assert!(ok, "the program did not finish; events {:?}", r.events);
    println!("furthest from the centre line {worst:.4} (OFFN − R {inside:.4}); Y slide {wall_minus:.4} … {wall_plus:.4}");
    // The drives lag and corners blend within the path tolerance: 0.02 mm.
    assert!(worst <= inside + 0.02, "{worst}");
    assert!((wall_minus + inside).abs() < 1e-3 && (wall_plus - inside).abs() < 1e-3);
    let end = r.motion.commanded_display();
    let want = [25.0, 60.0, 50.0 + length, 120.0];
    assert!(
        end.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6),
        "{end:?}"
    );
}

/// Fixture 044 (§9.3.23, D118) through the interpreter, motion and the simulated drives:
/// the mill's Z meets a mechanical stop at 120 on its way from 150 to Z100; the move ends
/// there (X short of 250, the rest dropped), Z presses against the stop with the clamping
/// torque the block gives (12.3 %), `$AA_FXS[Z1]` reads 1, and the deselection's move takes
/// Z off the stop with its torque limit lifted. Without the stop the move ends at Z100
/// without meeting one: alarm 20091.
#[test]
fn f044_z_travels_to_its_fixed_stop_and_clamps_with_the_programmed_torque() {
    let text = fixture("044").replace("N10 G1 G94 ...", "N10 G1 G94 F100")
        + "N110 R1=$AA_FXS[Z1]\nN120 G1 Z140 FXS[Z1]=0\nN130 X0\nM30\n";
    let with_stop = |stop: Option<f64>| {
        let mut cfg = config("sim_mill_802d");
        cfg.sim.fixed_stops = stop
            .map(|at| cnc_runtime::config::FixedStopConfig {
                axis: "Z".into(),
                at,
            })
            .into_iter()
            .collect();
        let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
        let mut r = Rig::on(cfg, &text, Some(&kept));
        r.run_until(0.1, |_| false);
        r.started = true;
        r
    };
    let mut r = with_stop(Some(120.0));
    let mut clamped_torque = None;
    let mut lowest = f64::MAX;
    // F100 over some 150 mm each way: minutes of simulated time.
    let ok = r.run_until(600.0, |r| {
        lowest = lowest.min(r.fb.position[2]);
        if r.motion.fixed_stop_active(2) && r.motion.state() == cnc_motion::RunState::Idle {
            clamped_torque = Some(r.fb.torque_percent[2]);
        }
        r.program_done() || r.motion.state() == cnc_motion::RunState::Alarm
    });
    assert!(
        ok && r.program_done(),
        "motion {:?} {:?} at {:?}, PLC {:?}",
        r.motion.state(),
        r.motion.take_events(),
        r.fb.position,
        r.events
    );
    assert_eq!(lowest, 120.0, "Z never passed its stop");
    let kept = r.stream.interpreter().memory().kept;
    assert_eq!(kept.get(&10_001), Some(&1.0), "$AA_FXS[Z1] at the stop");
    println!("clamping torque {clamped_torque:?}");
    assert_eq!(clamped_torque, Some(12.3));
    assert_eq!(r.fb.torque_percent[2], 0.0, "off the stop");
    let end = r.motion.commanded_display();
    assert!(
        end[0].abs() < 1e-9 && (end[2] - 140.0).abs() < 1e-9,
        "{end:?}"
    );

    let mut r = with_stop(None);
    let alarmed = r.run_until(600.0, |r| r.motion.state() == cnc_motion::RunState::Alarm);
    assert!(alarmed, "a move that met no stop");
    let events = r.motion.take_events();
    assert!(
        events
            .iter()
            .any(|e| matches!(e, cnc_motion::MotionEvent::Alarm { number: 20091, .. })),
        "{events:?}"
    );
}

/// Fixture 041 (§9.3.20, D119) through motion: under COMPCAD the CAD points N60–N67 (its
/// template line made one more point of the curve) are cut within the compressor's tolerance
/// of every one of them, the STOPFIFO section starting once it is whole (the program's end
/// queued), and the program ends at its G0 Z50.
#[test]
fn f041_compcad_cuts_the_cad_points_within_the_tolerance() {
    // At F600 (the fixture's F10000 moves 0.67 mm a servo period) the path's samples lie
    // close enough to measure it between them.
    let text = fixture("041")
        .replace("\n...\n", "\nN67 X44.326 Z32.196\n")
        .replace("N20 G1 F10000", "N20 G1 F600");
    let mut r = mill(&text);
    let mut last: Option<Vec<f64>> = None;
    let points = [
        (30.0, 32.499),
        (41.365, 32.5),
        (43.115, 32.497),
        (43.365, 32.477),
        (43.556, 32.449),
        (43.818, 32.387),
        (44.076, 32.3),
        (44.326, 32.196),
    ];
    let mut nearest = [f64::MAX; 8];
    let ok = r.run_until(60.0, |r| {
        let c = r.motion.commanded_display();
        let a = last.replace(c.clone()).unwrap_or_else(|| c.clone());
        // Each point's distance from this period's piece of path (X–Z).
        let (dx, dz) = (c[0] - a[0], c[2] - a[2]);
        let len2 = dx * dx + dz * dz;
        for (k, (x, z)) in points.iter().enumerate() {
            let t = if len2 > 0.0 {
                (((x - a[0]) * dx + (z - a[2]) * dz) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (a[0] + t * dx - x).hypot(a[2] + t * dz - z);
            nearest[k] = nearest[k].min(d);
        }
        r.program_done()
    });
    assert!(ok, "events {:?}", r.events);
    println!("nearest approach to each point: {nearest:?}");
    assert!(nearest.iter().all(|d| *d <= 0.01), "{nearest:?}");
    let end = r.motion.commanded_display();
    assert!(
        (end[0] - 44.326).abs() < 1e-9 && (end[2] - 50.0).abs() < 1e-9,
        "{end:?}"
    );
}
