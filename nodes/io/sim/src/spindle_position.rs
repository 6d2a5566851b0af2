//! The simulated spindle drive in position control (M19, SPOS, rigid tapping; decisions
//! D100, D101): where the PLC's SPINDLE_ORIENT holds, the drive takes the stop position the
//! ladder copied into Y8–Y17 (angle in 0.001°, way, count, speed), turns to it and holds it.

use cnc_msgs::canon::Turn;
use cnc_msgs::signals::{y, SignalTable, YImage};

/// The positioning speed (the machine data's "speed in position control"), rpm, where the
/// NC sends none.
pub const POSITIONING_RPM: f64 = 500.0;
/// How fast the drive closes in on the last degrees, s.
const TIME_CONSTANT: f64 = 0.05;
/// In position: this close, degrees, and slower than 1 rpm.
const IN_POSITION: f64 = 0.05;

/// One stop position as the PLC commands it: angle (0.001°), way, count, speed (rpm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StopCommand(i32, u8, u8, i32);

impl StopCommand {
    pub fn of(yi: &YImage) -> StopCommand {
        StopCommand(
            yi.read_i32(y::ORIENT_ANGLE),
            yi.bytes[y::ORIENT_WAY],
            yi.bytes[y::ORIENT_COUNT],
            yi.read_i32(y::ORIENT_SPEED),
        )
    }

    /// The speed to position at: the NC's, else the drive's own.
    fn top_speed(self) -> f64 {
        if self.3 > 0 {
            f64::from(self.3)
        } else {
            POSITIONING_RPM
        }
    }

    fn degrees(self) -> f64 {
        f64::from(self.0) / 1000.0
    }

    /// An unknown way code positions the shortest way (the PLC wrote the bytes).
    fn way(self) -> Turn {
        Turn::from_code(i32::from(self.1)).unwrap_or(Turn::Shortest)
    }
}

/// A positioning in progress or held: its command and its goal on the unwrapped angle (the
/// degrees the spindle has turned since power-on, so a goal can lie turns away).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Positioning {
    pub command: StopCommand,
    pub goal: f64,
}

impl Positioning {
    /// The goal of `command` for a spindle that has turned `turned` degrees and turns at
    /// `rpm`, braking at `acceleration` rpm/s. Turning, the absolute ways count from where it
    /// could stop (it does not turn back), the shortest way keeps its direction.
    pub fn start(command: StopCommand, turned: f64, rpm: f64, acceleration: f64) -> Positioning {
        let target = command.degrees();
        let stops_at = if acceleration > 0.0 {
            turned + rpm.signum() * 3.0 * rpm * rpm / acceleration
        } else {
            turned
        };
        let turning = rpm.abs() >= 1.0;
        let ahead = |from: f64| from + (target - from).rem_euclid(360.0);
        let behind = |from: f64| from - (from - target).rem_euclid(360.0);
        let goal = match command.way() {
            Turn::Incremental => turned + target,
            Turn::Plus => ahead(stops_at),
            Turn::Minus => behind(stops_at),
            Turn::Shortest if turning && rpm > 0.0 => ahead(stops_at),
            Turn::Shortest if turning => behind(stops_at),
            Turn::Shortest => {
                let up = ahead(turned) - turned;
                if up <= 180.0 {
                    turned + up
                } else {
                    turned + up - 360.0
                }
            }
        };
        Positioning { command, goal }
    }

    /// The speed the drive commands this period: as fast as it can still stop on the goal
    /// (braking at `acceleration`), at most the command's speed, the last degrees closing in
    /// exponentially.
    pub fn speed(&self, turned: f64, acceleration: f64) -> f64 {
        let rest = self.goal - turned;
        // Degrees to stop from n rpm at a rpm/s: 3·n²/a, so n = √(a·rest/3); 90 % of it.
        let braking = 0.9 * (acceleration.max(0.0) * rest.abs() / 3.0).sqrt();
        let closing = rest.abs() / 360.0 * 60.0 / TIME_CONSTANT;
        rest.signum() * self.command.top_speed().min(braking).min(closing)
    }

