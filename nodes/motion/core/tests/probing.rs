//! Measuring blocks (MEAS/MEAW, D116) on the mill with a touch probe modelled here: a face
//! at Z `FACE` the stylus is deflected below, its edge latched where the period's straight
//! path crossed it (as the drive latches it).

use cnc_motion_core::motion::{alarm, ProbeInput};
use cnc_motion_core::{Block, Command, Motion, RunState};
use cnc_msgs::servo::MAX_AXES;
use cnc_msgs::signals::GImage;

mod support;
use support::*;

const FACE: f64 = 2.5;
/// Most travel past the edge at 10 mm/s on the test mill: two periods' detection and the
/// jerk-limited stop (see the first test).
const BRAKING: f64 = 0.08 + 0.224;

/// The probe over a face at Z `face`: deflected at or below it.
struct Face {
    face: f64,
    input: ProbeInput,
}

impl Face {
    fn new(face: f64, at: &[f64]) -> Self {
        Face {
            face,
            input: ProbeInput {
                deflected: at[2] <= face,
                ..ProbeInput::default()
            },
        }
    }

    /// The slides went from `a` to `b` in one period.
    fn step(&mut self, a: &[f64], b: &[f64]) {
        let now = b[2] <= self.face;
        if now != self.input.deflected {
            let t = (self.face - a[2]) / (b[2] - a[2]);
            let mut at = [0.0; MAX_AXES];
            for i in 0..3 {
                at[i] = a[i] + t * (b[i] - a[i]);
            }
            if now {
                self.input.rising += 1;
                self.input.rising_at = at;
            } else {
                self.input.falling += 1;
                self.input.falling_at = at;
            }
        }
        self.input.deflected = now;
    }
}

/// Runs to idle or alarm on a perfect drive over the face: the commanded positions per tick.
fn run_over(m: &mut Motion, face: &mut Face, max_ticks: usize) -> Vec<Vec<f64>> {
    let g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    let mut trace = Vec::new();
    for _ in 0..max_ticks {
        m.probe_input(face.input);
        let before = slides.clone();
        slides = m.tick(Some(&slides), &g).to_vec();
        face.step(&before, &slides);
        trace.push(m.commanded_display());
        if matches!(m.state(), RunState::Idle | RunState::Alarm) {
            break;
        }
    }
    trace
}

fn probe(seq: u64, end: [f64; 3], rising: bool, stop: bool) -> Block {
    block(
        seq,
        seq as u32 * 10,
        Command::Probe {
            end: end.to_vec(),
            feed: 600.0,
            rising,
            stop,
        },
    )
}

