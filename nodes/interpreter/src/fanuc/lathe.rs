//! What the family's lathe dialects share: the Z-X plane, tool offsets applied by T, the
//! lathe variable map, and tool-nose compensation started from the offset page.

use cnc_interpreter_core::comp::Startup;
use cnc_interpreter_core::{show, Aux, CompRules, Fault, Plane, ProgramError};

use super::block::{integer_word, Block};
use super::codes::G;
use super::expr::{EvalError, Value};
use super::{Family, Fanuc};

/// The lathe's working plane, Z-X.
pub const LATHE_PLANE: Plane = Plane {
    h: 'Z',
    v: 'X',
    normal: None,
    missing: (Fault::AxisAddress, "this function needs the X and Z axes"),
};

/// Tool-nose compensation on a lathe whose G00 may not run under it.
pub const LATHE_COMP: CompRules = CompRules {
    refuse_rapid: true,
    name: "tool-nose compensation",
};

/// Largest tool offset number (#4001–#4099: 99 offsets).
pub const MAX_OFFSET: u32 = 99;

/// Thread modal words (F/I lead, J/K run-out).
#[derive(Debug, Clone, Copy, Default)]
pub struct ThreadWords {
    pub lead: f64,
    pub j: Option<f64>,
    pub k: Option<f64>,
}

impl<D: Family> Fanuc<D> {
    /// G17/G19 on a lathe: it works in G18 only.
    pub fn lathe_plane(&mut self, g: G<D::G>) -> Result<(), ProgramError> {
        match g {
            G::PlaneXy | G::PlaneYz => Err(self.fault(
                Fault::NotSupported,
                "G17/G19 need a Y axis; this lathe works in G18",
            )),
            _ => Ok(()),
        }
    }

    /// The tool and offset numbers of a lathe T word: `Tmmnn` (tool mm, offset nn), `T1` =
    /// tool 1 offset 1 (decision D16).
    pub fn lathe_tool_numbers(&self, t: f64) -> Result<(Option<u32>, u32), ProgramError> {
        let code = integer_word(t).ok_or_else(|| {
            self.fault(
                Fault::ToolNumber,
                format!("tool word T{} must be an integer", show(t)),
            )
        })?;
        if code < 100 {
            Ok((Some(code), code))
        } else if code <= 9999 {
            Ok((Some(code / 100), code % 100))
        } else {
            Err(self.fault(Fault::ToolNumber, format!("T{code} out of range")))
        }
    }

    /// Selects `tool` (with the T strobe, if any) and makes `offset` the active offset.
    pub fn select_tool(&mut self, tool: Option<u32>, offset: u32) -> Result<(), ProgramError> {
        if offset > MAX_OFFSET {
            return Err(self.fault(
                Fault::ToolNumber,
                format!("offset number {offset} out of range"),
            ));
        }
        if let Some(tool) = tool.filter(|&t| t > 0) {
            self.core.aux(Aux::T(tool as i32));
            self.tool = tool;
        }
        self.apply_offset(offset);
        Ok(())
    }

    /// Makes `offset` the active tool offset (0 = none).
    pub fn apply_offset(&mut self, offset: u32) {
        // The offset takes effect with the next move: the work position shifts.
        self.offset_number = offset;
        let o = self.core.setup.offsets.tool(offset);
        for (i, &a) in self.core.setup.axes.iter().enumerate() {
            self.core.tool_offset[i] = if offset == 0 {
                0.0
            } else {
                match a {
                    'X' => o.x + o.wear_x,
                    'Z' => o.z + o.wear_z,
                    _ => 0.0,
                }
            };
        }
    }

    /// Variable `n` sets work system `system`'s zero on axis `letter` (`fault` when the value
    /// is beyond ±99999.999).
    pub fn write_work_offset(
        &mut self,
        n: i64,
        system: u8,
        letter: char,
        v: Value,
        fault: Fault,
    ) -> Result<(), ProgramError> {
        let x = v.unwrap_or(0.0);
        if !x.is_finite() || x.abs() > 99_999.0 {
            return Err(self.fault(fault, format!("#{n}: offset {x} out of range")));
        }
        self.core
            .setup
            .offsets
            .work
            .entry(system)
            .or_default()
            .insert(letter, x);
        Ok(())
    }

