//! The drives' setpoint queue (issue 48): what a drive in cyclic synchronous position mode
//! plays at each tick of its own clock.
//!
//! Motion sends setpoints ahead, each stamped with its index on the queued path, and with every
//! batch a brake tail: the path from the batch's last setpoint to a stop. The drives advance
//! along the queued path one setpoint a tick, or slower while feed hold or an override
//! time-scales it ([`crate::time_scale`], D135), interpolating between setpoints. A setpoint
//! missing where the drives arrive is an underrun: the brake tail starts (the machine stops on
//! the programmed path) and the episode closes, so setpoints planned before it are refused and
//! nothing planned for a machine that kept moving plays after the stop. Motion learns of it
//! from the feedback, takes the state it planned the tail with, and sends the next episode from
//! where the tail ends (D133). Pure: the io node calls [`SetpointQueue::play`] once per tick of
//! its clock.

use std::collections::VecDeque;

use cnc_msgs::servo::{BrakeTail, ServoFeedback, ServoSetpoint, MAX_AXES, TAIL_TICKS};

use crate::gearing::{SpindleReading, TapGear, ThreadCam};
use crate::single_block::BlockStop;
use crate::time_scale::{next_rate, within, Scaling};

/// What the drives do in one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Played {
    pub setpoint: ServoSetpoint,
    /// The drives reached no queued setpoint: the brake tail (or a hold where it ended) played.
    pub underrun: bool,
    /// Where on the queued path the drives are: the index of the setpoints, fractional while
    /// the path is time-scaled.
    pub index: f64,
    /// The rate they advance along it (1: a setpoint a tick), and the rate they head for
    /// (feed hold 0, an override's share).
    pub scale: f64,
    pub target: f64,
}

#[derive(Debug, Clone)]
pub struct SetpointQueue {
    /// Queued setpoints in index order, from the one before the drives' position on.
    queue: VecDeque<ServoSetpoint>,
    /// Setpoints whose batch's brake tail has not come yet: they join the queue with it, so
    /// the queue always ends where a tail starts (motion stopped between a batch and its tail
    /// leaves the batch out, not the tail).
    pending: VecDeque<ServoSetpoint>,
    /// The latest batch's brake tail, and the one being played since the queue ran dry.
    tail: Option<Box<BrakeTail>>,
    braking: Option<Box<BrakeTail>>,
    episode: u32,
    /// What the last tick played, held while nothing else is there, with the kind of the last
    /// setpoint reached (a brake tail is scaled and geared as the setpoints it continues).
    last: ServoSetpoint,
    /// A setpoint has played: from now on a missing one is an underrun.
    armed: bool,
    /// The index the queue ran dry at, while the tail (or the hold after it) plays.
    dry_since: Option<u64>,
    /// The index the current episode last ran dry at (0: never).
    dry_tick: u64,
    /// The setpoint before the one the queue ran dry at: the tail continues it.
    before_dry: [f64; MAX_AXES],
    /// Ticks played without a setpoint of their own, since start.
    pub underrun_ticks: u64,
    /// Dry ticks at which no brake tail continued the queue: the drives held the last
    /// setpoint, a step in velocity (motion was stopped between a batch and its tail).
    pub tailless_stops: u64,
    /// The setpoint played before `last`, for the axes' velocity.
    before_last: [f64; MAX_AXES],
    /// The emergency-stop input is pressed: no setpoint is taken.
    emergency_stop: bool,
    /// The drives' own stop after an emergency stop: per axis its velocity (per tick) and
    /// how much it may lose a tick.
    quick_stop: Option<QuickStop>,
    /// Why the last episode ended (`ServoFeedback::ENDED_*`).
    ended: u32,
    /// Where the drives are on the queued path, and the rate they advance at.
    index: f64,
    scale: f64,
    target: f64,
    /// Each axis's acceleration × period², mm a tick²: how fast the rate may change.
    limit: [f64; MAX_AXES],
    /// A reset: the drives stop on the path, then the episode ends; the resets motion has
    /// taken, and those the drives have stopped for.
    resetting: bool,
    resets: u32,
    resets_done: u32,
    /// The key of the jog being played was released: the drives stop, then the episode ends.
    jog_released: bool,
    /// The spindle's encoder as the drives read it, the tap they gear to it and the thread
    /// they play by it ([`crate::gearing`]).
    spindle: SpindleReading,
    gear: Option<TapGear>,
    cam: ThreadCam,
    /// Where the thread's cam put the axes this tick.
    cam_position: Option<[f64; MAX_AXES]>,
    /// Single block at the drives: the block end they stop at ([`crate::single_block`]).
    block_stop: BlockStop,
    /// Per axis, how far ahead of the encoder reading a geared or cammed setpoint is computed,
    /// s (the period and the drive's lag, as motion's lock-step tap and thread).
    gear_lead: [f64; MAX_AXES],
}

