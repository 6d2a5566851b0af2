//! Measuring with the touch probe (a `Probe` block: MEAS/MEAW of the 802D, a skip move): a
//! line cut on its own through the planner while the probe's edge is watched. The drive
//! latches every axis's position at the edge (the feedback's latched counts), so the result
//! does not depend on where a servo period happened to end. With delete distance to go the
//! axes brake along the line at the edge and the block ends where they come to rest; without
//! it the line runs to its end. The result goes to the interpreter with the block.

use cnc_msgs::servo::ServoFeedback;

use super::*;

/// The probe's input as the drives report it each period: deflected now, the rising and
/// falling edges counted (wrapping), and each axis's count latched at the last of each
/// (slide travel, as the encoders count).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ProbeInput {
    pub deflected: bool,
    pub rising: u32,
    pub falling: u32,
    pub rising_at: Point,
    pub falling_at: Point,
}

impl ProbeInput {
    /// The probe's part of a drive feedback.
    pub fn from_feedback(fb: &ServoFeedback) -> Self {
        ProbeInput {
            deflected: fb.probe != 0,
            rising: fb.probe_rising,
            falling: fb.probe_falling,
            rising_at: fb.probe_rising_position,
            falling_at: fb.probe_falling_position,
        }
    }
}

/// A measuring block under way.
#[derive(Debug, Clone, Copy)]
pub(super) struct Probing {
    seq: u64,
    rising: bool,
    /// Delete distance to go: brake at the edge.
    stop: bool,
    /// The edge count when the block started: a later count is this block's edge.
    seen: u32,
    /// Machine position (slide travel) at the edge, once it came.
    latched: Option<Point>,
    /// Braking after the edge; the block ends at rest.
    pub(super) braking: bool,
}

impl Motion {
    /// The probe's input of this period's feedback.
    pub fn probe_input(&mut self, input: ProbeInput) {
        self.probe_input = input;
    }

    /// Starts watching the probe for a measuring block; a rising edge cannot come while the
    /// probe is already deflected (alarm, nothing moves).
    pub(super) fn start_probing(&mut self, block: &Block) -> Result<(), (u32, String)> {
        let Command::Probe { rising, stop, .. } = block.kind else {
            return Err((alarm::BAD_BLOCK, "not a measuring block".into()));
        };
        if rising && self.probe_input.deflected {
            return Err((
                alarm::PROBE_DEFLECTED,
                "probe already deflected: its rising edge cannot be detected".into(),
            ));
        }
        self.block_result = None;
        self.probing = Some(Probing {
            seq: block.seq,
            rising,
            stop,
            seen: self.edge_count(rising),
            latched: None,
            braking: false,
        });
        Ok(())
    }

    fn edge_count(&self, rising: bool) -> u32 {
        if rising {
            self.probe_input.rising
        } else {
            self.probe_input.falling
        }
    }

    /// Each period of a measuring block: the first edge of the block latches the position
    /// and, with delete distance to go, starts the braking.
    pub(super) fn watch_probe(&mut self) {
        let Some(p) = self.probing else {
            return;
        };
        if p.latched.is_some() || self.edge_count(p.rising) == p.seen {
            return;
        }
        let counts = if p.rising {
            self.probe_input.rising_at
        } else {
            self.probe_input.falling_at
        };
        let mut at = [0.0; MAX_AXES];
        for (i, (a, s)) in at.iter_mut().zip(&self.shift).enumerate() {
            *a = counts[i] + s;
        }
        if let Some(q) = self.probing.as_mut() {
            q.latched = Some(at);
            q.braking = q.stop;
        }
    }

    /// Whether the active path is a measuring block braking at its edge.
    pub(super) fn probe_braking(&self) -> bool {
        self.probing.is_some_and(|p| p.braking)
    }

    /// Once the measuring block is done (`done_seq` has reached it): its result.
    pub(super) fn finish_probing(&mut self) {
        let Some(p) = self.probing else {
            return;
        };
        if self.done_seq < p.seq {
            return;
        }
        self.probing = None;
        let rest = self.display_point(&self.commanded);
        let position = p.latched.map_or(rest, |l| self.display_point(&l));
        self.block_result = Some(BlockResult {
            seq: p.seq,
            triggered: p.latched.is_some(),
            position,
            rest,
        });
    }
}
