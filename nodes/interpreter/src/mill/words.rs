//! Mill-only words and codes (`003`, inventory Appendix A.2): the T word that only selects a
//! tool, G43/G44/G49 tool length compensation with H, the D word of cutter compensation, G52
//! local coordinate systems, G10 L2 and G53, G27/G29/G30 and G60. Decisions D47, D48, D50.

use cnc_interpreter_core::{show, Aux, Command, Fault, MoveKind, ProgramError};

use super::{Mill, MillG};
use crate::fanuc::block::{integer_word, Block};
use crate::fanuc::codes::G;
use crate::fanuc::Fanuc;

/// How far short of its end point G60 stops an axis before the final approach, mm (FANUC
/// parameters 0204–0207, no value in the seed; decision D50).
const G60_OVERRUN: f64 = 1.0;

impl Fanuc<Mill> {
    /// G10 L2 Pp: work offset p (1–6 = G54–G59) gets the axis words, added under G91.
    pub(super) fn set_offset_data(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        match b.get('L') {
            Some(2.0) => {}
            Some(l) => {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("G10 L{}: only L2 (work offsets) is built", show(l)),
                ))
            }
            None => return Err(self.fault(Fault::MissingWord, "G10 needs L2")),
        }
        let p = match b.get('P') {
            Some(p) if (1.0..=6.0).contains(&p) && p.fract() == 0.0 => p as u8 - 1,
            Some(p) => {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!("G10 L2 P{}: work offset 1–6 (G54–G59)", show(p)),
                ))
            }
            None => return Err(self.fault(Fault::MissingWord, "G10 L2 needs P (1–6)")),
        };
        for &a in &self.core.setup.axes.clone() {
            if let Some(v) = b.get(a) {
                let base = if self.incremental {
                    self.core.setup.offsets.work(p, a)
                } else {
                    0.0
                };
                self.core
                    .setup
                    .offsets
                    .work
                    .entry(p)
                    .or_default()
                    .insert(a, base + v);
            }
        }
        Ok(())
    }

    /// G53: a rapid to the block's axis words as machine coordinates (absolute only).
    pub(super) fn machine_coordinates(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let mut target = self.core.work_position();
        for (i, &a) in self.core.setup.axes.clone().iter().enumerate() {
            if let Some(v) = b.get(a) {
                if self.incremental {
                    return Err(self.fault(Fault::IllegalWord, "G53 takes absolute positions"));
                }
                target[i] = v - self.core.origin(i);
            }
        }
        self.core.emit(&target, MoveKind::Rapid)
    }

    /// T on the mill: the tool to put ready in the magazine (`003` §6.2, T 0–99); M06 changes
    /// it. Lengths come from H, radii from D, never from T.
    pub(super) fn mill_tool_word(&mut self, t: f64) -> Result<(), ProgramError> {
        let code = integer_word(t).filter(|&c| c <= 99).ok_or_else(|| {
            self.fault(Fault::ToolNumber, format!("T{}: tools are T0–T99", show(t)))
        })?;
        self.core.aux(Aux::T(code as i32));
        self.tool = code;
        Ok(())
    }

    /// An H or D word's offset number, 0–200 (`003` table 7.1; FANUC alarm 030).
    pub(super) fn offset_word(
        &self,
        b: &Block<Mill>,
        letter: char,
    ) -> Result<Option<u32>, ProgramError> {
        let Some(v) = b.get(letter) else {
            return Ok(None);
        };
        integer_word(v)
            .filter(|&n| n <= cnc_machine::tools::MAX_TOOL_NUMBER)
            .map(Some)
            .ok_or_else(|| {
                self.fault(
                    Fault::ToolNumber,
                    format!("{letter}{}: offset numbers are 0–200", show(v)),
                )
            })
    }

    /// G43 (+1) / G44 (−1) / G49 (0) and H: the length of offset H shifts the Z axis's
    /// program zero, so the next Z move puts the tool tip where the program says. A new H
    /// replaces the length; H0 and G49 cancel (Appendix A.2). The compensation takes effect
    /// with the next move, not by a move of its own (decision D47).
    pub(super) fn length_compensation(
        &mut self,
        b: &Block<Mill>,
        sign: Option<i8>,
    ) -> Result<(), ProgramError> {
        let h = self.offset_word(b, 'H')?;
        if let Some(s) = sign {
            self.d.length_sign = s;
        }
        if let Some(h) = h {
            self.d.length_offset = h;
        }
        let Some(z) = self.core.axis('Z') else {
            return Ok(());
        };
        let t = self.core.setup.offsets.tool(self.d.length_offset);
        self.core.tool_offset[z] = if self.d.length_offset == 0 {
            0.0
        } else {
            f64::from(self.d.length_sign) * (t.z + t.wear_z)
        };
        Ok(())
    }

    /// The cutter radius G41/G42 use: offset D of this block, else the modal D (D0: none).
    /// A negative value swaps the side, as on FANUC; beyond ±1000 mm it is P/S 029.
    pub(super) fn cutter_radius(&mut self, b: &Block<Mill>) -> Result<f64, ProgramError> {
        self.refuse_arc_for_comp(b, "G41/G42")?;
        if let Some(d) = self.offset_word(b, 'D')? {
            self.d.radius_offset = d;
        }
        if self.d.radius_offset == 0 {
            return Ok(0.0);
        }
        let r = self.core.setup.offsets.tool(self.d.radius_offset).radius;
        if r.is_finite() && r.abs() <= 1000.0 {
            Ok(r)
        } else {
            Err(self.fault(
                Fault::CompRadiusZero,
                format!(
                    "D{}: radius {} is not usable",
                    self.d.radius_offset,
                    show(r)
                ),
            ))
        }
    }

    /// Cutter compensation starts and ends in G00/G01 blocks, never in an arc (P/S 034).
    pub(super) fn refuse_arc_for_comp(
        &self,
        b: &Block<Mill>,
        code: &str,
    ) -> Result<(), ProgramError> {
        if matches!(b.group(1).unwrap_or(self.motion), G::ArcCw | G::ArcCcw) {
            return Err(self.fault(
                Fault::CompStartNotLine,
                format!("{code} in an arc block: start and cancel compensation with G00/G01"),
            ));
        }
        Ok(())
    }

    /// What needs the tool's own position, not a compensated one, is refused while G41/G42
    /// is in force: G27–G30, G53, G92, G52 and canned cycles (decision D48; LinuxCNC refuses
    /// the same, FANUC ignores compensation in cycles).
    pub(super) fn refuse_under_cutter_comp(&self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let code = b.g.iter().find_map(|&(_, g, _)| match g {
            G::ReferenceReturn => Some("G28"),
            G::Own(MillG::ReferenceCheck) => Some("G27"),
            G::Own(MillG::FromReference) => Some("G29"),
            G::Own(MillG::SecondReference) => Some("G30"),
            G::Own(MillG::MachineCoordinates) => Some("G53"),
            G::SetCoordinate => Some("G92"),
            G::Own(MillG::MillLocal) => Some("G52"),
            G::Own(MillG::HoleCycle(_)) => Some("a canned cycle"),
            _ => None,
        });
        let code = match code {
            Some(c) => c,
            None if self.d.hole.is_some() && b.group(1).is_none() && b.group(9).is_none() => {
                "a canned cycle"
            }
            None => return Ok(()),
        };
        Err(self.fault(
            Fault::CompInCycle,
            format!("{code} while cutter compensation is active: cancel it with G40 first"),
        ))
    }

    /// G30 (P2, the default): through the intermediate point to the second reference point,
    /// where the mill changes tools. P3/P4 name reference points this machine has not got.
    pub(super) fn second_reference(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        if let Some(p) = b.get('P').filter(|&p| p != 2.0) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "G30 P{}: this machine has a second reference point only (P2)",
                    show(p)
                ),
            ));
        }
        let second = self.core.setup.second_reference.clone();
        self.return_through(b, &second)
    }

    /// G27: rapid to the point given, then check it is the reference point (P/S 092 when an
    /// axis named is not there).
    pub(super) fn reference_check(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let end = self.end_point(b)?;
        let named = self.named_axes(b, &end);
        self.core.emit(&end, MoveKind::Rapid)?;
        for (i, &n) in named.iter().enumerate() {
            let reference = self.core.setup.reference.get(i).copied().unwrap_or(0.0);
            if n && (self.core.pos[i] - reference).abs() > 1e-3 {
                return Err(self.fault(
                    Fault::ReferenceCheck,
                    format!(
                        "G27: {} ends at {} in machine coordinates, not at the reference point {}",
                        self.core.setup.axes[i],
                        show(self.core.pos[i]),
                        show(reference)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// G29: from the reference point through the last G28/G30 intermediate point to the point
    /// given, named axes only.
    pub(super) fn return_from_reference(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let end = self.end_point(b)?;
        let named = self.named_axes(b, &end);
        let Some(mid) = self.intermediate.clone() else {
            return Err(self.fault(
                Fault::MissingWord,
                "G29 needs a G28 or G30 before it (no intermediate point)",
            ));
        };
        let mut via = self.core.pos.clone();
        for (i, &n) in named.iter().enumerate() {
            if n {
                via[i] = mid[i];
            }
        }
        self.core.push(Command::Rapid { end: via.clone() });
        self.core.pos = via;
        self.core.emit(&end, MoveKind::Rapid)
    }

    /// G60: every axis that moves comes to its end point from below, rapid to
    /// `G60_OVERRUN` short of it first, so backlash is always taken up the same way.
    pub(super) fn one_direction(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        let end = self.end_point(b)?;
        let here = self.core.work_position();
        let short: Vec<f64> = end
            .iter()
            .zip(&here)
            .map(|(&e, &h)| {
                if (e - h).abs() > 1e-9 {
                    e - G60_OVERRUN
                } else {
                    e
                }
            })
            .collect();
        if short != end {
            self.core.emit(&short, MoveKind::Rapid)?;
        }
        self.core.emit(&end, MoveKind::Rapid)
    }

    /// M06 on the mill: the tool axis must stand at the second reference point (G30), where
    /// the changer reaches the spindle (decision D50).
    pub(super) fn check_tool_change_position(&self) -> Result<(), ProgramError> {
        let Some(z) = self.core.axis('Z') else {
            return Ok(());
        };
        let at = self.core.pos[z];
        let second = self
            .core
            .setup
            .second_reference
            .get(z)
            .copied()
            .unwrap_or(at);
        if (at - second).abs() > 1e-3 {
            return Err(self.fault(
                Fault::ToolChangePosition,
                format!(
                    "M06 with Z at {} (machine): return it to the tool change position with G30 first",
                    show(at)
                ),
            ));
        }
        Ok(())
    }

    /// G52: the local system's zero at the given work coordinates, for every work system;
    /// axes not written keep theirs, `G52 X0 Y0 Z0` cancels (`003` §4.3.4: not cumulative).
    pub(super) fn local_system(&mut self, b: &Block<Mill>) -> Result<(), ProgramError> {
        for (i, &a) in self.core.setup.axes.clone().iter().enumerate() {
            if let Some(v) = b.get(a) {
                self.core.local[i] = v;
            }
        }
        Ok(())
    }
}
