//! `cargo bench --workspace --bench plc_scan`: scan time of the standard lathe program.
//!
//! 100,000 scans with the inputs of a working machine changing under it (M/S/T strobes, turret
//! sensors, door, chuck, keys), each timed. Reported against two references measured in the same
//! run: a program of END1/END2 alone (the cost of copying the images in and out), and the 1 ms
//! target; and per step against the manual's 3 µs per step (`000` §18.1).

use std::hint::black_box;
use std::time::Instant;

use cnc_msgs::signals::{f, x, FImage, SignalTable, XImage};
use cnc_plc_core::{Plc, Program};

const SCANS: usize = 100_000;

/// The inputs at scan `k`: a pattern that walks through strobes and sensor changes.
fn inputs(k: usize) -> (FImage, XImage) {
    let mut fi = FImage::default();
    let mut xi = XImage::default();
    xi.set(x::ESP_N, true);
    xi.set(x::ROBOT_CLEAR, true);
    xi.set(x::AIR_OK, true);
    xi.set(x::DOOR_CLOSED, true);
    xi.set(x::CHUCK_CLAMPED, k % 700 < 650);
    xi.set(x::CHUCK_UNCLAMPED, k % 700 >= 660);
    xi.set(x::TURRET_LOCKED, k % 50 > 10);
    xi.set(x::TOOL[(k / 50) % 8], k % 50 > 5);
    xi.set(x::SPINDLE_AT_SPEED, k % 40 > 20);
    xi.set(x::KEY_SINGLE_BLOCK, k.is_multiple_of(300));
    xi.bytes[x::FEED_OVERRIDE_SWITCH as usize] = 100;
    xi.bytes[x::SPINDLE_OVERRIDE_SWITCH as usize] = 100;
    let phase = k % 200;
    fi.set(f::OP, true);
    match phase {
        10..=40 => {
            fi.set(f::MF, true);
            fi.write_i32(f::M_CODE, [3, 5, 8, 10, 30][(k / 200) % 5]);
        }
        60..=90 => {
            fi.set(f::TF, true);
            fi.write_i32(f::T_CODE, ((k / 200) % 8) as i32 + 1);
        }
        110..=130 => {
            fi.set(f::SF, true);
            fi.write_i32(f::S_CODE, 1200);
        }
        _ => {}
    }
    (fi, xi)
}

/// Nanoseconds of each scan.
fn measure(program: &Program) -> Vec<u64> {
    let mut plc = Plc::new(program.clone(), None, 2);
    let mut out = Vec::with_capacity(SCANS);
    for k in 0..SCANS {
        let (fi, xi) = inputs(k);
        let t = Instant::now();
        plc.scan(black_box(&fi), black_box(&xi), k as u64 * 10);
        out.push(t.elapsed().as_nanos() as u64);
        black_box(plc.outputs());
    }
    out
}

fn percentile(sorted: &[u64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p) as usize] as f64 / 1000.0
}

fn main() {
    let standard = Program::parse(cnc_plc_core::LATHE_STANDARD).expect("standard program");
    let empty = Program::parse("END1\nEND2\n").expect("empty program");
    let mut reference = measure(&empty);
    let mut scan = measure(&standard);
    reference.sort_unstable();
    scan.sort_unstable();
    let level1 = standard.level1().len();
    let level2 = standard.level2().len();
    let per_scan = level1 as f64 + level2 as f64 / 2.0;
    let p50 = percentile(&scan, 0.5);
    println!(
        "standard lathe program: {} steps (level 1 {level1}, level 2 {level2} in 2 slices), {SCANS} scans",
        standard.steps.len()
    );
    println!(
        "scan time p50 {p50:.2} µs, p99 {:.2} µs, max {:.2} µs",
        percentile(&scan, 0.99),
        percentile(&scan, 1.0)
    );
    println!(
        "images alone (END1/END2): p50 {:.2} µs; the program costs {:.1}x that",
        percentile(&reference, 0.5),
        p50 / percentile(&reference, 0.5).max(1e-3)
    );
    println!(
        "against the 1 ms target: p50 {:.4}, p99 {:.4}",
        p50 / 1000.0,
        percentile(&scan, 0.99) / 1000.0
    );
    println!(
        "per step: {:.3} µs, the manual's PLC 3 µs ({:.1}x faster)",
        p50 / per_scan,
        3.0 / (p50 / per_scan)
    );
}
