//! The `program_events` topic: a run's story (started, each block, paused, resumed, completed,
//! aborted) told from the sequence of machine states the interpreter publishes. Pure: the shell
//! feeds every state in order with the time and the active alarms, and publishes what comes back.

use cnc_msgs::msg::{Alarm, MachineState, ProgramEvent};

/// The run being followed.
struct Run {
    program: String,
    line: u32,
    blocks: u32,
    started: f64,
    paused: bool,
}

#[derive(Default)]
pub struct ProgramEvents {
    run: Option<Run>,
}

fn kind_name(kind: u8) -> &'static str {
    match kind {
        ProgramEvent::STARTED => "STARTED",
        ProgramEvent::BLOCK => "BLOCK",
        ProgramEvent::PAUSED => "PAUSED",
        ProgramEvent::RESUMED => "RESUMED",
        ProgramEvent::COMPLETED => "COMPLETED",
        ProgramEvent::ABORTED => "ABORTED",
        _ => "UNKNOWN",
    }
}

impl ProgramEvents {
    /// The events that machine state `s`, seen at `now` seconds, adds to the story.
    pub fn update(&mut self, s: &MachineState, alarms: &[Alarm], now: f64) -> Vec<ProgramEvent> {
        let mut out = Vec::new();
        let event = |run: &Run, kind: u8, reason: String| ProgramEvent {
            kind,
            kind_name: kind_name(kind).into(),
            program: run.program.clone(),
            line: run.line,
            blocks: run.blocks,
            elapsed: if kind == ProgramEvent::STARTED {
                0.0
            } else {
                (now - run.started).max(0.0)
            },
            reason,
            ..ProgramEvent::default()
        };
        let running = matches!(
            s.execution,
            MachineState::ACTIVE | MachineState::FEED_HOLD | MachineState::INTERRUPTED
        ) || (s.execution == MachineState::PROGRAM_STOPPED && self.run.is_some());
        // A run of another program, or a start after the last run ended, is a new run; a run
        // that vanished without its end being seen (the state stream skipped it) is aborted.
        if running && self.run.as_ref().is_some_and(|r| r.program != s.program) {
            if let Some(r) = self.run.take() {
                out.push(event(
                    &r,
                    ProgramEvent::ABORTED,
                    "another program started".into(),
                ));
            }
        }
        if !running {
            if let Some(r) = self.run.take() {
                let (kind, reason) = match s.execution {
                    MachineState::PROGRAM_COMPLETED => (ProgramEvent::COMPLETED, String::new()),
                    _ => (ProgramEvent::ABORTED, abort_reason(s, alarms)),
                };
                out.push(event(&r, kind, reason));
            }
            return out;
        }
        let run = match &mut self.run {
            Some(run) => {
                if s.line != run.line && s.line > 0 {
                    run.line = s.line;
                    run.blocks = run.blocks.saturating_add(1);
                    out.push(event(run, ProgramEvent::BLOCK, String::new()));
                }
                run
            }
            None => {
                // A start seen before any line ran has no block yet.
                let run = self.run.insert(Run {
                    program: s.program.clone(),
                    line: s.line,
                    blocks: u32::from(s.line > 0),
                    started: now,
                    paused: false,
                });
                out.push(event(run, ProgramEvent::STARTED, String::new()));
                run
            }
        };
        let paused = matches!(
            s.execution,
            MachineState::FEED_HOLD | MachineState::INTERRUPTED | MachineState::PROGRAM_STOPPED
        );
        if paused != run.paused {
            run.paused = paused;
            if paused {
                let reason = match s.execution {
                    MachineState::PROGRAM_STOPPED => "program stop (M00/M01)",
                    _ => "held (feed hold, single block or M00/M01)",
                };
                out.push(event(run, ProgramEvent::PAUSED, reason.into()));
            } else {
                out.push(event(run, ProgramEvent::RESUMED, String::new()));
            }
        }
        out
    }
}