#[derive(Debug, Clone, Copy)]
struct QuickStop {
    velocity: [f64; MAX_AXES],
    step: [f64; MAX_AXES],
}

impl Default for SetpointQueue {
    fn default() -> Self {
        SetpointQueue::new()
    }
}

impl SetpointQueue {
    pub fn new() -> SetpointQueue {
        SetpointQueue {
            queue: VecDeque::with_capacity(1024),
            pending: VecDeque::with_capacity(1024),
            tail: None,
            braking: None,
            episode: 0,
            last: ServoSetpoint::default(),
            armed: false,
            dry_since: None,
            dry_tick: 0,
            before_dry: [0.0; MAX_AXES],
            underrun_ticks: 0,
            tailless_stops: 0,
            before_last: [0.0; MAX_AXES],
            emergency_stop: false,
            quick_stop: None,
            ended: ServoFeedback::ENDED_DRY,
            index: 0.0,
            scale: 1.0,
            target: 1.0,
            limit: [0.0; MAX_AXES],
            resetting: false,
            resets: 0,
            resets_done: 0,
            jog_released: false,
            spindle: SpindleReading::default(),
            gear: None,
            cam: ThreadCam::default(),
            cam_position: None,
            block_stop: BlockStop::default(),
            gear_lead: [0.0; MAX_AXES],
        }
    }

    /// Each axis's rated acceleration (mm/s²) and the period (s): the rate of the queued path
    /// changes within them.
    pub fn set_limits(&mut self, acceleration: &[f64], period: f64) {
        for (l, a) in self.limit.iter_mut().zip(acceleration) {
            *l = a.abs() * period * period;
        }
    }

    /// Per axis, how far ahead of the encoder a geared setpoint is computed (s).
    pub fn set_gear_lead(&mut self, lead: &[f64]) {
        for (l, v) in self.gear_lead.iter_mut().zip(lead) {
            *l = *v;
        }
    }

    /// The spindle encoder's reading after a tick: speed (rpm, signed) and angle (degrees).
    pub fn read_spindle(&mut self, rpm: f64, angle_deg: f64) {
        self.spindle.read(rpm, angle_deg);
    }

    /// The emergency-stop input reached the drives. Pressed: the episode ends and each axis
    /// ramps from its velocity to a stop, losing at most `decel[i]` (mm/s²) × period² of
    /// step a tick (the drives' quick stop; the path is not kept, each axis stops on its
    /// own); no setpoint is taken while it is pressed. Released: the drives take the next
    /// episode's setpoints.
    pub fn emergency_stop(&mut self, pressed: bool, decel: &[f64], period: f64) {
        if pressed && !self.emergency_stop {
            let mut qs = QuickStop {
                velocity: [0.0; MAX_AXES],
                step: [0.0; MAX_AXES],
            };
            if self.armed {
                for (i, d) in decel.iter().enumerate().take(MAX_AXES) {
                    qs.velocity[i] = self.last.position[i] - self.before_last[i];
                    qs.step[i] = d.abs() * period * period;
                }
            }
            self.quick_stop = Some(qs);
            self.end_episode(ServoFeedback::ENDED_EMERGENCY_STOP);
        }
        self.emergency_stop = pressed;
    }

    /// Motion has taken `count` resets: for one not yet done the drives stop on the queued path
    /// as for feed hold, whatever the setpoints, then drop the rest of it and end the episode
    /// (`ENDED_RESET`); motion goes on from where they stand.
    pub fn reset(&mut self, count: u32) {
        if count != self.resets_done {
            self.resetting = true;
            self.resets = count;
        }
    }

    /// The resets the drives have stopped for.
    pub fn resets_done(&self) -> u32 {
        self.resets_done
    }

    fn end_episode(&mut self, why: u32) {
        if why == ServoFeedback::ENDED_RESET {
            self.resets_done = self.resets;
        }
        self.episode = self.episode.wrapping_add(1);
        self.ended = why;
        self.queue.clear();
        self.pending.clear();
        self.tail = None;
        self.braking = None;
        self.dry_since = None;
        self.armed = false;
        self.resetting = false;
        self.jog_released = false;
        self.block_stop.clear();
    }

    /// The drives stand after an emergency stop's ramp (their power may go).
    pub fn stopped_by_emergency_stop(&self) -> bool {
        self.quick_stop
            .is_some_and(|q| q.velocity.iter().all(|v| *v == 0.0))
    }

    /// Why the last episode ended (`ServoFeedback::ENDED_*`).
    pub fn episode_ended(&self) -> u32 {
        self.ended
    }

