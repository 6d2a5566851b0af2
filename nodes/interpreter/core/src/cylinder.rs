//! The cylinder surface transformation: a program written on the developed surface of a
//! cylinder (X the radial infeed, the surface axis — Y — the developed circumference at the
//! machining radius, Z along the cylinder's axis) runs on a machine that turns the cylinder
//! with a rotary axis. The program's coordinates, through the frames and offsets, are the
//! basic coordinate system (the core's position while the transformation is on); this stage
//! maps them onto the machine's axes:
//!
//! ```text
//! rotary  = rotary_at_zero + (surface − wall) / radius   (degrees)
//! surface = centre + wall                                (the real slide)
//! ```
//!
//! `wall` is the part of the radius compensation's offset along the surface axis: with a
//! real slide on that axis (standing on the rotary axis's centre when the transformation
//! starts) the offset across a groove is made by the slide, not by turning the cylinder, so
//! groove walls come out parallel to the groove's centre plane whatever the cutter's
//! diameter. Lines map to single machine lines (the rotary axis is linear in the developed
//! coordinate); circles of the developed surface are cut as chords within
//! [`CHORD_TOLERANCE`]; each machine line gets the feed that keeps the programmed feed along
//! the developed path.

use crate::canon::Command;
use crate::error::{Fault, ProgramError};
use crate::geometry::{arc_sweep, Pt};
use crate::show;
use crate::state::Core;

/// Largest distance of a chord from the developed circle it cuts, mm.
pub const CHORD_TOLERANCE: f64 = 0.001;

/// Most chords one circle of the developed surface is cut as.
const MAX_CHORDS: usize = 100_000;

/// The transformation in force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// The rotary axis that turns the cylinder.
    pub rotary: usize,
    /// The axis of the developed circumference (and the real slide across a groove).
    pub surface: usize,
    /// Half the machining diameter, mm.
    pub radius: f64,
    /// The rotary axis's position where the developed coordinate is 0, degrees.
    pub rotary_at_zero: f64,
    /// Where the real slide stood when the transformation started: on the rotary axis's
    /// centre.
    pub centre: f64,
}

