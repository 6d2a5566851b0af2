//! A one-dimensional trapezoidal move, advanced online tick by tick.
//!
//! Each tick the velocity steps toward the lowest of: the commanded speed, the speed from which
//! the end can still be reached by braking (`√(2·a·remaining)`), or zero when holding. Because it
//! is online, feed hold and resume need no re-planning. The look-ahead planner of issue 4 replaces
//! this per-block profile.

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    pub length: f64,
    pub position: f64,
    pub velocity: f64,
    pub max_velocity: f64,
    pub acceleration: f64,
}

impl Profile {
    pub fn new(length: f64, max_velocity: f64, acceleration: f64) -> Self {
        Profile {
            length,
            position: 0.0,
            velocity: 0.0,
            max_velocity,
            acceleration,
        }
    }

    pub fn done(&self) -> bool {
        self.position >= self.length
    }

    /// Advances by `dt` seconds; `hold` brakes to a stop on the path.
    pub fn step(&mut self, dt: f64, hold: bool) {
        if self.done() {
            self.velocity = 0.0;
            return;
        }
        let remaining = self.length - self.position;
        let a = self.acceleration;
        // Highest speed this tick from which braking by a·dt per tick (trapezoidal integration)
        // still stops at the end: v²/2a + v·dt/2 ≤ remaining − v₀·dt/2.
        let room = remaining - 0.5 * self.velocity * dt;
        let half = 0.5 * a * dt;
        let braking = if room <= 0.0 {
            0.0
        } else {
            -half + (half * half + 2.0 * a * room).sqrt()
        };
        let target = if hold {
            0.0
        } else {
            self.max_velocity.min(braking)
        };
        let dv = a * dt;
        let mut v = if target > self.velocity {
            (self.velocity + dv).min(target)
        } else {
            (self.velocity - dv).max(target)
        };
        if !hold {
            v = v.min(braking);
        }
        let ds = 0.5 * (self.velocity + v) * dt;
        if !hold && ds >= remaining - 1e-9 {
            self.position = self.length;
            self.velocity = 0.0;
        } else {
            self.position = (self.position + ds).min(self.length);
            self.velocity = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reaches_the_end_exactly_within_limits() {
        let mut p = Profile::new(10.0, 50.0, 500.0);
        let dt = 0.004;
        let mut last_v = 0.0;
        let mut ticks = 0;
        while !p.done() {
            p.step(dt, false);
            assert!(p.velocity <= 50.0 + 1e-9);
            assert!(
                (p.velocity - last_v).abs() <= 500.0 * dt * (1.0 + 1e-9),
                "accel limit: {} -> {}",
                last_v,
                p.velocity
            );
            last_v = p.velocity;
            ticks += 1;
            assert!(ticks < 10_000);
        }
        assert_eq!(p.position, 10.0);
        // 10 mm at 50 mm/s with 0.1 s ramps: 0.3 s, within a few ticks.
        assert!((ticks as f64 * dt - 0.3).abs() < 0.02, "{ticks} ticks");
    }

    #[test]
    fn hold_stops_on_the_path_and_resume_finishes() {
        let mut p = Profile::new(20.0, 50.0, 500.0);
        for _ in 0..50 {
            p.step(0.004, false);
        }
        let at_hold = p.position;
        let v = p.velocity;
        while p.velocity > 0.0 {
            p.step(0.004, true);
        }
        // Braking distance v²/2a, within one tick of travel.
        assert!((p.position - at_hold - v * v / 1000.0).abs() < v * 0.004 + 1e-9);
        assert!(!p.done());
        while !p.done() {
            p.step(0.004, false);
        }
        assert_eq!(p.position, 20.0);
    }
}
