//! motion node shell: the servo loop on its own thread, and a DDS thread that feeds it blocks
//! and commands and publishes what it reports.

use std::sync::mpsc::{channel as mpsc, Receiver, Sender, TryRecvError};
use std::time::Duration;

use cnc_msgs::msg::{
    Alarm, Axis, AxisState, MotionBlock, MotionStatus, ProgramCommand, ServoStats,
};
use cnc_msgs::servo::{ServoFeedback, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{FImage, GImage};
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::{monotonic_ns, sleep_until_ns};
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::servo::ServoStatistics;
use crate::{AuxCode, AxisConfig, Block, BlockKind, Motion, MotionConfig, MotionEvent, RunState};

enum Input {
    Block(Block),
    Command(u8),
}

enum Report {
    Status(MotionStatus),
    Axes(AxisState),
    Alarm(u32, String, u32),
    Stats(ServoStats),
}

pub fn motion_config(cfg: &LaunchConfig) -> MotionConfig {
    let axes = cfg
        .machine
        .axes
        .iter()
        .map(|a| AxisConfig {
            name: a.name.clone(),
            diameter: a.diameter,
            min: a.min,
            max: a.max,
            max_velocity: a.max_velocity,
            max_acceleration: a.max_acceleration,
            in_position: a.in_position,
            drive_lag: a.drive_lag,
        })
        .collect();
    let idx = |n: &str| cfg.axis_index(n).unwrap_or(0);
    MotionConfig {
        axes,
        period: cfg.servo.period_ms / 1000.0,
        queue_capacity: cfg.servo.queue_capacity,
        arc_plane: (
            idx(&cfg.machine.arc_plane[0]),
            idx(&cfg.machine.arc_plane[1]),
        ),
    }
}

/// Converts a block from DDS; malformed blocks become `None` (and an alarm upstream).
fn block_from_msg(m: &MotionBlock) -> Option<Block> {
    let kind = match m.kind {
        MotionBlock::KIND_RAPID => BlockKind::Rapid { end: m.end.clone() },
        MotionBlock::KIND_LINEAR => BlockKind::Linear {
            end: m.end.clone(),
            feed: m.feed,
        },
        MotionBlock::KIND_ARC_CW | MotionBlock::KIND_ARC_CCW => BlockKind::Arc {
            end: m.end.clone(),
            center: m.center.clone(),
            clockwise: m.kind == MotionBlock::KIND_ARC_CW,
            feed: m.feed,
        },
        MotionBlock::KIND_DWELL => BlockKind::Dwell {
            seconds: m.dwell_seconds,
        },
        MotionBlock::KIND_AUX => BlockKind::Aux(match m.aux_kind {
            MotionBlock::AUX_M => AuxCode::M(m.aux_code),
            MotionBlock::AUX_S => AuxCode::S(m.aux_value),
            MotionBlock::AUX_T => AuxCode::T(m.aux_code),
            _ => return None,
        }),
        MotionBlock::KIND_PROGRAM_END => BlockKind::ProgramEnd,
        _ => return None,
    };
    Some(Block {
        run_id: m.run_id,
        seq: m.seq,
        line: m.line,
        kind,
    })
}

/// Runs the motion node until shutdown (blocking). Prints the servo statistics at exit.
pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<String, String> {
    let (in_tx, in_rx) = mpsc::<Input>();
    let (out_tx, out_rx) = mpsc::<Report>();
    let mcfg = motion_config(&cfg);
    let names: Vec<String> = cfg.machine.axes.iter().map(|a| a.name.clone()).collect();
    let servo_shutdown = shutdown.clone();
    let servo = std::thread::Builder::new()
        .name("servo".into())
        .spawn(move || servo_loop(mcfg, names, instance, in_rx, out_tx, servo_shutdown))
        .map_err(|e| format!("servo thread: {e}"))?;
    let dds_result = dds_loop(&cfg, in_tx, out_rx, &shutdown);
    shutdown.request();
    let servo_result = servo
        .join()
        .map_err(|_| "servo thread panicked".to_string())?;
    dds_result?;
    servo_result
}

fn dds_loop(
    cfg: &LaunchConfig,
    to_servo: Sender<Input>,
    from_servo: Receiver<Report>,
    shutdown: &Shutdown,
) -> Result<(), String> {
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "motion")?;
    let blocks = ros.subscription::<MotionBlock>(
        "_internal/motion_blocks",
        "cnc_msgs/msg/MotionBlock",
        qos::commands(),
    )?;
    let commands = ros.subscription::<ProgramCommand>(
        "_internal/program_command",
        "cnc_msgs/msg/ProgramCommand",
        qos::commands(),
    )?;
    let status_pub = ros.publisher::<MotionStatus>(
        "_internal/motion_status",
        "cnc_msgs/msg/MotionStatus",
        qos::state(),
    )?;
    let axes_pub = ros.publisher::<AxisState>("axes", "cnc_msgs/msg/AxisState", qos::state())?;
    let stats_pub =
        ros.publisher::<ServoStats>("servo_stats", "cnc_msgs/msg/ServoStats", qos::state())?;
    let alarms = AlarmReporter::new(&mut ros, "motion")?;
    while !shutdown.requested() {
        let mut idle = true;
        while let Ok(Some((m, _))) = blocks.take() {
            idle = false;
            match block_from_msg(&m) {
                Some(b) => {
                    let _ = to_servo.send(Input::Block(b));
                }
                None => alarms.raise(alarms.alarm(
                    33,
                    Alarm::SEVERITY_ERROR,
                    "unknown internal interpolation function",
                    &m.program,
                    m.line,
                )),
            }
        }
        while let Ok(Some((c, _))) = commands.take() {
            idle = false;
            let _ = to_servo.send(Input::Command(c.command));
        }
        loop {
            match from_servo.try_recv() {
                Ok(Report::Status(s)) => publish(&status_pub, s),
                Ok(Report::Axes(a)) => publish(&axes_pub, a),
                Ok(Report::Stats(s)) => publish(&stats_pub, s),
                Ok(Report::Alarm(number, text, line)) => {
                    alarms.raise(alarms.alarm(number, Alarm::SEVERITY_ERROR, &text, "", line))
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return Ok(()),
            }
            idle = false;
        }
        if idle {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    Ok(())
}

fn publish<M: ros2_client::Message + std::fmt::Debug>(p: &ros2_client::dds::Publisher<M>, m: M) {
    if let Err(e) = p.publish(m) {
        log::warn!("motion: publish failed: {e:?}");
    }
}

fn servo_loop(
    mcfg: MotionConfig,
    names: Vec<String>,
    instance: String,
    inputs: Receiver<Input>,
    reports: Sender<Report>,
    shutdown: Shutdown,
) -> Result<String, String> {
    let shm = ShmNode::new(&instance, "motion")?;
    let setpoints = shm.sender::<ServoSetpoint>(channel::SETPOINT, true)?;
    let feedback = shm.receiver::<ServoFeedback>(channel::FEEDBACK, true)?;
    let g_in = shm.receiver::<GImage>(channel::G_IMAGE, false)?;
    let f_out = shm.sender::<FImage>(channel::F_IMAGE, false)?;
    let n = mcfg.axes.len();
    let period_ns = (mcfg.period * 1e9) as u64;
    // Start from where the drives are.
    let first = feedback
        .wait(Duration::from_secs(2))?
        .ok_or("no feedback from the drives (is io running?)")?;
    let mut actual = first.position;
    let mut motion = Motion::new(mcfg.clone(), &actual[..n]);
    let mut g = GImage::default();
    let mut stats = ServoStatistics::default();
    let mut seq = 0u64;
    let mut last_status = (u64::MAX, u64::MAX, u64::MAX, RunState::Idle, 0u32);
    let mut last_tick: Option<u64> = None;
    let mut next = monotonic_ns() + period_ns;
    let mut have_feedback = true;
    while !shutdown.requested() {
        sleep_until_ns(next);
        let now = monotonic_ns();
        if let Some(prev) = last_tick {
            stats.interval.record((now - prev) as f64 / 1000.0);
        }
        last_tick = Some(now);
        stats.ticks += 1;
        if now > next + period_ns / 2 {
            stats.late_ticks += 1;
        }
        next += period_ns;
        if now > next + 10 * period_ns {
            next = now + period_ns; // far behind (machine suspended): resynchronise, counted as late
        }
        loop {
            match inputs.try_recv() {
                Ok(Input::Block(b)) => motion.push(b),
                Ok(Input::Command(ProgramCommand::FEED_HOLD)) => motion.feed_hold(),
                Ok(Input::Command(ProgramCommand::CYCLE_STOP)) => motion.cycle_stop(),
                Ok(Input::Command(ProgramCommand::RESET)) => motion.reset(),
                Ok(Input::Command(ProgramCommand::START)) => motion.cycle_start(),
                Ok(Input::Command(_)) => {}
                Err(_) => break,
            }
        }
        if let Some(latest) = g_in.latest()? {
            g = latest;
        }
        let commanded = {
            let c = motion.tick(have_feedback.then_some(&actual[..n]), &g);
            let mut p = [0.0; MAX_AXES];
            p[..n].copy_from_slice(c);
            p
        };
        f_out.send(*motion.f_image())?;
        seq += 1;
        let sent = monotonic_ns();
        setpoints.send(ServoSetpoint {
            seq,
            sent_ns: sent,
            position: commanded,
            axis_count: n as u32,
            enable: 1,
        })?;
        have_feedback = false;
        if let Some(fb) = feedback.wait(Duration::from_nanos(period_ns / 2))? {
            if fb.seq == seq {
                stats
                    .round_trip
                    .record((monotonic_ns() - fb.setpoint_sent_ns) as f64 / 1000.0);
            }
            actual = fb.position;
            have_feedback = true;
        }
        for e in motion.take_events() {
            let MotionEvent::Alarm { number, text, line } = e;
            let _ = reports.send(Report::Alarm(number, text, line));
        }
        let status = (
            motion.run_id(),
            motion.accepted_seq(),
            motion.done_seq(),
            motion.state(),
            motion.line(),
        );
        if status != last_status || seq.is_multiple_of(25) {
            last_status = status;
            let state = match motion.state() {
                RunState::Idle => MotionStatus::STATE_IDLE,
                RunState::Running => MotionStatus::STATE_RUNNING,
                RunState::Hold => MotionStatus::STATE_HOLD,
                RunState::Alarm => MotionStatus::STATE_ALARM,
            };
            let _ = reports.send(Report::Status(MotionStatus {
                run_id: status.0,
                accepted_seq: status.1,
                done_seq: status.2,
                capacity: motion.capacity() as u32,
                line: status.4,
                state,
            }));
        }
        if seq.is_multiple_of(10) {
            let cmd = motion.commanded_display();
            let axes = mcfg
                .axes
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    let act = actual[i] / a.scale();
                    Axis {
                        name: names[i].clone(),
                        commanded_position: cmd[i],
                        actual_position: act,
                        following_error: cmd[i] - act,
                        homed: true,
                    }
                })
                .collect();
            let _ = reports.send(Report::Axes(AxisState {
                stamp: stamp(),
                axes,
            }));
        }
        if seq.is_multiple_of(250) {
            let _ = reports.send(Report::Stats(stats_msg(&stats, mcfg.period)));
        }
    }
    let _ = reports.send(Report::Stats(stats_msg(&stats, mcfg.period)));
    Ok(stats.summary(mcfg.period * 1e6))
}

fn stats_msg(s: &ServoStatistics, period: f64) -> ServoStats {
    ServoStats {
        stamp: stamp(),
        period_us: period * 1e6,
        ticks: s.ticks,
        late_ticks: s.late_ticks,
        interval_min_us: s.interval.min(),
        interval_p50_us: s.interval.quantile(0.5),
        interval_p99_us: s.interval.quantile(0.99),
        interval_max_us: s.interval.max(),
        round_trips: s.round_trip.count(),
        round_trip_min_us: s.round_trip.min(),
        round_trip_p50_us: s.round_trip.quantile(0.5),
        round_trip_p99_us: s.round_trip.quantile(0.99),
        round_trip_max_us: s.round_trip.max(),
    }
}
