//! Manual moves (issue 28): jog of one axis at a feed, continuous or by an increment, as the
//! operator's jog keys and the cell's `jog` service give them. A continuous jog is held by
//! its keeper: each request holds it for [`DEAD_MAN_TICKS`] more servo periods, so a client
//! that disappears (a lost connection, a crashed robot program) stops the axis within that
//! time and its deceleration.

use cnc_msgs::msg::MachineState;
use cnc_msgs::signals::{g, GImage, SignalTable};

use super::{Motion, RunState};

/// The feed of the PLC's jog keys, mm/min (display units; D71).
pub const KEY_JOG_FEED: f64 = 1000.0;

/// The one key pressed among `plus` and `minus` (bits by axis index), if exactly one is.
fn one_key(plus: u32, minus: u32) -> Option<(usize, bool)> {
    match (plus.count_ones(), minus.count_ones()) {
        (1, 0) => Some((plus.trailing_zeros() as usize, true)),
        (0, 1) => Some((minus.trailing_zeros() as usize, false)),
        _ => None,
    }
}

/// How long one continuous jog request holds the axis moving: 100 ms at 4 ms, so that with
/// the deceleration, the drive lag and a request's way through the cell the axis stands
/// within 200 ms of the client's last request.
pub const DEAD_MAN_TICKS: u32 = 25;

/// A manual move in progress.
#[derive(Debug, Clone)]
pub(super) struct Jog {
    axis: usize,
    /// +1 or -1.
    direction: f64,
    /// Slide speed asked for, mm/s.
    speed: f64,
    /// Where an incremental move ends (slide, machine coordinates); `None`: continuous.
    end: Option<f64>,
    /// Servo periods the last request still holds a continuous jog.
    held: u32,
    velocity: f64,
}

impl Motion {
    /// Jogs `axis` (index) in the positive or negative direction at `feed` (mm/min of the
    /// axis's display units), continuously (`increment` `None`, held by repeating the request)
    /// or by `increment` (display units). A repeated request for the jog in progress holds it;
    /// any other is refused while an axis moves. Referenced axes stop at their soft limits.
    pub fn jog(
        &mut self,
        axis: usize,
        positive: bool,
        feed: f64,
        increment: Option<f64>,
    ) -> Result<(), String> {
        let Some(a) = self.cfg.axes.get(axis) else {
            return Err(format!("jog: no axis {axis}"));
        };
        let bad_increment = increment.is_some_and(|d| !(d.is_finite() && d > 0.0));
        if !(feed.is_finite() && feed > 0.0) || bad_increment {
            return Err("jog: feed and increment must be positive numbers".into());
        }
        if self.state() == RunState::Alarm || self.servo_off {
            return Err("jog refused: alarm or emergency stop (reset first)".into());
        }
        if self.on_overtravel_switch(axis, positive) {
            return Err(format!(
                "jog refused: {} is on its {} overtravel switch: jog it the other way",
                a.name,
                if positive { "+" } else { "−" }
            ));
        }
        let direction = if positive { 1.0 } else { -1.0 };
        if let Some(j) = self.jog.as_mut() {
            let same = j.axis == axis && j.direction == direction;
            if same && j.end.is_none() && increment.is_none() {
                j.held = DEAD_MAN_TICKS;
                return Ok(());
            }
            return Err("jog refused: an axis is moving".into());
        }
        if self.handwheel.moving() {
            return Err("jog refused: the handwheel is moving an axis".into());
        }
        if self.active.is_some() || !self.queue.is_empty() || self.reference.is_some() {
            return Err("jog refused: a program or a reference return is moving the axes".into());
        }
        let scale = a.scale();
        let speed = (feed * scale / 60.0).min(a.max_velocity / 60.0);
        let end = increment.map(|d| self.commanded[axis] + direction * d * scale);
        self.jog = Some(Jog {
            axis,
            direction,
            speed,
            end,
            held: DEAD_MAN_TICKS,
            velocity: 0.0,
        });
        Ok(())
    }

    /// Stops a jog: the axis decelerates (the key released).
    pub fn jog_stop(&mut self) {
        if let Some(j) = self.jog.as_mut() {
            j.held = 0;
            if let Some(end) = j.end.as_mut() {
                // An increment stops where it can.
                let stop = j.velocity * j.velocity / (2.0 * self.cfg.axes[j.axis].max_acceleration);
                *end = self.commanded[j.axis] + j.velocity.signum() * stop;
            }
        }
    }

