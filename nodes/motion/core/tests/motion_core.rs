//! Motion core on a perfect drive. `Motion::new` takes slide positions (X as radius): X50 is 25.
//! (actual = commanded) and a simple PLC that answers strobes.

use cnc_motion_core::{motion::alarm, Aux, Block, Command, Motion, MotionEvent, Panel, RunState};
use cnc_msgs::signals::{f, g, GImage, SignalTable};

mod support;
use support::*;

#[test]
fn program_runs_to_its_end_point_with_fin_handshake() {
    let mut m = Motion::new(lathe(), &[25.0, 50.0]);
    m.push(block(1, 1, Command::Aux(Aux::M(3))));
    m.push(block(
        2,
        2,
        Command::Rapid {
            end: vec![50.0, 2.0],
        },
    ));
    m.push(block(
        3,
        3,
        Command::Linear {
            end: vec![50.0, -30.0],
            feed: 600.0,
        },
    ));
    m.push(block(
        4,
        4,
        Command::Arc {
            end: vec![70.0, -40.0],
            center: vec![50.0, -40.0],
            clockwise: false,
            feed: 600.0,
            plane: None,
        },
    ));
    m.push(block(5, 5, Command::Aux(Aux::M(30))));
    m.push(block(6, 5, Command::ProgramEnd));
    let (trace, strobes) = run(&mut m, 100_000);
    assert_eq!(m.state(), RunState::Idle);
    assert_eq!(m.done_seq(), 6);
    assert_eq!(m.commanded_display(), vec![70.0, -40.0]);
    assert_eq!(strobes.iter().map(|s| s.1).collect::<Vec<_>>(), [3, 30]);
    // The arc stays on its circle: radius 10 around X50 (radius 25) Z-40 in slide units.
    let arc_points = trace.iter().filter(|p| p[1] < -30.0 && p[1] > -40.0);
    for p in arc_points {
        let r = ((p[0] / 2.0 - 25.0).powi(2) + (p[1] + 40.0).powi(2)).sqrt();
        assert!((r - 10.0).abs() < 1e-9, "{p:?} off the arc (r={r})");
    }
    // Feed 600 mm/min = 10 mm/s: no tick moves more than 10 mm/s * 4 ms along the line.
    for w in trace
        .windows(2)
        .filter(|w| w[0][1] <= 2.0 && w[1][1] >= -30.0 && w[0][0] == 50.0)
    {
        assert!((w[1][1] - w[0][1]).abs() <= 0.04 + 1e-9, "{w:?}");
    }
}

#[test]
fn soft_limit_is_refused_before_any_motion() {
    let mut m = Motion::new(lathe(), &[25.0, 50.0]);
    m.push(block(
        1,
        7,
        Command::Linear {
            end: vec![50.0, -500.0],
            feed: 600.0,
        },
    ));
    m.push(block(
        2,
        8,
        Command::Rapid {
            end: vec![0.0, 0.0],
        },
    ));
    let (trace, _) = run(&mut m, 100);
    assert_eq!(m.state(), RunState::Alarm);
    assert!(trace.iter().all(|p| p == &vec![50.0, 50.0]), "axes moved");
    let events = m.take_events();
    assert!(
        matches!(&events[..], [MotionEvent::Alarm { number, line: 7, .. }] if *number == alarm::SOFT_LIMIT),
        "{events:?}"
    );
    // An arc whose end is inside but whose bulge leaves the limits is refused too.
    // From X20 Z50 counter-clockwise around Z70 (radius 20) the arc dips to X-20, below -10.
    let mut m = Motion::new(lathe(), &[10.0, 50.0]);
    let arc = |clockwise| Command::Arc {
        end: vec![20.0, 90.0],
        center: vec![20.0, 70.0],
        clockwise,
        feed: 100.0,
        plane: None,
    };
    m.push(Block {
        run_id: 2,
        seq: 1,
        line: 3,
        kind: arc(false),
    });
    run(&mut m, 100);
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!(m.commanded_display(), vec![20.0, 50.0]);
    // The same arc clockwise goes over the top (X60) and is allowed.
    let mut m = Motion::new(lathe(), &[10.0, 50.0]);
    m.push(Block {
        run_id: 2,
        seq: 1,
        line: 3,
        kind: arc(true),
    });
    run(&mut m, 100_000);
    assert_eq!(m.state(), RunState::Idle);
    assert_eq!(m.commanded_display(), vec![20.0, 90.0]);
}

#[test]
fn feed_hold_stops_on_the_path_and_cycle_start_resumes() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -50.0],
            feed: 1200.0,
        },
    ));
    m.push(block(2, 2, Command::ProgramEnd));
    let g = GImage::released();
    ticks(&mut m, &g, 200);
    m.feed_hold();
    ticks(&mut m, &g, 200);
    assert_eq!(m.state(), RunState::Hold);
    let held = m.commanded_display();
    ticks(&mut m, &g, 1);
    assert_eq!(m.commanded_display(), held, "still moving in hold");
    assert_eq!(held[0], 50.0);
    m.cycle_start();
    let (_, _) = run(&mut m, 10_000);
    assert_eq!(m.commanded_display(), vec![50.0, -50.0]);
    assert_eq!(m.state(), RunState::Idle);
}

