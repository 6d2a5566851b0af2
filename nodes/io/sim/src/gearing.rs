//! Spindle-locked moves at the drives (issue 48, D135, D136): the drives set the axes from
//! their own spindle encoder every tick, as a real drive's electronic gearing and cam do, so a
//! tap or a thread stays in its groove whatever the queue and the spindle's speed did since
//! motion computed it. A rigid tap is a gear: each axis from its start to its end while the
//! spindle turns the tap's degrees. A thread is a cam: its queued setpoints are a table of
//! positions by spindle angle, looked up with the encoder's reading.

use cnc_msgs::servo::{ServoSetpoint, MAX_AXES};

/// The spindle encoder at the drives: its last raw angle, degrees turned (signed, unwrapped),
/// speed (rpm), and where it last stood (a tap's origin).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SpindleReading {
    raw: Option<f64>,
    pub(crate) turned: f64,
    pub(crate) rpm: f64,
    pub(crate) standing: f64,
}

impl SpindleReading {
    /// Takes the encoder's reading after a tick: speed (rpm, signed), angle (degrees).
    pub(crate) fn read(&mut self, rpm: f64, angle_deg: f64) {
        if !rpm.is_finite() || !angle_deg.is_finite() {
            return;
        }
        if let Some(prev) = self.raw {
            self.turned += wrap(angle_deg - prev);
        }
        self.raw = Some(angle_deg);
        self.rpm = rpm;
        if rpm == 0.0 {
            self.standing = self.turned;
        }
    }

    /// The degrees turned at which the encoder shows `angle`, nearest to where it is now.
    fn nearest(&self, angle: f64) -> f64 {
        self.turned + wrap(angle - self.raw.unwrap_or(angle))
    }

    /// Degrees the spindle turns in `seconds` at its speed now (signed).
    fn ahead(&self, seconds: f64) -> f64 {
        self.rpm * 6.0 * seconds
    }
}

/// An angle difference brought into −180°..180°.
fn wrap(degrees: f64) -> f64 {
    (degrees + 180.0).rem_euclid(360.0) - 180.0
}

/// Electronic gearing of a tap: each axis from `start` to `end` while the spindle turns
/// `degrees` from `origin` (degrees turned).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TapGear {
    start: [f64; MAX_AXES],
    end: [f64; MAX_AXES],
    degrees: f64,
    origin: f64,
}

impl TapGear {
    /// The gear a `SCALE_GEARED` setpoint asks for: the `previous` tick's when it is the same
    /// tap, else one from where the spindle last stood.
    pub(crate) fn of(
        sp: &ServoSetpoint,
        previous: Option<TapGear>,
        spindle: &SpindleReading,
    ) -> Self {
        let origin = match previous {
            Some(g) if g.start == sp.gear_start && g.end == sp.gear_end => g.origin,
            _ => spindle.standing,
        };
        TapGear {
            start: sp.gear_start,
            end: sp.gear_end,
            degrees: sp.gear_degrees,
            origin,
        }
    }

    /// Each axis's position at the encoder's reading, read ahead by the axis's `lead` (s).
    pub(crate) fn position(
        &self,
        spindle: &SpindleReading,
        lead: &[f64; MAX_AXES],
    ) -> [f64; MAX_AXES] {
        let mut out = [0.0; MAX_AXES];
        for (i, o) in out.iter_mut().enumerate() {
            let ahead = spindle.turned + spindle.ahead(lead[i]);
            let share = match self.degrees != 0.0 {
                true => ((ahead - self.origin) / self.degrees).clamp(0.0, 1.0),
                false => 1.0,
            };
            *o = self.start[i] + (self.end[i] - self.start[i]) * share;
        }
        out
    }
}

/// Thread setpoints the cam looks at in one tick, from the one reached on: 64 ticks (256 ms)
/// is more than a spindle runs ahead of motion's prediction (it ends when the queue does).
const WINDOW: usize = 64;

/// Where a thread's cam puts the drives this tick: the index on the queued path the
/// encoder's reading has reached (fractional between setpoints), and each axis's position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CamPlay {
    pub(crate) index: f64,
    pub(crate) position: [f64; MAX_AXES],
}

