//! The motion core: the run's block queue, the servo tick, drive faults and the NC's state
//! signals to the PLC. What a block becomes is in `activate.rs` (soft limits, checks,
//! segments), what the active block does each tick (rapids, dwells, the M/S/T handshake) in
//! `active.rs`, how blocks join the look-ahead window in `window.rs`, the operator's switches
//! and machine lock in `panel.rs`.
//!
//! Pure: the shell calls [`Motion::tick`] every servo period with the latest drive feedback and
//! PLC image and sends the returned setpoint to the drives. Positions inside are slide travel
//! (X in radius); blocks and reports use display units (X in diameter).

use std::collections::VecDeque;
use std::f64::consts::TAU;

use cnc_msgs::msg::MachineState;
use cnc_msgs::signals::{f, g, FImage, GImage, SignalTable};

use crate::block::{Aux, Block, Command, Turn};
use crate::config::MotionConfig;
use crate::encoder::Encoder;
use crate::path::{self, Point, Segment, MAX_AXES};
use crate::planner::{Done, Planner};
use crate::profile::{Ahead, Limits, Mover, Shape};
use crate::thread_cutting::{Piece, ThreadChain};

pub use crate::alarm;
pub use panel::Panel;

use active::{Active, RapidAxis};

mod activate;
mod active;
mod block_ends;
mod brake_tail;
mod compressor;
mod contour;
mod drive_fault;
mod drive_scaling;
mod feedforward;
mod fixed_stop;
pub mod handwheel;
pub mod jog;
mod live_tool;
mod overtravel;
mod panel;
mod probe;
mod reference;
mod signals;
mod tapping;
mod timers;
mod window;

pub use brake_tail::PlannedStop;
pub use probe::ProbeInput;
pub use reference::ReferenceInputs;
pub use timers::RunTimers;

/// Something the shell must publish.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionEvent {
    Alarm {
        number: u32,
        text: String,
        line: u32,
    },
}

/// A finished block whose end the machine decided (a measuring block, a travel to a fixed
/// stop), in display units (X in diameter on a lathe): the interpreter reads on from `rest`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockResult {
    pub seq: u64,
    /// Its event came: the probe switched, the fixed stop was reached.
    pub triggered: bool,
    /// Every axis's machine position at the event (`rest` when none came).
    pub position: Point,
    /// Where the axes came to rest.
    pub rest: Point,
}

/// Run state reported to the interpreter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    Idle,
    Running,
    Hold,
    Alarm,
}

/// Servo ticks the reset signal RST stays on: 100 ms, ten PLC scans.
const RESET_SIGNAL_TICKS: u32 = 25;