    /// Takes a setpoint from motion (it plays once its batch's tail has come, see
    /// [`SetpointQueue::set_tail`]); false (refused) when it belongs to an episode that has
    /// ended, or is not later than what is queued or where the drives are.
    pub fn push(&mut self, sp: ServoSetpoint) -> bool {
        let now = self.position();
        let last = self.pending.back().or(self.queue.back());
        let after = last.map_or(now, |b| b.tick.max(now));
        if self.emergency_stop || sp.episode != self.episode || sp.tick <= after {
            return false;
        }
        self.pending.push_back(sp);
        true
    }

    /// The brake tail of the latest batch (of this episode; another is ignored): the batch's
    /// setpoints before the tail's first tick join the queue.
    pub fn set_tail(&mut self, tail: &BrakeTail) {
        if tail.episode != self.episode {
            return;
        }
        while let Some(sp) = self.pending.front().filter(|s| s.tick < tail.first_tick) {
            self.queue.push_back(*sp);
            self.pending.pop_front();
        }
        match &mut self.tail {
            Some(t) => **t = *tail,
            None => self.tail = Some(Box::new(*tail)),
        }
    }

    /// The index of the setpoint the drives are at (or past, while time-scaled).
    pub fn position(&self) -> u64 {
        self.index.floor() as u64
    }

    /// What the drives play at the next tick of their clock (called once per tick).
    pub fn play(&mut self, scaling: &Scaling) -> Played {
        let scaling = Scaling {
            reset: scaling.reset || self.resetting,
            ..*scaling
        };
        if !self.armed {
            return self.play_unarmed(&scaling);
        }
        self.block_stop.update(
            scaling.single_block && !scaling.reset,
            scaling.starts,
            (self.index, self.scale),
            &self.queue,
            &self.limit,
        );
        self.advance(&scaling);
        if (scaling.reset || self.jog_released) && self.scale == 0.0 {
            self.end_episode(match scaling.reset {
                true => ServoFeedback::ENDED_RESET,
                false => ServoFeedback::ENDED_JOG_RELEASE,
            });
            return self.played(self.last.position, false);
        }
        let k = self.position();
        while self.queue.get(1).is_some_and(|s| s.tick < k) {
            self.queue.pop_front();
        }
        let position = match self.cam_position.take().or_else(|| self.at(self.index)) {
            Some(p) => p,
            None => {
                let missing = if self.point(k).is_none() { k } else { k + 1 };
                self.run_dry(missing);
                self.at(self.index).unwrap_or(self.before_dry)
            }
        };
        if self.dry_since.is_some() && self.queue.front().is_some_and(|f| f.tick <= k) {
            self.dry_since = None;
            self.braking = None;
        }
        if let Some(sp) = self.sample(k).copied() {
            let keep = self.last.position;
            self.last = sp;
            self.last.position = keep;
        }
        let position = self.geared(position);
        let underrun = self.dry_since.is_some();
        if underrun {
            self.underrun_ticks += 1;
        }
        self.played(position, underrun)
    }

    /// Before the first setpoint of an episode: the drives hold (or ramp down after an
    /// emergency stop) and their position on the path runs with their clock.
    fn play_unarmed(&mut self, scaling: &Scaling) -> Played {
        self.index += 1.0;
        self.scale = 1.0;
        self.target = 1.0;
        let k = self.position();
        while self.queue.front().is_some_and(|s| s.tick < k) {
            self.queue.pop_front();
        }
        if scaling.reset {
            self.end_episode(ServoFeedback::ENDED_RESET);
        }
        if let Some(sp) = self.queue.front().filter(|s| s.tick == k).copied() {
            self.armed = true;
            self.quick_stop = None;
            let held = self.last.position;
            self.last = sp;
            self.last.position = held;
            let position = self.geared(sp.position);
            return self.played(position, false);
        }
        if let Some(q) = self.quick_stop.as_mut() {
            let mut p = self.last.position;
            for ((p, v), step) in p.iter_mut().zip(q.velocity.iter_mut()).zip(q.step) {
                *v -= v.signum() * v.abs().min(step);
                *p += *v;
            }
            return self.played(p, false);
        }
        self.played(self.last.position, false)
    }

    /// A tap's position: while the setpoints reached are geared (or a tail continues them),
    /// each axis is set from the spindle's encoder, not from what was queued, so the tap stays
    /// in its thread whatever the queue did.
    fn geared(&mut self, queued: [f64; MAX_AXES]) -> [f64; MAX_AXES] {
        if self.last.scaling != ServoSetpoint::SCALE_GEARED {
            self.gear = None;
            return queued;
        }
        let gear = TapGear::of(&self.last, self.gear, &self.spindle);
        self.gear = Some(gear);
        gear.position(&self.spindle, &self.gear_lead)
    }

