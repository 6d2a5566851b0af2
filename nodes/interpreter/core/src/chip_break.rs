//! A path filter: linear chip breaking. While it is on, a feed move stops for a pause after
//! every given length of its path, so the chip breaks: the move is split into pieces with a
//! dwell between them (decision D45).

use crate::canon::Command;
use crate::emit::MoveKind;
use crate::error::{Fault, ProgramError};
use crate::show;
use crate::state::Core;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipBreak {
    /// The pause, seconds.
    pub pause: f64,
    /// The path length between pauses, mm.
    pub length: f64,
}

/// Most pieces one G01 is split into.
const MAX_PIECES: f64 = 100_000.0;

impl Core {
    /// A G01 to `end` (work) in pieces of the chip-break length, with the pause between them.
    pub fn linear_with_chip_break(
        &mut self,
        end: &[f64],
        feed: f64,
        cb: ChipBreak,
    ) -> Result<(), ProgramError> {
        let start = self.work_position();
        // Path length in mm: X is programmed as a diameter on a diameter axis.
        let x = self.axis('X');
        let scale = self.x_scale();
        let length = start
            .iter()
            .zip(end)
            .enumerate()
            .map(|(i, (a, b))| {
                let d = b - a;
                if Some(i) == x {
                    d * scale
                } else {
                    d
                }
            })
            .map(|d| d * d)
            .sum::<f64>()
            .sqrt();
        let pieces = (length / cb.length - 1e-9).ceil().max(1.0);
        if pieces > MAX_PIECES {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "G07 L{} splits this move into more than {MAX_PIECES} pieces",
                    show(cb.length)
                ),
            ));
        }
        let full = (pieces as usize).saturating_sub(1);
        for k in 1..=full {
            let t = k as f64 * cb.length / length;
            let point: Vec<f64> = start
                .iter()
                .zip(end)
                .map(|(a, b)| a + (b - a) * t)
                .collect();
            self.emit(&point, MoveKind::Feed(feed))?;
            self.push(Command::Dwell { seconds: cb.pause });
        }
        self.emit(end, MoveKind::Feed(feed))
    }
}
