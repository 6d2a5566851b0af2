//! Motion's planning loop with the drives' setpoint queue (issue 48, `servo.drive_queue_ms`
//! above 0). The drives run on their own clock and play the setpoint stamped for each of their
//! ticks; motion keeps their queue `queue_ticks` ahead of the tick they last reported, so a
//! host that wakes motion late costs nothing while the queue lasts.
//!
//! Tick j is computed with the drives' feedback of tick j − `queue_ticks` (the core knows its
//! feedback is that old: `MotionConfig::feedback_delay_ticks`), so what motion sends for a
//! tick does not depend on when it was computed. With every batch motion sends the brake tail
//! its core plans ([`Motion::brake_tail`]) and keeps the state that tail ends in: if the queue
//! runs dry, the drives play the tail and motion goes on from that state, in feed hold, with the
//! bus alarm shown until cycle start (D133).

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, Sender};
use std::time::Duration;

use cnc_msgs::servo::{BrakeTail, ServoFeedback, ServoSetpoint, MAX_AXES, TAIL_TICKS};
use cnc_msgs::signals::{FImage, GImage};
use cnc_runtime::clock::monotonic_ns;
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::Shutdown;

use crate::loop_stats::{LateWatch, ServoStatistics};
use crate::motion::{alarm, PlannedStop};
use crate::node::{
    plc_signals, take_inputs, Clockwork, Input, Latest, PlcLink, Report, Reporter, Timing,
};
use crate::{Motion, MotionConfig, RunState};

/// Setpoints and feedback a stream channel buffers (as the drives' side).
const STREAM_DEPTH: usize = 1024;
/// Motion computes when at least this many ticks are missing from the queue: one wake-up
/// then plans a batch of them and one brake tail.
const BATCH_TICKS: u64 = 5;
/// Brake tails kept with the state they end in: the drives may run dry on one sent before
/// the latest.
const TAILS_KEPT: usize = 4;

/// The stops planned for the latest batches: the tick each tail starts at, and the state
/// motion is in once the drives have played it.
struct Tails {
    kept: VecDeque<(u64, usize, Box<Motion>)>,
    buffer: Vec<[f64; MAX_AXES]>,
    msg: Box<BrakeTail>,
}

impl Tails {
    /// Plans the tail after the batch that ends before `first_tick` and sends it.
    fn plan(
        &mut self,
        motion: &Motion,
        g: &GImage,
        first_tick: u64,
        episode: u32,
        sender: &cnc_runtime::shm::Sender<BrakeTail>,
    ) -> Result<(), String> {
        let PlannedStop { len, stopped } = motion.brake_tail(g, &mut self.buffer);
        self.msg.episode = episode;
        self.msg.first_tick = first_tick;
        self.msg.len = len as u32;
        self.msg.position[..len].copy_from_slice(&self.buffer[..len]);
        sender.send(*self.msg)?;
        self.kept.push_back((first_tick, len, stopped));
        while self.kept.len() > TAILS_KEPT {
            self.kept.pop_front();
        }
        Ok(())
    }

    /// The state after the tail that starts at `first_tick`, and the tick after its end.
    fn take(&mut self, first_tick: u64) -> Option<(Box<Motion>, u64)> {
        let i = self.kept.iter().position(|(t, _, _)| *t == first_tick)?;
        let (t, len, m) = self.kept.remove(i)?;
        self.kept.clear();
        Some((m, t + len as u64))
    }
}

