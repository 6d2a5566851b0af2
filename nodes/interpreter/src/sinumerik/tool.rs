//! Tools, cutting edges and radius compensation (`001` §9.6; inventory §3.7, §5.2–§5.3).
//! T selects a tool and its edge D1; D1–D9 choose the edge, D0 none. An edge's offsets are
//! the offset page's entry T×10+D (decision D80): its Z length (geometry plus wear) is the
//! tool length along the axis normal to the plane (G17 Z, G18 Y, G19 X), its radius the
//! cutter radius of G41/G42. Whether T changes the tool at once or only preselects it for M6
//! is the machine's choice (`Setup::tool_change_with_m6`).

use cnc_interpreter_core::comp::{Side, Startup};
use cnc_interpreter_core::{Aux, Fault, ProgramError};

use super::exec::Words;
use super::{plane_of, Motion, Sinumerik};

impl Sinumerik {
    /// T, D, M6 and the G40/G41/G42 choice of the block. With M6 changing tools (D127): a D
    /// in the block that preselects the tool is that tool's edge and waits for M6 with it; a D
    /// in the M6 block wins over it; with neither the new tool comes with D1 (§9.6.3's
    /// "N55 D3 M6 ; T4 and its D3"); a D in any other block is the active tool's edge.
    pub(super) fn tool_words(&mut self, w: &Words) -> Result<(), ProgramError> {
        let d = match w.get("D") {
            Some(d) if d.fract() != 0.0 || !(0.0..=9.0).contains(&d) => {
                return Err(self.fault(Fault::ToolNumber, "D is 0…9: a cutting edge of the tool"))
            }
            d => d.map(|d| d as u32),
        };
        let m6 = w.m.contains(&6);
        let mut d_for_active = d;
        if let Some(t) = w.get("T") {
            if t.fract() != 0.0 || !(0.0..=32_000.0).contains(&t) {
                return Err(self.fault(Fault::ToolNumber, "T is 0…32000"));
            }
            let t = t as u32;
            self.core.aux(Aux::T(t as i32));
            if self.core.setup.tool_change_with_m6 {
                self.preselected = Some(t);
                self.preselected_edge = None;
                if !m6 {
                    // The edge of the tool to come, not of the one in the spindle.
                    self.preselected_edge = d_for_active.take();
                }
            } else {
                self.change_tool(t)?;
            }
        }
        if m6 {
            self.core.aux(Aux::M(6));
            if let Some(t) = self.preselected.take() {
                self.change_tool(t)?;
                let held = self.preselected_edge.take();
                if d_for_active.is_none() {
                    d_for_active = held;
                }
            }
        }
        if let Some(d) = d_for_active {
            if d > 0 && self.tool == 0 {
                return Err(self.fault(Fault::ToolNumber, "D without an active tool: T first"));
            }
            self.edge = d;
            self.edge_loaded();
            self.apply_length();
            self.change_compensation_radius()?;
        }
        for g in [40, 41, 42] {
            if w.has_g(g) {
                self.comp_side = match g {
                    41 => Some(Side::Left),
                    42 => Some(Side::Right),
                    _ => None,
                };
                if g == 40 && self.core.comp.is_some() {
                    self.core.comp_cancel = true;
                }
                self.comp_again = g != 40 && self.core.comp.is_some();
            }
        }
        Ok(())
    }