#[derive(Clone)]
pub struct Motion {
    cfg: MotionConfig,
    queue: VecDeque<Block>,
    run_id: u64,
    accepted_seq: u64,
    done_seq: u64,
    line: u32,
    active: Option<(Block, Active)>,
    /// Commanded slide position per axis: where the program has brought the axes.
    commanded: Vec<f64>,
    /// The setpoint the drives get: the commanded position, or under machine lock where the
    /// slides stood when the lock was taken.
    drive: Vec<f64>,
    /// Last tick's `drive`, for the feedforward's velocity.
    last_drive: Vec<f64>,
    /// The drive setpoints of the last `feedback_delay_ticks` ticks, oldest first: the
    /// feedback answers the oldest, so the following error is measured against it.
    sent_drive: VecDeque<[f64; MAX_AXES]>,
    /// FFWON: the drives get the feedforward lead (D106).
    feedforward: bool,
    /// The spindle drive's acceleration, a share of its rated (`ACC[S]`, D108).
    spindle_acceleration: f64,
    /// The axes machine lock holds, a bit per axis: all of them under machine lock, some
    /// under an axis lock (the mill's Z-axis lock); the switches are taken at rest only.
    locked: u32,
    /// Last actual slide position per axis.
    actual: Vec<f64>,
    feed_hold: bool,
    cycle_stop: bool,
    /// With the drives' queue: what the drives' time-scaling takes over (D135).
    at_drives: drive_scaling::AtDrives,
    /// Emergency stop from the PLC (`*ESP` low): servo hold, the run dropped. Releasing it
    /// returns the NC to the reset state, as on a FANUC control, but blocks of the dropped run
    /// stay refused (`dead_run`).
    emergency_stop: bool,
    dead_run: u64,
    /// ST of the last G image, for its rising edge.
    plc_start: bool,
    /// Ticks left of the NC's reset signal RST (F1.1), long enough for the PLC to see it.
    reset_ticks: u32,
    alarm: bool,
    f: FImage,
    events: Vec<MotionEvent>,
    /// Last spindle speed sent to the PLC, rpm: the base of feed per revolution and threads
    /// until motion follows the spindle encoder (issue 4).
    spindle_rpm: f64,
    feed_per_rev: bool,
    /// G09/G61 in force: path blocks end at rest.
    exact_stop: bool,
    /// Ticks since the last strobe that may change the spindle's speed (S, M03/M04/M05, M19),
    /// and readings in a row at the same speed: with the drives' queue a thread starts only
    /// once the (older) encoder reading shows the spindle settled after the last command.
    spindle_quiet: u32,
    spindle_steady: u32,
    /// The look-ahead window: built once, so the servo thread allocates nothing per block.
    planner: Planner,
    /// Consecutive ticks without drive feedback.
    missed_feedback: u32,
    /// Servo off after a drive fault (lost feedback, following error) until reset.
    servo_off: bool,
    /// Blocks the planner finished this tick (kept to avoid allocating every tick).
    finished: Vec<Done>,
    /// The thread being cut (built once, like the planner).
    thread: ThreadChain,
    encoder: Encoder,
    panel: Panel,
    /// Stopped between blocks (single block, M00, M01) until cycle start.
    block_stop: bool,
    /// Line of the block finished last (single block stops when the line changes).
    last_line: Option<u32>,
    /// End points of lines being merged into one chord (built once).
    merge_points: Vec<Point>,
    /// Chords of merged lines still in the planner, and the end of the line being cut.
    merged: VecDeque<block_ends::MergedLines>,
    block_end: Option<Point>,
    /// Per axis, how far ahead of the encoder reading a thread's setpoint is computed, s:
    /// one servo period (the setpoint is reached at the end of the coming period) plus the
    /// drive lag (the slide trails a moving setpoint by it).
    thread_lead_time: [f64; MAX_AXES],
    /// Per axis: it knows its machine position (an absolute encoder, or referenced).
    referenced: Vec<bool>,
    /// Per axis: machine position less the encoder's count, set by the reference return.
    shift: Vec<f64>,
    /// The setpoint as the drives count (the drive setpoint less `shift`).
    encoder_setpoint: Vec<f64>,
    reference: Option<reference::ReferenceReturn>,
    reference_inputs: ReferenceInputs,
    jog: Option<jog::Jog>,
    handwheel: handwheel::Handwheel,
    trial: handwheel::TrialRun,
    /// Overtravel switches pressed, bits per axis: (+, −).
    overtravel: (u32, u32),
    /// The mode the interpreter accepted (`MachineState::MODE_*`): the PLC's jog keys act in
    /// JOG and HANDWHEEL only.
    mode: u8,
    /// The PLC's jog keys of the last tick (+J bits, −J bits by axis index).
    jog_keys: (u32, u32),
    /// The jog in progress was started by the PLC's keys (their release stops it).
    key_jog: bool,
    /// Per axis, its place in the PLC's per-axis signals (X, Y, Z, A, B, C: 0–5), found once
    /// from its letter so that the tick does not search for it.
    signal_axis: Vec<Option<usize>>,
    /// The touch probe's input of the latest feedback.
    probe_input: ProbeInput,
    /// The measuring block under way.
    probing: Option<probe::Probing>,
    /// The last block whose end the machine decided, in this run.
    block_result: Option<BlockResult>,
    /// Per axis, its travel to a fixed stop (FXS).
    fixed_stops: Vec<Option<fixed_stop::FixedStop>>,
    /// COMPCAD: runs of lines on a circle are cut as its arc (D119).
    compressor: bool,
    /// STOPFIFO: the blocks after it wait until the queue is full or the section's end is
    /// queued (D119).
    fifo_fill: bool,
    /// The run-time timers (D121).
    timers: RunTimers,
    /// A program runs: from its first block to its end, a reset or a dropped run.
    program_running: bool,
    /// The turn-mill's C axis in the path (polar interpolation, D141).
    contour: contour::Contour,
    /// The turn-mill's live tool in the path (D142).
    live: live_tool::LiveTool,
}

