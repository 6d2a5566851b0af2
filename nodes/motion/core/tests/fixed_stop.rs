//! Travel to a fixed stop (FXS, D118) on the mill with a stop modelled here: Z's slide
//! cannot go below `STOP`; otherwise the drive follows its setpoint exactly.

use cnc_motion_core::motion::alarm;
use cnc_motion_core::{Block, Command, Motion, RunState};
use cnc_msgs::signals::GImage;

mod support;
use support::*;

const STOP: f64 = 95.0;

/// Ticks until idle or alarm; Z is held at the stop. The commanded positions and the
/// drive's setpoints (encoder counts) per tick.
fn run_against_stop(m: &mut Motion, max_ticks: usize) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    let (mut trace, mut sent) = (Vec::new(), Vec::new());
    for _ in 0..max_ticks {
        let setpoint = m.tick(Some(&slides), &g).to_vec();
        slides = setpoint.clone();
        slides[2] = slides[2].max(STOP);
        trace.push(m.commanded_display());
        sent.push(setpoint);
        if matches!(m.state(), RunState::Idle | RunState::Alarm) {
            break;
        }
    }
    (trace, sent)
}

fn fxs(seq: u64, on: bool) -> Block {
    block(
        seq,
        seq as u32 * 10,
        Command::FixedStop {
            axis: 2,
            on,
            torque: 12.3,
            window: 2.0,
        },
    )
}

fn line(seq: u64, end: [f64; 3]) -> Block {
    block(
        seq,
        seq as u32 * 10,
        Command::Linear {
            end: end.to_vec(),
            feed: 300.0,
        },
    )
}

#[test]
fn the_move_ends_at_the_stop_and_the_axis_presses_there_with_its_torque() {
    let mut m = Motion::new(mill(), &[0.0, 0.0, 120.0]);
    m.push(fxs(1, true));
    m.push(line(2, [20.0, 0.0, 80.0]));
    let (trace, sent) = run_against_stop(&mut m, 50_000);
    assert_eq!(m.state(), RunState::Idle, "{:?}", m.take_events());
    let r = *m.block_result().expect("the move's result");
    assert_eq!(r.seq, 2);
    assert!(r.triggered);
    // The rest of the move was dropped where Z met the stop (X short of 20 too), and the
    // commanded Z is where the slide stands.
    assert_eq!(r.rest[2], STOP);
    assert!(r.rest[0] > 0.0 && r.rest[0] < 20.0, "{:?}", r.rest);
    assert_eq!(m.commanded_display()[2], STOP);
    // The setpoint ran at most the threshold (2 mm) and the braking distance past the stop.
    let deepest = trace.iter().map(|p| p[2]).fold(f64::MAX, f64::min);
    assert!(deepest > STOP - 2.5, "{deepest}");
    // Clamped: the drive is set beyond the stop (pressing) with the torque limited.
    assert!(
        sent.last().is_some_and(|s| s[2] < STOP),
        "{:?}",
        sent.last()
    );
    assert_eq!(m.torque_limits()[2], 12.3);
    assert_eq!(m.torque_limits()[0], 100.0);
    assert!(m.take_events().is_empty());
    // FXS off with a move up: the limit is lifted and Z leaves the stop.
    m.push(fxs(3, false));
    m.push(line(4, [20.0, 0.0, 110.0]));
    run_against_stop(&mut m, 50_000);
    assert_eq!(m.state(), RunState::Idle);
    assert_eq!(m.commanded_display(), vec![20.0, 0.0, 110.0]);
    assert_eq!(m.torque_limits()[2], 100.0);
}

#[test]
fn a_move_that_never_meets_the_stop_is_alarm_20091() {
    let mut m = Motion::new(mill(), &[0.0, 0.0, 120.0]);
    m.push(fxs(1, true));
    m.push(line(2, [0.0, 0.0, 100.0]));
    run_against_stop(&mut m, 50_000);
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!(alarms(&mut m), [(alarm::FIXED_STOP_NOT_REACHED, 20)]);
    assert_eq!(m.torque_limits()[2], 100.0);
}

#[test]
fn a_clamped_axis_pushed_out_of_its_window_is_alarm_20094() {
    let mut m = Motion::new(mill(), &[0.0, 0.0, 120.0]);
    m.push(fxs(1, true));
    m.push(line(2, [0.0, 0.0, 80.0]));
    run_against_stop(&mut m, 50_000);
    assert_eq!(m.state(), RunState::Idle);
    // The stop gives way (the part slips): the slide goes 3 mm past where it was met.
    let g = GImage::released();
    for _ in 0..5 {
        let mut slides = m.setpoint().to_vec();
        slides[2] = STOP - 3.0;
        m.tick(Some(&slides), &g);
    }
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!(alarms(&mut m), [(alarm::FIXED_STOP_ABORTED, 20)]);
    // Without FXS the same stop is a crash: the following error trips the drive.
    let mut m = Motion::new(mill(), &[0.0, 0.0, 120.0]);
    m.push(line(1, [0.0, 0.0, 80.0]));
    run_against_stop(&mut m, 50_000);
    assert_eq!(alarms(&mut m), [(alarm::FOLLOWING_ERROR, 10)]);
}
