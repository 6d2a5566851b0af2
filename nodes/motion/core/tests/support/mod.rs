//! What the motion core's tests share: the machines (a lathe and a 3-axis mill on a
//! perfect drive) and running a program on them with a PLC that answers every strobe.

#![allow(dead_code)] // each test file uses its own part

use cnc_motion_core::{AxisConfig, Block, Command, Motion, MotionConfig, MotionEvent, RunState};
use cnc_msgs::signals::{f, g, GImage, SignalTable};

/// A two-axis lathe (X on diameter, Z) with the S-curve profile, a 4 ms period.
pub fn lathe() -> MotionConfig {
    let axis = |name: &str, diameter, min, max| AxisConfig {
        name: name.into(),
        diameter,
        min,
        max,
        max_velocity: 6000.0,
        max_acceleration: 1000.0,
        max_jerk: None,
        following_error: None,
        in_position: 0.0005,
        drive_lag: 0.008,
        home: 0.0,
        second_reference: None,
        fixed_points: Vec::new(),
        reference: None,
        overtravel: None,
    };
    MotionConfig {
        axes: vec![
            axis("X", true, -10.0, 300.0),
            axis("Z", false, -400.0, 100.0),
        ],
        period: 0.004,
        queue_capacity: 16,
        arc_plane: (1, 0),
        lookahead: 16,
        tolerance: 0.01,
        shape: cnc_motion_core::profile::Shape::SCurve,
        feedback_lost_ticks: 3,
        dry_run_feed: 1000.0,
        reference_order: vec![0, 1],
        spindle_max_rpm: 6000.0,
        feedback_delay_ticks: 1,
        time_scaling_at_drives: false,
        c_axis: None,
        live_tool: None,
    }
}

pub fn block(seq: u64, line: u32, kind: Command) -> Block {
    Block {
        run_id: 1,
        seq,
        line,
        kind,
    }
}

/// `n` ticks on a perfect drive, with the PLC image `g`.
pub fn ticks(m: &mut Motion, g: &GImage, n: usize) {
    for _ in 0..n {
        let actual = m.commanded().to_vec();
        m.tick(Some(&actual), g);
    }
}

/// Runs until idle or alarm on a perfect drive, answering every strobe with FIN: the displayed
/// positions per tick and the M codes strobed, numbered.
pub fn run(m: &mut Motion, max_ticks: usize) -> (Vec<Vec<f64>>, Vec<(u64, i32)>) {
    let d = drive(m, max_ticks);
    let m_codes = d.strobes.iter().filter(|(s, _)| *s == "M");
    let numbered = m_codes.enumerate().map(|(k, (_, c))| (k as u64 + 1, *c));
    (d.displayed, numbered.collect())
}

/// A 3-axis mill (X, Y, Z) on a perfect drive, arcs configured in X-Y.
pub fn mill() -> MotionConfig {
    let mut cfg = lathe();
    let axis = |name: &str| AxisConfig {
        name: name.into(),
        diameter: false,
        min: -500.0,
        max: 500.0,
        ..cfg.axes[1].clone()
    };
    cfg.axes = vec![axis("X"), axis("Y"), axis("Z")];
    cfg.arc_plane = (0, 1);
    cfg.reference_order = vec![2, 0, 1];
    cfg
}

/// What a run on a perfect drive showed, tick by tick.
pub struct Driven {
    /// The commanded position in display units.
    pub displayed: Vec<Vec<f64>>,
    /// The setpoints the drives got (slide units).
    pub sent: Vec<Vec<f64>>,
    /// Strobes seen, as (signal, code).
    pub strobes: Vec<(&'static str, i32)>,
}

/// Ticks until idle or alarm on a perfect drive that follows the setpoints motion sends (not
/// the commanded position, which machine lock separates from them), answering every strobe
/// with FIN.
pub fn drive(m: &mut Motion, max_ticks: usize) -> Driven {
    let mut d = Driven {
        displayed: vec![],
        sent: vec![],
        strobes: vec![],
    };
    let mut g = GImage::released();
    let mut slides = m.setpoint().to_vec();
    for _ in 0..max_ticks {
        slides = m.tick(Some(&slides), &g).to_vec();
        d.sent.push(slides.clone());
        d.displayed.push(m.commanded_display());
        let fi = *m.f_image();
        for (name, strobe, code) in [
            ("M", f::MF, f::M_CODE),
            ("S", f::SF, f::S_CODE),
            ("T", f::TF, f::T_CODE),
        ] {
            if fi.get(strobe) && !g.get(g::FIN) {
                d.strobes.push((name, fi.read_i32(code)));
                g.set(g::FIN, true);
            }
        }
        if !(fi.get(f::MF) || fi.get(f::SF) || fi.get(f::TF)) {
            g.set(g::FIN, false);
        }
        if matches!(m.state(), RunState::Idle | RunState::Alarm) {
            break;
        }
    }
    d
}

/// The alarms motion has raised since last asked, as (number, line).
pub fn alarms(m: &mut Motion) -> Vec<(u32, u32)> {
    m.take_events()
        .into_iter()
        .map(|e| match e {
            MotionEvent::Alarm { number, line, .. } => (number, line),
        })
        .collect()
}
