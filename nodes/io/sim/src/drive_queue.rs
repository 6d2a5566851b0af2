//! The drives' setpoint queue (issue 48): what a drive in cyclic synchronous position mode
//! plays at each tick of its own clock.
//!
//! Motion sends setpoints ahead, each stamped with the drive tick it is for, and with every
//! batch a brake tail: the path from the batch's last setpoint to a stop. The drives play the
//! setpoint of each tick; a tick without one is an underrun. The first underrun of an episode
//! starts the brake tail (the machine stops on the programmed path) and closes the episode:
//! setpoints planned before it are refused, so nothing planned for a machine that kept moving
//! plays after the stop. Motion learns of it from the feedback, takes the state it planned the
//! tail with, and sends the next episode from where the tail ends (D133). Pure: the io node calls
//! [`SetpointQueue::play`] once per tick of its clock.

use std::collections::VecDeque;

use cnc_msgs::servo::{BrakeTail, ServoFeedback, ServoSetpoint, MAX_AXES, TAIL_TICKS};

/// What the drives do in one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Played {
    pub setpoint: ServoSetpoint,
    /// No setpoint was queued for the tick: the brake tail (or a hold where it ended) played.
    pub underrun: bool,
}

#[derive(Debug, Clone)]
pub struct SetpointQueue {
    /// Queued setpoints in tick order; the front is the next to play.
    queue: VecDeque<ServoSetpoint>,
    /// Setpoints whose batch's brake tail has not come yet: they join the queue with it, so
    /// the queue always ends where a tail starts (motion stopped between a batch and its tail
    /// leaves the batch out, not the tail).
    pending: VecDeque<ServoSetpoint>,
    /// The latest batch's brake tail, and the one being played since the queue ran dry.
    tail: Option<Box<BrakeTail>>,
    braking: Option<Box<BrakeTail>>,
    episode: u32,
    /// What the last tick played, held while nothing else is there.
    last: ServoSetpoint,
    /// A setpoint has played: from now on a tick without one is an underrun.
    armed: bool,
    /// The tick the queue ran dry at, while the tail (or the hold after it) plays.
    dry_since: Option<u64>,
    /// The tick the current episode last ran dry at (0: never).
    dry_tick: u64,
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
            underrun_ticks: 0,
            tailless_stops: 0,
            before_last: [0.0; MAX_AXES],
            emergency_stop: false,
            quick_stop: None,
            ended: ServoFeedback::ENDED_DRY,
        }
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
            self.episode = self.episode.wrapping_add(1);
            self.ended = ServoFeedback::ENDED_EMERGENCY_STOP;
            self.queue.clear();
            self.pending.clear();
            self.tail = None;
            self.braking = None;
            self.dry_since = None;
            self.armed = false;
        }
        self.emergency_stop = pressed;
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
    /// ended, or is not later than what is queued or `now` (the tick being played).
    pub fn push(&mut self, sp: ServoSetpoint, now: u64) -> bool {
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

    /// What the drives play at `tick` (called once per tick, in order).
    pub fn play(&mut self, tick: u64) -> Played {
        while self.queue.front().is_some_and(|s| s.tick < tick) {
            self.queue.pop_front();
        }
        if let Some(sp) = self.queue.front().filter(|s| s.tick == tick).copied() {
            self.queue.pop_front();
            self.armed = true;
            self.dry_since = None;
            self.quick_stop = None;
            self.before_last = self.last.position;
            self.last = sp;
            return Played {
                setpoint: sp,
                underrun: false,
            };
        }
        if let Some(q) = self.quick_stop.as_mut() {
            self.before_last = self.last.position;
            for i in 0..MAX_AXES {
                let v = q.velocity[i];
                q.velocity[i] = v - v.signum() * v.abs().min(q.step[i]);
                self.last.position[i] += q.velocity[i];
            }
            self.last.tick = tick;
            return Played {
                setpoint: self.last,
                underrun: false,
            };
        }
        if !self.armed {
            return Played {
                setpoint: self.last,
                underrun: false,
            };
        }
        self.underrun_ticks += 1;
        let since = match self.dry_since {
            Some(t) => t,
            None => {
                // The queue ran dry: this episode is over.
                self.dry_since = Some(tick);
                self.dry_tick = tick;
                self.episode = self.episode.wrapping_add(1);
                self.ended = ServoFeedback::ENDED_DRY;
                self.queue.clear();
                self.pending.clear();
                self.braking = self.tail.take().filter(|t| t.first_tick == tick);
                if self.braking.is_none() {
                    self.tailless_stops += 1;
                }
                tick
            }
        };
        if let Some(t) = self.braking.as_ref().filter(|t| t.len > 0) {
            let len = (t.len as usize).min(TAIL_TICKS);
            let i = ((tick - since) as usize).min(len - 1);
            let n = (self.last.axis_count as usize).min(MAX_AXES);
            self.before_last = self.last.position;
            self.last.position[..n].copy_from_slice(&t.position[i][..n]);
        }
        self.last.tick = tick;
        Played {
            setpoint: self.last,
            underrun: true,
        }
    }

    /// Ticks of setpoints queued after `tick`.
    pub fn depth(&self, tick: u64) -> u32 {
        self.queue
            .back()
            .map_or(0, |b| b.tick.saturating_sub(tick) as u32)
    }

    /// The episode whose setpoints are taken.
    pub fn episode(&self) -> u32 {
        self.episode
    }

    /// The tick the queue last ran dry at (0: never).
    pub fn dry_tick(&self) -> u64 {
        self.dry_tick
    }
}

