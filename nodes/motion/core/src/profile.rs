//! Speed along a path, chosen online tick by tick.
//!
//! Each servo tick the [`Mover`] picks its next speed so that it can still slow down to every
//! speed limit ahead ([`Ahead`]): corners, slow segments, the end of what is planned. Because
//! it decides online from the current state, feed hold, resume and newly arrived blocks need no
//! re-planning of the profile. Two shapes: trapezoidal (acceleration limited) and S-curve
//! (acceleration and jerk limited), chosen per machine.

/// The profile shape is chosen in the launch config (`servo.profile`).
pub use cnc_machine::ProfileShape as Shape;

/// Limits along the path for this tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub velocity: f64,
    pub acceleration: f64,
    /// Ignored by the trapezoidal shape.
    pub jerk: f64,
}

/// A speed limit ahead: at `distance` along the path the speed must be at most `velocity`;
/// `acceleration` is the lowest braking allowed on the way there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ahead {
    pub distance: f64,
    pub velocity: f64,
    pub acceleration: f64,
}

/// Speed and acceleration along the path.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Mover {
    pub velocity: f64,
    pub acceleration: f64,
}

impl Mover {
    /// Advances one tick of `dt` seconds; returns the distance travelled. `hold` brakes to a
    /// stop (feed hold).
    pub fn step(&mut self, dt: f64, shape: Shape, lim: Limits, hold: bool, ahead: &[Ahead]) -> f64 {
        match shape {
            Shape::Trapezoidal => self.step_trapezoidal(dt, lim, hold, ahead),
            Shape::SCurve => self.step_s_curve(dt, lim, hold, ahead),
        }
    }

    fn step_trapezoidal(&mut self, dt: f64, lim: Limits, hold: bool, ahead: &[Ahead]) -> f64 {
        let v0 = self.velocity;
        let a = lim.acceleration;
        let mut target = if hold { 0.0 } else { lim.velocity };
        let mut brake = f64::INFINITY;
        for c in ahead {
            brake = brake.min(braking_speed(v0, c, dt));
        }
        target = target.min(brake);
        let mut v1 = if target > v0 {
            (v0 + a * dt).min(target)
        } else {
            (v0 - a * dt).max(target)
        };
        // The braking curve is exact in discrete time; holding to it keeps stops on the point.
        v1 = v1.min(brake).max(0.0);
        self.acceleration = (v1 - v0) / dt;
        self.velocity = v1;
        0.5 * (v0 + v1) * dt
    }