#[test]
fn emergency_stop_drops_the_run_and_holds_position() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -50.0],
            feed: 1200.0,
        },
    ));
    let mut g = GImage::released();
    ticks(&mut m, &g, 50);
    g.set(g::ESP_N, false);
    ticks(&mut m, &g, 1);
    let stopped = m.commanded_display();
    ticks(&mut m, &g, 10);
    assert_eq!(m.commanded_display(), stopped);
    assert_eq!(m.state(), RunState::Alarm);
}

fn rapid(run_id: u64, seq: u64, x: f64) -> Block {
    Block {
        run_id,
        seq,
        line: 1,
        kind: Command::Rapid { end: vec![x, 0.0] },
    }
}

/// Issue 26: one block with `run_id = 2^64-1` once disabled motion until a restart. A block
/// that neither continues the current run nor begins one is refused with an alarm, and
/// leaves no run id or sequence number behind: after reset the next run moves.
#[test]
fn a_block_of_no_run_is_refused_with_an_alarm_and_leaves_nothing_behind() {
    let mut m = Motion::new(lathe(), &[0.0, 0.0]);
    m.push(rapid(2, 1, 10.0));
    run(&mut m, 10_000);
    m.push(rapid(1, 2, 99.0));
    run(&mut m, 10_000);
    assert_eq!(m.commanded_display(), vec![10.0, 0.0]);
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!((m.run_id(), m.accepted_seq()), (2, 1));
    m.reset();
    m.push(rapid(u64::MAX, 7, 50.0));
    assert_eq!(
        (m.run_id(), m.accepted_seq()),
        (2, 1),
        "nothing of it stays"
    );
    m.reset();
    // A gap in the current run is refused the same way.
    m.push(rapid(3, 1, 20.0));
    run(&mut m, 10_000);
    m.push(rapid(3, 3, 30.0));
    run(&mut m, 10_000);
    assert_eq!(m.commanded_display(), vec![20.0, 0.0]);
    assert_eq!(m.state(), RunState::Alarm);
    m.reset();
    // Blocks of the run the reset dropped, still on their way, are let go quietly.
    m.push(rapid(3, 2, 25.0));
    assert_ne!(m.state(), RunState::Alarm);
    // Even a run with the largest id does not shut out the runs after it.
    m.push(rapid(u64::MAX, 1, 40.0));
    run(&mut m, 10_000);
    m.push(rapid(4, 1, 5.0));
    run(&mut m, 10_000);
    assert_eq!(m.commanded_display(), vec![5.0, 0.0]);
    assert_eq!(m.run_id(), 4);
}

#[test]
fn cycle_stop_stops_on_the_path_and_drops_the_rest_of_the_run() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -50.0],
            feed: 1200.0,
        },
    ));
    m.push(block(
        2,
        2,
        Command::Rapid {
            end: vec![80.0, 0.0],
        },
    ));
    let g = GImage::released();
    ticks(&mut m, &g, 100);
    m.cycle_stop();
    ticks(&mut m, &g, 200);
    assert_eq!(m.state(), RunState::Idle);
    let stopped = m.commanded_display();
    assert!(
        stopped[1] < 0.0 && stopped[1] > -50.0,
        "stopped at {stopped:?}"
    );
    assert_eq!(stopped[0], 50.0, "the rapid after the stop never started");
    // The next run starts from where the axes stand.
    m.push(Block {
        run_id: 2,
        seq: 1,
        line: 1,
        kind: Command::Rapid {
            end: vec![60.0, 10.0],
        },
    });
    run(&mut m, 10_000);
    assert_eq!(m.commanded_display(), vec![60.0, 10.0]);
}

#[test]
fn a_block_for_another_axis_set_is_refused_with_an_alarm() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        4,
        Command::Rapid {
            end: vec![10.0, 0.0, 5.0],
        },
    ));
    run(&mut m, 10);
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!(m.commanded_display(), vec![50.0, 0.0]);
    assert!(
        matches!(&m.take_events()[..], [MotionEvent::Alarm { number, line: 4, .. }] if *number == alarm::BAD_BLOCK)
    );
}

/// A full circle of radius 10 (slide units) around X50 Z-20 at F1200, from X70 Z-20.
fn circle_program(m: &mut Motion) {
    m.push(block(
        1,
        1,
        Command::Arc {
            end: vec![70.0, -20.0],
            center: vec![50.0, -20.0],
            clockwise: true,
            feed: 1200.0,
            plane: None,
        },
    ));
    m.push(block(2, 2, Command::ProgramEnd));
}

/// Path length travelled over a trace of display points (X diameter → slide radius).
fn travelled(trace: &[Vec<f64>]) -> f64 {
    trace
        .windows(2)
        .map(|w| ((w[1][0] - w[0][0]) / 2.0).hypot(w[1][1] - w[0][1]))
        .sum()
}

