//! With the drives' queue the drives time-scale feed hold and overrides up to 100 % (D135): the
//! core plans as if they were off, plans an override above 100 % itself, and tells the drives
//! with each setpoint how it may be scaled.

mod support;

use cnc_motion_core::{Command, Motion, MotionConfig, Panel, RunState};
use cnc_msgs::servo::ServoSetpoint;
use cnc_msgs::signals::GImage;
use support::*;

fn scaling_lathe() -> MotionConfig {
    MotionConfig {
        time_scaling_at_drives: true,
        ..lathe()
    }
}

/// A line of 30 mm at F600 on Z, then program end.
fn line(m: &mut Motion) {
    m.push(block(
        1,
        10,
        Command::Linear {
            end: vec![50.0, -30.0],
            feed: 600.0,
        },
    ));
    m.push(block(2, 20, Command::ProgramEnd));
}

/// Largest Z speed in a run of ticks (mm/min) and the last tick's setpoint scaling.
fn top_speed(m: &mut Motion, ticks: usize) -> (f64, ServoSetpoint) {
    let g = GImage::released();
    let mut top: f64 = 0.0;
    for _ in 0..ticks {
        let before = m.commanded_display()[1];
        let actual = m.commanded().to_vec();
        m.tick(Some(&actual), &g);
        top = top.max((m.commanded_display()[1] - before).abs() / 0.004 * 60.0);
    }
    let mut sp = ServoSetpoint::default();
    m.fill_setpoint(&mut sp);
    (top, sp)
}

/// Overrides up to 100 % are left to the drives (the core's path runs at F); above 100 % the
/// core plans them; every path setpoint is a feed the drives may scale, with the override it
/// was planned at.
#[test]
fn overrides_up_to_100_percent_are_the_drives_and_above_it_the_cores() {
    for (ov, want, planned) in [(0.5, 600.0, 1.0), (1.0, 600.0, 1.0), (1.5, 900.0, 1.5)] {
        let mut m = Motion::new(scaling_lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            feed_override: ov,
            ..Panel::default()
        });
        line(&mut m);
        let (speed, sp) = top_speed(&mut m, 400);
        assert!((speed - want).abs() < 1e-6, "override {ov}: {speed} mm/min");
        assert_eq!(sp.scaling, ServoSetpoint::SCALE_FEED);
        assert_eq!(sp.planned_override, planned);
    }
    // Without the drives' scaling the core keeps them all (lock-step).
    let mut m = Motion::new(lathe(), &[25.0, 0.0]);
    m.set_panel(Panel {
        feed_override: 0.5,
        ..Panel::default()
    });
    line(&mut m);
    assert!((top_speed(&mut m, 400).0 - 300.0).abs() < 1e-6);
}

/// Feed hold is the drives': the core's path goes on (the drives stand, so its queue fills and
/// it stops planning), it shows the hold and tells the drives; cycle start counts. A cycle
/// stop stays the core's planned stop, not told to the drives as a hold.
#[test]
fn feed_hold_is_told_to_the_drives_and_a_cycle_stop_is_planned() {
    let mut m = Motion::new(scaling_lathe(), &[25.0, 0.0]);
    line(&mut m);
    top_speed(&mut m, 400);
    m.feed_hold();
    assert_eq!(m.state(), RunState::Hold);
    let control = m.drive_control();
    assert_eq!(control.hold, 1);
    assert!(
        (top_speed(&mut m, 50).0 - 600.0).abs() < 1e-6,
        "the path goes on"
    );
    m.cycle_start();
    let released = m.drive_control();
    assert_eq!((released.hold, released.starts), (0, control.starts + 1));
    m.cycle_stop();
    assert_eq!(
        m.drive_control().hold,
        0,
        "a cycle stop is no hold at the drives"
    );
    top_speed(&mut m, 200);
    assert_eq!(
        top_speed(&mut m, 20).0,
        0.0,
        "the core brakes for a cycle stop"
    );
}

/// Ten lines of 3 mm along Z at F3000, merged into one chord by the planner: with the drives'
/// scaling every setpoint still names the programmed line being cut, and where the line
/// changes it says where between the two setpoints the block ended (D137): interpolated
/// there, the point is the programmed end. With single block on, the core does not stop
/// between the blocks itself (the drives do), but gives each its own setpoint.
#[test]
fn setpoints_say_where_each_block_ends_also_in_merged_lines() {
    for single_block in [false, true] {
        let mut m = Motion::new(scaling_lathe(), &[25.0, 0.0]);
        m.set_panel(Panel {
            single_block,
            ..Panel::default()
        });
        for k in 1..=10u32 {
            m.push(block(
                u64::from(k),
                10 * k,
                Command::Linear {
                    end: vec![50.0, -3.0 * f64::from(k)],
                    feed: 3000.0,
                },
            ));
        }
        m.push(block(11, 110, Command::ProgramEnd));
        let g = GImage::released();
        let mut setpoints: Vec<(f64, u32, f64)> = Vec::new();
        for _ in 0..600 {
            let actual = m.commanded().to_vec();
            let z = m.tick(Some(&actual), &g)[1];
            let mut sp = ServoSetpoint::default();
            m.fill_setpoint(&mut sp);
            setpoints.push((z, sp.line, sp.block_start));
            assert_ne!(m.state(), RunState::Hold, "the core does not stop");
        }
        let mut ends = Vec::new();
        for w in setpoints.windows(2) {
            let ((z0, l0, _), (z1, l1, began)) = (w[0], w[1]);
            if l0 != l1 && l0 != 0 && l1 != 0 {
                ends.push((l0, z0 + (z1 - z0) * began));
            }
        }
        assert_eq!(ends.len(), 9, "single block {single_block}: {ends:?}");
        for (k, (line, z)) in ends.iter().enumerate() {
            let want = -3.0 * (k + 1) as f64;
            assert_eq!(*line, 10 * (k as u32 + 1));
            assert!(
                (z - want).abs() < 1e-9,
                "line {line} ends at Z {z}, not {want}"
            );
        }
    }
}
