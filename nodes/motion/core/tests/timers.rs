//! The run-time timers in motion (`001` §9.12.1, decisions D121): counted in servo periods,
//! the cutting time only on feed moves, a program's time not while it is held, at feed
//! override 0 or under dry run; the preprocessing stop reports once every block before it is
//! done.

use cnc_motion_core::{Block, Command, Motion, Panel, RunState};
use cnc_msgs::signals::GImage;

mod support;
use support::*;

const PERIOD: f64 = 0.004;

fn of_run(run_id: u64, seq: u64, kind: Command) -> Block {
    Block {
        run_id,
        seq,
        line: seq as u32,
        kind,
    }
}

/// A rapid of 100 mm, a cut of 100 mm at F600 (10 s), a dwell of 2 s, the preprocessing stop,
/// the end.
fn program(run_id: u64, from: f64) -> Vec<Block> {
    vec![
        of_run(
            run_id,
            1,
            Command::Rapid {
                end: vec![from + 100.0, 0.0, 0.0],
            },
        ),
        of_run(
            run_id,
            2,
            Command::Linear {
                end: vec![from + 200.0, 0.0, 0.0],
                feed: 600.0,
            },
        ),
        of_run(run_id, 3, Command::Dwell { seconds: 2.0 }),
        of_run(run_id, 4, Command::Sync),
        of_run(run_id, 5, Command::ProgramEnd),
    ]
}

/// Ticks a perfect drive until the run is idle: the ticks it took.
fn until_idle(m: &mut Motion, g: &GImage) -> usize {
    for n in 1..20_000 {
        ticks(m, g, 1);
        if m.state() == RunState::Idle {
            return n;
        }
    }
    panic!("the run did not end");
}

#[test]
fn a_program_counts_its_time_and_its_feed_moves_alone_count_as_cutting() {
    let g = GImage::released();
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    ticks(&mut m, &g, 250); // a second at power-on, no program
    for b in program(1, 0.0) {
        m.push(b);
    }
    let n = until_idle(&mut m, &g);
    let t = m.timers();
    eprintln!("{n} ticks: {t:?}");
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    assert!(close(t.power_on, (250 + n) as f64 * PERIOD), "{t:?}");
    // The program ran from its first block to its end: every tick of it, none before.
    assert!(
        close(t.cycle, t.operating) && t.cycle <= n as f64 * PERIOD + 1e-9,
        "{t:?}"
    );
    assert!(t.cycle > n as f64 * PERIOD - 0.05, "{t:?} of {n} ticks");
    // 100 mm at F600 is 10 s and a little for the ramps; the rapid and the dwell are not.
    assert!((10.0..10.3).contains(&t.cutting), "{t:?}");
    assert!(
        t.cycle - t.cutting > 2.0 + 1.0,
        "rapid 1 s and more, dwell 2 s: {t:?}"
    );
    // The preprocessing stop was reported after the cut, where the axes stood.
    let r = m.block_result().expect("the stop's report");
    assert_eq!((r.seq, r.triggered), (4, true));
    assert_eq!(r.rest[..3], [200.0, 0.0, 0.0]);
}

#[test]
fn a_held_program_at_override_zero_or_on_dry_run_does_not_count() {
    let g = GImage::released();
    let mut m = Motion::new(mill(), &[0.0, 0.0, 0.0]);
    for b in program(1, 0.0) {
        m.push(b);
    }
    until_idle(&mut m, &g);
    let first = m.timers();
    // The next program: its cycle time starts from 0, the operating time goes on.
    for b in program(2, 200.0) {
        m.push(b);
    }
    ticks(&mut m, &g, 300); // into the cut
    let before = m.timers();
    assert!(before.cycle < 300.0 * PERIOD + 1e-9);
    assert!(before.operating > first.operating);
    // Feed hold: the axes brake and stand; nothing of the program counts until cycle start.
    m.feed_hold();
    ticks(&mut m, &g, 200);
    let held = m.timers();
    ticks(&mut m, &g, 500);
    let still = m.timers();
    assert_eq!(
        (still.cycle, still.cutting, still.operating),
        (held.cycle, held.cutting, held.operating)
    );
    assert!(still.power_on > held.power_on);
    m.cycle_start();
    ticks(&mut m, &g, 100);
    assert!(m.timers().cutting > still.cutting);
    // Feed override 0, then dry run: the program runs on or stands, its time does not count.
    for panel in [
        Panel {
            feed_override: 0.0,
            ..Panel::default()
        },
        Panel {
            dry_run: true,
            ..Panel::default()
        },
    ] {
        m.set_panel(panel);
        let at = m.timers();
        ticks(&mut m, &g, 100);
        let after = m.timers();
        assert_eq!(
            (after.cycle, after.cutting),
            (at.cycle, at.cutting),
            "{panel:?}"
        );
        m.set_panel(Panel::default());
    }
    until_idle(&mut m, &g);
    // Reset after the end: nothing counts while no program runs.
    m.reset();
    let end = m.timers();
    ticks(&mut m, &g, 100);
    assert_eq!(m.timers().operating, end.operating);
}