#[test]
fn feed_hold_mid_arc_stops_within_the_braking_distance_and_resumes_on_the_same_path() {
    for shape in [
        cnc_motion_core::profile::Shape::Trapezoidal,
        cnc_motion_core::profile::Shape::SCurve,
    ] {
        let mut cfg = lathe();
        cfg.shape = shape;
        let start = [35.0, -20.0];
        // Without hold: the reference trace.
        let mut plain = Motion::new(cfg.clone(), &start);
        circle_program(&mut plain);
        let mut reference = vec![plain.commanded_display()];
        reference.extend(run(&mut plain, 100_000).0);
        let length = travelled(&reference);
        assert!(
            (length - std::f64::consts::TAU * 10.0).abs() < 1e-3,
            "{length}"
        );

        let mut m = Motion::new(cfg.clone(), &start);
        circle_program(&mut m);
        let g = GImage::released();
        let mut trace = vec![m.commanded_display()];
        for _ in 0..100 {
            let actual = m.commanded().to_vec();
            m.tick(Some(&actual), &g);
            trace.push(m.commanded_display());
        }
        let at_hold = travelled(&trace);
        m.feed_hold();
        for _ in 0..300 {
            let actual = m.commanded().to_vec();
            m.tick(Some(&actual), &g);
            trace.push(m.commanded_display());
        }
        assert_eq!(m.state(), RunState::Hold);
        // Braking from 20 mm/s: v²/2a (+ v·a/2j for the S-curve, with j = a / 0.05 s) plus a
        // tick of travel.
        let v: f64 = 20.0;
        let a = 1000.0 * cnc_machine::DEFAULT_JERK_TIME;
        let allowed = v * v / 2000.0 + v * a / 2.0 / 1000.0 + v * 0.004;
        let braked = travelled(&trace) - at_hold;
        assert!(
            braked > 0.0 && braked <= allowed,
            "{shape:?}: {braked} > {allowed}"
        );
        m.cycle_start();
        let (rest, _) = run(&mut m, 100_000);
        trace.extend(rest);
        assert_eq!(m.state(), RunState::Idle);
        // The same path: every point on the circle, the same length, the same end.
        for p in &trace {
            let r = (p[0] / 2.0 - 25.0).hypot(p[1] + 20.0);
            assert!((r - 10.0).abs() < 1e-9, "{shape:?}: {p:?} off the circle");
        }
        let total = travelled(&trace);
        // Chords of different samplings differ from the arc by a few nanometres.
        assert!(
            (total - length).abs() < 1e-5,
            "{shape:?}: {total} vs {length}"
        );
        assert_eq!(trace.last(), reference.last());
    }
}

#[test]
fn lost_drive_feedback_stops_the_output_within_three_ticks() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -50.0],
            feed: 1200.0,
        },
    ));
    let g = GImage::released();
    ticks(&mut m, &g, 50);
    assert_eq!(m.state(), RunState::Running);
    // The drives stop answering.
    let mut outputs = vec![];
    for _ in 0..10 {
        outputs.push(m.tick(None, &g).to_vec());
    }
    assert_eq!(m.state(), RunState::Alarm);
    assert!(!m.servo_enabled());
    let events = m.take_events();
    assert!(
        matches!(&events[..], [MotionEvent::Alarm { number, .. }] if *number == alarm::FEEDBACK_LOST),
        "{events:?}"
    );
    // From the third tick without feedback the setpoint no longer moves.
    assert!(outputs[2..].windows(2).all(|w| w[0] == w[1]), "{outputs:?}");
    // Reset (after the drives are back) re-enables the servo.
    let actual = m.commanded().to_vec();
    m.tick(Some(&actual), &g);
    m.reset();
    assert!(m.servo_enabled());
    assert_eq!(m.state(), RunState::Idle);
}

#[test]
fn a_stalled_drive_raises_the_following_error_alarm() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Rapid {
            end: vec![50.0, -200.0],
        },
    ));
    let g = GImage::released();
    // Z is stuck at 0 while its setpoint runs away.
    let mut raised = None;
    for tick in 0..2000 {
        let mut actual = m.commanded().to_vec();
        actual[1] = 0.0;
        m.tick(Some(&actual), &g);
        if m.state() == RunState::Alarm {
            raised = Some(tick);
            break;
        }
    }
    assert!(raised.is_some(), "no alarm");
    let events = m.take_events();
    assert!(
        matches!(&events[..], [MotionEvent::Alarm { number, text, .. }]
            if *number == alarm::FOLLOWING_ERROR && text.contains('Z')),
        "{events:?}"
    );
    assert!(!m.servo_enabled());
    // The setpoint is put back where the slide is: no jump when the servo comes back.
    assert_eq!(m.commanded()[1], 0.0);
}