    /// The key holding a continuous key jog, as the drives are told it (`jog_key`: +(k + 1)
    /// for +J of axis signal k, −(k + 1) for −J); none for other moves.
    pub(super) fn held_jog_key(&self) -> Option<i32> {
        let j = self
            .jog
            .as_ref()
            .filter(|j| self.key_jog && j.end.is_none() && j.held > 0)?;
        let k = (*self.signal_axis.get(j.axis)?)? as i32 + 1;
        Some(if j.direction > 0.0 { k } else { -k })
    }

    /// A manual move in progress.
    pub fn jogging(&self) -> bool {
        self.jog.is_some()
    }

    /// One servo period of the jog.
    pub(super) fn jog_tick(&mut self, dt: f64) {
        let Some(mut j) = self.jog.take() else {
            return;
        };
        let i = j.axis;
        let a = &self.cfg.axes[i];
        let accel = a.max_acceleration;
        // A referenced axis stays inside its soft limits (slide travel).
        let (lo, hi) = (a.min * a.scale(), a.max * a.scale());
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        let limit = if self.referenced[i] {
            Some(if j.direction > 0.0 { hi } else { lo })
        } else {
            None
        };
        let here = self.commanded[i];
        let stop_at = match (j.end, limit) {
            (Some(e), Some(l)) => Some(if j.direction > 0.0 {
                e.min(l)
            } else {
                e.max(l)
            }),
            (e, l) => e.or(l),
        };
        // The feed override applies to jogging (`000` §2: jog feed × override).
        let speed = j.speed * self.panel.feed_override;
        let mut target = if j.end.is_some() || j.held > 0 {
            j.direction * speed
        } else {
            0.0
        };
        if let Some(s) = stop_at {
            let left = (s - here) * j.direction;
            let brake = (2.0 * accel * left.max(0.0)).sqrt();
            target = j.direction * (target * j.direction).min(brake);
        }
        j.held = j.held.saturating_sub(1);
        let step = accel * dt;
        j.velocity += (target - j.velocity).clamp(-step, step);
        let mut next = here + j.velocity * dt;
        if let Some(s) = stop_at {
            if (s - next) * j.direction <= 0.0 {
                next = s;
                j.velocity = 0.0;
            }
        }
        self.commanded[i] = next;
        let arrived = stop_at.is_some_and(|s| next == s);
        let done = j.velocity == 0.0
            && match j.end {
                Some(_) => arrived,
                None => j.held == 0,
            };
        if done {
            self.planner.reset(self.commanded_point());
            return;
        }
        self.jog = Some(j);
    }

    /// The mode the interpreter accepted: the PLC's jog keys act in JOG and HANDWHEEL only,
    /// and a key jog stops when the mode changes.
    pub fn set_mode(&mut self, mode: u8) {
        self.mode = mode;
        if self.key_jog {
            self.jog_stop();
            self.key_jog = false;
        }
    }

    /// The PLC's jog keys (G100 +J, G102 −J; D71). In JOG mode one key held jogs its axis at
    /// [`KEY_JOG_FEED`] (with G19.7 RT at the rapid rate and its override), and its release
    /// stops it; in HANDWHEEL mode each press moves one step of 0.001 mm times the multiplier
    /// (G19.0 MP1, G19.1 MP2: ×1, ×10, ×100, ×1000). Two keys at once move nothing.
    pub(super) fn key_jogs(&mut self, plc: &GImage) {
        let (mut plus, mut minus) = (0u32, 0u32);
        for (i, k) in self.signal_axis.iter().enumerate() {
            if let Some(k) = *k {
                plus |= u32::from(plc.get(g::jog_plus(k))) << i;
                minus |= u32::from(plc.get(g::jog_minus(k))) << i;
            }
        }
        let (was_plus, was_minus) = self.jog_keys;
        self.jog_keys = (plus, minus);
        match self.mode {
            MachineState::MODE_JOG => match one_key(plus, minus) {
                Some((i, positive)) => {
                    let a = &self.cfg.axes[i];
                    let feed = if plc.get(g::RT) {
                        a.max_velocity / a.scale() * self.panel.rapid_override
                    } else {
                        KEY_JOG_FEED
                    };
                    if feed > 0.0 && self.jog(i, positive, feed, None).is_ok() {
                        self.key_jog = true;
                    }
                }
                None if self.key_jog => {
                    self.jog_stop();
                    self.key_jog = false;
                }
                None => {}
            },
            MachineState::MODE_HANDWHEEL => {
                if let Some((i, positive)) = one_key(plus & !was_plus, minus & !was_minus) {
                    let times =
                        10f64.powi(i32::from(plc.get(g::MP1)) + 2 * i32::from(plc.get(g::MP2)));
                    let _ = self.jog(i, positive, KEY_JOG_FEED, Some(0.001 * times));
                }
            }
            _ => {}
        }
    }
}
