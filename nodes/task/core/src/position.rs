//! Where the program in automatic operation is: the program and its line as the machine runs
//! it, kept across a power loss or a kill so that the operator or the supervisor knows where
//! to restart (issue 26; decisions D64). The shell hands every change to a
//! [`cnc_runtime::persist::Keeper`], so the interpreter's loop never waits for the disk; what is
//! on the disk lags the machine by at most [`LINE_INTERVAL_NS`] and the write in progress.

use std::collections::BTreeMap;

use cnc_msgs::msg::MachineState;
use serde::{Deserialize, Serialize};

use crate::run::StateView;

/// The kept position: the program, the line the machine was at (the block in progress is run
/// again on a restart) and its state then (`execution_name` of `MachineState`). For a restart
/// at the interrupted block (decisions D67): the block (the program's canonical command in
/// progress, from 1), the program text it was read from ([`text_hash`]) and the kept variables
/// as the run found them at its start, so the block search runs the program as the run did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProgramPosition {
    pub program: String,
    pub line: u32,
    pub state: String,
    #[serde(default)]
    pub block: u64,
    #[serde(default)]
    pub text_hash: String,
    #[serde(default)]
    pub kept_at_start: BTreeMap<i64, f64>,
    /// The fingerprint of every program the run called, by its name in program memory.
    #[serde(default)]
    pub called: BTreeMap<String, String>,
}