    /// Whether the spindle stands on the goal.
    pub fn reached(&self, turned: f64, rpm: f64) -> bool {
        (self.goal - turned).abs() < IN_POSITION && rpm.abs() < 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(degrees: f64, way: Turn) -> StopCommand {
        StopCommand((degrees * 1000.0).round() as i32, way as u8, 1, 0)
    }

    #[test]
    fn each_way_finds_its_goal() {
        let at =
            |deg, way, turned, rpm| Positioning::start(command(deg, way), turned, rpm, 3000.0).goal;
        // Standing at 350°: 14.3° is 24.3° ahead, the shortest way; 300° is 50° back.
        assert!((at(14.3, Turn::Shortest, 350.0, 0.0) - 374.3).abs() < 1e-9);
        assert!((at(300.0, Turn::Shortest, 350.0, 0.0) - 300.0).abs() < 1e-9);
        // ACP: ahead even when behind is nearer; ACN: behind.
        assert!((at(300.0, Turn::Plus, 350.0, 0.0) - 660.0).abs() < 1e-9);
        assert!((at(14.3, Turn::Minus, 350.0, 0.0) - 14.3).abs() < 1e-9);
        // Already there: no turn.
        assert!((at(350.0, Turn::Plus, 350.0, 0.0) - 350.0).abs() < 1e-9);
        // IC: the signed travel, turns included.
        assert!((at(-720.5, Turn::Incremental, 10.0, 0.0) - (10.0 - 720.5)).abs() < 1e-9);
        // Turning at 600 rpm forward, the shortest way keeps the direction, beyond the
        // 360° it needs to stop: 3·600²/3000 = 360.
        let g = at(14.3, Turn::Shortest, 0.0, 600.0);
        assert!(g >= 360.0 && (g - 374.3).abs() < 1e-9, "{g}");
        let g = at(14.3, Turn::Shortest, 0.0, -600.0);
        assert!((g - (14.3 - 720.0)).abs() < 1e-9, "{g}");
    }

    #[test]
    fn the_drive_never_asks_more_than_it_can_brake() {
        let p = Positioning::start(command(0.0, Turn::Incremental), 0.0, 0.0, 3000.0);
        assert_eq!(p.speed(0.0, 3000.0), 0.0);
        let p = Positioning { goal: 3600.0, ..p };
        assert_eq!(p.speed(0.0, 3000.0), POSITIONING_RPM);
        // 200° before the goal: √(3000·200/3) = 447.2 rpm, 90 % of it; 10° before it the
        // drive closes in at 10/360·60/0.05 = 33.3 rpm.
        assert!((p.speed(3400.0, 3000.0) - 0.9 * 200_000f64.sqrt()).abs() < 1e-9);
        assert!((p.speed(3590.0, 3000.0) - 100.0 / 3.0).abs() < 1e-9);
        assert!(p.speed(3600.5, 3000.0) < 0.0);
        assert!(p.reached(3600.01, 0.5) && !p.reached(3600.2, 0.0) && !p.reached(3600.0, 2.0));
        // A speed from the NC (rigid tapping's S) replaces the drive's own.
        let p = Positioning {
            command: StopCommand(3_600_000, Turn::Incremental as u8, 2, 600),
            goal: 3600.0,
        };
        assert_eq!(p.speed(0.0, 3000.0), 600.0);
    }
}

/// The spindle in contour control (the turn-mill's C axis under polar interpolation, D141):
/// holding its position, the drive follows C's setpoint every tick as an axis drive follows
/// its own (a first-order lag of `tau` with the exact response to a ramp between setpoints).
#[derive(Debug, Clone, Copy, Default)]
pub struct ContourFollow {
    /// The last setpoint taken, on the unwrapped angle; none outside contour control.
    last: Option<f64>,
}

impl ContourFollow {
    /// The spindle's angle after `dt` following the setpoint `c` (degrees whose value modulo
    /// 360 is the encoder angle to reach) from `turned`; `None` when not following.
    pub fn step(&mut self, follow: bool, c: f64, turned: f64, tau: f64, dt: f64) -> Option<f64> {
        let last = self.last.unwrap_or(turned);
        // The setpoint's unwrapped value: within half a turn of the last one.
        let target = last + (c - last + 180.0).rem_euclid(360.0) - 180.0;
        self.step_unwrapped(follow, target, turned, tau, dt)
    }

    /// As [`ContourFollow::step`] with a setpoint on the drive's own unwrapped count (the
    /// live tool's).
    pub fn step_unwrapped(
        &mut self,
        follow: bool,
        target: f64,
        turned: f64,
        tau: f64,
        dt: f64,
    ) -> Option<f64> {
        if !follow || !target.is_finite() {
            self.last = None;
            return None;
        }
        let last = self.last.unwrap_or(turned);
        self.last = Some(target);
        Some(if tau > 0.0 && dt > 0.0 {
            let v = (target - last) / dt;
            let settled = target - v * tau;
            let off = turned - (last - v * tau);
            settled + off * (-dt / tau).exp()
        } else {
            target
        })
    }
}
