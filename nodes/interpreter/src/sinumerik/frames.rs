//! Zero offsets and programmable frames (`001` §9.2.6–§9.2.10; inventory §3.4). The settable
//! offsets G54–G59 and G507–G554 are the work offsets of the offset page, G500 none. The
//! programmable frame is the core's [`Frame`]: TRANS, ROT, SCALE and MIRROR set it anew
//! (an absolute frame instruction clears the others), ATRANS, AROT, ASCALE and AMIRROR add to
//! it in the coordinates it already defines, so an ATRANS under SCALE is scaled (decision
//! D79). MIRROR turns circles the other way through the emitter; radius compensation runs in
//! the program's coordinates, so its side follows the mirrored contour.

use cnc_interpreter_core::{Fault, Frame, ProgramError, NO_WORK_OFFSET};

use super::exec::Words;
use super::Sinumerik;

const FRAMES: [&str; 8] = [
    "TRANS", "ATRANS", "ROT", "AROT", "SCALE", "ASCALE", "MIRROR", "AMIRROR",
];

impl Sinumerik {
    /// G500 (`None`) or a settable offset by index.
    pub(super) fn set_work_offset(&mut self, index: Option<u8>) {
        self.core.work_system = index.unwrap_or(NO_WORK_OFFSET);
    }

    /// The block's frame instruction, if it has one: its axis words are the instruction's
    /// values, and it moves nothing (an own block, §9.2.6).
    pub(super) fn frame_instruction(&mut self, w: &Words) -> Result<bool, ProgramError> {
        let mut found = w.keys.iter().copied().filter(|k| FRAMES.contains(k));
        let Some(kind) = found.next() else {
            return Ok(false);
        };
        if found.next().is_some() {
            return Err(self.fault(Fault::SameGroup, "one frame instruction per block"));
        }
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                format!("{kind} while tool radius compensation is active: G40 first"),
            ));
        }
        let n = self.core.setup.axes.len();
        let unit = if self.inch { 25.4 } else { 1.0 };
        let given = |default: f64, scale: f64| -> Vec<f64> {
            (0..n)
                .map(|i| w.axes.get(&i).map_or(default, |v| v.0 * scale))
                .collect()
        };
        let absolute = !kind.starts_with('A');
        let mut frame = if absolute {
            Frame::identity(n)
        } else {
            self.core.frame.clone()
        };
        match kind.trim_start_matches('A') {
            "TRANS" => frame.translate(&given(0.0, unit)),
            "ROT" => {
                if !w.axes.is_empty() {
                    return Err(self.fault(
                        Fault::NotSupported,
                        "ROT about the axes (spatial rotation) is not built: ROT RPL= turns in the plane",
                    ));
                }
                if let Some(deg) = w.get("RPL") {
                    let (h, v) = self.core.plane_axes()?;
                    frame.rotate(h, v, deg);
                }
            }
            "SCALE" => {
                let f = given(1.0, 1.0);
                if f.contains(&0.0) {
                    return Err(self.fault(Fault::OutOfRange, "a scale factor of 0"));
                }
                frame.scale(&f);
            }
            _ => {
                // MIRROR: the axes named change direction; their values mean nothing.
                let f: Vec<f64> = (0..n)
                    .map(|i| if w.axes.contains_key(&i) { -1.0 } else { 1.0 })
                    .collect();
                frame.scale(&f);
            }
        }
        if w.get("RPL").is_some() && !kind.ends_with("ROT") {
            return Err(self.fault(Fault::IllegalWord, "RPL= belongs to ROT and AROT"));
        }
        self.core.frame = frame;
        self.tangent = None;
        Ok(true)
    }
}