/// Issue 45 item 3: a drive that reports no number (NaN) is the axis's servo alarm, the run
/// stops, reset does not make it go away while the drive still reports none, and a jog is
/// refused meanwhile; the setpoints keep their last valid values.
#[test]
fn a_drive_that_reports_no_valid_position_is_an_alarm_that_stays() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Rapid {
            end: vec![50.0, -200.0],
        },
    ));
    let g = GImage::released();
    for _ in 0..10 {
        let actual = m.commanded().to_vec();
        m.tick(Some(&actual), &g);
    }
    assert_eq!(m.state(), RunState::Running);
    let before = m.commanded().to_vec();
    let mut broken = before.clone();
    broken[0] = f64::NAN;
    m.tick(Some(&broken), &g);
    assert_eq!(m.state(), RunState::Alarm);
    let events = m.take_events();
    assert!(
        matches!(&events[..], [MotionEvent::Alarm { number, text, .. }]
            if *number == alarm::FOLLOWING_ERROR && text.contains("X: no valid position")),
        "{events:?}"
    );
    assert!(
        m.commanded().iter().all(|v| v.is_finite()),
        "{:?}",
        m.commanded()
    );
    for _ in 0..5 {
        m.tick(Some(&broken), &g);
    }
    assert!(m.take_events().is_empty(), "raised once while it stands");
    m.reset();
    m.tick(Some(&broken), &g);
    assert_eq!(
        m.state(),
        RunState::Alarm,
        "reset does not hide a drive without position"
    );
    assert!(m.jog(0, true, 100.0, None).is_err(), "no jog meanwhile");
    assert!(m.commanded().iter().all(|v| v.is_finite()));
}

/// Three lines at F600 on Z from Z0, each 10 mm long, then program end.
fn three_lines(m: &mut Motion) {
    for k in 1..=3u64 {
        m.push(block(
            k,
            k as u32 * 10,
            Command::Linear {
                end: vec![50.0, -10.0 * k as f64],
                feed: 600.0,
            },
        ));
    }
    m.push(block(4, 40, Command::ProgramEnd));
}

/// Largest Z speed in a run of ticks, mm/min.
fn top_speed(m: &mut Motion, ticks: usize) -> f64 {
    let g = GImage::released();
    let mut top: f64 = 0.0;
    for _ in 0..ticks {
        let before = m.commanded_display()[1];
        let actual = m.commanded().to_vec();
        m.tick(Some(&actual), &g);
        top = top.max((m.commanded_display()[1] - before).abs() / 0.004 * 60.0);
    }
    top
}

#[test]
fn single_block_stops_after_each_line_until_cycle_start() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.set_panel(Panel {
        single_block: true,
        ..Panel::default()
    });
    three_lines(&mut m);
    let g = GImage::released();
    let mut stops = vec![];
    for _ in 0..20 {
        ticks(&mut m, &g, 2000);
        if m.state() == RunState::Idle {
            break;
        }
        // Stopped at rest, at the end of a line, holding.
        assert_eq!(m.state(), RunState::Hold);
        let z = m.commanded_display()[1];
        let before = m.commanded().to_vec();
        ticks(&mut m, &g, 50);
        assert_eq!(m.commanded(), &before[..], "moved while stopped");
        stops.push(z);
        m.cycle_start();
    }
    assert_eq!(stops, vec![-10.0, -20.0, -30.0]);
    assert_eq!(m.done_seq(), 4);
}

#[test]
fn feed_override_scales_the_feed_and_zero_stops_it() {
    let mut speeds = vec![];
    for ov in [0.5, 1.0, 1.5] {
        let mut m = Motion::new(lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            feed_override: ov,
            ..Panel::default()
        });
        three_lines(&mut m);
        speeds.push(top_speed(&mut m, 3000));
    }
    for (got, want) in speeds.iter().zip([300.0, 600.0, 900.0]) {
        assert!((got - want).abs() < 1e-6, "{speeds:?}");
    }
    // Turned down mid-move: the tool slows to the new feed without leaving the line.
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    three_lines(&mut m);
    top_speed(&mut m, 500);
    m.set_panel(Panel {
        feed_override: 0.2,
        ..Panel::default()
    });
    top_speed(&mut m, 200);
    let late = top_speed(&mut m, 200);
    assert!((late - 120.0).abs() < 1e-6, "{late}");
    assert_eq!(m.commanded_display()[0], 50.0);
    // 0 % stops the feed; raising it resumes.
    m.set_panel(Panel {
        feed_override: 0.0,
        ..Panel::default()
    });
    top_speed(&mut m, 200);
    assert_eq!(top_speed(&mut m, 100), 0.0);
    m.set_panel(Panel::default());
    run(&mut m, 100_000);
    assert_eq!(m.commanded_display(), vec![50.0, -30.0]);
}

#[test]
fn rapid_override_scales_the_rapid_rate() {
    let mut times = vec![];
    for ov in [1.0, 0.5, 0.25] {
        let mut m = Motion::new(lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            rapid_override: ov,
            ..Panel::default()
        });
        m.push(block(
            1,
            1,
            Command::Rapid {
                end: vec![50.0, -300.0],
            },
        ));
        m.push(block(2, 2, Command::ProgramEnd));
        let (trace, _) = run(&mut m, 100_000);
        times.push(trace.len() as f64 * 0.004);
    }
    // 300 mm at 6000 mm/min × override, plus less than 0.2 s of ramps.
    for (t, ov) in times.iter().zip([1.0, 0.5, 0.25]) {
        let cruise = 300.0 / (100.0 * ov);
        assert!(*t > cruise && *t < cruise + 0.2, "{times:?}");
    }
}

#[test]
fn dry_run_runs_feed_moves_at_the_dry_run_feed() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.set_panel(Panel {
        dry_run: true,
        ..Panel::default()
    });
    three_lines(&mut m);
    let top = top_speed(&mut m, 3000);
    assert!((top - 1000.0).abs() < 1e-6, "{top}");
    assert_eq!(m.commanded_display(), vec![50.0, -30.0]);
}

