//! The motion core: block queue, per-block profiles, soft limits, M/S/T handshake with the PLC.
//!
//! Pure: the shell calls [`Motion::tick`] every servo period with the latest drive feedback and
//! PLC image and sends the returned setpoint to the drives. Positions inside are slide travel
//! (X in radius); blocks and reports use display units (X in diameter).

use std::collections::VecDeque;
use std::f64::consts::TAU;

use cnc_msgs::signals::{FImage, GImage};

use crate::block::{Aux, Block, Command};
use crate::config::MotionConfig;
use crate::profile::Profile;

/// Alarm numbers raised by motion (`000` Appendix 1, inventory §11.2).
pub mod alarm {
    pub const SOFT_LIMIT: u32 = 38;
    /// The block stream from the interpreter is out of step: queue overflow, a block with the
    /// wrong number of axes, or one that could not run (`000` alarm 111, pre-read/execution sync).
    pub const BAD_BLOCK: u32 = 111;
    /// Feed per revolution or threading with the spindle stopped (`000` alarm 36).
    pub const SPINDLE_NOT_TURNING: u32 = 36;
}

/// Something the shell must publish.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionEvent {
    Alarm {
        number: u32,
        text: String,
        line: u32,
    },
}

/// Run state reported to the interpreter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    Idle,
    Running,
    Hold,
    Alarm,
}

#[derive(Debug, Clone)]
enum Active {
    /// Straight line or arc along one path profile.
    Path {
        path: Path,
        profile: Profile,
    },
    /// Each axis on its own profile (dog-leg rapid).
    Rapid {
        start: Vec<f64>,
        end: Vec<f64>,
        profiles: Vec<Profile>,
    },
    Dwell {
        remaining: f64,
    },
    /// Waits for the axes to settle, then sends the strobe and waits for FIN.
    Aux {
        code: Aux,
        strobe: Option<u64>,
    },
    End,
}

#[derive(Debug, Clone)]
enum Path {
    Line {
        start: Vec<f64>,
        end: Vec<f64>,
    },
    Arc {
        start: Vec<f64>,
        end: Vec<f64>,
        center: (f64, f64),
        radius: f64,
        start_angle: f64,
        sweep: f64,
    },
}

pub struct Motion {
    cfg: MotionConfig,
    queue: VecDeque<Block>,
    run_id: u64,
    accepted_seq: u64,
    done_seq: u64,
    line: u32,
    active: Option<(Block, Active)>,
    /// Commanded slide position per axis.
    commanded: Vec<f64>,
    /// Last actual slide position per axis.
    actual: Vec<f64>,
    feed_hold: bool,
    cycle_stop: bool,
    alarm: bool,
    strobe_seq: u64,
    f: FImage,
    events: Vec<MotionEvent>,
    /// Last spindle speed sent to the PLC, rpm: the base of feed per revolution and threads
    /// until motion follows the spindle encoder (issue 4).
    spindle_rpm: f64,
    feed_per_rev: bool,
}

impl Motion {
    /// `start` is the slide position the drives report at start-up.
    pub fn new(cfg: MotionConfig, start: &[f64]) -> Self {
        let n = cfg.axes.len();
        let commanded: Vec<f64> = (0..n)
            .map(|i| start.get(i).copied().unwrap_or(0.0))
            .collect();
        Motion {
            cfg,
            queue: VecDeque::new(),
            run_id: 0,
            accepted_seq: 0,
            done_seq: 0,
            line: 0,
            active: None,
            actual: commanded.clone(),
            commanded,
            feed_hold: false,
            cycle_stop: false,
            alarm: false,
            strobe_seq: 0,
            spindle_rpm: 0.0,
            feed_per_rev: false,
            f: FImage::default(),
            events: Vec::new(),
        }
    }