impl Motion {
    /// `start` is the slide position the drives report at start-up.
    pub fn new(cfg: MotionConfig, start: &[f64]) -> Self {
        let n = cfg.axes.len();
        let commanded: Vec<f64> = (0..n)
            .map(|i| start.get(i).copied().unwrap_or(0.0))
            .collect();
        let planner = Planner::new(cfg.planner(), path::point_from(&commanded));
        let mut thread_lead_time = [0.0; MAX_AXES];
        for (l, a) in thread_lead_time.iter_mut().zip(&cfg.axes) {
            // The setpoint is reached `feedback_delay_ticks` periods after the reading (one
            // in lock-step, the queue's length with the drives' queue), then lags the drive.
            *l = f64::from(cfg.feedback_delay_ticks.max(1)) * cfg.period + a.drive_lag.max(0.0);
        }
        let thread = ThreadChain::new(cfg.lookahead.max(1), cfg.planner().limits);
        let delay = cfg.feedback_delay_ticks.max(1) as usize;
        let cfg_scaling = cfg.time_scaling_at_drives;
        let referenced = cfg.axes.iter().map(|a| a.reference.is_none()).collect();
        let signal_axis = cfg
            .axes
            .iter()
            .map(|a| "XYZABC".find(a.name.as_str()).filter(|_| a.name.len() == 1))
            .collect();
        Motion {
            contour: contour::Contour::default(),
            live: live_tool::LiveTool::of(&cfg),
            compressor: false,
            fifo_fill: false,
            timers: RunTimers::default(),
            program_running: false,
            fixed_stops: vec![None; n],
            probe_input: ProbeInput::default(),
            probing: None,
            block_result: None,
            referenced,
            shift: vec![0.0; n],
            encoder_setpoint: commanded.clone(),
            reference: None,
            reference_inputs: ReferenceInputs::default(),
            jog: None,
            handwheel: handwheel::Handwheel::default(),
            trial: handwheel::TrialRun::default(),
            overtravel: (0, 0),
            mode: 0,
            jog_keys: (0, 0),
            key_jog: false,
            signal_axis,
            thread,
            encoder: Encoder::default(),
            panel: Panel::default(),
            merge_points: Vec::with_capacity(window::MAX_MERGE),
            merged: VecDeque::with_capacity(64),
            block_end: None,
            block_stop: false,
            last_line: None,
            thread_lead_time,
            planner,
            cfg,
            queue: VecDeque::new(),
            run_id: 0,
            accepted_seq: 0,
            done_seq: 0,
            line: 0,
            active: None,
            actual: commanded.clone(),
            drive: commanded.clone(),
            last_drive: commanded.clone(),
            sent_drive: VecDeque::with_capacity(delay + 1),
            spindle_quiet: u32::MAX,
            spindle_steady: 0,
            feedforward: false,
            spindle_acceleration: 1.0,
            locked: 0,
            commanded,
            feed_hold: false,
            cycle_stop: false,
            at_drives: drive_scaling::AtDrives {
                on: cfg_scaling,
                ..Default::default()
            },
            emergency_stop: false,
            dead_run: 0,
            plc_start: false,
            reset_ticks: 0,
            alarm: false,
            spindle_rpm: 0.0,
            feed_per_rev: false,
            exact_stop: false,
            missed_feedback: 0,
            servo_off: false,
            finished: Vec::with_capacity(64),
            f: FImage::default(),
            events: Vec::new(),
        }
    }