#[test]
fn m00_always_and_m01_with_the_switch_stop_until_cycle_start() {
    for (code, switch, stops) in [(0, false, true), (1, false, false), (1, true, true)] {
        let mut m = Motion::new(lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            optional_stop: switch,
            ..Panel::default()
        });
        m.push(block(1, 1, Command::Aux(Aux::M(code))));
        m.push(block(
            2,
            2,
            Command::Linear {
                end: vec![50.0, -10.0],
                feed: 600.0,
            },
        ));
        m.push(block(3, 3, Command::ProgramEnd));
        run(&mut m, 1000);
        let moved = m.commanded_display()[1] != 0.0;
        assert_eq!(moved, !stops, "M{code} switch {switch}");
        if stops {
            assert_eq!(m.state(), RunState::Hold);
            m.cycle_start();
            run(&mut m, 10_000);
        }
        assert_eq!(m.state(), RunState::Idle, "M{code} switch {switch}");
        assert_eq!(m.commanded_display(), vec![50.0, -10.0]);
    }
}

#[test]
fn a_thread_too_fine_to_finish_is_refused_with_an_alarm() {
    // A block off the DDS domain with a lead of 1e-300 mm: 1e301 revolutions.
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.spindle_feedback(300.0, 0.0);
    m.push(block(
        1,
        7,
        Command::Thread {
            end: vec![50.0, -10.0],
            lead: 1e-300,
            start_angle: 0.0,
        },
    ));
    ticks(&mut m, &GImage::released(), 3);
    assert_eq!(m.state(), RunState::Alarm);
    let events = m.take_events();
    assert!(
        matches!(&events[..], [MotionEvent::Alarm { number, line: 7, .. }] if *number == alarm::BAD_BLOCK),
        "{events:?}"
    );
    assert_eq!(m.commanded_display(), vec![50.0, 0.0]);
}

#[test]
fn plc_signals_drive_hold_start_overrides_and_reset_shows_as_rst() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Linear {
            end: vec![50.0, -50.0],
            feed: 600.0,
        },
    ));
    let mut g = GImage::released();
    g.bytes[g::FEED_OVERRIDE as usize] = 50;
    m.plc_signals(&g);
    ticks(&mut m, &g, 400);
    // 600 mm/min at 50 %: 5 mm/s of travel along the path.
    let before = m.commanded_display();
    ticks(&mut m, &g, 25);
    let after = m.commanded_display();
    let d = (((after[0] - before[0]) / 2.0).powi(2) + (after[1] - before[1]).powi(2)).sqrt();
    assert!((d - 0.5).abs() < 1e-6, "{d} mm in 0.1 s");
    // *SP low: feed hold; ST's rising edge resumes once *SP is high again.
    g.set(g::SP_N, false);
    m.plc_signals(&g);
    ticks(&mut m, &g, 200);
    assert_eq!(m.state(), RunState::Hold);
    g.set(g::SP_N, true);
    g.set(g::ST, true);
    m.plc_signals(&g);
    ticks(&mut m, &g, 1);
    assert_eq!(m.state(), RunState::Running);
    // Reset: RST (F1.1) stays on for 100 ms of ticks so the PLC's 10 ms scan sees it.
    m.reset();
    ticks(&mut m, &g, 24);
    assert!(m.f_image().get(f::RST));
    ticks(&mut m, &g, 2);
    assert!(!m.f_image().get(f::RST));
}

/// Each arc turns in the plane it names (G18: Z-X, G19: Y-Z), whatever the configured arc
/// plane; the third axis moves with it (a helix); an arc naming an axis the machine lacks is
/// refused.
#[test]
fn arcs_turn_in_the_plane_they_name() {
    // G18 half circle from X10 Z0 around X0 Z0 clockwise (seen from +Y) to X-10 Z0, rising
    // in Y from 0 to 4: it passes Z+10 (Z→X counter-clockwise is the G18 sense).
    let mut m = Motion::new(mill(), &[10.0, 0.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Arc {
            end: vec![-10.0, 4.0, 0.0],
            center: vec![0.0, 4.0, 0.0],
            clockwise: true,
            feed: 1200.0,
            plane: Some([2, 0]),
        },
    ));
    m.push(block(2, 2, Command::ProgramEnd));
    let (trace, _) = run(&mut m, 100_000);
    assert_eq!(m.state(), RunState::Idle);
    for p in &trace {
        let r = p[0].hypot(p[2]);
        assert!((r - 10.0).abs() < 0.01, "{p:?} off the Z-X circle");
        assert!(p[1] >= -1e-9 && p[1] <= 4.0 + 1e-9, "{p:?}");
    }
    let top = trace.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
    assert!(
        (top - 10.0).abs() < 0.01,
        "clockwise in G18 goes over +Z: {top}"
    );
    // G19 quarter from Y10 Z0 counter-clockwise around Y0 Z0 to Y0 Z10.
    let mut m = Motion::new(mill(), &[0.0, 10.0, 0.0]);
    m.push(block(
        1,
        1,
        Command::Arc {
            end: vec![0.0, 0.0, 10.0],
            center: vec![0.0, 0.0, 0.0],
            clockwise: false,
            feed: 1200.0,
            plane: Some([1, 2]),
        },
    ));
    m.push(block(2, 2, Command::ProgramEnd));
    let (trace, _) = run(&mut m, 100_000);
    assert_eq!(m.state(), RunState::Idle);
    assert!(trace
        .iter()
        .all(|p| (p[1].hypot(p[2]) - 10.0).abs() < 0.01 && p[1] >= -1e-9 && p[2] >= -1e-9));
    // An arc in a plane with an axis the machine does not have.
    let mut m = Motion::new(mill(), &[10.0, 0.0, 0.0]);
    m.push(block(
        1,
        7,
        Command::Arc {
            end: vec![-10.0, 0.0, 0.0],
            center: vec![0.0, 0.0, 0.0],
            clockwise: true,
            feed: 1200.0,
            plane: Some([0, 5]),
        },
    ));
    run(&mut m, 100);
    assert_eq!(m.state(), RunState::Alarm);
    assert_eq!(m.commanded_display(), vec![10.0, 0.0, 0.0]);
}

