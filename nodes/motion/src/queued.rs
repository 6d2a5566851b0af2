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

use cnc_msgs::servo::{
    BrakeTail, DriveControl, ServoFeedback, ServoSetpoint, MAX_AXES, TAIL_TICKS,
};
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
const BATCH_TICKS: u64 = 2;
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

/// What keeps the drives' queue fed: motion's core, the drives' feedback by tick, where the
/// queue ends.
struct Feeder {
    motion: Motion,
    latest: Latest,
    received: VecDeque<ServoFeedback>,
    /// The drive tick of the next setpoint to compute.
    next_tick: u64,
    episode: u32,
    ahead: u64,
    n: usize,
    g: GImage,
    plc: PlcLink,
    clock: Clockwork,
    reporter: Reporter,
    tails: Tails,
    /// Alarm 54 of a dry queue is shown (cleared once the machine runs again).
    dry_shown: bool,
    missing_feedback: u64,
    last_wake: u64,
    /// What the drives were last told beside the queue.
    control: DriveControl,
    /// Wake-ups without planning (the periodic status counts them).
    idle_wakes: u64,
}

impl Feeder {
    /// The queue's episode ended at the drives: a dry queue (the drives played a brake tail:
    /// go on from the state it ends in) or an emergency stop (the core holds where the slides
    /// are; the next episode starts from there).
    fn episode_ended(&mut self, newest: &ServoFeedback, now: u64, reports: &Sender<Report>) {
        self.episode = newest.episode;
        if matches!(
            newest.episode_ended,
            ServoFeedback::ENDED_RESET | ServoFeedback::ENDED_JOG_RELEASE
        ) {
            // The drives stopped on the queued path for motion's reset or a jog key's
            // release: go on from there.
            self.tails.kept.clear();
            self.motion.stand_at(&newest.setpoint[..self.n]);
            self.next_tick = newest.tick + self.ahead;
            return;
        }
        if self.control.resets != newest.resets_done {
            // A dry queue on the way to the reset's stop is part of it.
            return;
        }
        if newest.episode_ended == ServoFeedback::ENDED_EMERGENCY_STOP {
            self.tails.kept.clear();
            self.next_tick = newest.tick + self.ahead;
            return;
        }
        let text = format!(
            "the drives' setpoint queue ran dry at drive tick {} (motion's last wake-up {:.0} ms \
             before this one): the machine stopped on its path, cycle start goes on",
            newest.dry_tick,
            now.saturating_sub(self.last_wake) as f64 / 1e6
        );
        match self.tails.take(newest.dry_tick) {
            Some((stopped, after)) => {
                self.motion = *stopped;
                self.next_tick = after.max(newest.tick + self.ahead);
            }
            None => {
                // The drives held without a tail: a step in velocity, the servo alarm.
                self.motion
                    .servo_overrun(format!("{text}; no brake tail reached the drives"));
                self.next_tick = newest.tick + self.ahead;
            }
        }
        log::warn!("{text}");
        let _ = reports.send(Report::Warning(alarm::SERVO_OVERRUN, Some(text)));
        self.dry_shown = true;
    }

    /// Tells the drives motion's feed hold, cycle starts and resets when they change.
    fn tell_drives(&mut self, out: &Channels) -> Result<(), String> {
        let control = self.motion.drive_control();
        if control == self.control {
            return Ok(());
        }
        self.control = control;
        out.control.send(control)
    }

    /// Computes the setpoints up to `newest.tick` + the queue's length, each with the
    /// feedback of the tick a queue's length before it, and sends them.
    fn plan_batch(
        &mut self,
        newest: &ServoFeedback,
        period: f64,
        out: &Channels,
        reports: &Sender<Report>,
    ) -> Result<(), String> {
        let n = self.n;
        while self.next_tick <= newest.tick + self.ahead {
            let answered = self.next_tick - self.ahead;
            while self.received.front().is_some_and(|f| f.tick < answered) {
                self.received.pop_front();
            }
            match self.received.front().filter(|f| f.tick == answered) {
                Some(fb) => self.latest.read(fb, n),
                None => self.missing_feedback += 1,
            }
            self.latest.give(&mut self.motion, true);
            let mut sp = ServoSetpoint {
                seq: self.next_tick,
                sent_ns: monotonic_ns(),
                tick: self.next_tick,
                episode: self.episode,
                axis_count: n as u32,
                ..ServoSetpoint::default()
            };
            let position = self.motion.tick(Some(&self.latest.actual[..n]), &self.g);
            sp.position[..n].copy_from_slice(position);
            self.motion.fill_setpoint(&mut sp);
            out.setpoints.send(sp)?;
            let mut fi = *self.motion.f_image();
            fi.seq = self.next_tick;
            out.f_image.send(fi)?;
            let (tick, clock) = (self.next_tick, &self.clock);
            self.reporter
                .report(&mut self.motion, tick, &self.latest, clock, period, reports);
            self.next_tick += 1;
        }
        let (next, episode) = (self.next_tick, self.episode);
        self.tails
            .plan(&self.motion, &self.g, next, episode, &out.tails)?;
        if self.dry_shown && self.motion.state() == RunState::Running {
            self.dry_shown = false;
            let _ = reports.send(Report::Warning(alarm::SERVO_OVERRUN, None));
        }
        Ok(())
    }
}