/// A thread played by the encoder (`ServoSetpoint::SCALE_THREAD`): each queued setpoint is for
/// the encoder angle motion predicted for its tick (`thread_angle`); the drives find where
/// their own reading lies between two of them and interpolate, each axis at the reading plus
/// its lead (its lag's worth of turning at the speed now, as motion's thread adds at the speed
/// it predicted). A spindle slower or faster than predicted moves the drives along the table
/// slower or faster than their clock; at the speed predicted the cam plays each setpoint at its
/// own tick.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ThreadCam {
    /// The index the cam stood at and the degrees turned its setpoint is for.
    anchor: Option<(u64, f64)>,
}

/// One thread setpoint as the cam reads it: degrees turned it is for, its lead's speed, its
/// position.
#[derive(Clone, Copy)]
struct Entry {
    key: f64,
    rpm: f64,
    position: [f64; MAX_AXES],
}

impl ThreadCam {
    /// The cam at index `k` (`sample` looks queued setpoints up by index): none when the
    /// setpoint at `k` is no thread's, when the encoder has passed the thread's last setpoint,
    /// or when it has passed the last one queued: the drives go on by their clock (into the
    /// next block, or the brake tail).
    pub(crate) fn follow<'a>(
        &mut self,
        k: u64,
        sample: impl Fn(u64) -> Option<&'a ServoSetpoint>,
        spindle: &SpindleReading,
        lead: &[f64; MAX_AXES],
    ) -> Option<CamPlay> {
        // A thread setpoint whose angle or speed is no number plays by the clock.
        let thread = |m| {
            sample(m).filter(|s| {
                s.scaling == ServoSetpoint::SCALE_THREAD
                    && s.thread_angle.is_finite()
                    && s.thread_rpm.is_finite()
            })
        };
        let Some(here) = thread(k) else {
            self.anchor = None;
            return None;
        };
        let key = match self.anchor {
            Some((m, key)) if m == k => key,
            // Entering the thread: its setpoint is for the turn the encoder is on.
            _ => spindle.nearest(here.thread_angle),
        };
        let mut table = [Entry {
            key,
            rpm: here.thread_rpm,
            position: here.position,
        }; WINDOW];
        let (mut n, mut angle) = (1, here.thread_angle);
        while n < WINDOW {
            let Some(sp) = thread(k + n as u64) else {
                break;
            };
            table[n] = Entry {
                key: table[n - 1].key + wrap(sp.thread_angle - angle),
                rpm: sp.thread_rpm,
                position: sp.position,
            };
            angle = sp.thread_angle;
            n += 1;
        }
        let table = &table[..n];
        // Keys run the way the spindle turns.
        let way = if here.thread_rpm < 0.0 { -1.0 } else { 1.0 };
        let (j, frac) = locate(table, way, spindle.turned, |e| e.key);
        let reached = way * (spindle.turned - table[j].key) >= 0.0;
        if n == 1 && reached {
            // The encoder has reached the thread's last setpoint (or the last queued): the
            // clock goes on.
            self.anchor = None;
            return None;
        }
        self.anchor = Some((k + j as u64, table[j].key));
        let mut position = here.position;
        for (i, p) in position.iter_mut().enumerate() {
            let want = spindle.turned + spindle.ahead(lead[i]);
            let of = |e: &Entry| e.key + e.rpm * 6.0 * lead[i];
            let (a, f) = locate(table, way, want, of);
            let from = table[a].position[i];
            let to = table.get(a + 1).map_or(from, |e| e.position[i]);
            *p = from + (to - from) * f;
        }
        Some(CamPlay {
            index: (k + j as u64) as f64 + frac,
            position,
        })
    }
}

