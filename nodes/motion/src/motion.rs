//! The motion core: block queue, the look-ahead planner's window, rapids, dwells, soft limits,
//! drive faults, M/S/T handshake with the PLC.
//!
//! Pure: the shell calls [`Motion::tick`] every servo period with the latest drive feedback and
//! PLC image and sends the returned setpoint to the drives. Positions inside are slide travel
//! (X in radius); blocks and reports use display units (X in diameter).

use std::collections::VecDeque;
use std::f64::consts::TAU;

use cnc_msgs::signals::{f, g, FImage, GImage, SignalTable};

use crate::block::{Aux, Block, Command};
use crate::config::MotionConfig;
use crate::encoder::Encoder;
use crate::path::{self, Point, Segment, MAX_AXES};
use crate::planner::{Done, Planner};
use crate::profile::{Ahead, Limits, Mover};
use crate::thread::{Piece, ThreadChain};

pub use crate::alarm;

/// Something the shell must publish.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionEvent {
    Alarm {
        number: u32,
        text: String,
        line: u32,
    },
}

/// The operator's switches as motion sees them (`000` §7.3, §7.4; decision D38).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    /// Feed override, 0–1.5 (the manual's steps 0–150 %). Threads ignore it.
    pub feed_override: f64,
    /// Rapid override, 0–1 (the manual's F0 = 0 %, 25 %, 50 %, 100 %).
    pub rapid_override: f64,
    /// Single block: stop after each program line (a cycle is one line).
    pub single_block: bool,
    /// Dry run: feed moves at `servo.dry_run_feed` instead of F (threads stay locked).
    pub dry_run: bool,
    /// Optional stop: M01 stops like M00.
    pub optional_stop: bool,
    /// Machine lock: the program runs and its positions count, the drives are held where the
    /// slides stand. Taken and released with the machine at rest (decisions D66).
    pub machine_lock: bool,
    /// Auxiliary function lock: M, S and T complete without reaching the PLC, except M00,
    /// M01, M02 and M30.
    pub aux_lock: bool,
}

impl Default for Panel {
    fn default() -> Self {
        Panel {
            feed_override: 1.0,
            rapid_override: 1.0,
            single_block: false,
            dry_run: false,
            optional_stop: false,
            machine_lock: false,
            aux_lock: false,
        }
    }
}

/// Run state reported to the interpreter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    Idle,
    Running,
    Hold,
    Alarm,
}

// The rapid's per-axis state is inline on purpose: boxing it would allocate on the servo
// thread for every rapid.
#[allow(clippy::large_enum_variant)]
enum Active {
    /// Lines and arcs through the look-ahead planner; further path blocks join it as they
    /// arrive.
    Path,
    /// A thread chain, locked to the spindle encoder; `shift`: start angle after the index
    /// pulse, degrees.
    Thread {
        shift: f64,
    },
    /// Each axis on its own profile (dog-leg rapid).
    Rapid {
        start: Point,
        end: Point,
        axes: [RapidAxis; MAX_AXES],
    },
    Dwell {
        remaining: f64,
    },
    /// Waits for the axes to settle, then sends the strobe and waits for FIN.
    Aux {
        code: Aux,
        /// The strobe is up, waiting for FIN.
        raised: bool,
    },
    End,
}

/// One axis of a rapid: its travel and where it is on it.
#[derive(Debug, Clone, Copy)]
struct RapidAxis {
    length: f64,
    travelled: f64,
    mover: Mover,
}

/// Servo ticks the reset signal RST stays on: 100 ms, ten PLC scans.
const RESET_SIGNAL_TICKS: u32 = 25;

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
    /// Machine lock in effect (the switch is taken at rest only).
    locked: bool,
    /// The block-skip switch as the PLC gives it, answered on F4.0.
    block_skip: bool,
    /// Last actual slide position per axis.
    actual: Vec<f64>,
    feed_hold: bool,
    cycle_stop: bool,
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
    /// Per axis, how far ahead of the encoder reading a thread's setpoint is computed, s:
    /// one servo period (the setpoint is reached at the end of the coming period) plus the
    /// drive lag (the slide trails a moving setpoint by it).
    thread_lead_time: [f64; MAX_AXES],
}

/// Most spindle revolutions one thread block may take (a million: 2 h at 8000 rpm).
const MAX_THREAD_REVS: f64 = 1e6;