    /// Takes a block into the queue. A run begins with its block 1 (a new run replaces
    /// whatever is queued) and goes on block by block; blocks of a run a reset or an
    /// emergency stop dropped are let go. Any other block (another run's, a gap, a run that
    /// does not begin at 1) is refused with an alarm and changes nothing else: no run id,
    /// sequence number or queue of it stays behind (decisions D62).
    pub fn push(&mut self, block: Block) {
        if block.run_id == self.dead_run && self.dead_run != 0 {
            return;
        }
        if block.run_id != self.run_id {
            if block.seq != 1 {
                let text = format!(
                    "block {} of run {} refused: it does not belong to the current run {} \
                     and does not begin a run",
                    block.seq, block.run_id, self.run_id
                );
                self.raise(alarm::BAD_BLOCK, text, block.line);
                return;
            }
            if self.overtravel_pressed() {
                let (number, text) = self.overtravel_alarm(self.overtravel.0, self.overtravel.1);
                self.dead_run = block.run_id;
                self.raise(number, text, block.line);
                return;
            }
            if !self.all_referenced() || self.reference.is_some() {
                // No run begins before every axis knows where it is (D68); the run is let go.
                let names: Vec<&str> = self
                    .cfg
                    .axes
                    .iter()
                    .zip(&self.referenced)
                    .filter(|(_, r)| !**r)
                    .map(|(a, _)| a.name.as_str())
                    .collect();
                let text = format!(
                    "reference return not done ({}): return the axes to their reference point",
                    names.join(", ")
                );
                self.dead_run = block.run_id;
                self.raise(alarm::REFERENCE_NOT_DONE, text, block.line);
                return;
            }
            self.run_id = block.run_id;
            self.live_tool_run();
            self.queue.clear();
            self.merged.clear();
            self.active = None;
            let here = self.commanded_point();
            self.planner.reset(here);
            // A run starts in the machine's own profile (D99), without feedforward (D106),
            // at the rated accelerations (D108).
            self.planner.set_shape(self.cfg.shape);
            self.feedforward = false;
            self.rated_accelerations();
            self.accepted_seq = 0;
            self.done_seq = 0;
            self.feed_hold = false;
            self.cycle_stop = false;
            self.block_stop = false;
            self.last_line = None;
            self.probing = None;
            self.block_result = None;
            self.release_fixed_stops();
            self.compressor = false;
            self.fifo_fill = false;
            self.clear_strobe();
            self.start_program_time();
        }
        // Blocks of a run started during an emergency stop (before the PLC's first scan at
        // power-on) wait in the queue.
        if self.alarm || block.seq <= self.accepted_seq {
            return;
        }
        if block.seq != self.accepted_seq + 1 {
            let text = format!(
                "block {} of run {} refused: block {} expected",
                block.seq,
                block.run_id,
                self.accepted_seq + 1
            );
            self.raise(alarm::BAD_BLOCK, text, block.line);
            return;
        }
        if self.queue.len() >= self.cfg.queue_capacity {
            self.raise(
                alarm::BAD_BLOCK,
                format!(
                    "motion queue full ({} blocks): block {} dropped",
                    self.cfg.queue_capacity, block.seq
                ),
                block.line,
            );
            return;
        }
        self.accepted_seq = block.seq;
        self.queue.push_back(block);
    }

    /// The spindle encoder's reading this tick: speed (negative counter-clockwise) and
    /// angle after the index pulse in degrees.
    pub fn spindle_feedback(&mut self, rpm: f64, angle_deg: f64) {
        let before = self.encoder.rpm;
        self.encoder.read(rpm, angle_deg);
        let settled = (self.encoder.rpm - before).abs() <= 0.002 * before.abs();
        self.spindle_steady = if settled {
            self.spindle_steady.saturating_add(1)
        } else {
            0
        };
    }

    /// Feed hold: decelerate on the path and wait for [`Motion::cycle_start`].
    pub fn feed_hold(&mut self) {
        self.feed_hold = true;
    }

    /// Cycle start: resumes after feed hold, and after a single-block, M00 or M01 stop.
    pub fn cycle_start(&mut self) {
        self.at_drives.starts = self.at_drives.starts.wrapping_add(1);
        self.feed_hold = false;
        self.block_stop = false;
    }

    /// Cycle stop: decelerate on the path, then drop the rest of the run.
    pub fn cycle_stop(&mut self) {
        self.feed_hold = true;
        self.cycle_stop = true;
    }

    /// Reset: clears the alarm state and the queue; the axes stop where they are. The run
    /// is dropped: its blocks still on their way are let go.
    pub fn reset(&mut self) {
        self.at_drives.resets = self.at_drives.resets.wrapping_add(1);
        self.dead_run = self.run_id;
        self.program_running = false;
        self.reset_ticks = RESET_SIGNAL_TICKS;
        self.alarm = false;
        self.servo_off = false;
        self.missed_feedback = 0;
        self.queue.clear();
        self.merged.clear();
        self.active = None;
        self.feed_hold = false;
        self.cycle_stop = false;
        self.block_stop = false;
        self.last_line = None;
        self.probing = None;
        self.clear_strobe();
        self.reference = None;
        self.jog = None;
        self.release_fixed_stops();
        self.compressor = false;
        self.contour.on = false;
        // Reset stops the live tool (`000` B08.6).
        self.stop_live_tool();
        self.fifo_fill = false;
        self.handwheel.stop();
        self.hold_where_slides_are();
        let here = self.commanded_point();
        self.planner.reset(here);
        self.planner.set_shape(self.cfg.shape);
        self.feedforward = false;
        self.rated_accelerations();
    }

