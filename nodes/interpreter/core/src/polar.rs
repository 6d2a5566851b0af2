//! Polar interpolation (decision D141): a program
//! written in the face plane's Cartesian coordinates — the linear axis X and the rotary axis C
//! as a virtual linear axis, both mm — runs on a machine that moves X and turns C. The
//! program's coordinates, through the offsets, are the basic system (the core's position
//! while the transformation is on); this stage maps them onto the machine:
//!
//! ```text
//! u = (X − centre) × scale,  v = C − c_origin     (the face point, mm; scale ½ for diameter)
//! X = centre + √(u² + v²) / scale,  C = atan2(v, u)  (degrees, continuous from 0)
//! ```
//!
//! A straight line or circle of the face is a curve of the machine's axes: it is cut as
//! machine lines whose every point, mapped back, lies within [`FACE_TOLERANCE`] of it, each
//! with the feed that keeps the programmed feed along the face. Near the pole C turns fast
//! for little travel: the machine line's feed is then limited by C's rate in motion, so the
//! feed drops and the path stays (the manual's F < L·R·π/180).

use crate::canon::Command;
use crate::error::{Fault, ProgramError};
use crate::geometry::{arc_sweep, Pt};
use crate::show;
use crate::state::{Core, Plane};

/// Largest distance, on the face, of a machine line from the contour it cuts, mm.
pub const FACE_TOLERANCE: f64 = 0.000_25;

/// Nearest a move may pass the pole (where C would have to turn half a revolution at once), mm.
pub const POLE: f64 = 0.001;

/// Most degrees C turns in one machine line.
const MAX_C_STEP: f64 = 90.0;

/// Most machine lines one move of the face is cut as.
const MAX_CHORDS: usize = 200_000;

/// The transformation in force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polar {
    /// The linear axis (X) and the rotary axis (C) by index.
    pub linear: usize,
    pub rotary: usize,
    /// Machine X (display units) of the rotary axis's centre: the program's X0.
    pub centre: f64,
    /// Display units of the linear axis to mm on the face (½ for a diameter axis).
    pub scale: f64,
    /// The basic system's C where the face's v is 0.
    pub c_origin: f64,
    /// The last machine C given, degrees from the start: the next is taken on its side.
    pub c: f64,
    /// The plane before the transformation, back after it.
    pub plane: Plane,
}

impl Polar {
    /// The face point (mm) of a basic-system point.
    fn face(&self, p: &[f64]) -> Pt {
        Pt::new(
            (p[self.linear] - self.centre) * self.scale,
            p[self.rotary] - self.c_origin,
        )
    }

    /// The machine point of basic-system point `p`, C taken within half a turn of `near`.
    fn machine(&self, p: &[f64], near: f64) -> Vec<f64> {
        let f = self.face(p);
        let mut q = p.to_vec();
        q[self.linear] = self.centre + f.z.hypot(f.r) / self.scale;
        let a = f.r.atan2(f.z).to_degrees();
        q[self.rotary] = near + (a - near + 180.0).rem_euclid(360.0) - 180.0;
        q
    }

    /// The face point of a machine point.
    fn face_of_machine(&self, m: &[f64]) -> Pt {
        let r = (m[self.linear] - self.centre) * self.scale;
        let (s, c) = m[self.rotary].to_radians().sin_cos();
        Pt::new(r * c, r * s)
    }

