//! What the machine builder rates the machine for: travel and drive ratings per axis and the
//! spindle's top speed (decisions D61). Only the machine's own launch file sets them (the
//! `limits` section is no parameter); an axis it does not name is rated at its values as
//! that file gives them. A parameter written from the cell may lower a rating, down to a
//! hundredth of it (so every move still ends), never raise it.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::config::AxisEntry;
use crate::parameter_rules::show;

/// The lowest fraction of a rating a parameter may set: a move at 1 % of the rapid rate and
/// acceleration still ends (300 mm at 60 mm/min: five minutes).
pub const LOWEST_FRACTION: f64 = 0.01;

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MachineLimits {
    /// Per axis name: travel and drive ratings.
    #[serde(default)]
    pub axes: BTreeMap<String, AxisLimits>,
    /// The spindle drive's top speed, rpm: every commanded speed, override included, is
    /// clamped to it. Absent: 6000 rpm.
    #[serde(default = "default_spindle_max")]
    pub spindle_max_rpm: f64,
    /// The builder's value of each monitor (`parameter_rules`: following error, in-position
    /// window, lateness alarms, tolerances), by parameter name: the cell may tighten a monitor,
    /// never loosen it beyond this. Taken from the machine's own file as read
    /// ([`crate::parameters::builder_monitors`]) where the section does not name it.
    #[serde(default)]
    pub monitors: BTreeMap<String, f64>,
}

fn default_spindle_max() -> f64 {
    6000.0
}

impl Default for MachineLimits {
    fn default() -> Self {
        MachineLimits {
            axes: BTreeMap::new(),
            spindle_max_rpm: default_spindle_max(),
            monitors: BTreeMap::new(),
        }
    }
}

/// One axis's travel (display units, as `min`/`max` of the axis) and drive ratings.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AxisLimits {
    pub min: f64,
    pub max: f64,
    /// mm/min of slide travel.
    pub max_velocity: f64,
    /// mm/s² of slide travel.
    pub max_acceleration: f64,
    /// mm/s³; absent: the axis's jerk as the machine's file gives it.
    #[serde(default)]
    pub max_jerk: Option<f64>,
}

impl AxisLimits {
    fn of(a: &AxisEntry) -> AxisLimits {
        AxisLimits {
            min: a.min,
            max: a.max,
            max_velocity: a.max_velocity,
            max_acceleration: a.max_acceleration,
            max_jerk: Some(a.jerk()),
        }
    }
}

impl MachineLimits {
    /// Rates every axis the section does not name at its values in the machine's file; run
    /// once, on the file as read, before any parameter is applied.
    pub fn complete(&mut self, axes: &[AxisEntry]) {
        for a in axes {
            self.axes
                .entry(a.name.clone())
                .or_insert_with(|| AxisLimits::of(a));
        }
    }

    /// Checks the ratings themselves, then every axis against them; an error names the
    /// setting, its value and the limit.
    pub fn check(&self, axes: &[AxisEntry]) -> Result<(), String> {
        let s = self.spindle_max_rpm;
        if !(s.is_finite() && s > 0.0 && s <= 100_000.0) {
            return Err(format!(
                "limits.spindle_max_rpm {}: 0 < rpm ≤ 100000",
                show(s)
            ));
        }
        for (name, l) in &self.axes {
            let Some(a) = axes.iter().find(|a| &a.name == name) else {
                return Err(format!("limits.axes.{name}: no such axis in machine.axes"));
            };
            let rated = [l.min, l.max, l.max_velocity, l.max_acceleration]
                .into_iter()
                .chain(l.max_jerk)
                .all(f64::is_finite)
                && l.min < l.max
                && l.max_velocity > 0.0
                && l.max_acceleration > 0.0
                && l.max_jerk.is_none_or(|j| j > 0.0);
            if !rated {
                return Err(format!(
                    "limits.axes.{name}: finite values, min < max, positive velocity, \
                     acceleration and jerk"
                ));
            }
            check_axis(a, l)?;
        }
        Ok(())
    }
}

/// One axis's settings against its ratings.
fn check_axis(a: &AxisEntry, l: &AxisLimits) -> Result<(), String> {
    let n = &a.name;
    let travel = |what: &str, v: f64| {
        if v.is_finite() && (l.min..=l.max).contains(&v) {
            Ok(())
        } else {
            Err(format!(
                "machine.axes.{n}.{what} {}: outside the rated travel {}..{}",
                show(v),
                show(l.min),
                show(l.max)
            ))
        }
    };
    travel("min", a.min)?;
    travel("max", a.max)?;
    let rating = |what: &str, v: f64, rated: f64| {
        let low = rated * LOWEST_FRACTION;
        if v.is_finite() && v >= low && v <= rated {
            Ok(())
        } else {
            Err(format!(
                "machine.axes.{n}.{what} {}: the machine is rated {}..{} \
                 (limits.axes.{n}.{what})",
                show(v),
                show(low),
                show(rated)
            ))
        }
    };
    rating("max_velocity", a.max_velocity, l.max_velocity)?;
    rating("max_acceleration", a.max_acceleration, l.max_acceleration)?;
    if let Some(j) = l.max_jerk {
        rating("max_jerk", a.jerk(), j)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis() -> AxisEntry {
        serde_yaml::from_str(
            "{ name: X, min: -2.0, max: 300.0, max_velocity: 6000.0, max_acceleration: 1500.0 }",
        )
        .unwrap()
    }

    #[test]
    fn an_axis_unnamed_is_rated_at_its_own_values_and_may_only_be_lowered() {
        let mut limits = MachineLimits {
            spindle_max_rpm: 3000.0,
            ..Default::default()
        };
        let mut a = axis();
        limits.complete(std::slice::from_ref(&a));
        assert!(limits.check(std::slice::from_ref(&a)).is_ok());
        a.max_velocity = 3000.0;
        assert!(limits.check(std::slice::from_ref(&a)).is_ok());
        a.max_velocity = 6001.0;
        let e = limits.check(std::slice::from_ref(&a)).unwrap_err();
        assert!(
            e.contains("max_velocity 6001") && e.contains("60..6000"),
            "{e}"
        );
        a.max_velocity = 6000.0;
        a.max_acceleration = 1e-300;
        let e = limits.check(std::slice::from_ref(&a)).unwrap_err();
        assert!(
            e.contains("max_acceleration") && e.contains("15..1500"),
            "{e}"
        );
        a.max_acceleration = 1500.0;
        a.max = 1e308;
        let e = limits.check(std::slice::from_ref(&a)).unwrap_err();
        assert!(e.contains("rated travel -2..300"), "{e}");
    }
}
