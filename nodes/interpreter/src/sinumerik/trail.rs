//! Coupled motion, TRAILON/TRAILOF (`001` §9.3.25.1–2; inventory §3.9; decision D115): a
//! following axis travels its coupling factor times its leading axis's travel, besides its
//! own programmed path, in the basic coordinate system (the core's [`Coupling`], applied to
//! every move in machine coordinates). A follower has at most two leaders; a follower may
//! lead another group. `$AA_COUP_ACT[axis]` reads 8 for a follower, else 0.

use cnc_interpreter_core::{Coupling, Fault, ProgramError};

use super::expr::Expr;
use super::Sinumerik;

/// Leading axes one following axis may have (§9.3.25.2 "最多可同时指定 2 个引导轴").
const MAX_LEADERS: usize = 2;

impl Sinumerik {
    /// An axis named as an argument (`V`, `Y`): its index.
    pub(super) fn axis_argument(
        &self,
        what: &str,
        e: &Option<Expr>,
    ) -> Result<usize, ProgramError> {
        let name = match e {
            Some(Expr::Var(n, idx)) if idx.is_empty() => n.as_ref(),
            Some(Expr::Axis(n)) => n.as_ref(),
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    format!("{what}: an axis name (X, Y, Z, …)"),
                ))
            }
        };
        self.axis_named(name).ok_or_else(|| {
            self.fault(
                Fault::NoSuchAxis,
                format!("{what}: {name} is no axis of this machine"),
            )
        })
    }

    /// TRAILON(follow, lead[, factor]): couples `follow` to `lead` (factor 1 by default; a new
    /// factor for a pair already coupled).
    pub(super) fn trail_on(&mut self, args: &[Option<Expr>]) -> Result<(), ProgramError> {
        let (f, l, factor) = match args {
            [f, l] => (f, l, None),
            [f, l, k] => (f, l, k.as_ref()),
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    "TRAILON(following axis, leading axis[, coupling factor])",
                ))
            }
        };
        if self.core.cylinder.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "TRAILON under TRACYL: coupled motion and the cylinder transformation together \
                 are not built",
            ));
        }
        let follow = self.axis_argument("TRAILON", f)?;
        let lead = self.axis_argument("TRAILON", l)?;
        let factor = match factor {
            None => 1.0,
            Some(e) => self.number(e)?,
        };
        if !factor.is_finite() || factor.abs() > 1e6 {
            return Err(self.fault(
                Fault::OutOfRange,
                "TRAILON: the coupling factor is out of range",
            ));
        }
        if follow == lead {
            return Err(self.fault(
                Fault::MacroArgument,
                "TRAILON: an axis cannot follow itself",
            ));
        }
        if self
            .core
            .couplings
            .iter()
            .any(|c| c.follow == lead && c.lead == follow)
        {
            return Err(self.fault(
                Fault::MacroArgument,
                "TRAILON: the two axes would follow each other",
            ));
        }
        let couplings = &mut self.core.couplings;
        if let Some(c) = couplings
            .iter_mut()
            .find(|c| c.follow == follow && c.lead == lead)
        {
            c.factor = factor;
            return Ok(());
        }
        if couplings.iter().filter(|c| c.follow == follow).count() >= MAX_LEADERS {
            return Err(self.fault(
                Fault::MacroArgument,
                "TRAILON: a following axis has at most 2 leading axes",
            ));
        }
        couplings.push(Coupling {
            follow,
            lead,
            factor,
        });
        Ok(())
    }

    /// TRAILOF(follow, lead[, lead2]) ends those couplings, TRAILOF(follow) all of the axis's.
    /// A follower with no leader left takes its position as its program's: what it travelled
    /// coupled is no longer apart from its own path (D115).
    pub(super) fn trail_off(&mut self, args: &[Option<Expr>]) -> Result<(), ProgramError> {
        let Some((f, leads)) = args.split_first() else {
            return Err(self.fault(
                Fault::MacroArgument,
                "TRAILOF(following axis[, leading axis[, leading axis 2]])",
            ));
        };
        if leads.len() > MAX_LEADERS {
            return Err(self.fault(Fault::MacroArgument, "TRAILOF: at most 2 leading axes"));
        }
        let follow = self.axis_argument("TRAILOF", f)?;
        let leads = leads
            .iter()
            .map(|l| self.axis_argument("TRAILOF", l))
            .collect::<Result<Vec<_>, _>>()?;
        self.core
            .couplings
            .retain(|c| c.follow != follow || !(leads.is_empty() || leads.contains(&c.lead)));
        if !self.core.couplings.iter().any(|c| c.follow == follow) {
            self.core.coupled[follow] = 0.0;
        }
        Ok(())
    }

    /// `$AA_COUP_ACT[axis]`: 8 while the axis follows another, else 0.
    pub(super) fn coupling_state(&self, axis: usize) -> f64 {
        if self.core.couplings.iter().any(|c| c.follow == axis) {
            8.0
        } else {
            0.0
        }
    }
}