    /// Takes a block into the queue. Blocks of an older run are dropped; a newer run replaces
    /// whatever is queued.
    pub fn push(&mut self, block: Block) {
        if block.run_id < self.run_id {
            return;
        }
        if block.run_id > self.run_id {
            self.run_id = block.run_id;
            self.queue.clear();
            self.active = None;
            self.accepted_seq = 0;
            self.done_seq = 0;
            self.feed_hold = false;
            self.cycle_stop = false;
            self.clear_strobe();
        }
        if self.alarm || block.seq <= self.accepted_seq {
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

    /// Feed hold: decelerate on the path and wait for [`Motion::cycle_start`].
    pub fn feed_hold(&mut self) {
        self.feed_hold = true;
    }

    pub fn cycle_start(&mut self) {
        self.feed_hold = false;
    }

    /// Cycle stop: decelerate on the path, then drop the rest of the run.
    pub fn cycle_stop(&mut self) {
        self.feed_hold = true;
        self.cycle_stop = true;
    }

    /// Reset: clears the alarm state and the queue; the axes stop where they are.
    pub fn reset(&mut self) {
        self.alarm = false;
        self.queue.clear();
        self.active = None;
        self.feed_hold = false;
        self.cycle_stop = false;
        self.clear_strobe();
        self.commanded.clone_from(&self.actual);
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
    pub fn f_image(&self) -> &FImage {
        &self.f
    }
    pub fn config(&self) -> &MotionConfig {
        &self.cfg
    }

    pub fn state(&self) -> RunState {
        if self.alarm {
            RunState::Alarm
        } else if self.feed_hold && (self.active.is_some() || !self.queue.is_empty()) {
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
            .map(|(_, a)| matches!(a, Active::Path { .. }))
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
    /// Returns the new commanded slide position.
    pub fn tick(&mut self, actual: Option<&[f64]>, plc: &GImage) -> &[f64] {
        if let Some(a) = actual {
            for (dst, src) in self.actual.iter_mut().zip(a) {
                *dst = *src;
            }
        }
        if plc.emergency_stop != 0 {
            // Servo off: hold where the slides are, drop the run. The PLC raises the alarm.
            if !self.alarm {
                self.alarm = true;
                self.queue.clear();
                self.active = None;
                self.clear_strobe();
            }
            self.commanded.clone_from(&self.actual);
            self.update_f();
            return &self.commanded;
        }
        let dt = self.cfg.period;
        let mut budget = 8; // blocks that can finish within one tick (zero-length moves, aux)
        while budget > 0 && !self.alarm {
            budget -= 1;
            if self.active.is_none() {
                // A cycle stop starts nothing new; it ends below once the axes stand.
                if self.cycle_stop {
                    break;
                }
                let Some(block) = self.queue.pop_front() else {
                    break;
                };
                self.line = block.line;
                if let Command::FeedMode { per_rev } = block.kind {
                    self.feed_per_rev = per_rev;
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
            if self.advance(dt, plc) {
                let moved = matches!(
                    self.active,
                    Some((_, Active::Path { .. } | Active::Rapid { .. }))
                );
                if let Some((block, _)) = self.active.take() {
                    self.done_seq = block.seq;
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
            self.queue.clear();
            self.active = None;
            self.cycle_stop = false;
            self.feed_hold = false;
            self.clear_strobe();
        }
        self.update_f();
        &self.commanded
    }

    fn stopped_on_path(&self) -> bool {
        match &self.active {
            None => true,
            Some((_, Active::Path { profile, .. })) => profile.velocity == 0.0,
            Some((_, Active::Rapid { profiles, .. })) => profiles.iter().all(|p| p.velocity == 0.0),
            Some(_) => true,
        }
    }

    fn raise(&mut self, number: u32, text: String, line: u32) {
        self.alarm = true;
        self.active = None;
        self.clear_strobe();
        self.events.push(MotionEvent::Alarm { number, text, line });
    }

    fn clear_strobe(&mut self) {
        self.f.mf = 0;
        self.f.sf = 0;
        self.f.tf = 0;
    }

    fn update_f(&mut self) {
        self.f.op = u32::from(self.active.is_some() || !self.queue.is_empty());
        self.f.alarm = u32::from(self.alarm);
    }

    /// Slide positions of a display-unit point.
    fn to_slide(&self, p: &[f64]) -> Vec<f64> {
        self.cfg
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| p.get(i).copied().unwrap_or(0.0) * a.scale())
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
    fn activate(&self, block: &Block) -> Result<Active, (u32, String)> {
        let n = self.cfg.axes.len();
        let bad_len = |v: &[f64]| v.len() != n || v.iter().any(|x| !x.is_finite());
        match &block.kind {
            kind if kind.end().is_some_and(bad_len) => Err((
                alarm::BAD_BLOCK,
                format!(
                    "block has {} axis values, machine has {n}",
                    kind.end().map_or(0, <[f64]>::len)
                ),
            )),
            Command::Rapid { end } => {
                self.check_limits(end)?;
                let end = self.to_slide(end);
                let start = self.commanded.clone();
                let profiles = (0..n)
                    .map(|i| {
                        let a = &self.cfg.axes[i];
                        Profile::new(
                            (end[i] - start[i]).abs(),
                            a.max_velocity / 60.0,
                            a.max_acceleration,
                        )
                    })
                    .collect();
                Ok(Active::Rapid {
                    start,
                    end,
                    profiles,
                })
            }
            Command::Thread { end, lead, .. } => {
                // Until motion follows the encoder (issue 4) a thread runs as a straight move
                // at lead × commanded speed along the long axis.
                let start = self.commanded_display();
                let long = (0..n)
                    .map(|i| (end[i] - start[i]).abs() * self.cfg.axes[i].scale())
                    .fold(0.0, f64::max);
                let length = (0..n)
                    .map(|i| ((end[i] - start[i]) * self.cfg.axes[i].scale()).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let rpm = self.spindle_rpm_for("thread cutting")?;
                let feed = if long > 0.0 {
                    lead * rpm * length / long
                } else {
                    lead * rpm
                };
                self.activate(&Block {
                    kind: Command::Linear {
                        end: end.clone(),
                        feed,
                    },
                    ..block.clone()
                })
            }
            Command::Linear { end, feed } => {
                let feed = &self.feed_mm_per_min(*feed)?;
                self.check_limits(end)?;
                let end = self.to_slide(end);
                let start = self.commanded.clone();
                let d: Vec<f64> = end.iter().zip(&start).map(|(e, s)| e - s).collect();
                let length = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                let (mut vmax, mut acc) = (feed / 60.0, f64::INFINITY);
                for (i, a) in self.cfg.axes.iter().enumerate() {
                    if length > 0.0 && d[i] != 0.0 {
                        let u = d[i].abs() / length;
                        vmax = vmax.min(a.max_velocity / 60.0 / u);
                        acc = acc.min(a.max_acceleration / u);
                    }
                }
                let acc = if acc.is_finite() { acc } else { 1.0 };
                Ok(Active::Path {
                    path: Path::Line { start, end },
                    profile: Profile::new(length, vmax, acc),
                })
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
            } => {
                let feed = &self.feed_mm_per_min(*feed)?;
                if bad_len(center) {
                    return Err((
                        alarm::BAD_BLOCK,
                        "arc centre has the wrong number of axes".into(),
                    ));
                }
                self.check_limits(end)?;
                let (h, v) = self.cfg.arc_plane;
                let start = self.commanded.clone();
                let end = self.to_slide(end);
                let c = self.to_slide(center);
                let radius = ((start[h] - c[h]).powi(2) + (start[v] - c[v]).powi(2)).sqrt();
                let a0 = (start[v] - c[v]).atan2(start[h] - c[h]);
                let a1 = (end[v] - c[v]).atan2(end[h] - c[h]);
                let mut sweep = a1 - a0;
                if *clockwise {
                    while sweep >= -1e-12 {
                        sweep -= TAU;
                    }
                    if sweep < -TAU + 1e-9
                        && ((end[h] - start[h]).abs() > 1e-9 || (end[v] - start[v]).abs() > 1e-9)
                    {
                        sweep += TAU;
                    }
                } else {
                    while sweep <= 1e-12 {
                        sweep += TAU;
                    }
                    if sweep > TAU - 1e-9
                        && ((end[h] - start[h]).abs() > 1e-9 || (end[v] - start[v]).abs() > 1e-9)
                    {
                        sweep -= TAU;
                    }
                }
                // Soft limits at the arc's extreme points (every quadrant crossing).
                let mut k = (a0 / (TAU / 4.0)).floor() as i64;
                loop {
                    let ang = if sweep > 0.0 {
                        (k + 1) as f64 * TAU / 4.0
                    } else {
                        k as f64 * TAU / 4.0
                    };
                    let passed = if sweep > 0.0 {
                        ang - a0 < sweep
                    } else {
                        ang - a0 > sweep && ang < a0
                    };
                    if !passed || (k - (a0 / (TAU / 4.0)).floor() as i64).abs() > 5 {
                        break;
                    }
                    let mut p = self.commanded_display();
                    p[h] = (c[h] + radius * ang.cos()) / self.cfg.axes[h].scale();
                    p[v] = (c[v] + radius * ang.sin()) / self.cfg.axes[v].scale();
                    self.check_limits(&p)?;
                    k += if sweep > 0.0 { 1 } else { -1 };
                }
                let length = radius * sweep.abs();
                let amin = self
                    .cfg
                    .axes
                    .iter()
                    .map(|a| a.max_acceleration)
                    .fold(f64::INFINITY, f64::min);
                let vmin = self
                    .cfg
                    .axes
                    .iter()
                    .map(|a| a.max_velocity / 60.0)
                    .fold(f64::INFINITY, f64::min);
                // Half the acceleration for the path, the rest for the centripetal part.
                let vmax = (feed / 60.0).min(vmin).min((0.5 * amin * radius).sqrt());
                Ok(Active::Path {
                    path: Path::Arc {
                        start,
                        end,
                        center: (c[h], c[v]),
                        radius,
                        start_angle: a0,
                        sweep,
                    },
                    profile: Profile::new(length, vmax, 0.5 * amin),
                })
            }
            Command::Dwell { seconds } => Ok(Active::Dwell {
                remaining: *seconds,
            }),
            // Feed mode was taken over when the block was popped; this planner stops exactly
            // at every block end, so G64 blending waits for the look-ahead planner (issue 4).
            Command::FeedMode { .. } | Command::PathMode { .. } => {
                Ok(Active::Dwell { remaining: 0.0 })
            }
            Command::Aux(code) => Ok(Active::Aux {
                code: *code,
                strobe: None,
            }),
            Command::ProgramEnd => Ok(Active::End),
        }
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

    /// A programmed feed in mm/min, from mm/rev under G99.
    fn feed_mm_per_min(&self, feed: f64) -> Result<f64, (u32, String)> {
        if self.feed_per_rev {
            Ok(feed * self.spindle_rpm_for("feed per revolution")?)
        } else {
            Ok(feed)
        }
    }

    fn in_position(&self) -> bool {
        self.cfg
            .axes
            .iter()
            .enumerate()
            .all(|(i, a)| (self.actual[i] - self.commanded[i]).abs() <= a.in_position)
    }

    /// Advances the active block by one tick; true when it is finished.
    fn advance(&mut self, dt: f64, plc: &GImage) -> bool {
        let hold = self.feed_hold;
        let in_pos = self.in_position();
        let Some((_, active)) = self.active.as_mut() else {
            return false;
        };
        match active {
            Active::Path { path, profile } => {
                profile.step(dt, hold);
                let s = profile.position;
                let total = profile.length;
                let (h, v) = self.cfg.arc_plane;
                match path {
                    Path::Line { start, end } => {
                        let f = if total > 0.0 { s / total } else { 1.0 };
                        for i in 0..self.commanded.len() {
                            self.commanded[i] = if profile.done() {
                                end[i]
                            } else {
                                start[i] + (end[i] - start[i]) * f
                            };
                        }
                    }
                    Path::Arc {
                        start,
                        end,
                        center,
                        radius,
                        start_angle,
                        sweep,
                    } => {
                        let f = if total > 0.0 { s / total } else { 1.0 };
                        if profile.done() {
                            self.commanded.clone_from(end);
                        } else {
                            let ang = *start_angle + *sweep * f;
                            for i in 0..self.commanded.len() {
                                self.commanded[i] = start[i] + (end[i] - start[i]) * f;
                            }
                            self.commanded[h] = center.0 + *radius * ang.cos();
                            self.commanded[v] = center.1 + *radius * ang.sin();
                        }
                    }
                }
                profile.done()
            }
            Active::Rapid {
                start,
                end,
                profiles,
            } => {
                for (i, p) in profiles.iter_mut().enumerate() {
                    p.step(dt, hold);
                    let dir = (end[i] - start[i]).signum();
                    self.commanded[i] = if p.done() {
                        end[i]
                    } else {
                        start[i] + dir * p.position
                    };
                }
                profiles.iter().all(Profile::done)
            }
            Active::Dwell { remaining } => {
                if !hold {
                    *remaining -= dt;
                }
                *remaining <= 0.0
            }
            Active::Aux { code, strobe } => match strobe {
                None => {
                    if !in_pos || hold {
                        return false;
                    }
                    self.strobe_seq += 1;
                    let seq = self.strobe_seq;
                    *strobe = Some(seq);
                    self.f.strobe_seq = seq;
                    match *code {
                        Aux::M(m) => {
                            self.f.m_code = m;
                            self.f.mf = 1;
                        }
                        Aux::S(s) => {
                            self.spindle_rpm = s;
                            self.f.s_value = s;
                            self.f.sf = 1;
                        }
                        Aux::T(t) => {
                            self.f.t_code = t;
                            self.f.tf = 1;
                        }
                    }
                    false
                }
                Some(seq) => {
                    if plc.fin_seq == *seq {
                        self.f.mf = 0;
                        self.f.sf = 0;
                        self.f.tf = 0;
                        true
                    } else {
                        false
                    }
                }
            },
            Active::End => in_pos,
        }
    }
}
