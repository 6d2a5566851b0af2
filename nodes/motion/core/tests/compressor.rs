//! COMPCAD and STOPFIFO in motion (D119): lines on a circle cut as its arc; a STOPFIFO
//! section waits in the queue until it is whole.

use cnc_motion_core::{Block, Command, Motion, RunState};
use cnc_msgs::signals::GImage;

mod support;
use support::*;

/// A CAD system's polyline of a circle of radius 50 about X0 Z0 (X–Z plane), every 5° from
/// 90° down to 0°, its coordinates rounded to a micrometre.
fn polyline(first_seq: u64) -> Vec<Block> {
    (1..=18)
        .map(|k| {
            let a = (90.0 - 5.0 * k as f64).to_radians();
            let q = |v: f64| (v * 1000.0).round() / 1000.0;
            block(
                first_seq + k - 1,
                100 + k as u32,
                Command::Linear {
                    end: vec![q(50.0 * a.cos()), 0.0, q(50.0 * a.sin())],
                    feed: 3000.0,
                },
            )
        })
        .collect()
}

/// Gives `blocks` to motion as the interpreter does, while fewer than its capacity are
/// unfinished, ticking a perfect drive until all are done: the commanded positions.
fn feed(m: &mut Motion, blocks: Vec<Block>) -> Vec<Vec<f64>> {
    let g = GImage::released();
    let mut blocks = std::collections::VecDeque::from(blocks);
    let mut trace = Vec::new();
    for _ in 0..100_000 {
        while m.accepted_seq() - m.done_seq() < m.capacity() as u64 {
            match blocks.pop_front() {
                Some(b) => m.push(b),
                None => break,
            }
        }
        let actual = m.commanded().to_vec();
        m.tick(Some(&actual), &g);
        trace.push(m.commanded_display());
        if blocks.is_empty() && matches!(m.state(), RunState::Idle | RunState::Alarm) {
            break;
        }
    }
    trace
}

/// The largest distance of the commanded path from the circle while it runs round it.
fn largest_deviation(compressor: bool) -> f64 {
    // A queue as deep as the cell's, so the interpreter's credit keeps the run in it.
    let mut cfg = mill();
    cfg.queue_capacity = 64;
    let mut m = Motion::new(cfg, &[0.0, 0.0, 50.0]);
    let mut blocks = vec![
        block(1, 1, Command::PathMode { exact_stop: false }),
        block(2, 2, Command::Compressor { on: compressor }),
    ];
    blocks.extend(polyline(3));
    let trace = feed(&mut m, blocks);
    assert_eq!(m.state(), RunState::Idle, "{:?}", m.take_events());
    let end = m.commanded_display();
    assert!(
        (end[0] - 50.0).abs() < 1e-9 && end[2].abs() < 1e-9,
        "{end:?}"
    );
    trace
        .iter()
        .map(|p| (p[0].hypot(p[2]) - 50.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn compcad_cuts_a_polyline_of_a_circle_on_the_circle() {
    let with = largest_deviation(true);
    let without = largest_deviation(false);
    println!(
        "largest distance from the circle: {with:.4} mm with COMPCAD, {without:.4} mm without"
    );
    // The chords' sagitta is 50·(1 − cos 2.5°) = 0.048 mm; the arc stays within the rounding.
    assert!(without > 0.02, "{without}");
    assert!(with < 0.005, "{with}");
}

#[test]
fn a_stopfifo_section_waits_until_it_is_whole() {
    let g = GImage::released();
    let mut m = Motion::new(mill(), &[0.0, 0.0, 50.0]);
    m.push(block(1, 1, Command::Fifo { fill: true }));
    let lines = polyline(2);
    for b in lines.iter().take(10).cloned() {
        m.push(b);
    }
    ticks(&mut m, &g, 50);
    assert_eq!(
        m.commanded_display(),
        vec![0.0, 0.0, 50.0],
        "nothing ran yet"
    );
    // The section's end is queued: it runs.
    m.push(block(12, 30, Command::Fifo { fill: false }));
    ticks(&mut m, &g, 50);
    assert_ne!(m.commanded_display(), vec![0.0, 0.0, 50.0]);
    // A full queue starts a section too (capacity 16 in the test mill).
    let mut m = Motion::new(mill(), &[0.0, 0.0, 50.0]);
    m.push(block(1, 1, Command::Fifo { fill: true }));
    for b in lines.iter().take(14).cloned() {
        m.push(b);
    }
    ticks(&mut m, &g, 50);
    assert_eq!(m.commanded_display(), vec![0.0, 0.0, 50.0]);
    m.push(lines[14].clone());
    ticks(&mut m, &g, 50);
    assert_ne!(m.commanded_display(), vec![0.0, 0.0, 50.0]);
}