#[test]
fn meas_latches_the_face_brakes_and_drops_the_rest_of_the_line() {
    let start = [10.0, 20.0, 10.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(FACE, &start);
    m.push(probe(1, [10.0, 20.0, -10.0], true, true));
    // The next block starts from where the axes came to rest.
    m.push(block(
        2,
        20,
        Command::Linear {
            end: vec![10.0, 20.0, 20.0],
            feed: 600.0,
        },
    ));
    let trace = run_over(&mut m, &mut face, 20_000);
    assert_eq!(m.state(), RunState::Idle);
    let r = *m.block_result().expect("a result");
    assert_eq!(r.seq, 1);
    assert!(r.triggered);
    // Latched at the face exactly, not where a period ended.
    assert!((r.position[2] - FACE).abs() < 1e-9, "{:?}", r.position);
    assert_eq!((r.position[0], r.position[1]), (10.0, 20.0));
    // Braked past the face within the edge's detection (up to two periods at 10 mm/s, 0.08
    // mm) and the jerk-limited stop from 10 mm/s (jerk 20,000 mm/s³: v·√(v/j) = 0.224 mm),
    // and the line's rest (to Z-10) dropped.
    let lowest = trace.iter().map(|p| p[2]).fold(f64::MAX, f64::min);
    assert!(lowest < FACE && lowest > FACE - BRAKING, "lowest {lowest}");
    assert!((r.rest[2] - lowest).abs() < 1e-9, "rest {:?}", r.rest);
    assert_eq!(m.commanded_display(), vec![10.0, 20.0, 20.0]);
    assert_eq!(m.done_seq(), 2);
}

#[test]
fn meaw_latches_the_face_and_runs_the_line_to_its_end() {
    let start = [0.0, 0.0, 10.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(FACE, &start);
    m.push(probe(1, [4.0, 0.0, -10.0], true, false));
    let trace = run_over(&mut m, &mut face, 20_000);
    let r = *m.block_result().expect("a result");
    assert!(r.triggered);
    assert!((r.position[2] - FACE).abs() < 1e-9);
    // On the line from (0, 10) to (4, −10), Z 2.5 is at X 1.5.
    assert!((r.position[0] - 1.5).abs() < 1e-9, "{:?}", r.position);
    assert_eq!(r.rest[..3], [4.0, 0.0, -10.0]);
    assert_eq!(trace.last().map(|p| p[2]), Some(-10.0));
}

#[test]
fn a_probe_that_does_not_switch_reports_so_and_the_line_ends_as_programmed() {
    let start = [0.0, 0.0, 10.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(-50.0, &start);
    m.push(probe(1, [0.0, 0.0, 0.0], true, true));
    run_over(&mut m, &mut face, 20_000);
    let r = *m.block_result().expect("a result");
    assert!(!r.triggered);
    assert_eq!(r.rest[..3], [0.0, 0.0, 0.0]);
    assert_eq!(r.position, r.rest);
}

#[test]
fn a_falling_edge_is_where_the_stylus_comes_free() {
    // Start deflected below the face and move up out of it.
    let start = [0.0, 0.0, 0.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(FACE, &start);
    m.push(probe(1, [0.0, 0.0, 8.0], false, true));
    run_over(&mut m, &mut face, 20_000);
    let r = *m.block_result().expect("a result");
    assert!(r.triggered);
    assert!((r.position[2] - FACE).abs() < 1e-9);
    assert!(
        r.rest[2] > FACE && r.rest[2] < FACE + BRAKING,
        "{:?}",
        r.rest
    );
}

#[test]
fn a_rising_edge_asked_of_a_deflected_probe_is_an_alarm_and_nothing_moves() {
    let start = [0.0, 0.0, 0.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(FACE, &start);
    m.push(probe(1, [0.0, 0.0, -5.0], true, true));
    let trace = run_over(&mut m, &mut face, 1_000);
    assert_eq!(m.state(), RunState::Alarm);
    assert!(trace.iter().all(|p| p[..3] == [0.0, 0.0, 0.0]));
    assert_eq!(alarms(&mut m), [(alarm::PROBE_DEFLECTED, 10)]);
    assert!(m.block_result().is_none());
}

#[test]
fn a_measuring_line_is_cut_on_its_own_and_a_new_run_starts_without_a_result() {
    // Lines before it end at rest: the probe block never blends with them.
    let start = [0.0, 0.0, 10.0];
    let mut m = Motion::new(mill(), &start);
    let mut face = Face::new(FACE, &start);
    m.push(block(
        1,
        5,
        Command::Linear {
            end: vec![5.0, 0.0, 10.0],
            feed: 600.0,
        },
    ));
    m.push(probe(2, [5.0, 0.0, -10.0], true, true));
    let trace = run_over(&mut m, &mut face, 20_000);
    // At the corner (X5 Z10) the axes stood: some tick's position is the corner itself.
    assert!(trace.iter().any(|p| p[..3] == [5.0, 0.0, 10.0]));
    assert!(m.block_result().is_some_and(|r| r.triggered && r.seq == 2));
    // A new run does not carry the last run's result: none until its own block is done.
    m.push(Block {
        run_id: 2,
        ..probe(1, [5.0, 0.0, 20.0], false, true)
    });
    ticks(&mut m, &GImage::released(), 10);
    assert_eq!(m.state(), RunState::Running);
    assert!(m.block_result().is_none());
}
