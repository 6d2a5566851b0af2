//! motion node shell: the servo loop on its own thread, and a DDS thread that feeds it blocks
//! and commands and publishes what it reports.
//!
//! The servo thread only moves fixed-size values through its channels; building DDS messages
//! (names, vectors, stamps) is the DDS thread's work.

use std::sync::mpsc::{channel as mpsc, Receiver, Sender, TryRecvError};
use std::time::Duration;

use cnc_msgs::canon::from_motion_block;
use cnc_msgs::msg::{
    Alarm, Axis, AxisState, CommandResult, MotionBlock, MotionCommand, MotionStatus, ServoStats,
    SpindleState,
};
use cnc_msgs::servo::{ServoFeedback, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{FImage, GImage};
use cnc_msgs::task::MotionRequest;
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::{monotonic_ns, sleep_until_ns};
use cnc_runtime::dds::{stamp, RosNode};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::loop_stats::{LateWatch, Lateness, ServoStatistics};
use crate::motion::alarm;
use crate::motion::{BlockResult, ProbeInput, ReferenceInputs};
use crate::FromLaunch;
use crate::{Block, Motion, MotionConfig, MotionEvent, RunState};

/// The PLC must answer within this time, else motion takes it as an emergency stop.
const PLC_TIMEOUT_NS: u64 = 500_000_000;

pub(crate) enum Input {
    Block(Block),
    /// A command of the task's, with its id: answered by [`Report::Answer`].
    Command(u64, MotionRequest),
}

pub(crate) enum Report {
    /// The status, and the result of the last block whose end the machine decided (its
    /// vectors are filled here, off the servo thread).
    Status(MotionStatus, Option<BlockResult>),
    /// A tick later than the warning limit (its interval, µs), or the warning cleared.
    Late(Option<f64>),
    /// The axes as the `axes` topic shows them.
    Axes(Box<AxesReport>),
    Alarm(u32, String, u32),
    /// A warning raised with its reason (`Some`) or cleared (`None`).
    Warning(u32, Option<String>),
    Stats(ServoStats),
    /// The answer to the task's command of this id: accepted (what was done) or refused (why).
    Answer(u64, Result<String, String>),
}

/// Runs the motion node until shutdown (blocking). Returns the servo statistics line.
pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<String, String> {
    let (in_tx, in_rx) = mpsc::<Input>();
    let (out_tx, out_rx) = mpsc::<Report>();
    let mcfg = MotionConfig::from_launch(&cfg);
    let servo_shutdown = shutdown.clone();
    let timing = Timing::from_launch(&cfg);
    let servo = std::thread::Builder::new()
        .name("servo".into())
        .spawn(move || {
            if timing.queue_ticks > 0 {
                crate::queued::servo_loop(mcfg, timing, instance, in_rx, out_tx, servo_shutdown)
            } else {
                servo_loop(mcfg, timing, instance, in_rx, out_tx, servo_shutdown)
            }
        })
        .map_err(|e| format!("servo thread: {e}"))?;
    let dds_result = dds_loop(&cfg, in_tx, out_rx, &shutdown);
    shutdown.request();
    let servo_result = servo
        .join()
        .map_err(|_| "servo thread panicked".to_string())?;
    dds_result?;
    servo_result
}

/// What the servo thread needs of the launch config for its timing.
pub(crate) struct Timing {
    pub(crate) realtime: cnc_runtime::config::RealtimeConfig,
    /// A tick this long after the last is a warning, ns.
    warning_ns: u64,
    alarm_ticks: usize,
    /// Ticks motion keeps the drives' setpoint queue ahead (0: lock-step).
    pub(crate) queue_ticks: u64,
}

impl Timing {
    fn from_launch(cfg: &LaunchConfig) -> Timing {
        Timing {
            realtime: cfg.realtime.clone(),
            warning_ns: (cfg.servo.late_warning() * 1e6) as u64,
            alarm_ticks: cfg.servo.late_alarm_ticks as usize,
            queue_ticks: cfg.servo.drive_queue_ticks(),
        }
    }
}

fn dds_loop(
    cfg: &LaunchConfig,
    to_servo: Sender<Input>,
    from_servo: Receiver<Report>,
    shutdown: &Shutdown,
) -> Result<(), String> {
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "motion")?;
    let blocks = ros.subscription::<MotionBlock>(&topics::MOTION_BLOCKS)?;
    // Motion takes commands from the task only (issue 47), and answers each.
    let commands = ros.subscription::<MotionCommand>(&topics::MOTION_COMMAND)?;
    let results_pub = ros.publisher::<CommandResult>(&topics::MOTION_RESULT)?;
    let status_pub = ros.publisher::<MotionStatus>(&topics::MOTION_STATUS)?;
    let axes_pub = ros.publisher::<AxisState>(&topics::AXES)?;
    let stats_pub = ros.publisher::<ServoStats>(&topics::SERVO_STATS)?;
    // A turn-mill's live tool as a spindle (D143).
    let live_pub = match cfg.machine.live_tool {
        Some(_) => Some(ros.publisher::<SpindleState>(&topics::LIVE_TOOL)?),
        None => None,
    };
    let alarms = AlarmReporter::new(&mut ros, "motion")?;
    let axes = &cfg.machine.axes;
    // Motion's alarms are latched, as the manuals' are: they stay until reset (`000` §2.4,
    // §13.1.3; alarms 53/64 "press RESET"). One whose cause persists is raised again after
    // the reset.
    let mut raised = std::collections::BTreeSet::new();
    while !shutdown.requested() {
        ros.refresh();
        let mut idle = true;
        while let Ok(Some(m)) = blocks.take() {
            idle = false;
            match from_motion_block(&m) {
                Ok(kind) => {
                    let _ = to_servo.send(Input::Block(Block {
                        run_id: m.run_id,
                        seq: m.seq,
                        line: m.line,
                        kind,
                    }));
                }
                Err(why) => {
                    let text = format!("block refused: {why}");
                    raised.insert(alarm::BAD_BLOCK);
                    alarms.raise(alarms.alarm(
                        alarm::BAD_BLOCK,
                        Alarm::SEVERITY_ERROR,
                        &text,
                        &m.program,
                        m.line,
                    ));
                }
            }
        }
        while let Ok(Some(c)) = commands.take() {
            idle = false;
            match MotionRequest::from_command(&c, axes.len()) {
                Ok(request) => {
                    if request == MotionRequest::Reset {
                        for number in std::mem::take(&mut raised) {
                            alarms.clear(number);
                        }
                    }
                    let _ = to_servo.send(Input::Command(c.id, request));
                }
                Err(message) => publish(&results_pub, answer(c.id, Err(message))),
            }
        }
        loop {
            match from_servo.try_recv() {
                Ok(Report::Status(mut s, result)) => {
                    if let Some(p) = result {
                        let n = axes.len();
                        s.result_seq = p.seq;
                        s.result_triggered = p.triggered;
                        s.result_position = p.position[..n].to_vec();
                        s.result_rest = p.rest[..n].to_vec();
                    }
                    publish(&status_pub, s)
                }
                Ok(Report::Late(Some(us))) => alarms.raise(alarms.alarm(
                    alarm::SERVO_LATE,
                    Alarm::SEVERITY_WARNING,
                    &format!(
                        "servo tick {us:.0} us after the last (period {:.0} us)",
                        cfg.servo.period_ms * 1000.0
                    ),
                    "",
                    0,
                )),
                Ok(Report::Late(None)) => alarms.clear(alarm::SERVO_LATE),
                Ok(Report::Warning(number, Some(text))) => {
                    raised.insert(number);
                    alarms.raise(alarms.alarm(number, Alarm::SEVERITY_WARNING, &text, "", 0))
                }
                Ok(Report::Warning(number, None)) => {
                    if raised.remove(&number) {
                        alarms.clear(number);
                    }
                }
                Ok(Report::Axes(r)) => {
                    publish(&axes_pub, axis_state(&r, cfg));
                    if let (Some(p), Some(live)) = (&live_pub, &r.live_tool) {
                        publish(p, live_tool_state(live));
                    }
                }
                Ok(Report::Stats(s)) => publish(&stats_pub, s),
                Ok(Report::Answer(id, result)) => publish(&results_pub, answer(id, result)),
                Ok(Report::Alarm(number, text, line)) => {
                    raised.insert(number);
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

/// Commanded, actual and drive setpoint positions (machine coordinates), a bit per axis a
/// lock holds, a bit per referenced axis, the overtravel switches (+, −), and the spindle
/// encoder's angle (a turn-mill's C axis, D138).
pub(crate) struct AxesReport {
    commanded: [f64; MAX_AXES],
    actual: [f64; MAX_AXES],
    setpoint: [f64; MAX_AXES],
    locked: u32,
    referenced: u32,
    limits: (u32, u32),
    spindle_angle: f64,
    /// The live tool's, on a turn-mill (D142, D143).
    live_tool: Option<LiveToolReport>,
}

/// The live tool as the `axes` and `live_tool` topics show it.
pub(crate) struct LiveToolReport {
    /// Setpoint and actual angle, degrees turned.
    angle: (f64, f64),
    /// The speed mode's speed, r/min (0: position control), and the drive's actual speed.
    rpm: (f64, f64),
    /// It turns at the speed asked for (stands, in position control).
    at_speed: bool,
}

/// The `axes` topic's message: the configured axes, and on a turn-mill the spindle as C (its
/// encoder's angle, 0–360°, "displayed always positive", `000` §5.7).
fn axis_state(r: &AxesReport, cfg: &cnc_runtime::LaunchConfig) -> AxisState {
    let (axes, c_axis) = (&cfg.machine.axes, cfg.machine.spindle_c_axis);
    let n = axes.len();
    let mut list: Vec<Axis> = axes
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let (cmd, act) = (r.commanded[i] / a.scale(), r.actual[i] / a.scale());
            Axis {
                name: a.name.clone(),
                commanded_position: cmd,
                actual_position: act,
                following_error: r.setpoint[i] / a.scale() - act,
                homed: r.referenced & (1 << i) != 0,
                overtravel: i8::from(r.limits.0 & (1 << i) != 0)
                    - i8::from(r.limits.1 & (1 << i) != 0),
                locked: r.locked & (1 << i) != 0,
            }
        })
        .collect();
    if c_axis {
        list.push(Axis {
            name: "C".into(),
            commanded_position: r.spindle_angle,
            actual_position: r.spindle_angle,
            following_error: 0.0,
            homed: true,
            overtravel: 0,
            locked: false,
        });
    }
    // The live tool's angle, 0–360° as C's (D142).
    if let (Some(live), Some(t)) = (&r.live_tool, &cfg.machine.live_tool) {
        let (set, actual) = live.angle;
        list.push(Axis {
            name: t.axis.clone(),
            commanded_position: set.rem_euclid(360.0),
            actual_position: actual.rem_euclid(360.0),
            following_error: set - actual,
            homed: true,
            overtravel: 0,
            locked: false,
        });
    }
    AxisState {
        stamp: stamp(),
        axes: list,
        machine_lock: n > 0 && r.locked == (1u32 << n) - 1,
    }
}

/// The `live_tool` topic's message: the tool as a spindle, turning its positive way in speed
/// mode, positioned in position control (D143).
fn live_tool_state(live: &LiveToolReport) -> SpindleState {
    let (commanded, actual) = live.rpm;
    SpindleState {
        stamp: stamp(),
        commanded_rpm: commanded,
        actual_rpm: actual.abs(),
        direction: match commanded > 0.0 {
            true => SpindleState::DIRECTION_CW,
            false => SpindleState::DIRECTION_STOP,
        },
        load: 0.0,
        override_percent: 100.0,
        at_speed: live.at_speed,
        positioned: commanded == 0.0 && live.at_speed,
        position_deg: live.angle.1.rem_euclid(360.0),
    }
}

/// Whether the PLC keeps answering: motion takes its silence as an emergency stop.
///
/// Silence is counted in time and in servo ticks: a whole process or host that stood still (a
/// busy host's stolen time, `kill -STOP`) wakes with the clock far ahead and the PLC not yet
/// scanned; the PLC is silent only if it missed its chances (decisions D41).
pub(crate) struct PlcLink {
    last_heard: Option<u64>,
    /// Servo ticks since the PLC last answered.
    ticks_since: u64,
    /// The ticks of [`PLC_TIMEOUT_NS`] at the servo period.
    timeout_ticks: u64,
    reported: bool,
}

impl PlcLink {
    pub(crate) fn new(period_ns: u64) -> PlcLink {
        PlcLink {
            last_heard: None,
            ticks_since: 0,
            timeout_ticks: (PLC_TIMEOUT_NS / period_ns.max(1)).max(1),
            reported: false,
        }
    }

    fn heard(&mut self, now: u64) {
        self.last_heard = Some(now);
        self.ticks_since = 0;
        self.reported = false;
    }

    /// Counts one servo tick without an answer.
    fn tick(&mut self) {
        self.ticks_since = self.ticks_since.saturating_add(1);
    }

    /// True once the PLC, having answered before, has been quiet for [`PLC_TIMEOUT_NS`] and
    /// as many servo ticks.
    fn silent(&self, now: u64) -> bool {
        self.ticks_since >= self.timeout_ticks
            && self
                .last_heard
                .is_some_and(|t| now.saturating_sub(t) > PLC_TIMEOUT_NS)
    }
}

/// The task's command carried out: what was done, or why not.
fn obey(motion: &mut Motion, request: &MotionRequest) -> Result<String, String> {
    match *request {
        MotionRequest::FeedHold => motion.feed_hold(),
        MotionRequest::Resume => motion.cycle_start(),
        MotionRequest::CycleStop => motion.cycle_stop(),
        MotionRequest::Reset => motion.reset(),
        MotionRequest::Mode(m) => motion.set_mode(m),
        MotionRequest::ReferenceReturn => return motion.reference_return(),
        MotionRequest::Jog { direction: 0, .. } => motion.jog_stop(),
        MotionRequest::Jog {
            axis,
            direction,
            feed,
            increment,
        } => {
            let step = (increment > 0.0).then_some(increment);
            motion.jog(usize::from(axis), direction > 0, feed, step)?;
            return Ok("jog".into());
        }
    }
    Ok("done".into())
}

fn answer(id: u64, result: Result<String, String>) -> CommandResult {
    let (accepted, message) = match result {
        Ok(m) => (true, m),
        Err(m) => (false, m),
    };
    CommandResult {
        id,
        accepted,
        message,
        ..CommandResult::default()
    }
}

fn publish<M: ros2_client::Message + std::fmt::Debug + Send + Sync + 'static>(
    p: &cnc_runtime::dds::Publisher<M>,
    m: M,
) {
    if let Err(e) = p.publish(m) {
        log::warn!("motion: publish failed: {e:?}");
    }
}

/// The drives' latest feedback as motion reads it each tick.
pub(crate) struct Latest {
    pub(crate) actual: [f64; MAX_AXES],
    spindle: (f64, f64),
    /// The live tool's angle, degrees turned (D142), and speed, r/min (D143).
    live_tool: (f64, f64),
    /// The dogs and index marks; a mark is passed on once.
    reference: ReferenceInputs,
    /// The overtravel switches (+, −).
    overtravel: (u32, u32),
    handwheel: i32,
    /// The touch probe's input and latches.
    probe: ProbeInput,
}

impl Latest {
    pub(crate) fn first(fb: &ServoFeedback) -> Latest {
        Latest {
            actual: fb.position,
            spindle: (fb.spindle_rpm, fb.spindle_angle_deg),
            live_tool: (fb.live_tool_angle, fb.live_tool_rpm),
            reference: ReferenceInputs::default(),
            overtravel: (fb.overtravel_plus, fb.overtravel_minus),
            handwheel: fb.handwheel_count,
            probe: ProbeInput::from_feedback(fb),
        }
    }

    pub(crate) fn read(&mut self, fb: &ServoFeedback, n: usize) {
        self.actual = fb.position;
        self.spindle = (fb.spindle_rpm, fb.spindle_angle_deg);
        self.live_tool = (fb.live_tool_angle, fb.live_tool_rpm);
        self.reference.dog = fb.reference_dog;
        self.overtravel = (fb.overtravel_plus, fb.overtravel_minus);
        self.handwheel = fb.handwheel_count;
        self.probe = ProbeInput::from_feedback(fb);
        if fb.marker != 0 {
            self.reference.marker |= fb.marker;
            for i in 0..n {
                if fb.marker & (1 << i) != 0 {
                    self.reference.marker_position[i] = fb.marker_position[i];
                }
            }
        }
    }

    /// Hands motion the inputs of this tick (the spindle's only when the drives answered).
    pub(crate) fn give(&mut self, motion: &mut Motion, have_feedback: bool) {
        if have_feedback {
            motion.spindle_feedback(self.spindle.0, self.spindle.1);
            motion.live_tool_feedback(self.live_tool.0, self.live_tool.1);
        }
        motion.reference_inputs(self.reference);
        self.reference.marker = 0;
        motion.overtravel_inputs(self.overtravel.0, self.overtravel.1);
        motion.handwheel_input(self.handwheel);
        motion.probe_input(self.probe);
    }
}

/// Waits for the drives' first feedback: they (io) may come up after motion, and a loaded
/// machine can take seconds to start them; not past shutdown or 30 s.
fn first_feedback(
    feedback: &cnc_runtime::shm::Receiver<ServoFeedback>,
    shutdown: &Shutdown,
) -> Result<Option<ServoFeedback>, String> {
    for _ in 0..300 {
        if shutdown.requested() {
            return Ok(None);
        }
        if let Some(fb) = feedback.wait(Duration::from_millis(100))? {
            return Ok(Some(fb));
        }
    }
    Err("no feedback from the drives within 30 s (is io running?)".into())
}

/// The servo loop's own timing: its statistics and the lateness watch.
pub(crate) struct Clockwork {
    pub(crate) stats: ServoStatistics,
    pub(crate) watch: LateWatch,
    pub(crate) last_tick: Option<u64>,
}

impl Clockwork {
    /// Counts the tick that woke at `now` (`late`: past half a period); a late warning or its
    /// clearing is reported, an overrun is motion's alarm.
    pub(crate) fn tick(
        &mut self,
        now: u64,
        late: bool,
        motion: &mut Motion,
        reports: &Sender<Report>,
    ) {
        if let Some(prev) = self.last_tick {
            let interval = now - prev;
            self.stats.interval.record(interval as f64 / 1000.0);
            match self.watch.tick(self.stats.ticks, interval, late) {
                Lateness::OnTime => {}
                Lateness::Warning(us) => {
                    let _ = reports.send(Report::Late(Some(us)));
                }
                Lateness::Clear => {
                    let _ = reports.send(Report::Late(None));
                }
                Lateness::Overrun(n) => motion.servo_overrun(format!(
                    "servo loop overrun: {n} late ticks within a second ({})",
                    if self.stats.realtime {
                        "SCHED_FIFO"
                    } else {
                        "not real-time"
                    }
                )),
            }
        }
        self.last_tick = Some(now);
        self.stats.ticks += 1;
        if late {
            self.stats.late_ticks += 1;
        }
    }
}

/// The DDS thread's blocks and the task's commands, carried out; each command answered.
pub(crate) fn take_inputs(
    inputs: &Receiver<Input>,
    motion: &mut Motion,
    clock: &mut Clockwork,
    plc: &mut PlcLink,
    reports: &Sender<Report>,
) {
    while let Ok(input) = inputs.try_recv() {
        match input {
            Input::Block(b) => motion.push(b),
            Input::Command(id, request) => {
                if request == MotionRequest::Reset {
                    clock.watch.reset();
                    // A PLC still silent is reported again (its alarm was cleared by reset).
                    plc.reported = false;
                }
                let result = obey(motion, &request);
                if request == MotionRequest::ReferenceReturn {
                    // A refused reference return is also a warning on the alarm list.
                    let warning = result.as_ref().err().cloned();
                    let _ = reports.send(Report::Warning(alarm::REFERENCE_REFUSED, warning));
                }
                let _ = reports.send(Report::Answer(id, result));
            }
        }
    }
}

/// The PLC's G image of this tick: its latest, or all zero (emergency stop) once it has been
/// silent too long, reported once.
pub(crate) fn plc_signals(
    latest: Option<GImage>,
    g: &mut GImage,
    plc: &mut PlcLink,
    now: u64,
    line: u32,
    reports: &Sender<Report>,
) {
    match latest {
        Some(latest) => {
            *g = latest;
            plc.heard(now);
        }
        None => plc.tick(),
    }
    if !plc.silent(now) {
        return;
    }
    if !plc.reported {
        plc.reported = true;
        let quiet_ms = plc
            .last_heard
            .map_or(0, |t| now.saturating_sub(t) / 1_000_000);
        let _ = reports.send(Report::Alarm(
            alarm::PLC_SILENT,
            format!(
                "the PLC stopped answering ({quiet_ms} ms, {} ticks without its signals): emergency stop",
                plc.ticks_since
            ),
            line,
        ));
    }
    *g = GImage::default();
}

/// What the DDS thread publishes: motion's alarms; the status on a change and every 25 ticks;
/// the axes every 10; the servo statistics every 250.
pub(crate) struct Reporter {
    pub(crate) last_status: Option<(u64, u64, u64, RunState, u32, Option<BlockResult>)>,
}

impl Reporter {
    pub(crate) fn report(
        &mut self,
        motion: &mut Motion,
        seq: u64,
        latest: &Latest,
        clock: &Clockwork,
        period: f64,
        reports: &Sender<Report>,
    ) {
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
            motion.block_result().copied(),
        );
        if self.last_status != Some(status) || seq.is_multiple_of(25) {
            self.last_status = Some(status);
            let state = match status.3 {
                RunState::Idle => MotionStatus::STATE_IDLE,
                RunState::Running => MotionStatus::STATE_RUNNING,
                RunState::Hold => MotionStatus::STATE_HOLD,
                RunState::Alarm => MotionStatus::STATE_ALARM,
            };
            let capacity = motion.capacity() as u32;
            // The timers as of this period: the status that reports a preprocessing stop
            // reached carries them as they stood when the program stopped to read them.
            let timers = motion.timers();
            let msg = MotionStatus {
                run_id: status.0,
                accepted_seq: status.1,
                done_seq: status.2,
                capacity,
                line: status.4,
                state,
                cutting_time: timers.cutting,
                cycle_time: timers.cycle,
                operating_time: timers.operating,
                power_on_time: timers.power_on,
                ..MotionStatus::default()
            };
            let _ = reports.send(Report::Status(msg, status.5));
        }
        if seq.is_multiple_of(10) {
            report_axes(motion, latest.overtravel, reports);
        }
        if seq.is_multiple_of(250) {
            let _ = reports.send(Report::Stats(clock.stats.message(period)));
        }
    }
}

pub(crate) fn report_axes(motion: &Motion, limits: (u32, u32), reports: &Sender<Report>) {
    let n = motion.commanded().len();
    let mut commanded = [0.0; MAX_AXES];
    commanded[..n].copy_from_slice(motion.commanded());
    let mut machine = [0.0; MAX_AXES];
    machine[..n].copy_from_slice(motion.actual());
    // The setpoint the actual position answers (with the drives' queue, the one sent a
    // queue's length ago), so the following error is the drives'.
    let mut drive = [0.0; MAX_AXES];
    motion.answered_setpoint(&mut drive[..n]);
    let locked = motion.locked_axes();
    let referenced = motion
        .referenced()
        .iter()
        .enumerate()
        .fold(0u32, |bits, (i, r)| bits | (u32::from(*r) << i));
    let _ = reports.send(Report::Axes(Box::new(AxesReport {
        commanded,
        actual: machine,
        setpoint: drive,
        locked,
        referenced,
        limits,
        spindle_angle: motion.spindle_angle(),
        live_tool: motion.config().live_tool.as_ref().map(|_| {
            let (rpm, at_speed) = motion.live_tool_mode();
            LiveToolReport {
                angle: (motion.live_tool_setpoint(), motion.live_tool_actual()),
                rpm: (rpm, motion.live_tool_actual_rpm()),
                at_speed,
            }
        }),
    })));
}

fn servo_loop(
    mcfg: MotionConfig,
    timing: Timing,
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
    // After the setup, so no helper thread inherits the priority.
    let rt = &timing.realtime;
    let granted = cnc_runtime::realtime::enter(
        "servo loop",
        rt.servo_priority,
        rt.servo_cpu,
        rt.lock_memory,
    );
    let n = mcfg.axes.len();
    let period_ns = (mcfg.period * 1e9) as u64;
    // Start from where the drives are.
    let Some(first) = first_feedback(&feedback, &shutdown)? else {
        return Ok("stopped before the drives reported".into());
    };
    let mut latest = Latest::first(&first);
    let mut motion = Motion::new(mcfg.clone(), &latest.actual[..n]);
    // All zero: emergency stop until the PLC's first scan (`*ESP` is active low).
    let mut g = GImage::default();
    let mut plc = PlcLink::new(period_ns);
    // One second of ticks is the window of the overrun alarm; five clear a warning.
    let ticks_per_second = (1.0 / mcfg.period).round().max(1.0) as u64;
    let mut clock = Clockwork {
        stats: ServoStatistics {
            realtime: granted.is_realtime(),
            ..Default::default()
        },
        watch: LateWatch::new(
            timing.warning_ns,
            timing.alarm_ticks,
            ticks_per_second,
            5 * ticks_per_second,
        ),
        last_tick: None,
    };
    let mut reporter = Reporter { last_status: None };
    let mut seq = 0u64;
    let mut next = monotonic_ns() + period_ns;
    let mut have_feedback = true;
    while !shutdown.requested() {
        sleep_until_ns(next);
        let now = monotonic_ns();
        let late = now > next + period_ns / 2;
        let wake_late_us = now.saturating_sub(next) as f64 / 1000.0;
        clock.tick(now, late, &mut motion, &reports);
        next += period_ns;
        if now > next + 10 * period_ns {
            next = now + period_ns; // far behind (machine suspended): resynchronise, counted as late
        }
        take_inputs(&inputs, &mut motion, &mut clock, &mut plc, &reports);
        plc_signals(
            g_in.latest()?,
            &mut g,
            &mut plc,
            now,
            motion.line(),
            &reports,
        );
        motion.plc_signals(&g);
        latest.give(&mut motion, have_feedback);
        // What the drives get; under machine lock it is not the commanded position.
        let mut setpoint = [0.0; MAX_AXES];
        let actual = have_feedback.then_some(&latest.actual[..n]);
        setpoint[..n].copy_from_slice(motion.tick(actual, &g));
        let mut fi = *motion.f_image();
        fi.seq = seq + 1;
        f_out.send(fi)?;
        seq += 1;
        let computed = monotonic_ns();
        let mut out = ServoSetpoint {
            seq,
            sent_ns: monotonic_ns(),
            position: setpoint,
            axis_count: n as u32,
            ..ServoSetpoint::default()
        };
        motion.fill_setpoint(&mut out);
        setpoints.send(out)?;
        // The answer to this setpoint, within half a period; a late answer to an earlier one
        // still updates the position but is not a round trip of this tick.
        have_feedback = false;
        let deadline = monotonic_ns() + period_ns / 2;
        while let Some(fb) = feedback.wait(Duration::from_nanos(
            deadline.saturating_sub(monotonic_ns()),
        ))? {
            latest.read(&fb, n);
            have_feedback = true;
            if fb.seq == seq {
                clock
                    .stats
                    .round_trip
                    .record((monotonic_ns() - fb.setpoint_sent_ns) as f64 / 1000.0);
                break;
            }
        }
        let exchanged = monotonic_ns();
        clock.stats.phases(
            wake_late_us,
            computed.saturating_sub(now) as f64 / 1000.0,
            exchanged.saturating_sub(computed) as f64 / 1000.0,
        );
        reporter.report(&mut motion, seq, &latest, &clock, mcfg.period, &reports);
    }
    let stats = &clock.stats;
    let _ = reports.send(Report::Stats(stats.message(mcfg.period)));
    let period_us = mcfg.period * 1e6;
    Ok(format!(
        "{}\n{}",
        stats.summary(period_us),
        stats.interval_histogram(period_us).trim_end()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks of 4 ms from `start` without an answer, with the time after the last one.
    fn quiet_ticks(link: &mut PlcLink, start: u64, ticks: u64) -> u64 {
        for _ in 0..ticks {
            link.tick();
        }
        start + ticks * 4_000_000
    }

    #[test]
    fn a_plc_that_stops_answering_is_silent_after_the_timeout() {
        let mut link = PlcLink::new(4_000_000);
        quiet_ticks(&mut link, 0, 1000);
        assert!(
            !link.silent(10_000_000_000),
            "never heard: starting, not silent"
        );
        link.heard(1_000_000_000);
        let now = quiet_ticks(&mut link, 1_000_000_000, 125);
        assert_eq!(now, 1_000_000_000 + PLC_TIMEOUT_NS);
        assert!(!link.silent(now));
        assert!(link.silent(now + 1));
        link.heard(2_000_000_000);
        assert!(!link.silent(2_100_000_000));
    }

    /// A process that stood still for a second (the host busy elsewhere) wakes with the PLC not
    /// yet scanned: that is no silence; the same second of ticks without an answer is.
    #[test]
    fn a_stall_of_the_whole_process_is_not_a_silent_plc() {
        let mut link = PlcLink::new(4_000_000);
        link.heard(1_000_000_000);
        let now = quiet_ticks(&mut link, 2_000_000_000, 10);
        assert!(!link.silent(now), "ten ticks after a stall of one second");
        link.heard(now);
        let later = quiet_ticks(&mut link, now, 126);
        assert!(link.silent(later), "a PLC quiet for 126 ticks, 504 ms");
    }
}
