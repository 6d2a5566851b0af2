//! Programs and reference figures for the motion benchmarks (`../shared/bench/README.md`),
//! shared by `cargo bench --bench motion` and the tests that hold the planner to them.

use std::path::{Path, PathBuf};

/// A benchmark path and LinuxCNC 2.9's machining time for it at a 4 ms servo period.
pub struct BenchPath {
    pub file: &'static str,
    pub linuxcnc_seconds: f64,
}

pub const PATHS: [BenchPath; 2] = [
    BenchPath {
        file: "square.nc",
        linuxcnc_seconds: 7.568,
    },
    BenchPath {
        file: "circle_0p2mm.nc",
        linuxcnc_seconds: 3.616,
    },
];

/// The folder of the benchmark programs, beside the repository.
pub fn bench_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/bench")
}

/// The launch config of the benchmark mill.
pub fn bench_config() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("launch_configs/bench_mill.yaml")
}

/// A spiral from radius 20 to 60 mm as `segments` chords of 0.02 mm at F3000, coordinates to
/// 0.0001 mm as CAM output gives them: look-ahead over many tiny segments.
pub fn spiral_program(segments: usize) -> String {
    let mut text = String::with_capacity(segments * 28 + 64);
    let (r0, r1) = (20.0f64, 60.0f64);
    let chord = 0.02;
    let total = segments as f64 * chord;
    let mut theta = 0.0f64;
    text.push_str("G21 G90 G17 G64\nG0 X20.0000 Y0.0000 Z0\nF3000\n");
    for k in 1..=segments {
        // Radius grows linearly with the path length.
        let r = r0 + (r1 - r0) * (k as f64 * chord / total);
        theta += chord / r;
        text.push_str(&format!(
            "G1 X{:.4} Y{:.4}\n",
            r * theta.cos(),
            r * theta.sin()
        ));
    }
    text.push_str("M2\n");
    text
}