    /// Moves the drives' position along the queued path by this tick's rate; under single
    /// block not past the block end they stop at.
    fn advance(&mut self, scaling: &Scaling) {
        if self.block_stop.standing() && !scaling.reset {
            (self.scale, self.target) = (0.0, 0.0);
            return;
        }
        let unscaled = self.step_index(scaling);
        if let Some(end) = self.block_stop.end() {
            if unscaled && self.index > end {
                // A move by whole setpoints (spindle-locked, manual) stops on the end: the
                // path stands there (`single_block.rs` chose only such an end for it).
                self.index = end;
                self.cam_position = None;
            }
        }
        self.block_stop
            .arrive(&mut self.index, &mut self.scale, scaling.starts);
    }

    /// Moves the drives' position along the queued path by this tick's rate; true when the
    /// setpoints are not time-scaled (played by the clock one a tick, or by the encoder).
    fn step_index(&mut self, scaling: &Scaling) -> bool {
        let k = self.position();
        if !scaling.reset {
            // A thread goes by the spindle's encoder, not by the clock.
            let queue = &self.queue;
            let sample = |m| sample_in(queue, m);
            if let Some(c) = self.cam.follow(k, sample, &self.spindle, &self.gear_lead) {
                (self.scale, self.target) = (1.0, 1.0);
                self.index = c.index;
                self.cam_position = Some(c.position);
                return true;
            }
        }
        // The next setpoint's kind; past the queue's end (a brake tail) the last one reached.
        let next = self.sample(k + 1).unwrap_or(&self.last);
        let (kind, planned, key) = (next.scaling, next.planned_override, next.jog_key);
        if kind == ServoSetpoint::SCALE_JOG && !scaling.jog_key_held(key) {
            // The jog's key is released: stop on the jog's path now, not a queue later.
            self.jog_released = true;
        }
        let scaling = &Scaling {
            reset: scaling.reset || self.jog_released,
            ..*scaling
        };
        let fixed = matches!(
            kind,
            ServoSetpoint::SCALE_FIXED
                | ServoSetpoint::SCALE_GEARED
                | ServoSetpoint::SCALE_JOG
                | ServoSetpoint::SCALE_THREAD
        );
        if fixed && !scaling.reset {
            // Spindle-locked and manual moves play one a tick, from a whole index: motion
            // starts them from rest, so the snap moves nothing (D135).
            self.scale = 1.0;
            self.target = 1.0;
            self.index = (k + 1) as f64;
            return true;
        }
        let target = scaling.target(kind, planned);
        self.target = target;
        let here = self.last.position;
        let mut step = [0.0; MAX_AXES];
        for (d, (a, b)) in step.iter_mut().zip(here.iter().zip(&self.before_last)) {
            *d = a - b;
        }
        let keep = self.scale;
        match self.at(self.index + keep) {
            Some(keeping) => {
                let fits = |r: f64| {
                    self.at(self.index + r)
                        .is_some_and(|to| within(&self.limit, &here, &step, &keeping, &to))
                };
                let proposed = next_rate(keep, target, fits);
                let most = || next_rate(keep, 0.0, fits);
                self.scale = self.block_stop.rate(self.index, proposed, most);
            }
            // Nothing queued to measure by: the drives come to the end of what was queued.
            None => self.scale = self.scale.min(target),
        }
        self.index += self.scale;
        false
    }

    /// The queued path's position at `index`, interpolated between setpoints.
    fn at(&self, index: f64) -> Option<[f64; MAX_AXES]> {
        let k = index.floor() as u64;
        let frac = index - k as f64;
        let mut p = self.point(k)?;
        if frac > 0.0 {
            let b = self.point(k + 1)?;
            for (p, b) in p.iter_mut().zip(b) {
                *p += (b - *p) * frac;
            }
        }
        Some(p)
    }

    /// The queue ran dry at `missing`: this episode is over; its brake tail continues the
    /// path when it starts there.
    fn run_dry(&mut self, missing: u64) {
        let before = missing.checked_sub(1).and_then(|b| self.point(b));
        self.before_dry = before.unwrap_or(self.last.position);
        let tail = self.tail.take().filter(|t| t.first_tick == missing);
        let (resetting, released) = (self.resetting, self.jog_released);
        self.end_episode(ServoFeedback::ENDED_DRY);
        (self.resetting, self.jog_released) = (resetting, released);
        self.armed = true;
        self.dry_since = Some(missing);
        self.dry_tick = missing;
        if tail.is_none() {
            self.tailless_stops += 1;
        }
        self.braking = tail;
    }