#[test]
fn machine_lock_runs_the_program_and_holds_the_drives_where_the_slides_stand() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.set_panel(Panel {
        machine_lock: true,
        ..Panel::default()
    });
    drive(&mut m, 1); // the switch is taken at rest
    assert!(m.f_image().get(f::MMLK));
    three_lines(&mut m);
    let sent = drive(&mut m, 20_000).sent;
    assert_eq!(m.state(), RunState::Idle);
    assert!(m.take_events().is_empty(), "no following error, no alarm");
    assert!(m.f_image().get(f::MMLK));
    // The program's position followed every line; the drives never moved.
    assert_eq!(m.commanded_display(), vec![50.0, -30.0]);
    assert!(
        sent.len() > 100 && sent.iter().all(|s| s == &vec![25.0, 0.0]),
        "{:?}",
        sent.last()
    );

    // Released at rest: the program's position is where the slides are again.
    m.set_panel(Panel::default());
    let sent = drive(&mut m, 1).sent;
    assert_eq!(sent, vec![vec![25.0, 0.0]]);
    assert_eq!(m.commanded_display(), vec![50.0, 0.0]);
    assert!(!m.f_image().get(f::MMLK));
}

#[test]
fn machine_lock_switched_during_a_run_waits_for_the_machine_at_rest() {
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    three_lines(&mut m);
    drive(&mut m, 50);
    let moving = m.commanded().to_vec();
    assert_ne!(moving[1], 0.0, "the run is under way");
    // Lock on mid-run: the slides keep following the program to its end.
    m.set_panel(Panel {
        machine_lock: true,
        ..Panel::default()
    });
    let sent = drive(&mut m, 20_000).sent;
    assert_eq!(m.state(), RunState::Idle);
    assert_eq!(sent.last().map(|s| s[1]), Some(-30.0));
    assert!(!m.f_image().get(f::MMLK));
    // At rest it takes effect: the next run moves nothing.
    drive(&mut m, 1);
    assert!(m.f_image().get(f::MMLK));
    m.push(block(
        5,
        50,
        Command::Linear {
            end: vec![30.0, -30.0],
            feed: 600.0,
        },
    ));
    m.push(block(6, 60, Command::ProgramEnd));
    let sent = drive(&mut m, 20_000).sent;
    assert!(
        sent.iter().all(|s| s == &vec![25.0, -30.0]),
        "{:?}",
        sent.last()
    );
    assert_eq!(m.commanded_display(), vec![30.0, -30.0]);
}

#[test]
fn aux_lock_keeps_m_s_and_t_from_the_plc_but_not_the_program_stops() {
    for lock in [false, true] {
        let mut m = Motion::new(lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            aux_lock: lock,
            ..Panel::default()
        });
        let mut kinds: Vec<Command> = [Aux::M(3), Aux::S(800.0), Aux::T(3), Aux::M(8)]
            .into_iter()
            .map(Command::Aux)
            .collect();
        // The programmed speed is known either way: a feed per revolution runs.
        kinds.push(Command::FeedMode { per_rev: true });
        kinds.push(Command::Linear {
            end: vec![50.0, -1.0],
            feed: 0.1,
        });
        kinds.push(Command::Aux(Aux::M(0)));
        kinds.push(Command::ProgramEnd);
        for (k, kind) in kinds.into_iter().enumerate() {
            m.push(block(k as u64 + 1, k as u32 + 1, kind));
        }
        let strobes = drive(&mut m, 5_000).strobes;
        let all = vec![("M", 3), ("S", 800), ("T", 3), ("M", 8), ("M", 0)];
        let expected = if lock { vec![("M", 0)] } else { all };
        assert_eq!(strobes, expected, "aux lock {lock}");
        assert_eq!(m.f_image().get(f::MAFL), lock);
        assert!(m.take_events().is_empty(), "aux lock {lock}");
        assert_eq!(m.commanded_display(), vec![50.0, -1.0], "aux lock {lock}");
        // M00 holds in both cases, after its FIN.
        assert_eq!(m.state(), RunState::Hold, "aux lock {lock}");
    }
}