    fn step_s_curve(&mut self, dt: f64, lim: Limits, hold: bool, ahead: &[Ahead]) -> f64 {
        let (a_max, j_max) = (lim.acceleration, lim.jerk);
        let vmax = if hold { 0.0 } else { lim.velocity };
        let (v0, a0) = (self.velocity, self.acceleration);
        // The state after one tick with jerk j: (speed, acceleration, distance).
        let next = |j: f64| {
            let a1 = (a0 + j * dt).clamp(-a_max, a_max);
            let v1 = v0 + 0.5 * (a0 + a1) * dt;
            let ds = v0 * dt + (2.0 * a0 + a1) * dt * dt / 6.0;
            (v1, a1, ds)
        };
        let ahead_ok = |(v1, a1, ds): (f64, f64, f64)| {
            ahead.iter().all(|c| {
                if c.distance <= ds {
                    // Passed within this tick: the speed there is between v0 and v1.
                    return v0.max(v1) <= c.velocity + 1e-9;
                }
                let brake = c.acceleration.min(a_max);
                stop_distance(v1, a1, c.velocity, brake, j_max) <= c.distance - ds + 1e-9
            })
        };
        // Within the speed cap, also inside the tick (where the acceleration crosses zero) and
        // after it (once the acceleration is ramped away at full jerk).
        let feasible = |(v1, a1, ds): (f64, f64, f64)| {
            let after = v1 + a1.max(0.0).powi(2) / (2.0 * j_max);
            let inside = if a0 > 0.0 && a1 < 0.0 {
                v0 + a0 * a0 * dt / (2.0 * (a0 - a1))
            } else {
                v1
            };
            after.max(inside) <= vmax + 1e-9 && ahead_ok((v1, a1, ds))
        };
        let largest = |ok: &dyn Fn((f64, f64, f64)) -> bool, top: f64| {
            if ok(next(top)) {
                top
            } else if !ok(next(-j_max)) {
                -j_max
            } else {
                let (mut lo, mut hi) = (-j_max, top);
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if ok(next(mid)) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                lo
            }
        };
        let state = if v0 > vmax + 1e-9 {
            // Above the cap (feed hold, a slower segment): brake so the speed lands on the cap
            // just as the deceleration ramps back to zero, a = −√(2j·(v − cap)).
            let a_des = -(2.0 * j_max * (v0 - vmax)).sqrt().min(a_max);
            let j = ((a_des - a0) / dt).clamp(-j_max, j_max);
            next(largest(&ahead_ok, j))
        } else {
            // The highest end acceleration that neither passes the cap in this tick nor after:
            // v0 + (a0 + a1)·dt/2 + a1²/2j ≤ cap.
            let c = v0 + 0.5 * a0 * dt - vmax;
            let disc = 0.25 * dt * dt - 2.0 * c / j_max;
            let a1_cap = if disc >= 0.0 {
                j_max * (-0.5 * dt + disc.sqrt())
            } else {
                f64::NEG_INFINITY
            };
            if a1_cap >= 0.0 {
                let top = ((a1_cap - a0) / dt).clamp(-j_max, j_max);
                next(largest(&feasible, top))
            } else {
                // Reaching the cap inside this tick: ramp the acceleration to zero at full
                // jerk, then cruise for the rest of the tick.
                let t1 = (a0 / j_max).clamp(0.0, dt);
                let a1 = a0 - j_max * t1;
                let v1 = v0 + a0 * t1 - 0.5 * j_max * t1 * t1;
                let ds1 = v0 * t1 + 0.5 * a0 * t1 * t1 - j_max * t1 * t1 * t1 / 6.0;
                let cruise = (v1, a1, ds1 + v1 * (dt - t1));
                if ahead_ok(cruise) {
                    cruise
                } else {
                    next(largest(&ahead_ok, -j_max))
                }
            }
        };
        let (mut v1, mut a1, mut ds) = state;
        if v1 <= 0.0 {
            // Stopped: no creeping backwards.
            ds = ds.max(0.0);
            v1 = 0.0;
            a1 = a1.max(0.0).min(j_max * dt);
            if hold || vmax <= 0.0 {
                a1 = 0.0;
            }
        }
        self.velocity = v1;
        self.acceleration = a1;
        ds
    }
}

/// Trapezoidal: the highest speed for the next tick from which braking by `c.acceleration`
/// (trapezoidal integration, exact for a ramp) still arrives at `c.distance` no faster than
/// `c.velocity`: (v0+v1)/2·dt + (v1² − ve²)/2a ≤ d.
fn braking_speed(v0: f64, c: &Ahead, dt: f64) -> f64 {
    // Already no faster than the limit: ending the tick at it meets it whether the point is
    // passed within the tick or later.
    let floor = if v0 <= c.velocity { c.velocity } else { 0.0 };
    let a = c.acceleration;
    let room = c.distance - 0.5 * v0 * dt;
    let half = 0.5 * a * dt;
    let disc = half * half + c.velocity * c.velocity + 2.0 * a * room;
    if disc <= 0.0 {
        floor
    } else {
        (-half + disc.sqrt()).max(floor)
    }
}