    fn sample(&self, index: u64) -> Option<&ServoSetpoint> {
        sample_in(&self.queue, index)
    }

    /// The queued path's point at `index`: a queued setpoint, or while the queue is dry the
    /// brake tail (held at its end) up to the next episode's first setpoint.
    fn point(&self, index: u64) -> Option<[f64; MAX_AXES]> {
        if let Some(m) = self.dry_since {
            if self.queue.front().is_none_or(|f| index < f.tick) {
                if index + 1 == m {
                    return Some(self.before_dry);
                }
                if index >= m {
                    return Some(match self.braking.as_ref().filter(|t| t.len > 0) {
                        Some(t) => {
                            let len = (t.len as usize).min(TAIL_TICKS);
                            t.position[((index - m) as usize).min(len - 1)]
                        }
                        None => self.before_dry,
                    });
                }
            }
        }
        self.sample(index).map(|s| s.position)
    }

    fn played(&mut self, position: [f64; MAX_AXES], underrun: bool) -> Played {
        self.before_last = self.last.position;
        self.last.position = position;
        self.last.tick = self.position();
        Played {
            setpoint: self.last,
            underrun,
            index: self.index,
            scale: self.scale,
            target: self.target,
        }
    }

    /// Ticks of setpoints queued after the drives' position.
    pub fn depth(&self) -> u32 {
        let at = self.position();
        self.queue
            .back()
            .map_or(0, |b| b.tick.saturating_sub(at) as u32)
    }

    /// The drives stand at a block's end for single block, until a cycle start.
    pub fn standing_at_block_end(&self) -> bool {
        self.block_stop.standing()
    }

    /// A setpoint of this episode has been reached.
    pub fn armed(&self) -> bool {
        self.armed && self.dry_since.is_none()
    }

    /// The episode whose setpoints are taken.
    pub fn episode(&self) -> u32 {
        self.episode
    }

    /// The index the queue last ran dry at (0: never).
    pub fn dry_tick(&self) -> u64 {
        self.dry_tick
    }
}

