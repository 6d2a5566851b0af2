//! A program switches the acceleration profile (the 802D's BRISK and SOFT, decision D99):
//! the moves after the switch run in the other profile, the tool comes to rest where it
//! changes, and a new run starts in the machine's own profile again.

mod support;

use cnc_motion_core::profile::Shape;
use cnc_motion_core::{Block, Command, Motion, RunState};
use support::*;

const DT: f64 = 0.004;

/// Run `run_id`: two collinear lines along X at 50 mm/s, through X50 to `to`, with the
/// profile `switch` between them (if any). The X position tick by tick from `from`.
fn two_lines(m: &mut Motion, run_id: u64, from: f64, to: f64, switch: Option<bool>) -> Vec<f64> {
    let mut commands = vec![Command::Linear {
        end: vec![50.0, 0.0, 0.0],
        feed: 3000.0,
    }];
    if let Some(jerk_limited) = switch {
        commands.push(Command::Profile { jerk_limited });
    }
    commands.push(Command::Linear {
        end: vec![to, 0.0, 0.0],
        feed: 3000.0,
    });
    commands.push(Command::ProgramEnd);
    for (k, c) in commands.into_iter().enumerate() {
        let seq = k as u64 + 1;
        m.push(Block {
            run_id,
            ..block(seq, seq as u32, c)
        });
    }
    let (trace, _) = run(m, 100_000);
    assert_eq!(m.state(), RunState::Idle);
    let x: Vec<f64> = std::iter::once(from)
        .chain(trace.iter().map(|p| p[0]))
        .collect();
    assert!((x[x.len() - 1] - to).abs() < 1e-6, "{x:?}");
    x
}

/// The largest jerk (third difference of position) over the ticks whose four positions all
/// lie in `range`, mm/s³.
fn max_jerk(x: &[f64], range: std::ops::Range<f64>) -> f64 {
    x.windows(4)
        .filter(|w| w.iter().all(|p| range.contains(p)))
        .map(|w| ((w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / DT.powi(3)).abs())
        .fold(0.0, f64::max)
}

/// The lowest speed while passing X50 (within 0.5 mm), mm/s.
fn slowest_at_x50(x: &[f64]) -> f64 {
    x.windows(2)
        .filter(|w| (w[0] - 50.0).abs() < 0.5)
        .map(|w| (w[1] - w[0]).abs() / DT)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn soft_and_brisk_switch_the_profile_at_a_stop_and_a_new_run_starts_in_the_machines() {
    // The axes' jerk limit: acceleration over DEFAULT_JERK_TIME (1000 / 0.05 = 20 000 mm/s³);
    // a trapezoidal start steps the acceleration to 1000 mm/s² within one tick (250 000).
    let jerk = 1000.0 / cnc_machine::DEFAULT_JERK_TIME;
    let (before, after) = (0.0..49.5, 50.5..100.0);
    for machine in [Shape::Trapezoidal, Shape::SCurve] {
        let machine_soft = machine == Shape::SCurve;
        let mut cfg = mill();
        cfg.shape = machine;
        let mut m = Motion::new(cfg, &[0.0, 0.0, 0.0]);
        // The machine's profile up to X50, then the other one.
        let x = two_lines(&mut m, 1, 0.0, 100.0, Some(!machine_soft));
        let (soft, brisk) = if machine_soft {
            (before.clone(), after.clone())
        } else {
            (after.clone(), before.clone())
        };
        assert!(max_jerk(&x, soft) < 2.0 * jerk, "{machine:?}: {x:?}");
        assert!(max_jerk(&x, brisk) > 5.0 * jerk, "{machine:?}: {x:?}");
        // The tool rests where the profile changes, though the lines are collinear.
        assert!(slowest_at_x50(&x) < 1.0, "{machine:?}: {x:?}");
        // The next run, back to X0 without a switch, is in the machine's profile again and
        // passes X50 at speed.
        let x = two_lines(&mut m, 2, 100.0, 0.0, None);
        assert!(slowest_at_x50(&x) > 40.0, "{machine:?}: {x:?}");
        let largest = max_jerk(&x, 0.0..100.5);
        if machine_soft {
            assert!(largest < 2.0 * jerk, "{x:?}");
        } else {
            assert!(largest > 5.0 * jerk, "{x:?}");
        }
    }
}
