//! Mill-only words and codes (`003`, inventory Appendix A.2): the T word that only selects a
//! tool, G43/G44/G49 tool length compensation with H, and G52 local coordinate systems.
//! Decision D47.

use super::*;

impl Interpreter {
    /// T on the mill: the tool to put ready in the magazine (`003` §6.2, T 0–99); M06 changes
    /// it. Lengths come from H, radii from D, never from T.
    pub(super) fn mill_tool_word(&mut self, t: f64) -> Result<(), ProgramError> {
        let code = integer_word(t).filter(|&c| c <= 99).ok_or_else(|| {
            self.fault(Fault::ToolNumber, format!("T{}: tools are T0–T99", show(t)))
        })?;
        self.aux(Aux::T(code as i32));
        self.tool = code;
        Ok(())
    }

    /// An H or D word's offset number, 0–200 (`003` table 7.1; FANUC alarm 030).
    pub(super) fn offset_word(&self, b: &Block, letter: char) -> Result<Option<u32>, ProgramError> {
        let Some(v) = b.get(letter) else {
            return Ok(None);
        };
        integer_word(v)
            .filter(|&n| n <= cnc_runtime::tool_table::MAX_TOOL_NUMBER)
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
        b: &Block,
        sign: Option<i8>,
    ) -> Result<(), ProgramError> {
        let h = self.offset_word(b, 'H')?;
        if let Some(s) = sign {
            self.length_sign = s;
        }
        if let Some(h) = h {
            self.length_offset = h;
        }
        let Some(z) = self.axis('Z') else {
            return Ok(());
        };
        let t = self.setup.offsets.tool(self.length_offset);
        self.tool_offset[z] = if self.length_offset == 0 {
            0.0
        } else {
            f64::from(self.length_sign) * (t.z + t.wear_z)
        };
        Ok(())
    }

    /// G52: the local system's zero at the given work coordinates, for every work system;
    /// axes not written keep theirs, `G52 X0 Y0 Z0` cancels (`003` §4.3.4: not cumulative).
    pub(super) fn local_system(&mut self, b: &Block) -> Result<(), ProgramError> {
        for (i, &a) in self.setup.axes.clone().iter().enumerate() {
            if let Some(v) = b.get(a) {
                self.local[i] = v;
            }
        }
        Ok(())
    }
}