/// A program text's fingerprint (FNV-1a, 64 bits, hex): a restart refuses a program edited
/// since it was interrupted.
pub fn text_hash(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl ProgramPosition {
    /// The position `view` shows, if it is one worth keeping: a program in automatic operation
    /// that has reached a line, or has ended. A machine idle after a start or in another mode
    /// changes nothing, so the last position stays until the next program runs.
    pub fn of(view: &StateView) -> Option<ProgramPosition> {
        let running = matches!(
            view.execution,
            MachineState::ACTIVE
                | MachineState::FEED_HOLD
                | MachineState::INTERRUPTED
                | MachineState::STOPPED
                | MachineState::PROGRAM_STOPPED
        );
        let ended = view.execution == MachineState::PROGRAM_COMPLETED;
        if view.mode != MachineState::MODE_AUTO
            || view.program.is_empty()
            || !(ended || running && view.line > 0)
        {
            return None;
        }
        Some(ProgramPosition {
            program: view.program.clone(),
            line: view.line,
            state: MachineState::execution_name_of(view.execution).into(),
            block: 0,
            text_hash: String::new(),
            kept_at_start: BTreeMap::new(),
            called: BTreeMap::new(),
        })
    }

    /// Whether the program was left before its end: a restart would resume it.
    pub fn interrupted(&self) -> bool {
        self.state != MachineState::execution_name_of(MachineState::PROGRAM_COMPLETED)
    }

    /// The file's contents.
    pub fn to_yaml(&self) -> String {
        serde_yaml::to_string(self).unwrap_or_default()
    }

    /// A kept position read back; a file that is not one is an error, not a position.
    pub fn from_yaml(text: &str) -> Result<ProgramPosition, String> {
        serde_yaml::from_str(text).map_err(|e| format!("not a program position: {e}"))
    }
}

/// Line changes are written at most this often (a change of program or state at once): a
/// flash disk is not worn by a write per block of a program of short blocks.
pub const LINE_INTERVAL_NS: u64 = 100_000_000;

/// Which positions go to the disk: a new program or state at once, a new line at most every
/// [`LINE_INTERVAL_NS`], and the newest line once that interval has passed.
#[derive(Default)]
pub struct PositionTracker {
    written: Option<ProgramPosition>,
    written_ns: u64,
    pending: Option<ProgramPosition>,
}

impl PositionTracker {
    /// The position to keep now, if `latest` (the run core's, [`crate::run::RunCore::position`])
    /// at monotonic time `now_ns` moved it (or a line held back is due).
    pub fn update(
        &mut self,
        latest: Option<&ProgramPosition>,
        now_ns: u64,
    ) -> Option<ProgramPosition> {
        if let Some(p) = latest {
            if self.pending.as_ref() != Some(p) {
                self.pending = Some(p.clone());
            }
        }
        let next = self.pending.as_ref()?;
        let due = match &self.written {
            None => true,
            Some(w) if w == next => return None,
            Some(w) => {
                w.program != next.program
                    || w.state != next.state
                    || now_ns.saturating_sub(self.written_ns) >= LINE_INTERVAL_NS
            }
        };
        if !due {
            return None;
        }
        self.written_ns = now_ns;
        self.written = self.pending.clone();
        self.written.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(mode: u8, execution: u8, program: &str, line: u32) -> StateView {
        StateView {
            mode,
            execution,
            program: program.into(),
            line,
            emergency_stop: false,
            alarm_active: false,
            message: String::new(),
        }
    }

    /// The tracker fed the position `v` shows, as the run core gives it.
    fn up(t: &mut PositionTracker, v: &StateView, now_ns: u64) -> Option<ProgramPosition> {
        t.update(ProgramPosition::of(v).as_ref(), now_ns)
    }

    #[test]
    fn a_program_in_auto_is_kept_by_state_at_once_and_by_line_at_most_ten_times_a_second() {
        let auto = MachineState::MODE_AUTO;
        let ms = 1_000_000;
        let mut t = PositionTracker::default();
        // Idle, before any program, or a start that has not reached a line: nothing.
        assert_eq!(up(&mut t, &view(auto, MachineState::READY, "", 0), 0), None);
        assert_eq!(
            up(&mut t, &view(auto, MachineState::ACTIVE, "p.nc", 0), 0),
            None
        );
        let first = up(&mut t, &view(auto, MachineState::ACTIVE, "p.nc", 2), ms).unwrap();
        assert_eq!((first.program.as_str(), first.line), ("p.nc", 2));
        assert!(first.interrupted());
        // The same again is not written again; the next lines wait for the interval, and
        // the newest of them is written when it has passed, even with no new view.
        assert_eq!(
            up(&mut t, &view(auto, MachineState::ACTIVE, "p.nc", 2), 2 * ms),
            None
        );
        assert_eq!(
            up(&mut t, &view(auto, MachineState::ACTIVE, "p.nc", 3), 3 * ms),
            None
        );
        assert_eq!(
            up(&mut t, &view(auto, MachineState::ACTIVE, "p.nc", 4), 4 * ms),
            None
        );
        let idle = view(auto, MachineState::ACTIVE, "p.nc", 4);
        assert_eq!(up(&mut t, &idle, 100 * ms), None);
        assert_eq!(up(&mut t, &idle, 101 * ms).unwrap().line, 4);
        // A feed hold is written at once.
        assert_eq!(
            up(
                &mut t,
                &view(auto, MachineState::ACTIVE, "p.nc", 5),
                102 * ms
            ),
            None
        );
        let held = up(
            &mut t,
            &view(auto, MachineState::FEED_HOLD, "p.nc", 5),
            103 * ms,
        );
        assert_eq!(
            held.map(|h| (h.state, h.line)),
            Some(("FEED_HOLD".into(), 5))
        );
        // MDI and a machine back at READY leave the kept position alone.
        let mdi = view(MachineState::MODE_MDI, MachineState::ACTIVE, "MDI", 1);
        assert_eq!(up(&mut t, &mdi, 500 * ms), None);
        assert_eq!(
            up(
                &mut t,
                &view(auto, MachineState::READY, "p.nc", 0),
                600 * ms
            ),
            None
        );
        let done = view(auto, MachineState::PROGRAM_COMPLETED, "p.nc", 9);
        assert!(!up(&mut t, &done, 601 * ms).unwrap().interrupted());
    }

    #[test]
    fn a_kept_position_reads_back_and_a_damaged_file_is_an_error() {
        let p = ProgramPosition {
            program: "jobs/O0010.nc".into(),
            line: 42,
            state: "INTERRUPTED".into(),
            block: 97,
            text_hash: text_hash("O0010\nM30\n"),
            kept_at_start: [(500, 2.5)].into_iter().collect(),
            called: [("O2000".to_string(), text_hash("O2000\nM99\n"))]
                .into_iter()
                .collect(),
        };
        assert_eq!(ProgramPosition::from_yaml(&p.to_yaml()).unwrap(), p);
        assert!(ProgramPosition::from_yaml("program: [").is_err());
        assert!(ProgramPosition::from_yaml("line: 3").is_err());
    }
}