    pub fn run_id(&self) -> u64 {
        self.run_id
    }
    pub fn accepted_seq(&self) -> u64 {
        self.accepted_seq
    }
    pub fn done_seq(&self) -> u64 {
        self.done_seq
    }
    pub fn line(&self) -> u32 {
        self.line
    }

    /// The spindle encoder's angle, degrees 0–360 after its index (a turn-mill's C, D138).
    pub fn spindle_angle(&self) -> f64 {
        self.encoder.raw_ahead(0.0)
    }
    pub fn capacity(&self) -> usize {
        self.cfg.queue_capacity
    }
    pub fn commanded(&self) -> &[f64] {
        &self.commanded
    }
    /// The setpoint sent to the drives last tick (under machine lock not the commanded one).
    pub fn setpoint(&self) -> &[f64] {
        &self.drive
    }
    /// Whether machine lock holds every axis's drive.
    pub fn machine_locked(&self) -> bool {
        self.locked == self.all_axes()
    }
    /// The axes whose drives a lock holds, a bit per axis.
    pub fn locked_axes(&self) -> u32 {
        self.locked
    }
    fn all_axes(&self) -> u32 {
        (1u32 << self.cfg.axes.len()) - 1
    }
    pub fn f_image(&self) -> &FImage {
        &self.f
    }
    pub fn config(&self) -> &MotionConfig {
        &self.cfg
    }

    pub fn state(&self) -> RunState {
        if self.alarm || self.emergency_stop {
            RunState::Alarm
        } else if self.block_stop
            || self.at_drives.block_stop
            || self.feed_hold && (self.active.is_some() || !self.queue.is_empty())
        {
            RunState::Hold
        } else if self.axes_driven() || self.handwheel.moving() {
            RunState::Running
        } else {
            RunState::Idle
        }
    }

    /// A program, a reference return or a jog drives the axes (the handwheel aside: it takes
    /// more detents while it moves one).
    pub(super) fn axes_driven(&self) -> bool {
        self.active.is_some()
            || !self.queue.is_empty()
            || self.reference.is_some()
            || self.jog.is_some()
    }

    /// Whether the active block is a feed move (line, arc or thread) rather than a rapid,
    /// dwell or strobe; `None` when no block is active.
    pub fn active_cutting(&self) -> Option<bool> {
        self.active
            .as_ref()
            .map(|(_, a)| matches!(a, Active::Path | Active::Thread { .. }))
    }

    /// The last block of this run whose end the machine decided, once it is done.
    pub fn block_result(&self) -> Option<&BlockResult> {
        self.block_result.as_ref()
    }

    pub fn take_events(&mut self) -> Vec<MotionEvent> {
        std::mem::take(&mut self.events)
    }

    /// Commanded position in display units.
    /// A slide point in display units (X as diameter), as a block's result reports it; no
    /// allocation (it is made on the servo thread).
    fn display_point(&self, slide: &[f64]) -> Point {
        let mut p = [0.0; MAX_AXES];
        for ((d, s), a) in p.iter_mut().zip(slide).zip(&self.cfg.axes) {
            *d = s / a.scale();
        }
        p
    }

    pub fn commanded_display(&self) -> Vec<f64> {
        self.commanded
            .iter()
            .zip(&self.cfg.axes)
            .map(|(p, a)| p / a.scale())
            .collect()
    }

    /// One servo period. `actual` is the drives' slide position (None if no feedback arrived).
    /// Returns the setpoint for the drives: the new commanded slide position, unless machine
    /// lock holds them.
    pub fn tick(&mut self, actual: Option<&[f64]>, plc: &GImage) -> &[f64] {
        self.live.last = self.live.at;
        self.tick_machine(actual, plc);
        if self.servo_off || self.emergency_stop {
            self.stop_live_tool();
        }
        self.spin_live_tool(plc.get(g::SSTP_N));
        if self.at_drives.on {
            self.mark_block_start();
        }
        self.drive_output();
        &self.encoder_setpoint
    }

    /// The slides' positions in machine coordinates (the encoders' counts and the shift the
    /// reference return set).
    pub fn actual(&self) -> &[f64] {
        &self.actual
    }

