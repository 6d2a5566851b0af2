//! `cargo bench --workspace --bench motion`: the planner on the benchmark paths of
//! `../shared/bench` with the limits of its README, on the simulated clock.
//!
//! For each path and profile it prints the cycle time from the setpoint trace against
//! LinuxCNC 2.9's on the same limits, the largest axis velocity and acceleration over their
//! limits and the largest distance from the programmed path. Then a 50,000-segment program
//! of 0.02 mm chords at F3000: the time in feed moves against length / feed, and motion's CPU
//! time per servo tick.

use cnc::bench_paths::{bench_config, bench_dir, spiral_program, PATHS};
use cnc::simulate::{report, simulate, Options};
use cnc_interpreter::{Dialect, Library};
use cnc_runtime::config::ProfileShape;
use cnc_runtime::LaunchConfig;

fn main() {
    let cfg = match LaunchConfig::load(&bench_config()) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let profiles = [
        (
            "acceleration limited (trapezoidal)",
            ProfileShape::Trapezoidal,
        ),
        ("jerk limited (S-curve)", ProfileShape::SCurve),
    ];
    for path in &PATHS {
        let file = bench_dir().join(path.file);
        let Ok(text) = std::fs::read_to_string(&file) else {
            eprintln!("{}: cannot read", file.display());
            std::process::exit(1);
        };
        for (name, shape) in profiles {
            let options = Options {
                profile: Some(shape),
                timing: false,
            };
            match simulate(&cfg, Dialect::FanucMill, &text, Library::new(), options) {
                Ok(sim) => {
                    println!("== {} — {name}", path.file);
                    print!("{}", report(&sim));
                    println!(
                        "LinuxCNC 2.9 at 4 ms: {:.3} s; ratio {:.4}",
                        path.linuxcnc_seconds,
                        sim.cycle_time / path.linuxcnc_seconds
                    );
                }
                Err(e) => println!("== {}: {e}", path.file),
            }
        }
    }
    let segments = 50_000;
    let text = spiral_program(segments);
    for (name, shape) in profiles {
        let options = Options {
            profile: Some(shape),
            timing: true,
        };
        match simulate(&cfg, Dialect::FanucMill, &text, Library::new(), options) {
            Ok(sim) => {
                println!("== spiral of {segments} chords of 0.02 mm at F3000 — {name}");
                print!("{}", report(&sim));
                println!(
                    "feed moves over length / feed: {:.4}",
                    sim.stats.cutting_time / sim.stats.ideal_cutting_time
                );
            }
            Err(e) => println!("== spiral: {e}"),
        }
    }
}