/// Why a run ended without completing.
fn abort_reason(s: &MachineState, alarms: &[Alarm]) -> String {
    if s.emergency_stop {
        return "emergency stop".into();
    }
    if let Some(a) = alarms.first() {
        return format!("alarm {} ({}): {}", a.number, a.source, a.text);
    }
    match s.execution {
        MachineState::READY | MachineState::WAIT => "reset".into(),
        _ => "cycle stop".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(execution: u8, program: &str, line: u32) -> MachineState {
        MachineState {
            execution,
            program: program.into(),
            line,
            ..MachineState::default()
        }
    }

    fn kinds(events: &[ProgramEvent]) -> Vec<(&str, u32, u32)> {
        events
            .iter()
            .map(|e| (e.kind_name.as_str(), e.line, e.blocks))
            .collect()
    }

    #[test]
    fn a_run_is_started_blocks_paused_resumed_and_completed() {
        let mut p = ProgramEvents::default();
        let mut all = Vec::new();
        let seq = [
            (MachineState::READY, 0),
            (MachineState::ACTIVE, 0),
            (MachineState::ACTIVE, 2),
            (MachineState::ACTIVE, 2),
            (MachineState::ACTIVE, 3),
            (MachineState::FEED_HOLD, 3),
            (MachineState::ACTIVE, 3),
            (MachineState::ACTIVE, 5),
            (MachineState::PROGRAM_COMPLETED, 5),
            (MachineState::PROGRAM_COMPLETED, 0),
        ];
        for (i, (e, line)) in seq.into_iter().enumerate() {
            all.extend(p.update(&state(e, "O1", line), &[], i as f64));
        }
        assert_eq!(
            kinds(&all),
            [
                ("STARTED", 0, 0),
                ("BLOCK", 2, 1),
                ("BLOCK", 3, 2),
                ("PAUSED", 3, 2),
                ("RESUMED", 3, 2),
                ("BLOCK", 5, 3),
                ("COMPLETED", 5, 3),
            ]
        );
        assert_eq!(all[3].reason, "held (feed hold, single block or M00/M01)");
        assert_eq!(all[6].elapsed, 7.0);
        assert!(all.iter().all(|e| e.program == "O1"));
    }

    #[test]
    fn a_start_seen_with_its_first_line_counts_that_line_as_a_block() {
        let mut p = ProgramEvents::default();
        let e = p.update(&state(MachineState::ACTIVE, "O1", 4), &[], 0.0);
        assert_eq!(kinds(&e), [("STARTED", 4, 1)]);
        let e = p.update(&state(MachineState::ACTIVE, "O1", 5), &[], 0.0);
        assert_eq!(kinds(&e), [("BLOCK", 5, 2)]);
    }

    #[test]
    fn an_alarm_a_reset_or_an_emergency_stop_aborts_with_its_reason() {
        let alarm = Alarm {
            number: 21,
            source: "interpreter".into(),
            text: "bad word".into(),
            ..Alarm::default()
        };
        let mut p = ProgramEvents::default();
        p.update(&state(MachineState::ACTIVE, "O1", 2), &[], 0.0);
        let e = p.update(
            &state(MachineState::STOPPED, "O1", 3),
            std::slice::from_ref(&alarm),
            1.0,
        );
        assert_eq!(kinds(&e), [("ABORTED", 2, 1)]);
        assert_eq!(e[0].reason, "alarm 21 (interpreter): bad word");
        // Nothing more until the next run; reset after an abort adds nothing.
        assert!(p
            .update(&state(MachineState::READY, "O1", 0), &[], 2.0)
            .is_empty());

        p.update(&state(MachineState::ACTIVE, "O1", 2), &[], 3.0);
        let e = p.update(&state(MachineState::READY, "O1", 0), &[], 4.0);
        assert_eq!(e[0].reason, "reset");
        p.update(&state(MachineState::ACTIVE, "O1", 2), &[], 5.0);
        let e = p.update(&state(MachineState::STOPPED, "O1", 2), &[], 6.0);
        assert_eq!(e[0].reason, "cycle stop");
        p.update(&state(MachineState::ACTIVE, "O1", 2), &[], 5.0);
        let stopped = MachineState {
            emergency_stop: true,
            ..state(MachineState::STOPPED, "O1", 2)
        };
        assert_eq!(
            p.update(&stopped, &[alarm], 6.0)[0].reason,
            "emergency stop"
        );
    }

    #[test]
    fn a_program_stop_pauses_and_another_program_is_a_new_run() {
        let mut p = ProgramEvents::default();
        p.update(&state(MachineState::ACTIVE, "O1", 2), &[], 0.0);
        let e = p.update(&state(MachineState::PROGRAM_STOPPED, "O1", 3), &[], 1.0);
        assert_eq!(kinds(&e), [("BLOCK", 3, 2), ("PAUSED", 3, 2)]);
        assert_eq!(e[1].reason, "program stop (M00/M01)");
        let e = p.update(&state(MachineState::ACTIVE, "O2", 1), &[], 2.0);
        assert_eq!(kinds(&e), [("ABORTED", 3, 2), ("STARTED", 1, 1)]);
        assert_eq!(e[1].program, "O2");
        // A program stop with no run followed (the bridge started late) is not a run.
        let mut late = ProgramEvents::default();
        assert!(late
            .update(&state(MachineState::PROGRAM_STOPPED, "O1", 3), &[], 0.0)
            .is_empty());
    }
}