    /// Length of a machine move in motion's slide units (a diameter axis counts half, C in
    /// degrees), the other axes in `scales`.
    fn slide_length(&self, a: &[f64], b: &[f64], scales: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(scales)
            .map(|((x, y), s)| ((y - x) * s).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// The polar plane: X and C (as Y), Z its normal; arcs by I, J or R.
pub const POLAR_PLANE: Plane = Plane {
    h: 'X',
    v: 'C',
    normal: Some('Z'),
    missing: (
        Fault::PolarAxes,
        "polar interpolation needs the X and C axes",
    ),
};

impl Core {
    /// Polar interpolation on, X the linear axis and C the rotary one. The tool stands at
    /// X > 0 with C at 0; the position becomes the face's, C as mm.
    pub fn polar_on(&mut self) -> Result<(), ProgramError> {
        let (Some(linear), Some(rotary)) = (self.axis('X'), self.axis('C')) else {
            return Err(self.fault(
                Fault::PolarAxes,
                "polar interpolation needs X as its linear axis and C as its rotary axis",
            ));
        };
        if self.polar.is_some() {
            return Err(self.fault(Fault::PolarMode, "polar interpolation is on already"));
        }
        if self.comp.is_some() || self.cylinder.is_some() || !self.couplings.is_empty() {
            return Err(self.fault(
                Fault::PolarMode,
                "polar interpolation starts with no radius compensation, coupling or other \
                 transformation on",
            ));
        }
        if self.feed_per_rev {
            return Err(self.fault(
                Fault::PolarMode,
                "polar interpolation feeds per minute, not per revolution",
            ));
        }
        let work = self.work_position();
        let c = work[rotary].rem_euclid(360.0);
        if work[linear] <= 0.0 || (c > 1e-6 && c < 360.0 - 1e-6) {
            return Err(self.fault(
                Fault::PolarStart,
                format!(
                    "polar interpolation starts with X above 0 and C at 0: X{} C{}",
                    show(work[linear]),
                    show(work[rotary])
                ),
            ));
        }
        let scale = if self.setup.diameter.get(linear) == Some(&true) {
            0.5
        } else {
            1.0
        };
        let c_origin = self.pos[rotary] - work[rotary];
        self.pos[rotary] = c_origin;
        self.controlled.clone_from(&self.pos);
        self.polar = Some(Polar {
            linear,
            rotary,
            centre: self.pos[linear] - work[linear],
            scale,
            c_origin,
            c: 0.0,
            plane: self.plane,
        });
        self.plane = POLAR_PLANE;
        self.push(Command::Contour { on: true });
        Ok(())
    }

    /// Polar interpolation off: the position the machine's again (C in degrees), the plane
    /// as before it.
    pub fn polar_off(&mut self) -> Result<(), ProgramError> {
        let Some(p) = self.polar else {
            return Ok(());
        };
        if self.comp.is_some() {
            return Err(self.fault(
                Fault::PolarMode,
                "polar interpolation ends with radius compensation off",
            ));
        }
        let m = p.machine(&self.pos, p.c);
        self.pos[p.linear] = m[p.linear];
        self.pos[p.rotary] = p.c_origin + m[p.rotary];
        self.plane = p.plane;
        self.polar = None;
        self.push(Command::Contour { on: false });
        Ok(())
    }

    /// Queues `command` (in the basic system, from `from`) as the machine's moves.
    pub(crate) fn push_on_polar(
        &mut self,
        p: Polar,
        from: &[f64],
        command: Command,
    ) -> Result<(), ProgramError> {
        match command {
            Command::Linear { end, feed } => {
                let (a, b) = (from.to_vec(), end.clone());
                let (fa, fb) = (p.face(from), p.face(&end));
                let point = move |t: f64| lerp(&a, &b, t);
                let off_line = move |q: Pt| distance_to_line(q, fa, fb);
                let (h, v) = (p.linear, p.rotary);
                let length = fa
                    .dist(fb)
                    .hypot(dist(&drop(from, h, v), &drop(&end, h, v)));
                self.face_chords(p, &point, &off_line, length, feed)
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                ..
            } => {
                let (h, v) = (p.linear, p.rotary);
                let (fa, fe, fc) = (p.face(from), p.face(&end), p.face(&center));
                let rho = fa.dist(fc);
                let sweep = arc_sweep(fa, fe, fc, !clockwise);
                let a0 = (fa.r - fc.r).atan2(fa.z - fc.z);
                let (from_v, end_v) = (from.to_vec(), end.clone());
                let point = move |t: f64| {
                    let mut q = lerp(&from_v, &end_v, t);
                    if t < 1.0 {
                        let a = a0 + t * sweep;
                        q[h] = p.centre + (fc.z + rho * a.cos()) / p.scale;
                        q[v] = p.c_origin + fc.r + rho * a.sin();
                    }
                    q
                };
                let off_circle = move |q: Pt| (q.dist(fc) - rho).abs();
                let others = dist(&drop(from, h, v), &drop(&end, h, v));
                let length = (rho * sweep).hypot(others);
                self.face_chords(p, &point, &off_circle, length, feed)
            }
            Command::Rapid { .. } => Err(self.fault(
                Fault::PolarMode,
                "a rapid in polar interpolation: position before it, cut with lines and circles",
            )),
            _ => Err(self.fault(
                Fault::PolarMode,
                "threads, tapping, measuring and C-axis moves are not allowed in polar \
                 interpolation",
            )),
        }
    }

    /// Cuts the face curve `point(t)`, t from 0 to 1, `length` mm long, as machine lines
    /// within [`FACE_TOLERANCE`] of it (`off` the distance of a face point from it), each at
    /// the feed that keeps `feed` along the face.
    fn face_chords(
        &mut self,
        mut p: Polar,
        point: &dyn Fn(f64) -> Vec<f64>,
        off: &dyn Fn(Pt) -> f64,
        length: f64,
        feed: f64,
    ) -> Result<(), ProgramError> {
        let scales: Vec<f64> = (0..self.pos.len())
            .map(|i| match i {
                _ if i == p.linear => p.scale,
                _ => 1.0,
            })
            .collect();
        let mut t0: f64 = 0.0;
        let mut m0 = p.machine(&point(0.0), p.c);
        let mut chords = 0;
        while t0 < 1.0 {
            let mut dt = 1.0 - t0;
            let m1 = loop {
                let t1 = (t0 + dt).min(1.0);
                let q = point(t1);
                let f = p.face(&q);
                if f.z.hypot(f.r) < POLE {
                    return Err(self.fault(
                        Fault::PolarMode,
                        format!(
                            "the move passes within {} mm of the pole, where C would turn half \
                             a revolution at once: keep off the centre",
                            show(POLE)
                        ),
                    ));
                }
                let m1 = p.machine(&q, m0[p.rotary]);
                // At most a quarter turn of C a line: C's way is then the curve's (a circle
                // about the pole is one straight machine line either way round).
                let fits = (m1[p.rotary] - m0[p.rotary]).abs() <= MAX_C_STEP
                    && [0.25, 0.5, 0.75]
                        .iter()
                        .all(|&s| off(p.face_of_machine(&lerp(&m0, &m1, s))) <= FACE_TOLERANCE);
                if fits || dt < 1e-9 {
                    break m1;
                }
                dt /= 2.0;
            };
            chords += 1;
            if chords > MAX_CHORDS {
                return Err(self.fault(
                    Fault::PolarMode,
                    format!("a move of the face needs more than {MAX_CHORDS} machine lines"),
                ));
            }
            let t1 = (t0 + dt).min(1.0);
            let face = length * (t1 - t0);
            let slide = p.slide_length(&m0, &m1, &scales);
            let f = if face > 1e-12 && slide > 1e-12 {
                feed * slide / face
            } else {
                feed
            };
            p.c = m1[p.rotary];
            self.push(Command::Linear {
                end: m1.clone(),
                feed: f,
            });
            m0 = m1;
            t0 = t1;
        }
        self.polar = Some(p);
        Ok(())
    }
}

fn lerp(a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect()
}

/// `p` without its axes `h` and `v`.
fn drop(p: &[f64], h: usize, v: usize) -> Vec<f64> {
    p.iter()
        .enumerate()
        .filter(|&(i, _)| i != h && i != v)
        .map(|(_, &x)| x)
        .collect()
}

/// Distance of `q` from the line through `a` and `b`.
fn distance_to_line(q: Pt, a: Pt, b: Pt) -> f64 {
    let (dz, dr) = (b.z - a.z, b.r - a.r);
    let len = dz.hypot(dr);
    if len < 1e-12 {
        return q.dist(a);
    }
    ((q.z - a.z) * dr - (q.r - a.r) * dz).abs() / len
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}