    /// [`Motion::tick`] in machine coordinates: `actual` is what the encoders count, the
    /// drive setpoint is left in `self.drive`.
    fn tick_machine(&mut self, actual: Option<&[f64]>, plc: &GImage) {
        // Detents turned while the machine cannot take them (servo off, emergency stop) are
        // dropped with this period.
        self.spindle_quiet = self.spindle_quiet.saturating_add(1);
        let detents = self.take_detents();
        self.trial_run(plc, detents, self.cfg.period);
        self.count_power_on(self.cfg.period);
        self.read_feedback(actual);
        if self.servo_off {
            // Setpoints stay where they were; the drives are disabled (see `servo_enabled`).
            self.reference = None;
            self.jog = None;
            self.handwheel.stop();
            self.update_f();
            self.drive_setpoint();
            return;
        }
        if !plc.get(g::ESP_N) {
            // Servo hold where the slides are, the run dropped. The PLC raises the alarm.
            if !self.emergency_stop {
                self.emergency_stop = true;
                self.dead_run = self.run_id;
                self.drop_run();
                self.release_fixed_stops();
                self.feed_hold = false;
                self.cycle_stop = false;
                self.block_stop = false;
                self.reference = None;
                self.jog = None;
                self.handwheel.stop();
            }
            self.commanded.clone_from(&self.actual);
            self.update_f();
            self.drive_setpoint();
            return;
        }
        if self.emergency_stop {
            self.emergency_stop = false;
            self.planner.reset(self.commanded_point());
        }
        let dt = self.cfg.period;
        self.key_jogs(plc);
        self.handwheel_detents(plc, detents);
        if self.reference.is_some() && !self.alarm {
            self.reference_tick(dt);
            self.update_f();
            self.drive_setpoint();
            return;
        }
        if self.jog.is_some() && !self.alarm {
            self.jog_tick(dt);
            self.update_f();
            self.drive_setpoint();
            return;
        }
        if self.handwheel.moving() && !self.alarm {
            self.handwheel_tick(dt);
            self.update_f();
            self.drive_setpoint();
            return;
        }
        self.take_machine_lock();
        self.count_run_time(dt);
        self.watch_probe();
        self.watch_fixed_stops();
        self.run_blocks(dt, plc);
        self.finish_probing();
        self.finish_fixed_stops();
        // Cycle stop: once the axes stand on the path, the rest of the run is dropped.
        if self.cycle_stop && self.stopped_on_path() {
            self.drop_run();
            self.cycle_stop = false;
            self.feed_hold = false;
        }
        self.update_f();
        self.drive_setpoint();
    }

    /// The drives' feedback of this tick (encoder counts, the reference shift added), checked
    /// against its setpoint; none for too long is the lost-feedback alarm.
    fn read_feedback(&mut self, actual: Option<&[f64]>) {
        if let Some(a) = actual {
            for ((dst, src), s) in self.actual.iter_mut().zip(a).zip(&self.shift) {
                *dst = *src + *s;
            }
            self.missed_feedback = 0;
            self.check_following_error();
        } else {
            self.missed_feedback += 1;
            if self.missed_feedback >= self.cfg.feedback_lost_ticks && !self.servo_off {
                self.drive_fault(
                    alarm::FEEDBACK_LOST,
                    format!(
                        "no feedback from the drives for {} servo ticks",
                        self.missed_feedback
                    ),
                );
            }
        }
    }

