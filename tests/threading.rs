//! Threads locked to the spindle encoder (issue 4, decision D36): the manual's G92 and G76
//! examples run through the interpreter, motion and the simulated lathe (drive lag, spindle
//! ramp), with the spindle speed stepped between passes as a spindle override would. Every
//! pass must start at the same spindle angle within 0.1° and cut the programmed lead within
//! 0.1 µm per revolution, measured on the simulated slides against the spindle encoder, with
//! the feed override at 50 % (threads ignore it).

use cnc_interpreter::{Canon, Dialect, Interpreter, Library};
use cnc_io::node::sim_config;
use cnc_io::sim::SimLathe;
use cnc_motion::{Block, FromLaunch, Motion, MotionConfig, MotionEvent, Panel, RunState};
use cnc_msgs::servo::{ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{f, g, y as out, GImage, SignalTable, YImage};
use cnc_runtime::LaunchConfig;
use cnc_task::run::ProgramRun;

fn fixture(name: &str) -> String {
    let path = format!(
        "{}/../shared/fixtures/000/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// One tick of a thread pass: spindle revolutions since start-up and Z of the slide.
#[derive(Clone, Copy)]
struct Sample {
    revs: f64,
    z: f64,
}

/// A thread pass: where its thread block starts (Z) and its samples.
struct Pass {
    start_z: f64,
    rpm: f64,
    samples: Vec<Sample>,
}

/// Runs `program` on the simulated lathe; between passes the spindle speed command is
/// multiplied by the next of `factors`.
fn run(program: &str, factors: &[f64]) -> Vec<Pass> {
    let cfg = LaunchConfig::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/launch_configs/sim_lathe.yaml"
    )))
    .expect("config");
    let zi = cfg.axis_index("Z").expect("a Z axis");
    let setup = cnc_task::node::setup_from_config(&cfg, &cfg.home());
    let mut stream = ProgramRun::new(Interpreter::with_library(
        Dialect::HuaxingLathe,
        program,
        setup,
        Library::new(),
    ));
    let mcfg = MotionConfig::from_launch(&cfg);
    let n = mcfg.axes.len();
    let dt = mcfg.period;
    let start = cfg.home_slide();
    let mut motion = Motion::new(mcfg, &start);
    // Feed override does not apply to threads (`000` §5.23): set it far from 100 %.
    motion.set_panel(Panel {
        feed_override: 0.5,
        ..Panel::default()
    });
    let mut sim = SimLathe::new(sim_config(&cfg), &start);
    let mut y = YImage::default();
    let (mut s_command, mut factor_index) = (0.0, 0);
    let mut plc = GImage::released();
    let mut direction = 0;
    let mut passes: Vec<Pass> = Vec::new();
    let mut was_cutting = false;
    let mut fb = sim.step(&ServoSetpoint::default(), &y, dt);
    let mut revs = 0.0;
    let mut last_angle = fb.spindle_angle_deg;
    for _tick in 0..2_000_000 {
        let done = motion.done_seq();
        stream
            .feed(done, 64, |seq, Canon { line, command, .. }, _| {
                motion.push(Block {
                    run_id: 1,
                    seq,
                    line,
                    kind: command,
                })
            })
            .expect("program interprets");
        if stream.all_sent()
            && motion.done_seq() == stream.sent()
            && motion.state() == RunState::Idle
        {
            return passes;
        }
        // A PLC that answers M and S at once, M03/M04 once the spindle is at speed.
        let fi = *motion.f_image();
        if !(fi.get(f::MF) || fi.get(f::SF) || fi.get(f::TF)) {
            plc.set(g::FIN, false);
        } else if !plc.get(g::FIN) {
            let mut fin = true;
            if fi.get(f::MF) {
                match fi.read_i32(f::M_CODE) {
                    3 => direction = 1,
                    4 => direction = 2,
                    5 => direction = 0,
                    _ => {}
                }
                y.set(out::SPINDLE_CW, direction == 1);
                y.set(out::SPINDLE_CCW, direction == 2);
                fin = (sim.spindle_rpm().abs() - y.spindle_rpm).abs() <= 0.01 * y.spindle_rpm
                    || direction == 0;
            }
            if fi.get(f::SF) {
                s_command = f64::from(fi.read_i32(f::S_CODE));
            }
            plc.set(g::FIN, fin);
        }
        y.spindle_rpm = s_command * factors[factor_index % factors.len()];
        let mut actual = [0.0; MAX_AXES];
        actual[..n].copy_from_slice(&fb.position[..n]);
        motion.spindle_feedback(fb.spindle_rpm, fb.spindle_angle_deg);
        let commanded = motion.tick(Some(&actual[..n]), &plc).to_vec();
        if let Some(MotionEvent::Alarm { number, text, line }) =
            motion.take_events().into_iter().next()
        {
            panic!("alarm {number} at line {line}: {text}");
        }
        let mut sp = ServoSetpoint {
            enable: 1,
            axis_count: n as u32,
            ..Default::default()
        };
        sp.position[..n].copy_from_slice(&commanded);
        fb = sim.step(&sp, &y, dt);
        revs += ((fb.spindle_angle_deg - last_angle + 180.0).rem_euclid(360.0) - 180.0) / 360.0;
        last_angle = fb.spindle_angle_deg;
        let cutting = motion.active_cutting() == Some(true);
        if cutting && !was_cutting {
            // A new pass starts where the slide stands.
            passes.push(Pass {
                start_z: commanded[zi],
                rpm: fb.spindle_rpm,
                samples: Vec::new(),
            });
        }
        if !cutting && was_cutting {
            factor_index += 1;
        }
        if cutting {
            passes.last_mut().unwrap().samples.push(Sample {
                revs,
                z: fb.position[zi],
            });
        }
        was_cutting = cutting;
    }
    panic!("program did not finish");
}