/// The queued setpoint for `index`.
fn sample_in(queue: &VecDeque<ServoSetpoint>, index: u64) -> Option<&ServoSetpoint> {
    let i = queue.binary_search_by_key(&index, |s| s.tick).ok()?;
    queue.get(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One tick at full rate.
    fn play(q: &mut SetpointQueue) -> Played {
        q.play(&Scaling::default())
    }

    fn sp(tick: u64, x: f64, episode: u32) -> ServoSetpoint {
        let mut s = ServoSetpoint {
            tick,
            episode,
            axis_count: 1,
            enable: 1,
            ..ServoSetpoint::default()
        };
        s.position[0] = x;
        s
    }

    fn tail(first_tick: u64, xs: &[f64]) -> BrakeTail {
        let mut t = BrakeTail {
            first_tick,
            len: xs.len() as u32,
            ..BrakeTail::default()
        };
        for (p, x) in t.position.iter_mut().zip(xs) {
            p[0] = *x;
        }
        t
    }

    /// Motion's batch: setpoints `ticks` of `episode` and the tail after them.
    fn batch(q: &mut SetpointQueue, ticks: std::ops::RangeInclusive<u64>, episode: u32) {
        let end = *ticks.end();
        for t in ticks {
            assert!(q.push(sp(t, t as f64, episode)));
        }
        let mut t = tail(end + 1, &[end as f64]);
        t.episode = episode;
        q.set_tail(&t);
    }

    /// Setpoints play at their ticks once their batch's tail has come; before the first one
    /// the drives hold (no underrun); what is late or of another episode is refused.
    #[test]
    fn setpoints_play_at_their_ticks() {
        let mut q = SetpointQueue::new();
        assert!(!play(&mut q).underrun, "not armed yet");
        for t in 3..=6 {
            assert!(q.push(sp(t, t as f64, 0)));
        }
        assert_eq!(q.depth(), 0, "the batch waits for its tail");
        assert!(!q.push(sp(6, 0.0, 0)), "not later than the queue");
        assert!(!q.push(sp(7, 0.0, 1)), "another episode");
        q.set_tail(&tail(7, &[6.0]));
        assert_eq!(q.depth(), 5, "3–6 after the drives' position, 1");
        assert!(!play(&mut q).underrun, "still not armed");
        for t in 3..=6 {
            let p = play(&mut q);
            assert!(!p.underrun);
            assert_eq!(p.setpoint.position[0], t as f64);
        }
        assert_eq!(q.underrun_ticks, 0);
    }

    /// A dry queue plays the brake tail of the batch it ended with, then holds its last
    /// point; the episode ends, so setpoints planned before are refused and the next
    /// episode's are played.
    #[test]
    fn a_dry_queue_plays_the_brake_tail_and_ends_the_episode() {
        let mut q = SetpointQueue::new();
        for t in 1..=3 {
            q.push(sp(t, t as f64, 0));
        }
        q.set_tail(&tail(4, &[3.8, 4.4, 4.7, 4.8]));
        for _ in 1..=3 {
            play(&mut q);
        }
        let played: Vec<f64> = (4..=9).map(|_| play(&mut q).setpoint.position[0]).collect();
        assert_eq!(played, [3.8, 4.4, 4.7, 4.8, 4.8, 4.8]);
        assert_eq!((q.episode(), q.dry_tick(), q.underrun_ticks), (1, 4, 6));
        assert_eq!(q.tailless_stops, 0);
        assert!(!q.push(sp(12, 9.0, 0)), "planned before the stop");
        batch(&mut q, 11..=11, 1);
        assert!(
            play(&mut q).underrun,
            "held until the new episode's first tick"
        );
        let p = play(&mut q);
        assert!(!p.underrun);
        assert_eq!(p.setpoint.position[0], 11.0);
        assert_eq!(q.underrun_ticks, 7);
    }

    /// Motion stopped between a batch and its tail: the batch is left out and the queue runs
    /// dry where the last tail starts, which plays.
    #[test]
    fn a_batch_without_its_tail_does_not_play() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=3, 0);
        for t in 4..=5 {
            assert!(q.push(sp(t, 9.0, 0)));
        }
        for _ in 1..=3 {
            play(&mut q);
        }
        let p = play(&mut q);
        assert!(p.underrun);
        assert_eq!(p.setpoint.position[0], 3.0, "the tail of the batch 1–3");
        assert_eq!(q.tailless_stops, 0);
    }

    /// A tail that does not start where the queue ran dry is not played: the drives hold.
    #[test]
    fn a_tail_of_another_batch_is_not_played() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=3, 0);
        q.set_tail(&tail(9, &[9.0]));
        for _ in 1..=3 {
            play(&mut q);
        }
        assert_eq!(play(&mut q).setpoint.position[0], 3.0);
        assert_eq!(q.tailless_stops, 1);
    }

    /// Emergency stop: the episode ends, each axis ramps from its velocity to a stop by at
    /// most its step a tick, no setpoint is taken while pressed; after release the next
    /// episode's are.
    #[test]
    fn an_emergency_stop_ramps_each_axis_to_a_stop() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=4, 0);
        for _ in 1..=3 {
            play(&mut q);
        }
        // 1 mm a tick, losing at most 0.3 mm a tick: 1 s period, 0.3 mm/s².
        q.emergency_stop(true, &[0.3], 1.0);
        assert_eq!(q.episode(), 1);
        assert_eq!(q.episode_ended(), ServoFeedback::ENDED_EMERGENCY_STOP);
        assert!(!q.push(sp(9, 9.0, 1)), "nothing is taken while pressed");
        let xs: Vec<f64> = (4..=9).map(|_| play(&mut q).setpoint.position[0]).collect();
        let expected = [3.7, 4.1, 4.2, 4.2, 4.2, 4.2];
        for (x, e) in xs.iter().zip(expected) {
            assert!((x - e).abs() < 1e-9, "{xs:?}");
        }
        assert!(q.stopped_by_emergency_stop());
        assert_eq!(q.underrun_ticks, 0, "a stop, not an underrun");
        q.emergency_stop(false, &[0.3], 1.0);
        batch(&mut q, 12..=12, 1);
        assert!(!play(&mut q).underrun);
        assert!(!play(&mut q).underrun);
        assert_eq!(play(&mut q).setpoint.position[0], 12.0);
    }

    /// A queue of `n` setpoints of `scaling` along X at `step` mm a tick from 0 (from index
    /// 1), with its tail, armed: the drives at index 1. Limits: 1500 mm/s² at 4 ms.
    fn moving(scaling: u32, step: f64, n: u64) -> SetpointQueue {
        let mut q = SetpointQueue::new();
        q.set_limits(&[1500.0], 0.004);
        for t in 1..=n {
            let mut s = sp(t, step * (t - 1) as f64, 0);
            s.scaling = scaling;
            q.push(s);
        }
        q.set_tail(&tail(n + 1, &[step * n as f64]));
        play(&mut q);
        q
    }

    const LIMIT: f64 = 1500.0 * 0.004 * 0.004 * (1.0 + 1e-9);

    /// Plays `ticks` ticks under `sc`; asserts no step changes by more than one tick's
    /// acceleration, the path goes only forward, and returns the positions.
    fn run(q: &mut SetpointQueue, sc: &Scaling, ticks: usize, from: &mut Vec<f64>) {
        for _ in 0..ticks {
            let p = q.play(sc);
            assert!(!p.underrun);
            let x = p.setpoint.position[0];
            if let [.., a, b] = from[..] {
                let dv = (x - b) - (b - a);
                assert!(dv.abs() <= LIMIT, "a step in velocity: {dv} after {from:?}");
                assert!(x >= b, "backwards");
            }
            from.push(x);
        }
    }

    /// Feed hold at the drives: the first tick after it decelerates, within the axis's
    /// acceleration, to a stand on the queued path; release ramps back to a setpoint a tick,
    /// and the queued setpoints play on (D135).
    #[test]
    fn feed_hold_stops_on_the_queued_path_and_release_goes_on() {
        let mut q = moving(ServoSetpoint::SCALE_FEED, 0.4, 400);
        let mut xs = vec![0.0];
        run(&mut q, &Scaling::default(), 10, &mut xs);
        let step = xs[xs.len() - 1] - xs[xs.len() - 2];
        assert!((step - 0.4).abs() < 1e-9, "a setpoint a tick: {step}");
        let hold = Scaling {
            hold: true,
            ..Scaling::default()
        };
        let before = xs.len();
        run(&mut q, &hold, 60, &mut xs);
        let first = xs[before] - xs[before - 1];
        assert!(
            first < 0.4 - 0.02,
            "the first held tick decelerates: {first}"
        );
        let stood = xs[xs.len() - 1];
        assert_eq!(xs[xs.len() - 20], stood, "standing");
        // 0.4 mm a tick losing at most 0.024 a tick: 16 ticks, 3.136 mm at the least.
        let travel = stood - xs[before - 1];
        assert!(
            (3.136 - 1e-9..3.3).contains(&travel),
            "stopped in {travel} mm"
        );
        assert_eq!(q.play(&hold).scale, 0.0);
        run(&mut q, &Scaling::default(), 60, &mut xs);
        let last = xs[xs.len() - 1] - xs[xs.len() - 2];
        assert!(
            (last - 0.4).abs() < 1e-9,
            "back at a setpoint a tick: {last}"
        );
        assert_eq!(q.underrun_ticks, 0);
    }

    /// A path that speeds up and brakes at the axis's full acceleration: feed hold and its
    /// release at every phase of it keep each tick within that acceleration.
    #[test]
    fn hold_at_any_phase_of_a_braking_path_stays_within_the_acceleration() {
        let a = 1500.0 * 0.004 * 0.004;
        let mut path = vec![0.0];
        let mut v: f64 = 0.0;
        for k in 0..120 {
            v = match k {
                0..=16 => v + a,
                17..=60 => v,
                _ => (v - a).max(0.0),
            };
            path.push(path[path.len() - 1] + v);
        }
        // Then standing, as motion's idle setpoints do.
        path.extend([path[path.len() - 1]; 300]);
        for at in (0..110).step_by(7) {
            let mut q = SetpointQueue::new();
            q.set_limits(&[1500.0], 0.004);
            for (t, x) in path.iter().enumerate() {
                let mut s = sp(t as u64 + 1, *x, 0);
                s.scaling = ServoSetpoint::SCALE_FEED;
                q.push(s);
            }
            q.set_tail(&tail(path.len() as u64 + 1, &[path[path.len() - 1]]));
            let hold = Scaling {
                hold: true,
                ..Scaling::default()
            };
            let mut xs = vec![0.0];
            run(&mut q, &Scaling::default(), at, &mut xs);
            run(&mut q, &hold, 15, &mut xs);
            run(&mut q, &Scaling::default(), 150, &mut xs);
            assert_eq!(xs[xs.len() - 1], path[path.len() - 1], "the path's end");
        }
    }

    /// A geared tap follows the spindle's encoder from where it stood, not the queued
    /// positions, and goes on following it when the queue runs dry.
    #[test]
    fn a_geared_tap_follows_the_spindle_whatever_the_queue() {
        let mut q = SetpointQueue::new();
        q.set_limits(&[1500.0], 0.004);
        for t in 1..=20 {
            let mut s = sp(t, 99.0, 0);
            s.scaling = ServoSetpoint::SCALE_GEARED;
            s.gear_start[0] = 5.0;
            s.gear_end[0] = -25.0;
            s.gear_degrees = 13_500.0;
            q.push(s);
        }
        q.set_tail(&tail(21, &[99.0]));
        q.read_spindle(0.0, 350.0);
        // 600 rpm: 14.4° a tick, from 350° through the index mark.
        let mut angle = 350.0;
        for k in 0..40 {
            let p = play(&mut q);
            let turned = 14.4 * k as f64;
            let want = 5.0 - 30.0 * turned / 13_500.0;
            assert!(
                (p.setpoint.position[0] - want).abs() < 1e-9,
                "tick {k}: {} not {want}",
                p.setpoint.position[0]
            );
            assert_eq!(p.underrun, k >= 20, "the queue runs dry at 20");
            angle = (angle + 14.4f64).rem_euclid(360.0);
            q.read_spindle(600.0, angle);
        }
    }

    /// A key jog plays while its key is held; the key's release stops the drives on the
    /// jog's path within the acceleration, drops the rest of the queue and ends the episode.
    #[test]
    fn a_released_jog_key_stops_the_drives_at_once() {
        let mut q = moving(ServoSetpoint::SCALE_JOG, 0.4, 400);
        for s in q.queue.iter_mut().chain(q.pending.iter_mut()) {
            s.jog_key = -2;
        }
        q.last.jog_key = -2;
        let held = Scaling {
            jog_keys: (0, 0b10),
            ..Scaling::default()
        };
        let mut xs = vec![0.0];
        run(&mut q, &held, 10, &mut xs);
        assert!((xs[10] - xs[9] - 0.4).abs() < 1e-9, "jogging");
        assert_eq!(q.episode(), 0);
        let released = Scaling::default();
        let before = xs.len();
        run(&mut q, &released, 30, &mut xs);
        assert!(xs[before] - xs[before - 1] < 0.4 - 0.02, "slower at once");
        assert_eq!(q.episode(), 1);
        assert_eq!(q.episode_ended(), ServoFeedback::ENDED_JOG_RELEASE);
        assert_eq!(q.depth(), 0, "the rest of the queue is dropped");
        let stood = xs[xs.len() - 1] - xs[before - 1];
        assert!(stood < 3.3, "stopped within its braking distance: {stood}");
    }

    /// Setpoints that must play one a tick (spindle-locked, manual) are not held.
    #[test]
    fn fixed_setpoints_are_not_held() {
        let mut q = moving(ServoSetpoint::SCALE_FIXED, 0.4, 100);
        let hold = Scaling {
            hold: true,
            ..Scaling::default()
        };
        let mut xs = vec![0.0];
        run(&mut q, &hold, 20, &mut xs);
        assert!(xs
            .windows(2)
            .skip(1)
            .all(|w| (w[1] - w[0] - 0.4).abs() < 1e-12));
    }

    /// Overrides scale the queued feed moves and rapids within a tick, ramped.
    #[test]
    fn overrides_scale_feeds_and_rapids() {
        for (kind, sc) in [
            (
                ServoSetpoint::SCALE_FEED,
                Scaling {
                    feed_override: 0.5,
                    ..Scaling::default()
                },
            ),
            (
                ServoSetpoint::SCALE_RAPID,
                Scaling {
                    rapid_override: 0.5,
                    ..Scaling::default()
                },
            ),
        ] {
            let mut q = moving(kind, 0.4, 400);
            let mut xs = vec![0.0];
            run(&mut q, &Scaling::default(), 5, &mut xs);
            run(&mut q, &sc, 60, &mut xs);
            let n = xs.len();
            assert!(xs[n - 59] - xs[n - 60] < 0.4 - 0.02, "slower within a tick");
            assert!(
                (xs[n - 1] - xs[n - 2] - 0.2).abs() < 1e-9,
                "at half the speed"
            );
        }
    }

    /// A reset stops the drives on the path, then the queue is dropped and the episode ends;
    /// the next episode's setpoints are taken from where the drives stand.
    #[test]
    fn a_reset_stops_on_the_path_and_ends_the_episode() {
        let mut q = moving(ServoSetpoint::SCALE_FIXED, 0.4, 400);
        let mut xs = vec![0.0];
        run(&mut q, &Scaling::default(), 10, &mut xs);
        q.reset(1);
        run(&mut q, &Scaling::default(), 30, &mut xs);
        assert_eq!(q.episode(), 1);
        assert_eq!(q.episode_ended(), ServoFeedback::ENDED_RESET);
        assert_eq!(q.resets_done(), 1);
        q.reset(1);
        assert_eq!(q.episode(), 1, "a reset is stopped for once");
        assert_eq!(q.depth(), 0, "the rest of the queue is dropped");
        let stood = xs[xs.len() - 1];
        assert!(
            stood < 10.0 * 0.4 + 4.0,
            "stopped within its braking distance"
        );
        let next = q.position() + 5;
        for k in next..next + 20 {
            assert!(q.push(sp(k, stood, 1)));
        }
        let mut t = tail(next + 20, &[stood]);
        t.episode = 1;
        q.set_tail(&t);
        run(&mut q, &Scaling::default(), 10, &mut xs);
        assert!(q.armed(), "the next episode plays");
    }
}