    /// Reads a variable of the lathe map: #1–#40 local, #100–#289 common (#200– kept),
    /// #4001– the offset page, #5000– positions, #5220– work offsets.
    pub fn lathe_read(&self, n: i64) -> Result<Value, EvalError> {
        Ok(match n {
            0 => None,
            1..=40 => self.core.locals().get(n as usize).copied().flatten(),
            100..=289 => self.core.common.get(&n).copied(),
            1000..=1033 => {
                return Err(EvalError(
                    format!("#{n}: PLC inputs are not connected to the interpreter yet"),
                    Fault::MacroVariable,
                ))
            }
            4001..=4499 => {
                let (table, num) = (n / 100 - 40, (n % 100) as u32);
                let t = self.core.setup.offsets.tool(num);
                Some(match table {
                    0 => t.x,
                    1 => 0.0,
                    2 => t.z,
                    3 => t.radius,
                    _ => t.tip as f64,
                })
            }
            5000..=5005 | 5020..=5025 => {
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][(n % 10) as usize];
                let machine = n >= 5020;
                self.core.axis(letter).map(|i| {
                    if machine {
                        self.core.pos[i]
                    } else {
                        self.core.work_position()[i]
                    }
                })
            }
            5220..=5325 if (n - 5220) % 20 < 6 => {
                let sys = ((n - 5220) / 20) as u8;
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][((n - 5220) % 20) as usize];
                Some(self.core.setup.offsets.work(sys, letter))
            }
            _ => {
                return Err(EvalError(
                    format!("#{n} is not a variable of this control"),
                    Fault::MacroVariable,
                ))
            }
        })
    }

    /// Writes a variable of the lathe map.
    pub fn lathe_write(&mut self, n: i64, v: Value) -> Result<(), ProgramError> {
        match n {
            1..=40 => {
                if let Some(slot) = self.core.locals_mut().get_mut(n as usize) {
                    *slot = v;
                }
                Ok(())
            }
            100..=289 => {
                match v {
                    Some(x) => self.core.common.insert(n, x),
                    None => self.core.common.remove(&n),
                };
                Ok(())
            }
            // G54–G59 zero offsets: what a program sets is kept (decision D33).
            5220..=5325 if (n - 5220) % 20 < 6 => {
                let system = ((n - 5220) / 20) as u8;
                let letter = ['X', 'Y', 'Z', 'A', 'B', 'C'][((n - 5220) % 20) as usize];
                self.write_work_offset(n, system, letter, v, Fault::Macro)
            }
            4001..=4499 => {
                let (table, num) = (n / 100 - 40, (n % 100) as u32);
                let x = v.unwrap_or(0.0);
                let t = self.core.setup.offsets.tools.entry(num).or_default();
                match table {
                    0 => t.x = x,
                    2 => t.z = x,
                    3 => t.radius = x,
                    4 => t.tip = x.clamp(0.0, 9.0) as u8,
                    _ => return Err(self.fault(Fault::Macro, format!("#{n}: no Y axis offsets"))),
                }
                Ok(())
            }
            _ => Err(self.fault(Fault::MacroReadOnly, format!("#{n} cannot be written"))),
        }
    }

    /// A nose radius compensation can use (alarm otherwise); `of` names where it came from.
    pub fn nose_radius(&self, radius: f64, of: &str) -> Result<f64, ProgramError> {
        if radius > 0.0 && radius <= 1000.0 {
            Ok(radius)
        } else {
            Err(self.fault(
                Fault::CompRadiusZero,
                format!("tool-nose radius {} of {of} is not usable", show(radius)),
            ))
        }
    }

    /// The offset whose nose radius and tip G41/G42 use: a T word in the same block (its
    /// offset takes effect with this block's move), else the active one.
    pub fn nose_offset_number(&self, b: &Block<D>) -> u32 {
        match b.get('T') {
            Some(t) if t >= 0.0 && t.fract() == 0.0 && t <= 9999.0 => {
                let code = t as u32;
                if code < 100 {
                    code
                } else {
                    code % 100
                }
            }
            _ => self.offset_number,
        }
    }

    /// A G01 block with axis words: where the lathe starts and cancels compensation.
    pub fn compensation_line(&self, b: &Block<D>) -> bool {
        b.group(1).unwrap_or(self.motion) == G::Linear && self.has_axis_words(b)
    }

    /// G41/G42 in a G01 block with axis words, radius and tip direction from the offset page.
    pub fn lathe_start_comp(&mut self, b: &Block<D>, g: G<D::G>) -> Result<(), ProgramError> {
        self.refuse_second_start()?;
        if !self.compensation_line(b) {
            return Err(self.fault(
                Fault::CompStartNotLine,
                "G41/G42 must be given in a G01 block with X/Z (or U/W)",
            ));
        }
        let side = self.comp_side(g);
        let offset = self.nose_offset_number(b);
        let t = self.core.setup.offsets.tool(offset);
        let radius = self.nose_radius(t.radius, &format!("offset {offset}"))?;
        self.core
            .start_comp(side, radius, t.tip, Startup::ToNextElement)
    }

    /// G40 in a G01 block with axis words.
    pub fn lathe_cancel_comp(&self, b: &Block<D>) -> Result<(), ProgramError> {
        if !self.compensation_line(b) {
            return Err(self.fault(
                Fault::CompStartNotLine,
                "G40 must be given in a G01 block with X/Z (or U/W)",
            ));
        }
        Ok(())
    }

    /// G41/G42 while compensation is active.
    pub fn refuse_second_start(&self) -> Result<(), ProgramError> {
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompDirection,
                "G41/G42 while tool-nose compensation is active: cancel with G40 first",
            ));
        }
        Ok(())
    }
}