/// The last entry of `table` whose abscissa (`of`) the reading `at` has reached, running
/// `way` (±1), and the share of the way to the next one (0 at the table's ends).
fn locate(table: &[Entry], way: f64, at: f64, of: impl Fn(&Entry) -> f64) -> (usize, f64) {
    let mut j = 0;
    while j + 1 < table.len() && way * (at - of(&table[j + 1])) >= 0.0 {
        j += 1;
    }
    let Some(next) = table.get(j + 1) else {
        return (j, 0.0);
    };
    let span = way * (of(next) - of(&table[j]));
    let gone = way * (at - of(&table[j]));
    let frac = if span > 0.0 {
        (gone / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    // The next entry not reached: the share stays below a whole setpoint.
    (j, frac.min(1.0 - f64::EPSILON))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Z on a 1.5 mm helix at 600 rpm (14.4° a tick), as motion queues it: setpoint `t` for
    /// the angle predicted for its tick, its position the helix there plus the lead's turning.
    fn thread(ticks: u64, lead: f64) -> Vec<ServoSetpoint> {
        (1..=ticks)
            .map(|t| {
                let key = 14.4 * t as f64;
                let mut sp = ServoSetpoint {
                    tick: t,
                    scaling: ServoSetpoint::SCALE_THREAD,
                    thread_angle: (100.0 + key).rem_euclid(360.0),
                    thread_rpm: 600.0,
                    ..ServoSetpoint::default()
                };
                sp.position[0] = helix(key + 3600.0 * lead);
                sp
            })
            .collect()
    }

    /// The helix's Z after `degrees` past setpoint 0's angle.
    fn helix(degrees: f64) -> f64 {
        -1.5 * degrees / 360.0
    }

    fn reading(turned_from_100: f64, rpm: f64) -> SpindleReading {
        let mut s = SpindleReading::default();
        s.read(rpm, 100.0);
        let mut done = 0.0;
        while done < turned_from_100 {
            let step = (turned_from_100 - done).min(90.0);
            done += step;
            s.read(rpm, (100.0 + done).rem_euclid(360.0));
        }
        s
    }

    /// Wherever the encoder is between the queued angles, each axis is on the helix at the
    /// reading plus its lead at the speed now, and the index is where the reading lies.
    #[test]
    fn the_cam_puts_the_axis_on_the_helix_at_the_encoders_reading() {
        let lead = [0.012; MAX_AXES];
        let sps = thread(40, 0.012);
        let sample = |m: u64| sps.iter().find(|s| s.tick == m);
        for (turned, rpm) in [
            (144.0, 600.0),
            (150.0, 600.0),
            (151.2, 540.0),
            (200.0, 660.0),
        ] {
            let mut cam = ThreadCam::default();
            let s = reading(turned, rpm);
            let c = cam.follow(10, sample, &s, &lead).expect("a thread");
            let want = helix(turned + rpm * 6.0 * 0.012);
            assert!(
                (c.position[0] - want).abs() < 1e-12,
                "{turned}° at {rpm} rpm: {} not {want}",
                c.position[0]
            );
            assert!((c.index - turned / 14.4).abs() < 1e-9, "index {}", c.index);
        }
    }

    /// A thread setpoint whose angle is no number is played by the clock, not looked up.
    #[test]
    fn a_thread_setpoint_that_is_no_number_plays_by_the_clock() {
        let mut sps = thread(20, 0.0);
        sps[9].thread_angle = f64::NAN;
        let sample = |m: u64| sps.iter().find(|s| s.tick == m);
        let mut cam = ThreadCam::default();
        let lead = [0.0; MAX_AXES];
        assert!(cam
            .follow(10, sample, &reading(144.0, 600.0), &lead)
            .is_none());
    }

    /// Past the thread's last setpoint the clock goes on; before it the cam waits for the
    /// spindle, and a reading behind the index holds the setpoint reached.
    #[test]
    fn the_cam_hands_back_to_the_clock_at_the_threads_end() {
        let lead = [0.0; MAX_AXES];
        let mut sps = thread(20, 0.0);
        sps.push(ServoSetpoint {
            tick: 21,
            ..ServoSetpoint::default()
        });
        let sample = |m: u64| sps.iter().find(|s| s.tick == m);
        let mut cam = ThreadCam::default();
        let c = cam.follow(20, sample, &reading(14.4 * 19.5, 600.0), &lead);
        assert_eq!(c.map(|c| c.index), Some(20.0), "waits for the spindle");
        assert!(cam
            .follow(20, sample, &reading(14.4 * 20.0, 600.0), &lead)
            .is_none());
        assert!(cam
            .follow(21, sample, &reading(14.4 * 21.0, 600.0), &lead)
            .is_none());
        let c = cam
            .follow(5, sample, &reading(14.4 * 4.0, 600.0), &lead)
            .expect("thread");
        assert_eq!(c.index, 5.0, "behind the index: the setpoint reached");
        assert!((c.position[0] - helix(14.4 * 5.0)).abs() < 1e-12);
    }
}