/// A spindle position goes to the PLC as M19 with its stop position in F30–F35 (angle in
/// 0.001°, way, a count that changes with each positioning), M19 alone with 0 the shortest
/// way, so the ladder can pass the bytes on to the drive (D100).
#[test]
fn a_spindle_position_is_m19_with_its_stop_position_in_the_f_image() {
    use cnc_msgs::canon::Turn;
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    let orient = |degrees, way| Command::Aux(Aux::Orient { degrees, way });
    let kinds = [
        orient(14.3, Turn::Shortest),
        Command::Aux(Aux::M(19)),
        orient(-720.5, Turn::Incremental),
        orient(-720.5, Turn::Incremental),
        orient(300.0, Turn::Minus),
        Command::Aux(Aux::M(3)),
        Command::ProgramEnd,
    ];
    for (k, kind) in kinds.into_iter().enumerate() {
        m.push(block(k as u64 + 1, k as u32 + 1, kind));
    }
    let mut g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    let mut seen = Vec::new();
    for _ in 0..5_000 {
        slides = m.tick(Some(&slides), &g).to_vec();
        let fi = *m.f_image();
        if fi.get(f::MF) && !g.get(g::FIN) {
            seen.push((
                fi.read_i32(f::M_CODE),
                fi.read_i32(f::ORIENT_ANGLE),
                fi.bytes[f::ORIENT_WAY],
                fi.bytes[f::ORIENT_COUNT],
            ));
            g.set(g::FIN, true);
        }
        if !fi.get(f::MF) {
            g.set(g::FIN, false);
        }
        if m.state() == RunState::Idle {
            break;
        }
    }
    assert_eq!(
        seen,
        [
            (19, 14_300, 0, 1),
            (19, 0, 0, 2),
            (19, -720_500, 3, 3),
            (19, -720_500, 3, 4),
            (19, 300_000, 2, 5),
            (3, 0, 0, 5),
        ]
    );
}

/// Rigid tapping (D101): motion sends the tap's travel as an incremental positioning with its
/// speed (M19, F30–F39), then sets the axis by the spindle's angle as the encoder reports it,
/// whatever the spindle's acceleration; the PLC's FIN (the spindle standing at the end) ends
/// the block with the axis exactly at its end. Refused: under aux lock, above the spindle's
/// rating, and when the axis could not follow.
#[test]
fn a_tap_follows_the_spindles_angle_and_ends_with_its_positioning() {
    let tap = |end: f64, lead: f64, rpm: f64| Command::Tap {
        end: vec![0.0, 0.0, end],
        lead,
        rpm,
    };
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    m.push(block(1, 1, tap(-10.0, 1.25, 600.0)));
    m.push(block(2, 2, Command::ProgramEnd));
    let mut g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    // The simulated spindle: unwrapped angle, speed; it ramps at 3000 rpm/s to the goal.
    let (mut turned, mut rpm, mut goal) = (0.0f64, 0.0f64, None::<(f64, f64)>);
    let mut worst: f64 = 0.0;
    for _ in 0..10_000 {
        m.spindle_feedback(rpm, turned.rem_euclid(360.0));
        slides = m.tick(Some(&slides), &g).to_vec();
        let fi = *m.f_image();
        if fi.get(f::MF) && goal.is_none() {
            assert_eq!(fi.read_i32(f::M_CODE), 19);
            assert_eq!(fi.bytes[f::ORIENT_WAY], 3, "incremental");
            assert_eq!(fi.read_i32(f::ORIENT_SPEED), 600);
            goal = Some((
                turned + f64::from(fi.read_i32(f::ORIENT_ANGLE)) / 1000.0,
                turned,
            ));
        }
        if let Some((to, from)) = goal {
            // The axis where the spindle's angle puts it (the setpoint reads one period and
            // the drive lag ahead, so allow what the spindle turns in that time).
            let want = -(turned - from) / 360.0 * 1.25;
            worst = worst.max((m.commanded_display()[2] - want).abs());
            let rest = to - turned;
            let cmd = rest.signum() * 600f64.min((3000.0 * rest.abs() / 3.0).sqrt());
            rpm += (cmd - rpm).clamp(-12.0, 12.0);
            turned += rpm / 60.0 * 360.0 * 0.004;
            if (to - turned).abs() < 0.05 && rpm.abs() < 13.0 {
                (turned, rpm) = (to, 0.0);
                g.set(g::FIN, true);
            }
        }
        if !fi.get(f::MF) {
            g.set(g::FIN, false);
        }
        if m.state() == RunState::Idle {
            break;
        }
    }
    let (to, from) = goal.expect("the positioning was sent");
    // 10 mm at 1.25 mm a turn: eight turns the way M3 turns (the lead's sign), the axis down.
    assert!(
        (to - from - 10.0 / 1.25 * 360.0).abs() < 1e-3,
        "{}",
        to - from
    );
    assert_eq!(m.state(), RunState::Idle);
    assert_eq!(m.commanded_display()[2], -10.0);
    // 600 rpm × 1.25 mm = 12.5 mm/s: one period and the lag ahead is at most 0.2 mm.
    assert!(worst < 0.2, "the axis kept to the spindle: {worst}");

    for (kind, lock, number) in [
        (tap(-10.0, 1.25, 600.0), true, alarm::SPINDLE_NOT_TURNING),
        (tap(-10.0, 1.25, 7000.0), false, alarm::BAD_BLOCK),
        (tap(-10.0, 100.0, 6000.0), false, alarm::THREAD_RUN_IN),
    ] {
        let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
        m.set_panel(Panel {
            aux_lock: lock,
            ..Panel::default()
        });
        m.push(block(1, 1, kind.clone()));
        drive(&mut m, 100);
        assert_eq!(m.state(), RunState::Alarm, "{kind:?}");
        let raised: Vec<u32> = m
            .take_events()
            .into_iter()
            .map(|MotionEvent::Alarm { number, .. }| number)
            .collect();
        assert_eq!(raised, [number], "{kind:?}");
    }
}

