//! The live tool in speed mode (decision D143): motion turns its angle at the speed, ramped
//! at its acceleration, while the path feeds the slides and leaves the tool's axis alone; out
//! of speed mode it brakes and stands in position control, the program's angle 0 there, so
//! a tap after it turns from where it stopped. Program end and reset stop it.

use cnc_machine::LiveToolEntry;
use cnc_motion_core::{Command, Motion, MotionConfig, RunState};
use cnc_msgs::signals::{g, GImage, SignalTable};

mod support;
use support::*;

const PERIOD: f64 = 0.004;

/// The lathe with a live tool A: 2500 r/min top speed in 0.25 s.
fn with_live_tool() -> MotionConfig {
    let mut cfg = lathe();
    cfg.live_tool = Some(LiveToolEntry {
        axis: "A".into(),
        max_rpm: 2500.0,
        time_constant: 0.25,
        drive_lag: 0.008,
    });
    cfg
}

fn turn_mill() -> Motion {
    Motion::new(with_live_tool(), &[50.0, 0.0])
}

/// The turn-mill with `kinds` queued as one program, a block a line.
fn running(kinds: Vec<Command>) -> Motion {
    let mut m = turn_mill();
    for (i, kind) in (1..).zip(kinds) {
        m.push(block(u64::from(i), i, kind));
    }
    m
}

/// One tick of the run: (Z setpoint, the tool's angle setpoint, its speed in r/min).
fn tick(m: &mut Motion, g: &GImage) -> (f64, f64, f64) {
    ticks(m, g, 1);
    (
        m.commanded_display()[1],
        m.live_tool_setpoint(),
        m.live_tool_rpm(),
    )
}

#[test]
fn the_tool_turns_at_its_speed_while_the_slide_drills_and_a_tap_after_m66_starts_where_it_stopped()
{
    let g = GImage::released();
    let mut m = running(vec![
        Command::LiveTool { rpm: 1500.0 },
        Command::Linear {
            end: vec![50.0, -10.0, 0.0],
            feed: 120.0,
        },
        Command::LiveTool { rpm: 0.0 },
        // A tap after it: two turns with 2 mm of Z at 1000 r/min (the feed along the
        // machine line of mm and degrees, as the interpreter's G14 gives it).
        Command::Linear {
            end: vec![50.0, -12.0, 720.0],
            feed: 2f64.hypot(720.0) / 0.002,
        },
        Command::ProgramEnd,
    ]);
    let mut seen = Vec::new();
    for _ in 0..5_000 {
        seen.push(tick(&mut m, &g));
        if m.state() == RunState::Idle {
            break;
        }
    }
    assert_eq!(m.state(), RunState::Idle, "{:?}", alarms(&mut m));
    // The ramp: 1500 r/min is 60 % of the top speed, 0.15 s, 38 ticks; the slide waits for it.
    let up = seen.iter().position(|s| s.2 == 1500.0).expect("at speed");
    assert!((37..=38).contains(&up), "at speed after {up} ticks");
    assert!(
        seen[..up].iter().all(|s| s.0 == 0.0),
        "the slide waits for the tool"
    );
    // While Z feeds to −10 the tool turns 1500 r/min: 36° every tick, exactly.
    let drilling: Vec<_> = seen
        .windows(2)
        .filter(|w| w[1].0 < 0.0 && w[1].0 > -10.0)
        .collect();
    assert!(
        drilling.len() > 1000,
        "{} ticks of drilling",
        drilling.len()
    );
    for w in &drilling {
        assert!((w[1].1 - w[0].1 - 36.0).abs() < 1e-9, "{w:?}");
        assert_eq!(w[1].2, 1500.0);
    }
    // It stops at its acceleration, then the tap turns two turns from where it stood.
    let stood = seen
        .iter()
        .rposition(|s| s.0 == -10.0 && s.2 == 0.0 && s.1 > 1000.0)
        .expect("the tool stood at Z−10");
    let at_stop = seen[stood].1;
    let last = seen.last().expect("ticks");
    assert!((last.0 + 12.0).abs() < 1e-9, "Z at −12: {last:?}");
    assert!(
        (last.1 - at_stop - 720.0).abs() < 1e-9,
        "two turns from {at_stop}: {last:?}"
    );
    // Within the tap the tool's angle keeps to Z by the pitch.
    for s in seen.iter().filter(|s| s.0 < -10.0) {
        let want = at_stop + (-10.0 - s.0) / 2.0 * 720.0;
        assert!((s.1 - want).abs() < 1e-6, "{s:?} against {want}");
    }
    println!(
        "at speed after {up} ticks ({} s), {} ticks drilling at 36°/tick, stopped at {at_stop:.3}°",
        up as f64 * PERIOD,
        drilling.len()
    );
}

