//! The simulated touch probe (measuring input 1). Its stylus is deflected while the slides
//! stand inside one of the configured boxes: the work as the probe finds it, in slide
//! coordinates (where the axes are when the stylus touches, the probe's length included).
//! An edge latches every axis's position where the period's straight path entered or left a
//! box, as a drive's measuring input latches its count at the edge (microseconds, not a
//! servo period, of travel).

use cnc_msgs::servo::{ServoFeedback, MAX_AXES};

/// A box the stylus is deflected in: per axis its lower and upper bound (axes past the
/// bounds' length are not bounded).
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

impl Target {
    fn contains(&self, p: &[f64]) -> bool {
        self.min
            .iter()
            .zip(&self.max)
            .zip(p)
            .all(|((lo, hi), x)| (*lo..=*hi).contains(x))
    }

    /// The part `[t0, t1]` of the path `a + t·(b − a)`, 0 ≤ t ≤ 1, inside the box (the slab
    /// method), if any.
    fn crossing(&self, a: &[f64], b: &[f64]) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for ((lo, hi), (p, q)) in self.min.iter().zip(&self.max).zip(a.iter().zip(b)) {
            let d = q - p;
            if d.abs() < 1e-15 {
                if !(*lo..=*hi).contains(p) {
                    return None;
                }
                continue;
            }
            let (mut u, mut v) = ((lo - p) / d, (hi - p) / d);
            if u > v {
                std::mem::swap(&mut u, &mut v);
            }
            t0 = t0.max(u);
            t1 = t1.min(v);
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}

/// The probe's input and its edge latches.
#[derive(Debug, Clone, Default)]
pub struct Probe {
    targets: Vec<Target>,
    deflected: bool,
    rising: u32,
    falling: u32,
    rising_at: [f64; MAX_AXES],
    falling_at: [f64; MAX_AXES],
}

impl Probe {
    pub fn new(targets: Vec<Target>) -> Self {
        Probe {
            targets,
            ..Probe::default()
        }
    }

    fn inside(&self, p: &[f64]) -> bool {
        self.targets.iter().any(|t| t.contains(p))
    }

    /// The slides went straight from `a` to `b` this period (slide coordinates); `offset` is
    /// each axis's machine position less its encoder count. Reports the input and the edges'
    /// latched counts in `fb`.
    pub fn step(&mut self, a: &[f64], b: &[f64], offset: &[f64], fb: &mut ServoFeedback) {
        let now = self.inside(b);
        let crossings = self.targets.iter().filter_map(|t| t.crossing(a, b));
        let (enter, leave) = crossings.fold((None::<f64>, None::<f64>), |(e, l), (t0, t1)| {
            (
                Some(e.map_or(t0, |e| e.min(t0))),
                Some(l.map_or(t1, |l| l.max(t1))),
            )
        });
        let at = |t: f64, out: &mut [f64; MAX_AXES]| {
            for (i, o) in out.iter_mut().enumerate().take(a.len().min(b.len())) {
                *o = a[i] + t * (b[i] - a[i]) - offset.get(i).copied().unwrap_or(0.0);
            }
        };
        let mut touched = self.deflected;
        if !self.deflected {
            if let Some(t) = enter {
                self.rising = self.rising.wrapping_add(1);
                at(t, &mut self.rising_at);
                touched = true;
            }
        }
        if touched && !now {
            self.falling = self.falling.wrapping_add(1);
            at(leave.unwrap_or(0.0), &mut self.falling_at);
        }
        self.deflected = now;
        fb.probe = u32::from(now);
        fb.probe_rising = self.rising;
        fb.probe_falling = self.falling;
        fb.probe_rising_position = self.rising_at;
        fb.probe_falling_position = self.falling_at;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block() -> Probe {
        // A block whose top face is at Z 10 (X and Y from 0 to 100).
        Probe::new(vec![Target {
            min: vec![0.0, 0.0, -50.0],
            max: vec![100.0, 100.0, 10.0],
        }])
    }

    #[test]
    fn an_edge_latches_where_the_path_crosses_the_face_not_where_the_period_ends() {
        let mut p = block();
        let mut fb = ServoFeedback::default();
        p.step(&[50.0, 50.0, 12.0], &[50.0, 50.0, 10.4], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_rising), (0, 0));
        p.step(
            &[50.0, 50.0, 10.4],
            &[50.0, 50.0, 9.6],
            &[0.0, 0.0, 2.0],
            &mut fb,
        );
        assert_eq!((fb.probe, fb.probe_rising, fb.probe_falling), (1, 1, 0));
        // The face at 10, less the encoder's offset of 2.
        assert!((fb.probe_rising_position[2] - 8.0).abs() < 1e-12);
        assert!((fb.probe_rising_position[0] - 50.0).abs() < 1e-12);
        // Still inside: no new edge.
        p.step(&[50.0, 50.0, 9.6], &[50.0, 50.0, 9.5], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_rising), (1, 1));
        // Backing off: the falling edge where it left the face.
        p.step(&[50.0, 50.0, 9.5], &[50.0, 50.0, 10.5], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_falling), (0, 1));
        assert!((fb.probe_falling_position[2] - 10.0).abs() < 1e-12);
    }

    #[test]
    fn a_touch_within_one_period_counts_both_edges_and_a_miss_none() {
        let mut p = block();
        let mut fb = ServoFeedback::default();
        // Across a corner of the block within one period: in at X 0, out through the top
        // face at X 1.
        p.step(&[-1.0, 50.0, 8.0], &[3.0, 50.0, 12.0], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_rising, fb.probe_falling), (0, 1, 1));
        assert!((fb.probe_rising_position[0] - 0.0).abs() < 1e-12);
        assert!((fb.probe_falling_position[0] - 1.0).abs() < 1e-12);
        // Beside the block: nothing.
        p.step(&[150.0, 50.0, 0.0], &[160.0, 50.0, 0.0], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_rising, fb.probe_falling), (0, 1, 1));
        // No targets: the probe never switches.
        let mut none = Probe::default();
        none.step(&[0.0; 3], &[1.0; 3], &[0.0; 3], &mut fb);
        assert_eq!((fb.probe, fb.probe_rising), (0, 0));
    }
}
