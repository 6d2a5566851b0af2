//! G07 linear chip breaking (`000` §5.6): while it is on, a G01 stops for K seconds after
//! every L mm of its path, so the chip breaks. A plain `G07` cancels it. The interpreter
//! splits the move into L-mm pieces with a dwell between them (decision D45).

use super::*;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ChipBreak {
    /// K: the pause, seconds.
    pause: f64,
    /// L: the path length between pauses, mm.
    length: f64,
}

/// Most pieces one G01 is split into.
const MAX_PIECES: f64 = 100_000.0;

impl Interpreter {
    pub(super) fn set_chip_break(&mut self, b: &Block) -> Result<(), ProgramError> {
        if b.has('P') || b.has('Q') {
            // The format line prints thread chip breaking as `G07 P Q L` (inventory §14.3).
            return Err(self.fault(
                Fault::NotSupported,
                "G07 P Q L (thread chip breaking) needs an oscillation superimposed in motion",
            ));
        }
        self.chip_break = match (b.get('K'), b.get('L')) {
            (None, None) => None,
            (Some(pause), Some(length)) => {
                if !(0.0..=9999.999).contains(&pause) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!("G07 K{}: pause 0–9999.999 s", show(pause)),
                    ));
                }
                if !(length > 0.0 && length <= 99_999.0) {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!("G07 L{}: length above 0 mm", show(length)),
                    ));
                }
                Some(ChipBreak { pause, length })
            }
            _ => {
                return Err(self.fault(
                    Fault::MissingWord,
                    "G07 needs both K (pause) and L (length), or neither to cancel",
                ))
            }
        };
        Ok(())
    }

    /// A G01 to `end` (work) in pieces of the chip-break length, with the pause between them.
    pub(super) fn linear_with_chip_break(
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