/// Jerk-limited braking distance from speed `v` and acceleration `a` to speed `ve`, with
/// acceleration limit `a_max` and jerk limit `j`: ramp the acceleration down to −a_p, hold it,
/// ramp back to zero as the speed reaches `ve`.
pub fn stop_distance(v: f64, a: f64, ve: f64, a_max: f64, j: f64) -> f64 {
    if v <= ve && a <= 0.0 {
        return 0.0;
    }
    // Peak deceleration without a constant part: a_p² = a²/2 + j·(v − ve).
    let sq = 0.5 * a * a + j * (v - ve);
    let mut a_p = if sq > 0.0 { sq.sqrt() } else { 0.0 };
    let mut hold_time = 0.0;
    if a_p > a_max {
        a_p = a_max;
        // Speed lost in the ramps: (a² − a_p²)/2j and −a_p²/2j; the rest at −a_p.
        let dv_ramps = (a * a - a_p * a_p) / (2.0 * j) - a_p * a_p / (2.0 * j);
        hold_time = ((v + dv_ramps - ve) / a_p).max(0.0);
    }
    if a_p < -a {
        // Already braking harder than needed: only the final ramp.
        a_p = -a;
    }
    let mut state = (0.0, v, a);
    let phase = |(d, v, a): (f64, f64, f64), jerk: f64, t: f64| {
        if t > 0.0 {
            (
                d + v * t + 0.5 * a * t * t + jerk * t * t * t / 6.0,
                v + a * t + 0.5 * jerk * t * t,
                a + jerk * t,
            )
        } else {
            (d, v, a)
        }
    };
    state = phase(state, -j, (a + a_p) / j);
    state = phase(state, 0.0, hold_time);
    state = phase(state, j, a_p / j);
    state.0.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(shape: Shape, length: f64, lim: Limits) -> (usize, f64, f64, f64) {
        let mut m = Mover::default();
        let (dt, mut s, mut ticks) = (0.004, 0.0, 0);
        let (mut max_v, mut max_a) = (0.0f64, 0.0f64);
        let mut last_v = 0.0;
        while s < length - 1e-9 && ticks < 100_000 {
            let ahead = [Ahead {
                distance: length - s,
                velocity: 0.0,
                acceleration: lim.acceleration,
            }];
            let ds = m.step(dt, shape, lim, false, &ahead);
            s += ds;
            max_v = max_v.max(m.velocity);
            max_a = max_a.max(((m.velocity - last_v) / dt).abs());
            last_v = m.velocity;
            ticks += 1;
            if m.velocity == 0.0 && length - s < 1e-6 {
                break;
            }
        }
        (ticks, s, max_v, max_a)
    }

    #[test]
    fn trapezoid_reaches_the_end_within_limits() {
        let lim = Limits {
            velocity: 50.0,
            acceleration: 500.0,
            jerk: f64::INFINITY,
        };
        let (ticks, s, v, a) = run(Shape::Trapezoidal, 10.0, lim);
        assert!((s - 10.0).abs() < 1e-9, "{s}");
        assert!(v <= 50.0 + 1e-9 && a <= 500.0 * (1.0 + 1e-9), "{v} {a}");
        // 10 mm at 50 mm/s with 0.1 s ramps: 0.3 s.
        assert!((ticks as f64 * 0.004 - 0.3).abs() < 0.02, "{ticks} ticks");
    }

    #[test]
    fn s_curve_stays_within_jerk_and_lands_on_the_end() {
        let lim = Limits {
            velocity: 50.0,
            acceleration: 500.0,
            jerk: 10_000.0,
        };
        let (ticks, s, v, a) = run(Shape::SCurve, 10.0, lim);
        assert!((s - 10.0).abs() < 1e-4, "{s}");
        assert!(v <= 50.0 + 1e-6 && a <= 500.0 * 1.01, "{v} {a}");
        // Slower than the trapezoid by about a/j per ramp pair: 0.3 + 0.05 s.
        let t = ticks as f64 * 0.004;
        assert!(t > 0.33 && t < 0.40, "{t}");
    }

    #[test]
    fn stop_distance_matches_the_trapezoid_for_high_jerk() {
        let d = stop_distance(100.0, 0.0, 0.0, 2000.0, 1e12);
        assert!((d - 2.5).abs() < 1e-3, "{d}");
        // With jerk: v²/2a + v·a/2j.
        let d = stop_distance(100.0, 0.0, 0.0, 2000.0, 100_000.0);
        assert!((d - 3.5).abs() < 1e-9, "{d}");
    }
}