impl Cylinder {
    /// The machine position of the basic-system point `p` with the compensation's offset
    /// `wall` along the surface axis.
    fn machine(&self, p: &[f64], wall: f64) -> Vec<f64> {
        let mut q = p.to_vec();
        q[self.rotary] =
            self.rotary_at_zero + ((p[self.surface] - wall) / self.radius).to_degrees();
        q[self.surface] = self.centre + wall;
        q
    }
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn rotate(v: Pt, angle: f64) -> Pt {
    let (s, c) = angle.sin_cos();
    Pt::new(v.z * c - v.r * s, v.z * s + v.r * c)
}

impl Core {
    /// Switches the transformation on: `rotary` turns a cylinder of machining diameter
    /// `diameter` whose developed circumference the program writes on `surface`; the real
    /// slide on `surface` stands where it is, on the rotary axis's centre. The position
    /// becomes the developed one, continuing from where the rotary axis stands.
    pub fn cylinder_on(
        &mut self,
        rotary: usize,
        surface: usize,
        diameter: f64,
        rotary_at_zero: f64,
    ) -> Result<(), ProgramError> {
        if self.comp.is_some() || !self.couplings.is_empty() || self.cylinder.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "the cylinder transformation starts with no radius compensation, coupling or \
                 other transformation on",
            ));
        }
        if !(diameter.is_finite() && diameter > 0.0) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("machining diameter {} is not above 0", show(diameter)),
            ));
        }
        let radius = diameter / 2.0;
        let c = Cylinder {
            rotary,
            surface,
            radius,
            rotary_at_zero,
            centre: self.pos[surface],
        };
        self.pos[surface] = (self.pos[rotary] - rotary_at_zero).to_radians() * radius;
        self.controlled.clone_from(&self.pos);
        self.cylinder = Some(c);
        self.wall = Pt::new(0.0, 0.0);
        self.out_offset = None;
        Ok(())
    }

    /// Switches the transformation off: the position is the machine's again.
    pub fn cylinder_off(&mut self) -> Result<(), ProgramError> {
        let Some(c) = self.cylinder else {
            return Ok(());
        };
        if self.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                "the cylinder transformation ends with radius compensation off: G40 first",
            ));
        }
        self.pos = c.machine(&self.pos, 0.0);
        self.cylinder = None;
        Ok(())
    }

    /// The compensation offset's part along the surface axis.
    fn wall_along(&self, c: &Cylinder, v: Pt) -> f64 {
        match self.plane_axes() {
            Ok((h, _)) if h == c.surface => v.z,
            Ok((_, w)) if w == c.surface => v.r,
            _ => 0.0,
        }
    }

    /// Queues `command` (in the basic system, from `from`) as the machine's moves.
    pub(crate) fn push_on_cylinder(
        &mut self,
        c: Cylinder,
        from: &[f64],
        command: Command,
    ) -> Result<(), ProgramError> {
        let w0 = self.wall;
        // The offset at the move's end: what compensation gave with it, or none.
        let w1 = self.out_offset.take().unwrap_or(Pt::new(0.0, 0.0));
        self.wall = w1;
        let start = c.machine(from, self.wall_along(&c, w0));
        match command {
            Command::Rapid { end } => {
                let end = c.machine(&end, self.wall_along(&c, w1));
                self.push(Command::Rapid { end });
            }
            Command::Linear { end, feed } => {
                let to = c.machine(&end, self.wall_along(&c, w1));
                let feed = machine_feed(feed, dist(from, &end), &start, &to);
                self.push(Command::Linear { end: to, feed });
            }
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                plane,
            } => {
                let (h, v) = match plane {
                    Some([h, v]) => (usize::from(h), usize::from(v)),
                    None => self.plane_axes()?,
                };
                let on_plane = |p: &[f64]| Pt::new(p[h], p[v]);
                let (a, mid) = (on_plane(from), on_plane(&center));
                let a0 = (a.r - mid.r).atan2(a.z - mid.z);
                let rho = a.dist(mid);
                let sweep = arc_sweep(a, on_plane(&end), mid, !clockwise);
                let step = if rho > CHORD_TOLERANCE {
                    2.0 * (1.0 - CHORD_TOLERANCE / rho).acos()
                } else {
                    std::f64::consts::PI
                };
                let n = (sweep.abs() / step).ceil().max(1.0);
                if n > MAX_CHORDS as f64 {
                    return Err(self.fault(
                        Fault::ArcRadius,
                        format!(
                            "a circle of radius {} on the developed surface needs more than \
                             {MAX_CHORDS} chords",
                            show(rho)
                        ),
                    ));
                }
                let n = n as usize;
                let mut prev_bcs = from.to_vec();
                let mut prev = start;
                for k in 1..=n {
                    let t = k as f64 / n as f64;
                    let mut p: Vec<f64> = from
                        .iter()
                        .zip(&end)
                        .map(|(a, b)| a + t * (b - a))
                        .collect();
                    if k < n {
                        let a = a0 + t * sweep;
                        p[h] = center[h] + rho * a.cos();
                        p[v] = center[v] + rho * a.sin();
                    }
                    // The offset turns with the circle (around a corner, or off an arc).
                    let w = if k < n { rotate(w0, t * sweep) } else { w1 };
                    let q = c.machine(&p, self.wall_along(&c, w));
                    let f = machine_feed(feed, dist(&prev_bcs, &p), &prev, &q);
                    self.push(Command::Linear {
                        end: q.clone(),
                        feed: f,
                    });
                    prev_bcs = p;
                    prev = q;
                }
            }
            _ => {
                return Err(self.fault(
                    Fault::NotSupported,
                    "threads, tapping and measuring are not built under the cylinder \
                     transformation",
                ))
            }
        }
        Ok(())
    }
}

/// The feed of a machine line from `a` to `b` that takes as long as `length` of developed
/// path at `feed`.
fn machine_feed(feed: f64, length: f64, a: &[f64], b: &[f64]) -> f64 {
    let machine = dist(a, b);
    if length > 1e-12 && machine > 1e-12 {
        feed * machine / length
    } else {
        feed
    }
}
