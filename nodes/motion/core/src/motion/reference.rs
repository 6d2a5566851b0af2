//! Reference return (issue 28; decisions D68): an axis with an incremental encoder knows where
//! it is only after it has found its reference point. The sequence is the dog type of the
//! manuals (Huaxing `000` §14, FANUC `003` §4.1): toward the deceleration dog at the fast
//! feed, on and off the dog at the slow feed, and the first index mark after the dog is the
//! reference point (`home`); the axis then stands on it. One axis after the other, in the
//! config's order. Until every axis is referenced no program runs (alarm 224).

use super::{alarm, Motion, MAX_AXES};

/// What the encoders report in one servo period (the shell passes the drives' feedback).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReferenceInputs {
    /// Bit per axis: deceleration dog pressed.
    pub dog: u32,
    /// Bit per axis: index mark passed, at `marker_position` (encoder count, mm).
    pub marker: u32,
    pub marker_position: [f64; MAX_AXES],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Toward the dog at the fast feed.
    Approach,
    /// On the dog at the slow feed, until it is released.
    OffDog,
    /// Off the dog at the slow feed, until the next index mark.
    Mark,
    /// The mark set the position: back onto the reference point.
    ToReference,
    /// On the point; the slide settles into position before the next axis starts.
    Settle,
}

/// A reference return in progress.
#[derive(Debug, Clone)]
pub(super) struct ReferenceReturn {
    /// Axes still to reference, in order; the first is moving.
    pending: Vec<usize>,
    phase: Phase,
    /// Slide velocity of the moving axis, mm/s.
    velocity: f64,
    /// Slide travel so far on this axis, mm: more than its whole travel without a dog is an
    /// alarm (the dog or its switch is broken).
    travelled: f64,
}

impl Motion {
    /// The encoders' dog and index-mark signals of the latest feedback.
    pub fn reference_inputs(&mut self, inputs: ReferenceInputs) {
        self.reference_inputs = inputs;
    }

    /// Whether each axis knows its machine position.
    pub fn referenced(&self) -> &[bool] {
        &self.referenced
    }

    /// Whether an axis still needs its reference return.
    pub fn all_referenced(&self) -> bool {
        self.referenced.iter().all(|r| *r)
    }

    /// A reference return in progress.
    pub fn referencing(&self) -> bool {
        self.reference.is_some()
    }

    /// Starts the reference return of every axis with an incremental encoder, in the
    /// config's order. Refused while a program runs or the machine is stopped by an alarm.
    pub fn reference_return(&mut self) -> Result<String, String> {
        if self.axes_driven() || self.handwheel.moving() {
            return Err("reference return refused: the axes are moving".into());
        }
        if self.alarm || self.emergency_stop || self.servo_off {
            return Err("reference return refused: alarm or emergency stop (reset first)".into());
        }
        let pending: Vec<usize> = self
            .cfg
            .reference_order
            .iter()
            .copied()
            .filter(|&i| self.cfg.axes.get(i).is_some_and(|a| a.reference.is_some()))
            .collect();
        if pending.is_empty() {
            return Ok("every axis has an absolute encoder: no reference return needed".into());
        }
        let names: Vec<&str> = pending
            .iter()
            .map(|&i| self.cfg.axes[i].name.as_str())
            .collect();
        let message = format!("reference return of {}", names.join(", "));
        for &i in &pending {
            self.referenced[i] = false;
        }
        self.reference = Some(ReferenceReturn {
            pending,
            phase: Phase::Approach,
            velocity: 0.0,
            travelled: 0.0,
        });
        Ok(message)
    }

    /// One servo period of the reference return: moves the axis being referenced.
    pub(super) fn reference_tick(&mut self, dt: f64) {
        let Some(mut h) = self.reference.take() else {
            return;
        };
        let Some(&i) = h.pending.first() else {
            self.planner.reset(self.commanded_point());
            return;
        };
        let axis = &self.cfg.axes[i];
        let Some(r) = axis.reference else {
            return;
        };
        let toward = if r.positive { 1.0 } else { -1.0 };
        let acceleration = axis.max_acceleration;
        let fast = r.fast(axis.max_velocity) / 60.0;
        let slow = r.slow_feed / 60.0;
        let reference = axis.home * axis.scale();
        let travel = (axis.max - axis.min).abs() * axis.scale();
        let bit = 1u32 << i;
        let dog = self.reference_inputs.dog & bit != 0;
        let target = match h.phase {
            Phase::Approach => {
                if dog {
                    h.phase = Phase::OffDog;
                }
                toward * fast
            }
            Phase::OffDog => {
                if !dog {
                    h.phase = Phase::Mark;
                }
                toward * slow
            }
            Phase::Mark => {
                if self.reference_inputs.marker & bit != 0 {
                    // The mark is the reference point: the machine position is set from it.
                    let at_mark = self.reference_inputs.marker_position[i] + self.shift[i];
                    let delta = reference - at_mark;
                    self.shift[i] += delta;
                    self.commanded[i] += delta;
                    self.drive[i] += delta;
                    self.actual[i] += delta;
                    h.phase = Phase::ToReference;
                }
                toward * slow
            }
            Phase::ToReference => {
                let left = reference - self.commanded[i];
                left.signum() * slow.min((2.0 * acceleration * left.abs()).sqrt())
            }
            Phase::Settle => {
                if (self.actual[i] - reference).abs() <= axis.in_position {
                    // In position on the reference point: this axis is done.
                    self.referenced[i] = true;
                    h.pending.remove(0);
                    h.phase = Phase::Approach;
                    h.velocity = 0.0;
                    h.travelled = 0.0;
                    if h.pending.is_empty() {
                        self.planner.reset(self.commanded_point());
                        return;
                    }
                }
                self.reference = Some(h);
                return;
            }
        };
        let step = acceleration * dt;
        h.velocity += (target - h.velocity).clamp(-step, step);
        let left = reference - self.commanded[i];
        if h.phase == Phase::ToReference && left.abs() <= (h.velocity * dt).abs().max(1e-9) {
            self.commanded[i] = reference;
            h.phase = Phase::Settle;
            h.velocity = 0.0;
        } else {
            self.commanded[i] += h.velocity * dt;
            h.travelled += (h.velocity * dt).abs();
        }
        if h.travelled > 1.5 * travel + 2.0 * r.grid {
            let text = format!(
                "reference return of {}: no deceleration dog and index mark within its travel",
                axis.name
            );
            self.raise(alarm::REFERENCE_FAILED, text, 0);
            return;
        }
        self.reference = Some(h);
    }
}