/// Start angle (degrees, mod 360) and lead (mm/rev) of a pass, from the samples where the
/// thread runs locked: the middle half of its Z travel.
fn measure(pass: &Pass, z_end: f64, lead: f64) -> (Vec<f64>, f64) {
    let z = |s: &Sample| s.z;
    let (z0, z1) = (pass.start_z, z_end);
    let (a, b) = (z0 + (z1 - z0) * 0.25, z0 + (z1 - z0) * 0.75);
    let (lo, hi) = (a.min(b), a.max(b));
    let locked: Vec<&Sample> = pass
        .samples
        .iter()
        .filter(|s| (lo..=hi).contains(&z(s)))
        .collect();
    assert!(locked.len() > 20, "{} locked samples", locked.len());
    // Spindle angle at which the slide would pass the start point on this helix.
    let angles = locked
        .iter()
        .map(|s| ((s.revs - (z0 - z(s)).abs() / lead) * 360.0).rem_euclid(360.0))
        .collect();
    let (first, last) = (locked[0], locked[locked.len() - 1]);
    let lead = (z(last) - z(first)).abs() / (last.revs - first.revs);
    (angles, lead)
}

/// Spread of angles on a circle, degrees.
fn spread(angles: &[f64]) -> f64 {
    let reference = angles[0];
    let offsets: Vec<f64> = angles
        .iter()
        .map(|a| (a - reference + 180.0).rem_euclid(360.0) - 180.0)
        .collect();
    let max = offsets.iter().copied().fold(f64::MIN, f64::max);
    let min = offsets.iter().copied().fold(f64::MAX, f64::min);
    max - min
}

fn check(name: &str, program: &str, z_end: f64, lead: f64, passes_expected: usize) {
    let factors = [1.0, 1.3, 0.8, 1.15, 0.9, 1.25];
    let passes = run(program, &factors);
    assert_eq!(passes.len(), passes_expected, "{name}: passes");
    let rpms: Vec<f64> = passes.iter().map(|p| p.rpm.round()).collect();
    // The speed really changed between passes.
    assert!(
        rpms.windows(2).all(|w| (w[0] - w[1]).abs() >= 20.0),
        "{name}: {rpms:?}"
    );
    let mut all = Vec::new();
    for (k, pass) in passes.iter().enumerate() {
        let (angles, measured) = measure(pass, z_end, lead);
        eprintln!("{name} pass {k}: lead {measured:.8} mm/rev");
        assert!(
            (measured - lead).abs() <= 1e-4,
            "{name} pass {k}: lead {measured:.7} mm/rev"
        );
        all.extend(angles);
    }
    let s = spread(&all);
    eprintln!(
        "{name}: start angle spread {s:.5}° over {} passes at {rpms:?} rpm",
        passes.len()
    );
    assert!(s <= 0.1, "{name}: start angles spread {s}°");
}

#[test]
fn g92_passes_land_in_the_same_groove_at_changing_speed() {
    // `000` §5.23.5: four passes, Z5 → Z-27 (K1 run-out to Z-28), lead 3.
    check(
        "G92",
        &fixture("039_g92_thread_cycle_O0012.nc"),
        -27.0,
        3.0,
        4,
    );
}

#[test]
fn g76_passes_land_in_the_same_groove_at_changing_speed() {
    // `000` §5.23.6: M68×6, passes from Z≈59 (flank infeed) to Z-9 before the run-out.
    check(
        "G76",
        &fixture("040_g76_multiple_thread_O0013.nc"),
        -9.0,
        6.0,
        6,
    );
}

#[test]
fn g34_lead_grows_by_r_every_revolution() {
    // `000` §5.23.2: lead 2 mm growing by R0.2 mm per revolution.
    let program = "O0001;\nM3 S300 G0 X40 Z5 T0101;\nG34 Z-40 F2 R0.2;\nG0 X50;\nZ5;\nM30;\n";
    let passes = run(program, &[1.0]);
    assert_eq!(passes.len(), 1);
    let samples = &passes[0].samples;
    // Z at spindle count r, between samples.
    let z_at = |r: f64| -> Option<f64> {
        let i = samples.iter().position(|s| s.revs >= r)?;
        let (a, b) = (samples.get(i.checked_sub(1)?)?, &samples[i]);
        Some(a.z + (b.z - a.z) * (r - a.revs) / (b.revs - a.revs))
    };
    // Advance over one revolution from r; it grows by R per revolution on the locked part.
    let advance = |r: f64| Some(z_at(r)? - z_at(r + 1.0)?);
    let (first, last) = (samples[0].revs, samples[samples.len() - 1].revs);
    let mut checked = 0;
    let mut r = first + 3.0;
    while r + 5.0 < last {
        let (a0, a1) = (advance(r).unwrap(), advance(r + 1.0).unwrap());
        assert!(
            (a1 - a0 - 0.2).abs() <= 1e-4,
            "advance {a0:.6} then {a1:.6} mm per revolution at {r:.3}"
        );
        checked += 1;
        r += 0.37;
    }
    assert!(checked > 10, "{checked} revolutions checked");
}