#[test]
fn a_block_that_turns_the_spinning_tool_is_refused_and_reset_stops_it() {
    let g = GImage::released();
    let mut m = running(vec![
        Command::LiveTool { rpm: 2000.0 },
        Command::Linear {
            end: vec![50.0, -2.0, 360.0],
            feed: 100.0,
        },
    ]);
    for _ in 0..200 {
        ticks(&mut m, &g, 1);
    }
    assert_eq!(alarms(&mut m), [(111, 2)], "a tap while it spins");
    assert_eq!(m.live_tool_rpm(), 2000.0, "an alarm does not stop the tool");
    m.reset();
    let mut n = 0;
    while m.live_tool_rpm() > 0.0 && n < 1000 {
        ticks(&mut m, &g, 1);
        n += 1;
    }
    // 2000 r/min at 10,000 r/min a second: 0.2 s, 50 ticks.
    assert_eq!(n, 50, "braked in {n} ticks");
    assert_eq!(m.commanded_display()[1], 0.0, "the slide never moved");
}

#[test]
fn the_program_end_stops_the_tool_and_waits_for_it() {
    let g = GImage::released();
    let mut m = running(vec![
        Command::LiveTool { rpm: 2500.0 },
        Command::Dwell { seconds: 0.1 },
        Command::ProgramEnd,
    ]);
    let mut n = 0;
    while m.state() != RunState::Idle && n < 1000 {
        ticks(&mut m, &g, 1);
        n += 1;
    }
    assert_eq!(m.live_tool_rpm(), 0.0, "standing at the end");
    // Up 0.25 s, the dwell 0.1 s, down 0.25 s: 150 ticks and the end's own.
    assert!((150..=153).contains(&n), "{n} ticks");
}

#[test]
fn speed_mode_is_refused_above_the_top_speed_without_a_live_tool_and_with_the_drive_queue() {
    let g = GImage::released();
    let mut m = turn_mill();
    m.push(block(1, 7, Command::LiveTool { rpm: 2600.0 }));
    ticks(&mut m, &g, 3);
    assert_eq!(alarms(&mut m), [(111, 7)]);
    let mut plain = Motion::new(lathe(), &[50.0, 0.0]);
    plain.push(block(1, 8, Command::LiveTool { rpm: 1000.0 }));
    ticks(&mut plain, &g, 3);
    assert_eq!(alarms(&mut plain), [(111, 8)]);
    let mut cfg = with_live_tool();
    cfg.time_scaling_at_drives = true;
    let mut queued = Motion::new(cfg, &[50.0, 0.0]);
    queued.push(block(1, 9, Command::LiveTool { rpm: 1000.0 }));
    ticks(&mut queued, &g, 3);
    assert_eq!(alarms(&mut queued), [(111, 9)]);
    assert_eq!(queued.live_tool_rpm(), 0.0);
}

#[test]
fn the_plcs_spindle_stop_brakes_the_tool_and_lets_it_run_up_again() {
    let mut plc = GImage::released();
    let mut m = running(vec![
        Command::LiveTool { rpm: 1000.0 },
        Command::Dwell { seconds: 10.0 },
    ]);
    ticks(&mut m, &plc, 100);
    assert_eq!(m.live_tool_rpm(), 1000.0);
    plc.set(g::SSTP_N, false);
    // 1000 r/min at 10,000 r/min a second: 25 ticks.
    ticks(&mut m, &plc, 25);
    assert_eq!(m.live_tool_rpm(), 0.0, "braked by *SSTP");
    let stood = m.live_tool_setpoint();
    ticks(&mut m, &plc, 50);
    assert_eq!(m.live_tool_setpoint(), stood, "standing while *SSTP is low");
    plc.set(g::SSTP_N, true);
    ticks(&mut m, &plc, 25);
    assert_eq!(m.live_tool_rpm(), 1000.0, "at the programmed speed again");
}