/// Most lines merged into one chord.
const MAX_MERGE: usize = 32;
/// Share of the path tolerance merging may use; blends at the chord's ends use the rest.
const MERGE_SHARE: f64 = 0.5;
/// Blocks the planner must hold before a merge waits for more lines from the interpreter.
const MERGE_WAIT_BLOCKS: usize = 8;

/// Lines merged into one chord.
struct Merged {
    end: Point,
    /// Block number of the last line merged.
    seq: u64,
    blocks: usize,
    /// Largest distance of a programmed point from the chord, mm.
    deviation: f64,
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
            *l = cfg.period + a.drive_lag.max(0.0);
        }
        let thread = ThreadChain::new(cfg.lookahead.max(1), cfg.planner().limits);
        Motion {
            thread,
            encoder: Encoder::default(),
            panel: Panel::default(),
            merge_points: Vec::with_capacity(MAX_MERGE),
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
            locked: false,
            block_skip: false,
            commanded,
            feed_hold: false,
            cycle_stop: false,
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
            self.run_id = block.run_id;
            self.queue.clear();
            self.active = None;
            let here = self.commanded_point();
            self.planner.reset(here);
            self.accepted_seq = 0;
            self.done_seq = 0;
            self.feed_hold = false;
            self.cycle_stop = false;
            self.block_stop = false;
            self.last_line = None;
            self.clear_strobe();
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
        self.encoder.read(rpm, angle_deg);
    }

    /// The operator's switches; overrides take effect on the next tick.
    pub fn set_panel(&mut self, panel: Panel) {
        let clean = |v: f64, max: f64| {
            if v.is_finite() {
                v.clamp(0.0, max)
            } else {
                1.0
            }
        };
        self.panel = Panel {
            feed_override: clean(panel.feed_override, crate::planner::MAX_FEED_OVERRIDE),
            rapid_override: clean(panel.rapid_override, 1.0),
            ..panel
        };
    }

    /// The operator's signals in the PLC's G image, applied every tick: overrides and
    /// switches as levels, feed hold while `*SP` is low, cycle start on the rising edge of ST.
    pub fn plc_signals(&mut self, plc: &GImage) {
        self.set_panel(Panel {
            feed_override: plc.feed_override(),
            rapid_override: plc.rapid_override(),
            single_block: plc.get(g::SBK),
            dry_run: plc.get(g::DRN),
            optional_stop: plc.get(g::MOPS),
            machine_lock: plc.get(g::MLK),
            aux_lock: plc.get(g::AFL),
        });
        // The interpreter acts on the switch (it reads blocks); motion answers its lamp.
        self.block_skip = plc.get(g::BDT1);
        if !plc.get(g::SP_N) && plc.get(g::ESP_N) {
            self.feed_hold();
        }
        let start = plc.get(g::ST);
        if start && !self.plc_start && plc.get(g::SP_N) {
            self.cycle_start();
        }
        self.plc_start = start;
    }

    /// Feed hold: decelerate on the path and wait for [`Motion::cycle_start`].
    pub fn feed_hold(&mut self) {
        self.feed_hold = true;
    }

    /// Cycle start: resumes after feed hold, and after a single-block, M00 or M01 stop.
    pub fn cycle_start(&mut self) {
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
        self.dead_run = self.run_id;
        self.reset_ticks = RESET_SIGNAL_TICKS;
        self.alarm = false;
        self.servo_off = false;
        self.missed_feedback = 0;
        self.queue.clear();
        self.active = None;
        self.feed_hold = false;
        self.cycle_stop = false;
        self.block_stop = false;
        self.last_line = None;
        self.clear_strobe();
        self.commanded.clone_from(&self.actual);
        let here = self.commanded_point();
        self.planner.reset(here);
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
    /// Whether machine lock holds the drives.
    pub fn machine_locked(&self) -> bool {
        self.locked
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
            || self.feed_hold && (self.active.is_some() || !self.queue.is_empty())
        {
            RunState::Hold
        } else if self.active.is_some() || !self.queue.is_empty() {
            RunState::Running
        } else {
            RunState::Idle
        }
    }

    /// Whether the active block is a feed move (line, arc or thread) rather than a rapid,
    /// dwell or strobe; `None` when no block is active.
    pub fn active_cutting(&self) -> Option<bool> {
        self.active
            .as_ref()
            .map(|(_, a)| matches!(a, Active::Path | Active::Thread { .. }))
    }

    pub fn take_events(&mut self) -> Vec<MotionEvent> {
        std::mem::take(&mut self.events)
    }

    /// Commanded position in display units.
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
        if let Some(a) = actual {
            for (dst, src) in self.actual.iter_mut().zip(a) {
                *dst = *src;
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
        if self.servo_off {
            // Setpoints stay where they were; the drives are disabled (see `servo_enabled`).
            self.update_f();
            return self.drive_setpoint();
        }
        if !plc.get(g::ESP_N) {
            // Servo hold where the slides are, the run dropped. The PLC raises the alarm.
            if !self.emergency_stop {
                self.emergency_stop = true;
                self.dead_run = self.run_id;
                self.drop_run();
                self.feed_hold = false;
                self.cycle_stop = false;
                self.block_stop = false;
            }
            self.commanded.clone_from(&self.actual);
            self.update_f();
            return self.drive_setpoint();
        }
        if self.emergency_stop {
            self.emergency_stop = false;
            self.planner.reset(self.commanded_point());
        }
        self.take_machine_lock();
        let dt = self.cfg.period;
        let mut budget = 8; // blocks that can finish within one tick (zero-length moves, aux)
        while budget > 0 && !self.alarm {
            budget -= 1;
            if self.active.is_none() {
                // A cycle stop starts nothing new; it ends below once the axes stand.
                if self.cycle_stop || self.block_stop {
                    break;
                }
                let Some(next_line) = self.queue.front().map(|b| b.line) else {
                    break;
                };
                // Single block: the next line waits for cycle start (`000` §7.4).
                if self.panel.single_block && self.last_line.is_some_and(|l| l != next_line) {
                    self.block_stop = true;
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
        // Cycle stop: once the axes stand on the path, the rest of the run is dropped.
        if self.cycle_stop && self.stopped_on_path() {
            self.drop_run();
            self.cycle_stop = false;
            self.feed_hold = false;
        }
        self.update_f();
        self.drive_setpoint()
    }

    /// Machine lock is taken and released only with the machine at rest, so a running move
    /// never jumps. Released, the program's position goes back to where the slides stand
    /// (the interpreter takes its next start from there).
    fn take_machine_lock(&mut self) {
        let at_rest = self.active.is_none() && self.queue.is_empty();
        if !at_rest || self.panel.machine_lock == self.locked {
            return;
        }
        self.locked = self.panel.machine_lock;
        if !self.locked {
            self.commanded.clone_from(&self.drive);
            let here = self.commanded_point();
            self.planner.reset(here);
        }
    }

    /// What the drives get this tick: the commanded position, unless machine lock holds them.
    fn drive_setpoint(&mut self) -> &[f64] {
        if !self.locked {
            self.drive.clone_from(&self.commanded);
        }
        &self.drive
    }

    /// Whether the drives may be enabled: false after a drive fault until reset.
    pub fn servo_enabled(&self) -> bool {
        !self.servo_off
    }

    /// Compares each slide with the setpoint it was given (the one sent last tick).
    fn check_following_error(&mut self) {
        if self.servo_off {
            return;
        }
        let lagging = self.cfg.axes.iter().enumerate().find_map(|(i, a)| {
            let lag = (self.drive[i] - self.actual[i]).abs();
            let limit = a.following_error_limit();
            (lag > limit).then(|| {
                format!(
                    "following error: {} lags its setpoint by {lag:.3} mm (limit {limit:.3})",
                    a.name
                )
            })
        });
        if let Some(text) = lagging {
            self.drive_fault(alarm::FOLLOWING_ERROR, text);
        }
    }

    /// A drive fault: servo off, the run dropped, the setpoints held where the slides are
    /// (`000` §11.2: servo alarms switch the servo off).
    /// The servo loop cannot keep its period: the servo alarm, the axes stop where they are
    /// and the servo is switched off, as for a drive fault (D57).
    pub fn servo_overrun(&mut self, text: String) {
        self.drive_fault(alarm::SERVO_OVERRUN, text);
    }

    fn drive_fault(&mut self, number: u32, text: String) {
        let line = self.line;
        self.raise(number, text, line);
        self.queue.clear();
        self.servo_off = true;
        self.commanded.clone_from(&self.actual);
        let here = self.commanded_point();
        self.planner.reset(here);
    }

    /// Forgets the queue and whatever is moving; the axes keep their commanded position.
    fn drop_run(&mut self) {
        self.queue.clear();
        self.active = None;
        let here = self.commanded_point();
        self.planner.reset(here);
        self.clear_strobe();
    }

    /// Path blocks waiting in the queue join the planner's window while it has room, so
    /// corners between them are blended and the speed carries over.
    fn extend_chain(&mut self) -> Result<(), (u32, String, u32)> {
        if !matches!(self.active, Some((_, Active::Path))) {
            return Ok(());
        }
        while self.planner.has_room() {
            let Some(next) = self.queue.front() else {
                break;
            };
            let (seq, line) = (next.seq, next.line);
            if self.panel.single_block && line != self.line {
                break;
            }
            match &next.kind {
                Command::Linear { .. } if !self.exact_stop => {
                    let start = self.planner.end();
                    let (seg, feed) = self
                        .segment_for(next, &start)
                        .map_err(|(n, t)| (n, t, line))?;
                    let Some(merged) = self.merge_lines(&start, seg.end()) else {
                        break; // wait for more blocks to merge with
                    };
                    let seg = Segment::Line {
                        start,
                        end: merged.end,
                    };
                    self.planner
                        .push(seg, feed, merged.seq, line, true, merged.deviation);
                    for _ in 0..merged.blocks {
                        self.queue.pop_front();
                    }
                    continue;
                }
                Command::Linear { .. } | Command::Arc { .. } => {
                    let (seg, feed) = self
                        .segment_for(next, &self.planner.end())
                        .map_err(|(n, t)| (n, t, line))?;
                    let blend = !self.exact_stop;
                    self.planner.push(seg, feed, seq, line, blend, 0.0);
                }
                Command::FeedMode { per_rev } => {
                    self.feed_per_rev = *per_rev;
                    self.planner.push_marker(seq, line);
                }
                Command::PathMode { exact_stop } => {
                    self.exact_stop = *exact_stop;
                    self.planner.push_marker(seq, line);
                }
                _ => break,
            }
            self.queue.pop_front();
        }
        Ok(())
    }

    /// Lines at the front of the queue that lie within half the path tolerance of one chord
    /// from `start` are cut as that chord (decision D34: "collinear short segments merged"), so a
    /// curve given as short chords with rounded coordinates is not a string of kinks. The
    /// first line (ending at `first_end`) is always taken. `None`: the queue ran out while more
    /// lines might still merge and the planner has enough ahead to wait for them.
    fn merge_lines(&mut self, start: &Point, first_end: Point) -> Option<Merged> {
        let tolerance = self.cfg.tolerance * MERGE_SHARE;
        let first = self.queue.front()?;
        let (feed, line) = match &first.kind {
            Command::Linear { feed, .. } => (*feed, first.line),
            _ => return None,
        };
        let mut merged = Merged {
            end: first_end,
            seq: first.seq,
            blocks: 1,
            deviation: 0.0,
        };
        self.merge_points.clear();
        loop {
            if merged.blocks >= MAX_MERGE {
                return Some(merged);
            }
            let Some(b) = self.queue.get(merged.blocks) else {
                // More lines may come: wait for them while the window has plenty to cut (a
                // program's last line is followed by its end, which closes the merge).
                return (self.planner.blocks() < MERGE_WAIT_BLOCKS).then_some(merged);
            };
            let same = matches!(&b.kind, Command::Linear { feed: f, .. } if *f == feed)
                && !(self.panel.single_block && b.line != line);
            if !same || self.check_block(&b.kind).is_err() {
                return Some(merged);
            }
            let Some(end) = b.kind.end().filter(|e| self.check_limits(e).is_ok()) else {
                return Some(merged);
            };
            let candidate = self.to_slide(end);
            self.merge_points.push(merged.end);
            match path::chord_deviation(start, &candidate, &self.merge_points) {
                Some(d) if d <= tolerance => {
                    merged.end = candidate;
                    merged.seq = b.seq;
                    merged.blocks += 1;
                    merged.deviation = d;
                }
                _ => return Some(merged),
            }
        }
    }

    /// Thread blocks that follow the one being cut join its chain (continuous threading,
    /// `000` §5.23.1); once the chain is complete enough, it is synchronised to the spindle.
    fn extend_thread(&mut self) -> Result<(), (u32, String, u32)> {
        let Some((first, Active::Thread { shift })) = &self.active else {
            return Ok(());
        };
        let (shift, line) = (*shift, first.line);
        while self.thread.accepts() {
            let Some(next) = self.queue.front() else {
                break;
            };
            if !matches!(next.kind, Command::Thread { .. }) {
                break;
            }
            let start = self.thread_end();
            let piece = self
                .thread_piece(next, &start)
                .map_err(|(n, t)| (n, t, next.line))?;
            self.thread.push(piece);
            self.queue.pop_front();
        }
        // Under feed hold the thread does not start; once started, it is cut to its end.
        if self.thread.synchronised() || self.feed_hold {
            return Ok(());
        }
        // `000` §5.23: the thread starts only with the spindle turning (alarm 36).
        let omega = self.encoder.omega();
        if omega * 60.0 < 1.0 {
            return Err((
                alarm::SPINDLE_NOT_TURNING,
                "thread cutting with the spindle stopped".into(),
                line,
            ));
        }
        if let Some((axis, v)) = self.thread.too_fast(omega) {
            return Err((
                alarm::THREAD_RUN_IN,
                format!(
                    "thread feed {:.0} mm/min on {} at {:.0} rpm exceeds the axis's rapid rate",
                    v * 60.0,
                    self.cfg.axes.get(axis).map_or("?", |a| a.name.as_str()),
                    self.encoder.rpm.abs()
                ),
                line,
            ));
        }
        let ramp = self.thread.ramp_for(omega);
        if self.thread.total() < ramp {
            return Err((
                alarm::THREAD_RUN_IN,
                format!(
                    "thread of {:.2} revolutions too short: run-in and run-out need {ramp:.2} at {:.0} rpm",
                    self.thread.total(),
                    self.encoder.rpm.abs()
                ),
                line,
            ));
        }
        let lead_time = self.thread_lead_time.iter().copied().fold(0.0, f64::max);
        let e = self.encoder;
        self.thread
            .synchronise(e.revs, e.angle, shift, omega, ramp, lead_time);
        Ok(())
    }

    /// Where the last piece of the thread chain ends (slide coordinates).
    fn thread_end(&self) -> Point {
        self.thread
            .last_end()
            .unwrap_or_else(|| self.commanded_point())
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
        let here = self.commanded_point();
        self.planner.reset(here);
        self.clear_strobe();
        self.events.push(MotionEvent::Alarm { number, text, line });
    }

    fn clear_strobe(&mut self) {
        for b in [f::MF, f::SF, f::TF, f::DM00, f::DM01, f::DM02, f::DM30] {
            self.f.set(b, false);
        }
    }

    /// The NC's state signals (`000` App.2, inventory §9.4).
    fn update_f(&mut self) {
        let running = self.active.is_some() || !self.queue.is_empty();
        let distributing = matches!(
            self.active,
            Some((
                _,
                Active::Path | Active::Thread { .. } | Active::Rapid { .. }
            ))
        );
        let hold = self.state() == RunState::Hold;
        let fi = &mut self.f;
        fi.set(f::OP, running);
        fi.set(f::STL, running && !hold);
        fi.set(f::SPL, hold);
        fi.set(f::SA, !self.servo_off);
        fi.set(f::MA, !self.alarm && !self.servo_off);
        fi.set(f::AL, self.alarm);
        fi.set(f::DEN, !distributing);
        fi.set(
            f::CUT,
            matches!(self.active, Some((_, Active::Path | Active::Thread { .. }))),
        );
        fi.set(
            f::THRD,
            matches!(self.active, Some((_, Active::Thread { .. }))),
        );
        fi.set(f::MCYC, true);
        fi.set(f::MSBK, self.panel.single_block);
        fi.set(f::DRUR, self.panel.dry_run);
        fi.set(f::MMLK, self.locked);
        fi.set(f::MAFL, self.panel.aux_lock);
        fi.set(f::MBDT, self.block_skip);
        fi.set(f::RST, self.reset_ticks > 0);
        self.reset_ticks = self.reset_ticks.saturating_sub(1);
    }

    /// The commanded slide position as a planner point.
    fn commanded_point(&self) -> Point {
        path::point_from(&self.commanded)
    }

    /// Slide positions of a display-unit point.
    fn to_slide(&self, p: &[f64]) -> Point {
        let mut out = [0.0; MAX_AXES];
        for (i, a) in self.cfg.axes.iter().take(MAX_AXES).enumerate() {
            out[i] = p.get(i).copied().unwrap_or(0.0) * a.scale();
        }
        out
    }

    /// Display units of a slide point.
    fn to_display(&self, p: &Point) -> Vec<f64> {
        self.cfg
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| p[i] / a.scale())
            .collect()
    }

    /// Checks a display-unit point against the soft limits.
    fn check_limits(&self, p: &[f64]) -> Result<(), (u32, String)> {
        for (i, a) in self.cfg.axes.iter().enumerate() {
            let v = p.get(i).copied().unwrap_or(0.0);
            if v < a.min - 1e-9 || v > a.max + 1e-9 {
                return Err((
                    alarm::SOFT_LIMIT,
                    format!(
                        "soft limit: {} {:.4} outside {:.3}..{:.3}",
                        a.name, v, a.min, a.max
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Turns a block into its active form; soft limits are checked here, before any motion.
    fn activate(&mut self, block: &Block) -> Result<Active, (u32, String)> {
        let n = self.cfg.axes.len();
        let start = self.commanded_point();
        match &block.kind {
            Command::Rapid { end } => {
                self.check_block(&block.kind)?;
                self.check_limits(end)?;
                let end = self.to_slide(end);
                let mut axes = [RapidAxis {
                    length: 0.0,
                    travelled: 0.0,
                    mover: Mover::default(),
                }; MAX_AXES];
                for (i, ax) in axes.iter_mut().enumerate().take(n) {
                    ax.length = (end[i] - start[i]).abs();
                }
                Ok(Active::Rapid { start, end, axes })
            }
            Command::Linear { .. } | Command::Arc { .. } => {
                let (seg, feed) = self.segment_for(block, &start)?;
                self.planner.reset(start);
                self.planner
                    .push(seg, feed, block.seq, block.line, !self.exact_stop, 0.0);
                Ok(Active::Path)
            }
            Command::Thread { start_angle, .. } => {
                let piece = self.thread_piece(block, &start)?;
                self.thread.clear();
                self.thread.push(piece);
                Ok(Active::Thread {
                    shift: *start_angle,
                })
            }
            Command::Dwell { seconds } => Ok(Active::Dwell {
                remaining: *seconds,
            }),
            // Feed and path mode were taken over when the block was popped.
            Command::FeedMode { .. } | Command::PathMode { .. } => {
                Ok(Active::Dwell { remaining: 0.0 })
            }
            Command::Aux(code) => Ok(Active::Aux {
                code: *code,
                raised: false,
            }),
            Command::ProgramEnd => Ok(Active::End),
        }
    }

    /// A block's end point and arc centre must name every axis with a finite value.
    fn check_block(&self, kind: &Command) -> Result<(), (u32, String)> {
        let n = self.cfg.axes.len();
        let bad_len = |v: &[f64]| v.len() != n || v.iter().any(|x| !x.is_finite());
        if let Some(end) = kind.end() {
            if bad_len(end) {
                return Err((
                    alarm::BAD_BLOCK,
                    format!("block has {} axis values, machine has {n}", end.len()),
                ));
            }
        }
        if let Command::Arc { center, .. } = kind {
            if bad_len(center) {
                return Err((
                    alarm::BAD_BLOCK,
                    "arc centre has the wrong number of axes".into(),
                ));
            }
        }
        Ok(())
    }

    /// The path segment of a line, arc or thread starting at `start` (slide units), and its
    /// feed in mm/s. Soft limits are checked here, before the block joins the plan.
    fn segment_for(&self, block: &Block, start: &Point) -> Result<(Segment, f64), (u32, String)> {
        self.check_block(&block.kind)?;
        match &block.kind {
            Command::Linear { end, feed } => {
                let feed = self.feed_mm_per_min(*feed)?;
                self.check_limits(end)?;
                let end = self.to_slide(end);
                Ok((Segment::Line { start: *start, end }, feed / 60.0))
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                plane,
            } => {
                let feed = self.feed_mm_per_min(*feed)?;
                self.check_limits(end)?;
                let (h, v) = match plane {
                    None => self.cfg.arc_plane,
                    Some([h, v]) => (usize::from(*h), usize::from(*v)),
                };
                if h >= self.cfg.axes.len() || v >= self.cfg.axes.len() {
                    return Err((
                        alarm::BAD_BLOCK,
                        format!(
                            "arc plane axes {h}, {v}: the machine has {} axes",
                            self.cfg.axes.len()
                        ),
                    ));
                }
                let end = self.to_slide(end);
                let c = self.to_slide(center);
                let seg = path::arc(start, &end, &c, (h, v), *clockwise)
                    .ok_or((alarm::BAD_BLOCK, "arc of zero radius".to_string()))?;
                let Segment::Arc {
                    radius, a0, sweep, ..
                } = seg
                else {
                    return Err((alarm::BAD_BLOCK, "not an arc".into()));
                };
                // Soft limits at the arc's extreme points (every quadrant crossing).
                let quarter = TAU / 4.0;
                let first = (a0 / quarter).floor() as i64;
                let mut k = first;
                loop {
                    let ang = if sweep > 0.0 {
                        (k + 1) as f64 * quarter
                    } else {
                        k as f64 * quarter
                    };
                    let passed = if sweep > 0.0 {
                        ang - a0 < sweep
                    } else {
                        ang - a0 > sweep && ang < a0
                    };
                    if !passed || (k - first).abs() > 5 {
                        break;
                    }
                    let mut p = self.to_display(start);
                    p[h] = (c[h] + radius * ang.cos()) / self.cfg.axes[h].scale();
                    p[v] = (c[v] + radius * ang.sin()) / self.cfg.axes[v].scale();
                    self.check_limits(&p)?;
                    k += if sweep > 0.0 { 1 } else { -1 };
                }
                Ok((seg, feed / 60.0))
            }
            _ => Err((alarm::BAD_BLOCK, "not a path block".into())),
        }
    }

    /// A thread block as a piece of a thread chain starting at `start` (slide units): the
    /// long axis (X as radius, `000` §5.23.1) advances one lead per spindle revolution.
    fn thread_piece(&self, block: &Block, start: &Point) -> Result<Piece, (u32, String)> {
        self.check_block(&block.kind)?;
        let Command::Thread { end, lead, .. } = &block.kind else {
            return Err((alarm::BAD_BLOCK, "not a thread block".into()));
        };
        self.check_limits(end)?;
        let n = self.cfg.axes.len().min(MAX_AXES);
        let end = self.to_slide(end);
        let long = (0..n)
            .map(|i| (end[i] - start[i]).abs())
            .fold(0.0, f64::max);
        // Blocks come from anyone on the DDS domain: a lead so small that the thread would
        // take longer than any spindle could turn is refused, not waited for.
        let revs = long / lead;
        if !(revs.is_finite() && revs <= MAX_THREAD_REVS) {
            return Err((
                alarm::BAD_BLOCK,
                format!("thread of lead {lead} mm over {long:.4} mm: {revs:e} revolutions"),
            ));
        }
        Ok(Piece {
            start: *start,
            end,
            revs,
            seq: block.seq,
            line: block.line,
        })
    }

    fn spindle_rpm_for(&self, what: &str) -> Result<f64, (u32, String)> {
        if self.spindle_rpm > 0.0 {
            Ok(self.spindle_rpm)
        } else {
            Err((
                alarm::SPINDLE_NOT_TURNING,
                format!("{what} with no spindle speed commanded"),
            ))
        }
    }

    /// A programmed feed in mm/min, from mm/rev under G99; the dry-run feed under dry run.
    fn feed_mm_per_min(&self, feed: f64) -> Result<f64, (u32, String)> {
        if self.panel.dry_run {
            Ok(self.cfg.dry_run_feed)
        } else if self.feed_per_rev {
            Ok(feed * self.spindle_rpm_for("feed per revolution")?)
        } else {
            Ok(feed)
        }
    }

    fn in_position(&self) -> bool {
        // Under machine lock the slides stand at the held setpoint, not at the program's.
        let target = if self.locked {
            &self.drive
        } else {
            &self.commanded
        };
        self.cfg
            .axes
            .iter()
            .enumerate()
            .all(|(i, a)| (self.actual[i] - target[i]).abs() <= a.in_position)
    }

    /// Advances the active block by one tick; true when it is finished.
    fn advance(&mut self, dt: f64, plc: &GImage) -> bool {
        let hold = self.feed_hold;
        let in_pos = self.in_position();
        let n = self.commanded.len().min(MAX_AXES);
        let shape = self.cfg.shape;
        let Some((_, active)) = self.active.as_mut() else {
            return false;
        };
        match active {
            Active::Thread { .. } => {
                // Feed hold and override do not apply: the thread is cut to its end
                // (`000` §5.23.1).
                let mut out = path::point_from(&self.commanded);
                self.finished.clear();
                let e = self.encoder;
                let end = self.thread.step(
                    e.revs,
                    e.omega(),
                    &self.thread_lead_time[..n],
                    &mut out,
                    &mut self.finished,
                );
                self.commanded[..n].copy_from_slice(&out[..n]);
                for &seq in &self.finished {
                    self.done_seq = self.done_seq.max(seq);
                }
                if let Some(line) = self.thread.line() {
                    self.line = line;
                }
                end
            }
            Active::Path => {
                let mut out = [0.0; MAX_AXES];
                self.finished.clear();
                let end =
                    self.planner
                        .step(hold, self.panel.feed_override, &mut self.finished, &mut out);
                self.commanded[..n].copy_from_slice(&out[..n]);
                for &seq in &self.finished {
                    self.done_seq = self.done_seq.max(seq);
                }
                if let Some(line) = self.planner.line() {
                    self.line = line;
                }
                end
            }
            Active::Rapid { start, end, axes } => {
                let lim = self.planner.config().limits;
                let mut all = true;
                for (i, ax) in axes.iter_mut().enumerate().take(n) {
                    if ax.travelled < ax.length {
                        let limits = Limits {
                            velocity: lim.velocity[i] * self.panel.rapid_override,
                            acceleration: lim.acceleration[i],
                            jerk: lim.jerk[i],
                        };
                        let ahead = [Ahead {
                            distance: ax.length - ax.travelled,
                            velocity: 0.0,
                            acceleration: lim.acceleration[i],
                        }];
                        ax.travelled += ax.mover.step(dt, shape, limits, hold, &ahead);
                        let rest = ax.mover.velocity < 1e-3 && ax.mover.acceleration <= 0.0;
                        if ax.travelled >= ax.length - 1e-9
                            || (rest && ax.length - ax.travelled < 1e-4)
                        {
                            ax.travelled = ax.length;
                            ax.mover = Mover::default();
                        }
                    }
                    let dir = (end[i] - start[i]).signum();
                    self.commanded[i] = if ax.travelled >= ax.length {
                        end[i]
                    } else {
                        start[i] + dir * ax.travelled
                    };
                    all &= ax.travelled >= ax.length;
                }
                all
            }
            Active::Dwell { remaining } => {
                if !hold {
                    *remaining -= dt;
                }
                *remaining <= 0.0
            }
            // The M/S/T handshake (`000` §4.2.1): code and strobe up, wait for FIN, strobe
            // down; the next strobe waits until the PLC has dropped FIN again.
            Active::Aux { code, raised } => {
                if *raised {
                    if !plc.get(g::FIN) {
                        return false;
                    }
                    self.clear_strobe();
                    return true;
                }
                if !in_pos || hold || plc.get(g::FIN) {
                    return false;
                }
                // Auxiliary function lock: done without the PLC; the program stops stay. The
                // NC still knows the programmed speed (feed per revolution is computed from it).
                let program_stop = matches!(*code, Aux::M(0 | 1 | 2 | 30));
                if self.panel.aux_lock && !program_stop {
                    if let Aux::S(s) = *code {
                        self.spindle_rpm = s;
                    }
                    return true;
                }
                *raised = true;
                let fi = &mut self.f;
                match *code {
                    Aux::M(m) => {
                        fi.write_i32(f::M_CODE, m);
                        fi.set(f::DM00, m == 0);
                        fi.set(f::DM01, m == 1);
                        fi.set(f::DM02, m == 2);
                        fi.set(f::DM30, m == 30);
                        fi.set(f::MF, true);
                    }
                    Aux::S(s) => {
                        self.spindle_rpm = s;
                        fi.write_i32(f::S_CODE, s.round().clamp(0.0, i32::MAX as f64) as i32);
                        fi.set(f::SF, true);
                    }
                    Aux::T(t) => {
                        fi.write_i32(f::T_CODE, t);
                        fi.set(f::TF, true);
                    }
                }
                false
            }
            Active::End => in_pos,
        }
    }
}