    /// The run's blocks this tick: the next one activated when none is, the active one
    /// advanced; blocks that finish without moving (aux, dwell, settings) chain on within it.
    fn run_blocks(&mut self, dt: f64, plc: &GImage) {
        let mut budget = 8; // blocks that can finish within one tick (zero-length moves, aux)
        while budget > 0 && !self.alarm {
            budget -= 1;
            if self.active.is_none() {
                // A cycle stop starts nothing new; `tick_machine` ends it once the axes stand.
                if self.cycle_stop || self.block_stop {
                    break;
                }
                // STOPFIFO: the section waits in the queue until it is whole or the queue full.
                if self.fifo_fill && !self.fifo_ready() {
                    break;
                }
                let Some(next_line) = self.queue.front().map(|b| b.line) else {
                    break;
                };
                // Single block: the next line waits for cycle start (`000` §7.4); with the
                // drives time-scaling they stop at its end, and it starts a tick later (D137).
                if self.panel.single_block && self.last_line.is_some_and(|l| l != next_line) {
                    self.block_stop = self.planning_block_stop();
                    self.last_line = None;
                    break;
                }
                let Some(block) = self.queue.pop_front() else {
                    break;
                };
                self.line = block.line;
                match block.kind {
                    Command::FeedMode { per_rev } => self.feed_per_rev = per_rev,
                    Command::PathMode { exact_stop } => self.exact_stop = exact_stop,
                    Command::Profile { jerk_limited } => {
                        self.planner.set_shape(profile_shape(jerk_limited));
                    }
                    Command::Feedforward { on } => self.feedforward = on,
                    Command::Compressor { on } => self.compressor = on,
                    Command::Fifo { fill } => self.fifo_fill = fill,
                    Command::Acceleration { axis, percent } => {
                        self.set_acceleration_override(usize::from(axis), percent / 100.0);
                    }
                    _ => {}
                }
                match self.activate(&block) {
                    Ok(a) => self.active = Some((block, a)),
                    Err((number, text)) => {
                        self.raise(number, text, block.line);
                        self.queue.clear();
                        break;
                    }
                }
            }
            if let Err((number, text, line)) =
                self.extend_chain().and_then(|_| self.extend_thread())
            {
                self.raise(number, text, line);
                self.queue.clear();
                break;
            }
            self.count_locked_wait();
            if self.advance(dt, plc) {
                let moved = matches!(
                    self.active,
                    Some((
                        _,
                        Active::Path | Active::Rapid { .. } | Active::Thread { .. }
                    ))
                );
                if let Some((block, _)) = self.active.take() {
                    self.done_seq = self.done_seq.max(block.seq);
                    if block.kind == Command::ProgramEnd {
                        self.program_running = false;
                    }
                    self.last_line = Some(self.line);
                    // M00, and M01 with the optional-stop switch on, stop after their FIN.
                    self.block_stop = match block.kind {
                        Command::Aux(Aux::M(0)) => true,
                        Command::Aux(Aux::M(1)) => self.panel.optional_stop,
                        _ => false,
                    };
                }
                // A finished move used this tick; aux, dwell and end chain on within it.
                if moved {
                    break;
                }
                continue;
            }
            break;
        }
    }

    /// Whether a STOPFIFO section may run: the queue is full, or the section's end or the
    /// program's is in it.
    fn fifo_ready(&self) -> bool {
        self.queue.len() + 1 >= self.cfg.queue_capacity
            || self
                .queue
                .iter()
                .any(|b| matches!(b.kind, Command::Fifo { fill: false } | Command::ProgramEnd))
    }

    /// Whether the drives may be enabled: false after a drive fault until reset.
    pub fn servo_enabled(&self) -> bool {
        !self.servo_off
    }

    /// Forgets the queue and whatever is moving; the axes keep their commanded position.
    fn drop_run(&mut self) {
        self.program_running = false;
        self.queue.clear();
        self.active = None;
        self.probing = None;
        let here = self.commanded_point();
        self.planner.reset(here);
        self.clear_strobe();
    }

    fn stopped_on_path(&self) -> bool {
        match &self.active {
            None => true,
            Some((_, Active::Path)) => self.planner.velocity() == 0.0,
            Some((_, Active::Thread { .. })) => false,
            Some((_, Active::Rapid { axes, .. })) => axes.iter().all(|a| a.mover.velocity == 0.0),
            Some(_) => true,
        }
    }

    fn raise(&mut self, number: u32, text: String, line: u32) {
        self.alarm = true;
        self.active = None;
        self.probing = None;
        self.drop_fixed_stop_approaches();
        self.reference = None;
        self.jog = None;
        self.handwheel.stop();
        let here = self.commanded_point();
        self.planner.reset(here);
        self.clear_strobe();
        self.events.push(MotionEvent::Alarm { number, text, line });
    }

    /// The commanded slide position as a planner point.
    fn commanded_point(&self) -> Point {
        self.with_live_tool(self.with_contour(path::point_from(&self.commanded)))
    }
}

/// The planner's profile for a program's switch: jerk-limited is the S-curve (decision D99).
fn profile_shape(jerk_limited: bool) -> Shape {
    if jerk_limited {
        Shape::SCurve
    } else {
        Shape::Trapezoidal
    }
}