    /// The tool becomes active with its first edge (§9.6.2); T0 leaves none.
    fn change_tool(&mut self, t: u32) -> Result<(), ProgramError> {
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                "tool change while radius compensation is active: G40 first",
            ));
        }
        self.check_not_disabled(t)?;
        self.tool = t;
        // The machine now holds it: the next program starts with it (kept across power-off).
        self.core.setup.active_tool = t;
        self.edge = u32::from(t > 0);
        self.edge_loaded();
        self.apply_length();
        Ok(())
    }

    /// The active edge's entry on the offset page.
    pub(super) fn offset_entry(&self) -> Option<cnc_interpreter_core::ToolOffset> {
        (self.tool > 0 && self.edge > 0)
            .then(|| self.core.setup.offsets.tool(self.tool * 10 + self.edge))
    }

    /// Tool length along the plane's normal axis: taken up by the next move of that axis
    /// (§9.6.3).
    pub(super) fn apply_length(&mut self) {
        let length = self.offset_entry().map_or(0.0, |o| o.z + o.wear_z);
        for v in self.core.tool_offset.iter_mut() {
            *v = 0.0;
        }
        if let Some(i) = self.core.plane_normal() {
            self.core.tool_offset[i] = length;
        }
    }

    /// G17/G18/G19: the plane, the length axis with it, and polar coordinates start over.
    pub(super) fn set_plane(&mut self, code: u8) -> Result<(), ProgramError> {
        if code == self.plane_code {
            return Ok(());
        }
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompPlane,
                "the plane cannot change while radius compensation is active: G40 first",
            ));
        }
        self.plane_code = code;
        self.core.plane = plane_of(code);
        self.polar = (0.0, 0.0);
        self.tangent = None;
        self.apply_length();
        Ok(())
    }

    /// Starts radius compensation with the block's move, which must be a straight one
    /// (§9.6.4): the move ends perpendicular to the next element's start.
    pub(super) fn start_compensation(&mut self) -> Result<(), ProgramError> {
        if self.comp_side.is_none() {
            return Ok(());
        }
        if self.core.comp.is_some() && !std::mem::take(&mut self.comp_again) {
            return Ok(());
        }
        if !matches!(self.motion, Motion::Rapid | Motion::Line) {
            return Err(self.fault(Fault::CompStartNotLine, "G41/G42 start in a G0 or G1 block"));
        }
        self.begin_compensation()
    }

    /// Starts compensation on the side asked for with the next move, whatever the block's
    /// motion (a WAB approach's first move is its own, §9.14).
    pub(super) fn begin_compensation(&mut self) -> Result<(), ProgramError> {
        let Some(side) = self.comp_side else {
            return Ok(());
        };
        let offset = self.compensation_offset()?;
        // OFFN widens the offset (an allowance, half a slot's width); past the centre line
        // the path lies on the other side, which is how the manual switches G41↔G42 with a
        // negative OFFN (D96).
        let side = match side {
            Side::Left if offset < 0.0 => Side::Right,
            Side::Right if offset < 0.0 => Side::Left,
            s => s,
        };
        let radius = offset.abs();
        if self.core.comp.is_some() {
            // G41/G42 again without G40 (the same side or the other): the old ends normal to
            // its last element, the new starts normal to this one (§9.6.7, D104).
            self.core.comp_restart = Some((side, radius));
            return Ok(());
        }
        self.core
            .start_comp(side, radius, 0, Startup::ToNextElement)
    }

    /// The signed offset of compensation in the program's coordinates: the active edge's
    /// radius plus OFFN, divided by the frame's scale (so the machine path keeps the tool's
    /// radius); negative: past the centre line, on the other side.
    fn compensation_offset(&self) -> Result<f64, ProgramError> {
        let entry = self.offset_entry().ok_or_else(|| {
            self.fault(
                Fault::CompRadiusZero,
                "radius compensation without an active tool edge (T and D)",
            )
        })?;
        let (h, v) = self.core.plane_axes()?;
        let factor = match self.core.frame.plane_similarity(h, v) {
            Some((f, _)) => f,
            None if self.core.frame.is_identity() => 1.0,
            None => {
                return Err(self.fault(
                    Fault::CompInCycle,
                    "radius compensation under a frame that distorts the plane",
                ))
            }
        };
        // Under TRACYL compensation refers to the groove wall, OFFN from the centre line, and
        // the cutter runs inside it (§9.15, D117).
        let offset = if self.core.cylinder.is_some() {
            self.contour_offset - entry.radius
        } else {
            entry.radius + self.contour_offset
        };
        Ok(offset / factor)
    }

    /// A new edge or OFFN while compensation runs (§9.6.7 "补偿号的更换"): the new radius
    /// takes effect along the next move in the plane, from the old at its start to the new
    /// at its end (D105). Past the centre line it would change sides: refused.
    fn change_compensation_radius(&mut self) -> Result<(), ProgramError> {
        if self.core.comp.is_none() {
            return Ok(());
        }
        let offset = self.compensation_offset()?;
        let side = self.core.comp.as_ref().map(|c| c.side());
        let started = self.comp_side;
        let same_side = (offset >= 0.0) == (side == started);
        if !same_side {
            return Err(self.fault(
                Fault::CompDirection,
                "the new radius and OFFN put the path past the contour, on the other side: \
                 change sides with G41/G42",
            ));
        }
        if let Some(c) = self.core.comp.as_mut() {
            c.change_radius(offset.abs());
        }
        Ok(())
    }

    /// OFFN=: taken up by the next start of compensation, or under compensation along the
    /// next move (D105).
    pub(super) fn set_contour_offset(&mut self, offn: f64) -> Result<(), ProgramError> {
        if !offn.is_finite() || offn.abs() > 10_000.0 {
            return Err(self.fault(Fault::OutOfRange, "OFFN= is within ±10000 mm"));
        }
        let changed = offn != self.contour_offset;
        self.contour_offset = offn;
        if changed {
            self.change_compensation_radius()?;
        }
        Ok(())
    }
}