pub(crate) fn servo_loop(
    mcfg: MotionConfig,
    timing: Timing,
    instance: String,
    inputs: Receiver<Input>,
    reports: Sender<Report>,
    shutdown: Shutdown,
) -> Result<String, String> {
    let shm = ShmNode::new(&instance, "motion")?;
    let setpoints =
        shm.stream_sender::<ServoSetpoint>(channel::SETPOINT_QUEUE, false, STREAM_DEPTH)?;
    let tail_out = shm.sender::<BrakeTail>(channel::BRAKE_TAIL, false)?;
    let feedback =
        shm.stream_receiver::<ServoFeedback>(channel::FEEDBACK_STREAM, true, STREAM_DEPTH)?;
    let g_in = shm.receiver::<GImage>(channel::G_IMAGE, false)?;
    let f_out = shm.sender::<FImage>(channel::F_IMAGE, false)?;
    let rt = &timing.realtime;
    let granted = cnc_runtime::realtime::enter(
        "motion planning loop",
        rt.servo_priority,
        rt.servo_cpu,
        rt.lock_memory,
    );
    let n = mcfg.axes.len();
    let ahead = timing.queue_ticks.max(1);
    let period_ns = (mcfg.period * 1e9) as u64;
    let mut arrived: Vec<ServoFeedback> = Vec::with_capacity(STREAM_DEPTH);
    // Start from where the drives are, at the tick they report.
    let mut waited = 0;
    let first = loop {
        if shutdown.requested() {
            return Ok("stopped before the drives reported".into());
        }
        feedback.wait_for_any(Duration::from_millis(100))?;
        feedback.take_all(&mut arrived)?;
        if let Some(fb) = arrived.last() {
            break *fb;
        }
        waited += 1;
        if waited > 300 {
            return Err("no feedback from the drives within 30 s (is io running?)".into());
        }
    };
    let mut latest = Latest::first(&first);
    let mut motion = Motion::new(mcfg.clone(), &latest.actual[..n]);
    let mut received: VecDeque<ServoFeedback> = VecDeque::with_capacity(STREAM_DEPTH);
    received.extend(arrived.drain(..));
    let mut next_tick = first.tick + ahead;
    let mut episode = first.episode;
    let mut g = GImage::default();
    let mut plc = PlcLink::new(period_ns);
    let ticks_per_second = (1.0 / mcfg.period).round().max(1.0) as u64;
    // Motion's lateness is no alarm here (the queue absorbs it); its statistics stay.
    let mut clock = Clockwork {
        stats: ServoStatistics {
            realtime: granted.is_realtime(),
            ..Default::default()
        },
        watch: LateWatch::new(u64::MAX, usize::MAX, ticks_per_second, ticks_per_second),
        last_tick: None,
    };
    let mut reporter = Reporter { last_status: None };
    let mut tails = Tails {
        kept: VecDeque::with_capacity(TAILS_KEPT + 1),
        buffer: vec![[0.0; MAX_AXES]; TAIL_TICKS],
        msg: Box::default(),
    };
    let mut dry_shown = false;
    let mut missing_feedback = 0u64;
    let mut last_wake = monotonic_ns();
    while !shutdown.requested() {
        feedback.wait_for_any(Duration::from_nanos(period_ns))?;
        let now = monotonic_ns();
        feedback.take_all(&mut arrived)?;
        received.extend(arrived.drain(..));
        let Some(newest) = received.back().copied() else {
            continue;
        };
        if newest.episode != episode && newest.episode_ended == ServoFeedback::ENDED_EMERGENCY_STOP
        {
            // The drives stopped on their own (emergency stop, D134); the PLC tells the core,
            // which holds where the slides are. The next episode starts from there.
            episode = newest.episode;
            tails.kept.clear();
            next_tick = newest.tick + ahead;
        }
        if newest.episode != episode {
            // The queue ran dry: the drives play the tail of the batch they ran out at.
            episode = newest.episode;
            let text = format!(
                "the drives' setpoint queue ran dry at drive tick {} (motion was not scheduled \
                 for {:.0} ms): the machine stopped on its path, cycle start goes on",
                newest.dry_tick,
                now.saturating_sub(last_wake) as f64 / 1e6
            );
            match tails.take(newest.dry_tick) {
                Some((stopped, after)) => {
                    motion = *stopped;
                    next_tick = after.max(newest.tick + ahead);
                }
                None => {
                    // The drives held without a tail: a step in velocity, the servo alarm.
                    motion.servo_overrun(format!("{text}; no brake tail reached the drives"));
                    next_tick = newest.tick + ahead;
                }
            }
            log::warn!("{text}");
            let _ = reports.send(Report::Warning(alarm::SERVO_OVERRUN, Some(text)));
            dry_shown = true;
        }
        last_wake = now;
        if newest.tick + ahead < next_tick + BATCH_TICKS - 1 {
            continue;
        }
        clock.tick(now, false, &mut motion, &reports);
        take_inputs(&inputs, &mut motion, &mut clock, &mut plc, &reports);
        plc_signals(
            g_in.latest()?,
            &mut g,
            &mut plc,
            now,
            motion.line(),
            &reports,
        );
        let computing = monotonic_ns();
        while next_tick <= newest.tick + ahead {
            let answered = next_tick - ahead;
            while received.front().is_some_and(|f| f.tick < answered) {
                received.pop_front();
            }
            match received.front().filter(|f| f.tick == answered) {
                Some(fb) => latest.read(fb, n),
                None => missing_feedback += 1,
            }
            motion.plc_signals(&g);
            latest.give(&mut motion, true);
            let mut out = ServoSetpoint {
                seq: next_tick,
                sent_ns: monotonic_ns(),
                tick: next_tick,
                episode,
                axis_count: n as u32,
                ..ServoSetpoint::default()
            };
            out.position[..n].copy_from_slice(motion.tick(Some(&latest.actual[..n]), &g));
            motion.fill_setpoint(&mut out);
            setpoints.send(out)?;
            let mut fi = *motion.f_image();
            fi.seq = next_tick;
            f_out.send(fi)?;
            reporter.report(
                &mut motion,
                next_tick,
                &latest,
                &clock,
                mcfg.period,
                &reports,
            );
            next_tick += 1;
        }
        tails.plan(&motion, &g, next_tick, episode, &tail_out)?;
        if dry_shown && motion.state() == RunState::Running {
            dry_shown = false;
            let _ = reports.send(Report::Warning(alarm::SERVO_OVERRUN, None));
        }
        let done = monotonic_ns();
        clock
            .stats
            .phases(0.0, done.saturating_sub(computing) as f64 / 1000.0, 0.0);
    }
    let stats = &clock.stats;
    let _ = reports.send(Report::Stats(stats.message(mcfg.period)));
    let period_us = mcfg.period * 1e6;
    Ok(format!(
        "{}\nfeedback missing for {missing_feedback} planned ticks\n{}",
        stats.summary(period_us),
        stats.interval_histogram(period_us).trim_end()
    ))
}