/// The drive trace's header: tick, queue depth, underrun, emergency stop, per axis its
/// setpoint, actual position and following error, then the spindle encoder's speed (rpm) and
/// angle (degrees): the oscilloscope a commissioning engineer reads.
pub fn trace_header(axes: &[String]) -> String {
    let mut h = String::from("tick,queue_depth,underrun,emergency_stop");
    for a in axes {
        h.push_str(&format!(",{a}_setpoint,{a}_actual,{a}_following_error"));
    }
    h.push_str(",spindle_rpm,spindle_angle");
    h
}

/// One tick of the drive trace. Positions are written exactly (Rust's shortest round-trip
/// form), so two traces compare to the last bit.
pub fn trace_line(
    tick: u64,
    played: &Played,
    actual: &[f64],
    depth: u32,
    emergency_stop: bool,
    spindle: (f64, f64),
) -> String {
    use std::fmt::Write;
    let sp = &played.setpoint;
    let mut line = format!(
        "{tick},{depth},{},{}",
        u8::from(played.underrun),
        u8::from(emergency_stop)
    );
    for (i, a) in actual.iter().enumerate() {
        let c = sp.position[i];
        let _ = write!(line, ",{c:?},{a:?},{:?}", c - a);
    }
    let _ = write!(line, ",{:?},{:?}", spindle.0, spindle.1);
    line
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn batch(q: &mut SetpointQueue, ticks: std::ops::RangeInclusive<u64>, now: u64, episode: u32) {
        let end = *ticks.end();
        for t in ticks {
            assert!(q.push(sp(t, t as f64, episode), now));
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
        assert!(!q.play(1).underrun, "not armed yet");
        for t in 3..=6 {
            assert!(q.push(sp(t, t as f64, 0), 1));
        }
        assert_eq!(q.depth(2), 0, "the batch waits for its tail");
        assert!(!q.push(sp(6, 0.0, 0), 1), "not later than the queue");
        assert!(!q.push(sp(7, 0.0, 1), 1), "another episode");
        q.set_tail(&tail(7, &[6.0]));
        assert_eq!(q.depth(2), 4);
        assert!(!q.play(2).underrun, "still not armed");
        for t in 3..=6 {
            let p = q.play(t);
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
            q.push(sp(t, t as f64, 0), 0);
        }
        q.set_tail(&tail(4, &[3.8, 4.4, 4.7, 4.8]));
        for t in 1..=3 {
            q.play(t);
        }
        let played: Vec<f64> = (4..=9).map(|t| q.play(t).setpoint.position[0]).collect();
        assert_eq!(played, [3.8, 4.4, 4.7, 4.8, 4.8, 4.8]);
        assert_eq!((q.episode(), q.dry_tick(), q.underrun_ticks), (1, 4, 6));
        assert_eq!(q.tailless_stops, 0);
        assert!(!q.push(sp(12, 9.0, 0), 9), "planned before the stop");
        batch(&mut q, 11..=11, 9, 1);
        assert!(
            q.play(10).underrun,
            "held until the new episode's first tick"
        );
        let p = q.play(11);
        assert!(!p.underrun);
        assert_eq!(p.setpoint.position[0], 11.0);
        assert_eq!(q.underrun_ticks, 7);
    }

    /// Motion stopped between a batch and its tail: the batch is left out and the queue runs
    /// dry where the last tail starts, which plays.
    #[test]
    fn a_batch_without_its_tail_does_not_play() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=3, 0, 0);
        for t in 4..=5 {
            assert!(q.push(sp(t, 9.0, 0), 0));
        }
        for t in 1..=3 {
            q.play(t);
        }
        let p = q.play(4);
        assert!(p.underrun);
        assert_eq!(p.setpoint.position[0], 3.0, "the tail of the batch 1–3");
        assert_eq!(q.tailless_stops, 0);
    }

    /// A tail that does not start where the queue ran dry is not played: the drives hold.
    #[test]
    fn a_tail_of_another_batch_is_not_played() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=3, 0, 0);
        q.set_tail(&tail(9, &[9.0]));
        for t in 1..=3 {
            q.play(t);
        }
        assert_eq!(q.play(4).setpoint.position[0], 3.0);
        assert_eq!(q.tailless_stops, 1);
    }

    /// Emergency stop: the episode ends, each axis ramps from its velocity to a stop by at
    /// most its step a tick, no setpoint is taken while pressed; after release the next
    /// episode's are.
    #[test]
    fn an_emergency_stop_ramps_each_axis_to_a_stop() {
        let mut q = SetpointQueue::new();
        batch(&mut q, 1..=4, 0, 0);
        for t in 1..=3 {
            q.play(t);
        }
        // 1 mm a tick, losing at most 0.3 mm a tick: 1 s period, 0.3 mm/s².
        q.emergency_stop(true, &[0.3], 1.0);
        assert_eq!(q.episode(), 1);
        assert_eq!(q.episode_ended(), ServoFeedback::ENDED_EMERGENCY_STOP);
        assert!(!q.push(sp(9, 9.0, 1), 3), "nothing is taken while pressed");
        let xs: Vec<f64> = (4..=9).map(|t| q.play(t).setpoint.position[0]).collect();
        let expected = [3.7, 4.1, 4.2, 4.2, 4.2, 4.2];
        for (x, e) in xs.iter().zip(expected) {
            assert!((x - e).abs() < 1e-9, "{xs:?}");
        }
        assert!(q.stopped_by_emergency_stop());
        assert_eq!(q.underrun_ticks, 0, "a stop, not an underrun");
        q.emergency_stop(false, &[0.3], 1.0);
        batch(&mut q, 12..=12, 9, 1);
        assert!(!q.play(10).underrun);
        assert_eq!(q.play(12).setpoint.position[0], 12.0);
    }
}