/// FFWON (D106): while a block moves the axes the drives get the commanded position plus the
/// axis's velocity times its drive lag; at rest, after FFWOF and after a reset they get the
/// commanded position itself.
#[test]
fn feedforward_leads_the_setpoint_by_velocity_times_lag_only_while_moving() {
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    let lag = mill().axes[0].drive_lag;
    assert!(lag > 0.0);
    let kinds = [
        Command::Feedforward { on: true },
        Command::Linear {
            end: vec![100.0, 0.0, 0.0],
            feed: 3000.0,
        },
        Command::Feedforward { on: false },
        Command::Linear {
            end: vec![0.0, 0.0, 0.0],
            feed: 3000.0,
        },
        Command::ProgramEnd,
    ];
    for (k, kind) in kinds.into_iter().enumerate() {
        m.push(block(k as u64 + 1, k as u32 + 1, kind));
    }
    let g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    let (mut led, mut plain) = (0.0f64, 0.0f64);
    for _ in 0..20_000 {
        let before = m.commanded().to_vec();
        slides = m.tick(Some(&slides), &g).to_vec();
        let v = (m.commanded()[0] - before[0]) / 0.004;
        let lead = slides[0] - m.commanded()[0];
        if v > 49.9 {
            // 50 mm/s out: the lead is v × lag.
            assert!((lead - v * lag).abs() < 1e-9, "{lead} at {v}");
            led = led.max(lead);
        }
        if v < -49.9 {
            plain = plain.max(lead.abs());
        }
        if m.state() == RunState::Idle {
            break;
        }
    }
    assert!(led > 0.0 && plain == 0.0, "{led} {plain}");
    assert_eq!(slides, m.commanded());
}

/// ACC (D108): an axis's acceleration override holds for the moves after it; a new run starts
/// at the rated acceleration again.
#[test]
fn an_acceleration_override_scales_the_axis_until_the_next_run() {
    let peak = |m: &mut Motion, run_id: u64, kinds: Vec<Command>| {
        for (k, kind) in kinds.into_iter().enumerate() {
            m.push(Block {
                run_id,
                ..block(k as u64 + 1, k as u32 + 1, kind)
            });
        }
        let d = drive(m, 20_000);
        let v: Vec<f64> = d
            .displayed
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]) / 0.004)
            .collect();
        v.windows(2)
            .map(|w| ((w[1] - w[0]) / 0.004).abs())
            .fold(0.0, f64::max)
    };
    let line = |x: f64| Command::Linear {
        end: vec![x, 0.0, 0.0],
        feed: 6000.0,
    };
    let rated = mill().axes[0].max_acceleration;
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    let slow = peak(
        &mut m,
        1,
        vec![
            Command::Acceleration {
                axis: 0,
                percent: 50.0,
            },
            line(100.0),
            Command::ProgramEnd,
        ],
    );
    assert!(
        (slow - 0.5 * rated).abs() < 0.02 * rated,
        "{slow} of {rated}"
    );
    // The next run (a new run id) is at 100 % again.
    assert_eq!(m.state(), RunState::Idle);
    let full = peak(&mut m, 2, vec![line(0.0), Command::ProgramEnd]);
    assert!((full - rated).abs() < 0.02 * rated, "{full} of {rated}");
}

/// ACC[S] (D108): the spindle drive's share goes out with every setpoint from its block on;
/// the next run starts at 100 % again.
#[test]
fn the_spindle_acceleration_override_holds_until_the_next_run() {
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    let kinds = [
        Command::Acceleration {
            axis: cnc_msgs::canon::SPINDLE_AXIS,
            percent: 40.0,
        },
        Command::Linear {
            end: vec![10.0, 0.0, 0.0],
            feed: 6000.0,
        },
        Command::ProgramEnd,
    ];
    assert_eq!(m.spindle_acceleration_percent(), 100.0);
    for (k, kind) in kinds.into_iter().enumerate() {
        m.push(Block {
            run_id: 1,
            ..block(k as u64 + 1, k as u32 + 1, kind)
        });
    }
    drive(&mut m, 5_000);
    assert!((m.spindle_acceleration_percent() - 40.0).abs() < 1e-9);
    m.push(Block {
        run_id: 2,
        ..block(1, 1, Command::ProgramEnd)
    });
    drive(&mut m, 100);
    assert_eq!(m.spindle_acceleration_percent(), 100.0);
}