/// What motion sends the drives and the PLC.
struct Channels {
    setpoints: cnc_runtime::shm::Sender<ServoSetpoint>,
    tails: cnc_runtime::shm::Sender<BrakeTail>,
    f_image: cnc_runtime::shm::Sender<FImage>,
    control: cnc_runtime::shm::Sender<DriveControl>,
}

/// Waits for the drives' first feedback (not past shutdown or 30 s); everything that came.
fn first_feedback(
    feedback: &cnc_runtime::shm::Receiver<ServoFeedback>,
    shutdown: &Shutdown,
) -> Result<Option<Vec<ServoFeedback>>, String> {
    let mut arrived = Vec::with_capacity(STREAM_DEPTH);
    for _ in 0..300 {
        if shutdown.requested() {
            return Ok(None);
        }
        feedback.wait_for_any(Duration::from_millis(100))?;
        feedback.take_all(&mut arrived)?;
        if !arrived.is_empty() {
            return Ok(Some(arrived));
        }
    }
    Err("no feedback from the drives within 30 s (is io running?)".into())
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
    let out = Channels {
        setpoints: shm.stream_sender(channel::SETPOINT_QUEUE, false, STREAM_DEPTH)?,
        tails: shm.sender(channel::BRAKE_TAIL, false)?,
        f_image: shm.sender(channel::F_IMAGE, false)?,
        control: shm.sender(channel::DRIVE_CONTROL, false)?,
    };
    let feedback =
        shm.stream_receiver::<ServoFeedback>(channel::FEEDBACK_STREAM, true, STREAM_DEPTH)?;
    let g_in = shm.receiver::<GImage>(channel::G_IMAGE, false)?;
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
    // Start from where the drives are, at the tick they report.
    let Some(arrived) = first_feedback(&feedback, &shutdown)? else {
        return Ok("stopped before the drives reported".into());
    };
    let first = arrived[arrived.len() - 1];
    let latest = Latest::first(&first);
    let ticks_per_second = (1.0 / mcfg.period).round().max(1.0) as u64;
    let mut p = Feeder {
        motion: Motion::new(mcfg.clone(), &latest.actual[..n]),
        latest,
        received: arrived.into_iter().collect(),
        next_tick: first.tick + ahead,
        episode: first.episode,
        ahead,
        n,
        g: GImage::default(),
        plc: PlcLink::new(period_ns),
        // Motion's lateness is no alarm here (the queue absorbs it); its statistics stay.
        clock: Clockwork {
            stats: ServoStatistics {
                realtime: granted.is_realtime(),
                ..Default::default()
            },
            watch: LateWatch::new(u64::MAX, usize::MAX, ticks_per_second, ticks_per_second),
            last_tick: None,
        },
        reporter: Reporter { last_status: None },
        tails: Tails {
            kept: VecDeque::with_capacity(TAILS_KEPT + 1),
            buffer: vec![[0.0; MAX_AXES]; TAIL_TICKS],
            msg: Box::default(),
        },
        dry_shown: false,
        missing_feedback: 0,
        last_wake: monotonic_ns(),
        control: DriveControl::default(),
        idle_wakes: 0,
    };
    out.control.send(p.control)?;
    let mut arrived = Vec::with_capacity(STREAM_DEPTH);
    while !shutdown.requested() {
        feedback.wait_for_any(Duration::from_nanos(period_ns))?;
        let now = monotonic_ns();
        feedback.take_all(&mut arrived)?;
        p.received.extend(arrived.drain(..));
        let Some(newest) = p.received.back().copied() else {
            continue;
        };
        if newest.episode != p.episode {
            p.episode_ended(&newest, now, &reports);
        }
        p.last_wake = now;
        // Requests and the operator's signals at every wake, planned or not: a hold at the
        // drives keeps the queue full, and only a cycle start or reset taken here ends it.
        take_inputs(&inputs, &mut p.motion, &mut p.clock, &mut p.plc, &reports);
        let line = p.motion.line();
        plc_signals(g_in.latest()?, &mut p.g, &mut p.plc, now, line, &reports);
        p.motion.plc_signals(&p.g);
        p.motion.drives_at_block_end(newest.block_stop != 0);
        p.tell_drives(&out)?;
        // After a reset nothing is sent until the drives have stopped for it on the queued
        // path and ended the episode: motion goes on from where they stand.
        let resetting = p.control.resets != newest.resets_done;
        if resetting || newest.tick + ahead < p.next_tick + BATCH_TICKS - 1 {
            // Nothing to plan (the queue is full: held at the drives, or a reset on its way):
            // the state and alarms are reported all the same, at the wakes' rate.
            p.idle_wakes += 1;
            let (wakes, clock) = (p.idle_wakes, &p.clock);
            p.reporter.report(
                &mut p.motion,
                wakes,
                &p.latest,
                clock,
                mcfg.period,
                &reports,
            );
            continue;
        }
        p.clock.tick(now, false, &mut p.motion, &reports);
        let computing = monotonic_ns();
        p.plan_batch(&newest, mcfg.period, &out, &reports)?;
        let done = monotonic_ns();
        p.clock
            .stats
            .phases(0.0, done.saturating_sub(computing) as f64 / 1000.0, 0.0);
    }
    let stats = &p.clock.stats;
    let _ = reports.send(Report::Stats(stats.message(mcfg.period)));
    let period_us = mcfg.period * 1e6;
    Ok(format!(
        "{}\nfeedback missing for {} planned ticks\n{}",
        stats.summary(period_us),
        p.missing_feedback,
        stats.interval_histogram(period_us).trim_end()
    ))
}
