//! The brake tail (issue 48): the stop motion plans after each batch of setpoints, played by the
//! drives if their queue runs dry. Checked on a lathe whose feedback comes 25 ticks late (a
//! 100 ms queue): from any moment of a line and an arc the tail stops on the programmed path,
//! without a step in velocity, within the axes' acceleration, and leaves motion in feed hold.

use std::collections::VecDeque;

use cnc_motion_core::{Command, Motion, RunState};
use cnc_msgs::servo::{MAX_AXES, TAIL_TICKS};
use cnc_msgs::signals::GImage;

mod support;
use support::*;

const DELAY: usize = 25;

/// A line along Z at 3000 mm/min, then a quarter arc: X50 (radius 25) from Z50 to Z-30, then to
/// X70 Z-40 around X50 Z-40.
fn part() -> Motion {
    let mut cfg = lathe();
    cfg.feedback_delay_ticks = DELAY as u32;
    let mut m = Motion::new(cfg, &[25.0, 50.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -30.0],
            feed: 3000.0,
        },
    ));
    m.push(block(
        2,
        2,
        Command::Arc {
            end: vec![70.0, -40.0],
            center: vec![50.0, -40.0],
            clockwise: false,
            feed: 3000.0,
            plane: None,
        },
    ));
    m.push(block(3, 3, Command::ProgramEnd));
    m
}

/// On the programmed path, slide units: the line X25, or the arc of radius 10 around X25 Z-40.
fn off_path(p: &[f64]) -> f64 {
    if p[1] >= -30.0 {
        (p[0] - 25.0).abs()
    } else {
        let r = ((p[0] - 25.0).powi(2) + (p[1] + 40.0).powi(2)).sqrt();
        (r - 10.0).abs()
    }
}

#[test]
fn the_tail_stops_on_the_path_without_a_step_in_velocity() {
    let g = GImage::released();
    let mut m = part();
    // Drives that follow exactly, reporting 25 ticks late.
    let mut sent: VecDeque<Vec<f64>> = VecDeque::new();
    let mut history: Vec<Vec<f64>> = Vec::new();
    let mut tails_checked = 0;
    let mut out = vec![[0.0; MAX_AXES]; TAIL_TICKS];
    let accel_step = 1000.0 * 0.004 * 0.004 * 1.001 + 1e-9; // a_max × T², per axis
    for tick in 0..20_000 {
        let actual = sent
            .front()
            .filter(|_| sent.len() >= DELAY)
            .cloned()
            .unwrap_or_else(|| m.setpoint().to_vec());
        let sp = m.tick(Some(&actual), &g).to_vec();
        sent.push_back(sp.clone());
        if sent.len() > DELAY {
            sent.pop_front();
        }
        history.push(sp);
        if tick % 17 == 5 && m.state() == RunState::Running && history.len() > 2 {
            let stop = m.brake_tail(&g, &mut out);
            assert!(stop.len < TAIL_TICKS, "the tail ends standing");
            let mut path: Vec<Vec<f64>> = history[history.len() - 2..].to_vec();
            path.extend(out[..stop.len].iter().map(|p| p[..2].to_vec()));
            for p in &path {
                assert!(off_path(p) < 1e-6, "tick {tick}: {p:?} leaves the path");
            }
            for w in path.windows(3) {
                for i in 0..2 {
                    let dv = (w[2][i] - w[1][i]) - (w[1][i] - w[0][i]);
                    assert!(
                        dv.abs() <= accel_step,
                        "tick {tick}: a step in velocity {w:?}"
                    );
                }
            }
            let last = &out[stop.len - 1];
            assert_eq!(last[..2], out[stop.len - 2][..2], "it stands at the end");
            // In feed hold, or at the program's end if the stop reached it.
            let state = stop.stopped.state();
            assert!(
                matches!(state, RunState::Hold | RunState::Idle),
                "{state:?}"
            );
            tails_checked += 1;
        }
        if m.state() == RunState::Idle && tick > 10 {
            break;
        }
    }
    assert!(tails_checked > 25, "only {tails_checked} tails checked");
    assert_eq!(m.commanded_display(), vec![70.0, -40.0]);
}

/// Motion going on from the tail's end state finishes the part: cycle start after the stop.
#[test]
fn the_part_goes_on_from_where_the_tail_stopped() {
    let g = GImage::released();
    let mut m = part();
    let mut out = vec![[0.0; MAX_AXES]; TAIL_TICKS];
    for _ in 0..300 {
        let actual = m.setpoint().to_vec();
        m.tick(Some(&actual), &g);
    }
    let stop = m.brake_tail(&g, &mut out);
    let mut m = *stop.stopped;
    assert_eq!(m.state(), RunState::Hold);
    let stood = out[stop.len - 1];
    m.cycle_start();
    let mut first = None;
    for _ in 0..20_000 {
        let actual = m.setpoint().to_vec();
        let sp = m.tick(Some(&actual), &g).to_vec();
        first.get_or_insert(sp);
        if m.state() == RunState::Idle {
            break;
        }
    }
    let first = first.expect("ticks");
    assert!((first[1] - stood[1]).abs() < 1e-3, "resumes from the stop");
    assert_eq!(m.commanded_display(), vec![70.0, -40.0]);
}
