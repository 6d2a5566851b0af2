//! G25/G26 (`001` §9.2.11, §9.4.2; inventory §3.7, §4.4): with axis words the lower and upper
//! working-area limits, in machine coordinates of the tool tip, monitored under WALIMON
//! (group 28; WALIMOF, the power-on state, switches it off) before any move of a block is
//! sent: a block that would leave the area stops with 10730 and moves nothing. With S, the
//! spindle's lowest and highest speed: a programmed S outside is held at the limit.

use std::f64::consts::{FRAC_PI_2, TAU};

use cnc_interpreter_core::{show, Command, Fault, ProgramError};

use super::exec::Words;
use super::Sinumerik;

/// The programmed working area and spindle limits.
#[derive(Debug, Clone, Default)]
pub struct Limits {
    /// Per machine axis: lower (G25) and upper (G26) limit of the tool tip.
    pub lower: Vec<Option<f64>>,
    pub upper: Vec<Option<f64>>,
    /// WALIMON.
    pub monitored: bool,
    /// G25 S / G26 S, rpm.
    pub rpm_min: Option<f64>,
    pub rpm_max: Option<f64>,
}

impl Sinumerik {
    /// A G25/G26 block: the limits it sets (an own block: `true`, nothing moves).
    pub(super) fn limits_block(&mut self, w: &Words) -> Result<bool, ProgramError> {
        let lower = w.has_g(25);
        if !lower && !w.has_g(26) {
            return Ok(false);
        }
        let n = self.core.setup.axes.len();
        self.limits.lower.resize(n, None);
        self.limits.upper.resize(n, None);
        if let Some(s) = w.get("S") {
            if !w.axes.is_empty() {
                return Err(self.fault(
                    Fault::IllegalWord,
                    "G25/G26 take either axis limits or S, not both",
                ));
            }
            if !(0.0..=99_999.999).contains(&s) {
                return Err(self.fault(Fault::OutOfRange, "S is 0…99999.999 rpm"));
            }
            if lower {
                self.limits.rpm_min = Some(s);
            } else {
                self.limits.rpm_max = Some(s);
            }
            return Ok(true);
        }
        if w.axes.is_empty() {
            return Err(self.fault(
                Fault::MissingWord,
                "G25/G26 need axis limits (X… Y… Z…) or S",
            ));
        }
        let unit = if self.inch { 25.4 } else { 1.0 };
        for (&i, &(v, _)) in w.axes.iter() {
            let slot = if lower {
                &mut self.limits.lower
            } else {
                &mut self.limits.upper
            };
            slot[i] = Some(v * unit);
        }
        Ok(true)
    }

    /// The spindle speed a program asks for, held within G25 S / G26 S.
    pub(super) fn limited_rpm(&self, s: f64) -> f64 {
        let s = self.limits.rpm_max.map_or(s, |m| s.min(m));
        self.limits.rpm_min.map_or(s, |m| s.max(m))
    }

    /// Under WALIMON: every move queued from `from` on (what this block produced) stays in
    /// the working area, arcs with their extreme points; `start` is the machine position
    /// the first of them starts from.
    pub(super) fn check_work_area(&self, from: usize, start: &[f64]) -> Result<(), ProgramError> {
        if !self.limits.monitored {
            return Ok(());
        }
        let mut here = start.to_vec();
        for c in self.core.queued_since(from) {
            let Some(end) = c.end() else { continue };
            let mut points = vec![end.to_vec()];
            if let Command::Arc {
                center,
                clockwise,
                plane,
                ..
            } = c
            {
                let axes = match plane {
                    Some([h, v]) => (usize::from(*h), usize::from(*v)),
                    None => self.core.plane_axes()?,
                };
                points.extend(arc_extremes(&here, end, center, *clockwise, axes));
            }
            for p in &points {
                self.in_area(p)?;
            }
            here = end.to_vec();
        }
        Ok(())
    }

    fn in_area(&self, machine: &[f64]) -> Result<(), ProgramError> {
        for (i, m) in machine.iter().enumerate() {
            let tip = m - self.core.tool_offset.get(i).copied().unwrap_or(0.0);
            let letter = self.core.setup.axes[i];
            let lo = self.limits.lower.get(i).copied().flatten();
            let hi = self.limits.upper.get(i).copied().flatten();
            let out = lo.is_some_and(|l| tip < l - 1e-9) || hi.is_some_and(|h| tip > h + 1e-9);
            if out {
                let mut e = self.fault(
                    Fault::OutOfRange,
                    format!(
                        "axis {letter}: working area limitation {}…{} (G25/G26, WALIMON): the block goes to {}",
                        lo.map_or("–".into(), show),
                        hi.map_or("–".into(), show),
                        show(tip)
                    ),
                );
                e.number = 10730;
                return Err(e);
            }
        }
        Ok(())
    }
}

/// The points where an arc from `start` to `end` about `center` reaches its extremes along
/// the plane axes `h`, `v` (the quarter points its sweep passes).
fn arc_extremes(
    start: &[f64],
    end: &[f64],
    center: &[f64],
    clockwise: bool,
    (h, v): (usize, usize),
) -> Vec<Vec<f64>> {
    let (Some(&ch), Some(&cv)) = (center.get(h), center.get(v)) else {
        return Vec::new();
    };
    let r = (start[h] - ch).hypot(start[v] - cv);
    let a0 = (start[v] - cv).atan2(start[h] - ch);
    let a1 = (end[v] - cv).atan2(end[h] - ch);
    let mut sweep = if clockwise {
        (a0 - a1).rem_euclid(TAU)
    } else {
        (a1 - a0).rem_euclid(TAU)
    };
    if sweep < 1e-12 {
        sweep = TAU;
    }
    (0..4)
        .filter_map(|k| {
            let q = f64::from(k) * FRAC_PI_2;
            let along = if clockwise {
                (a0 - q).rem_euclid(TAU)
            } else {
                (q - a0).rem_euclid(TAU)
            };
            (along <= sweep).then(|| {
                let mut p = start.to_vec();
                p[h] = ch + r * q.cos();
                p[v] = cv + r * q.sin();
                p
            })
        })
        .collect()
}
