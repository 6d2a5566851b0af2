//! One goal of the `RunProgram` action, followed through the machine's state: the cycles it
//! starts, the feedback it owes, and how it ends. Pure: the shell feeds it what it sees on the
//! state topics with the time, and carries out the actions it returns.

use cnc_msgs::action::{GoalStatus, RunProgramFeedback, RunProgramGoal, RunProgramResult, Uuid};
use cnc_msgs::msg::{Alarm, MachineState};

/// Most cycles one goal may ask for.
pub const MAX_CYCLES: u32 = 10_000;
/// The longest `start_block` (a label or `interrupted`, not a program).
const MAX_START_BLOCK: usize = 64;

/// Where the goal's first cycle starts, as the interpreter's cycle start takes it (`text` of
/// START; the interpreter searches the block and refuses what it cannot find).
pub fn start_at(goal: &RunProgramGoal) -> String {
    if goal.start_line != 0 {
        format!("line {}", goal.start_line)
    } else {
        goal.start_block.trim().to_string()
    }
}

/// What the shell must do for the goal.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Start the program again (the next cycle).
    StartCycle,
    Feedback(RunProgramFeedback),
}

/// The machine as the bridge sees it at one instant.
pub struct View<'a> {
    pub state: &'a MachineState,
    /// Motion's current run and the blocks it has finished in it.
    pub run_id: u64,
    pub done_blocks: u64,
    pub part_count: u32,
    pub alarms: &'a [Alarm],
    /// Seconds, any monotonic origin.
    pub now: f64,
}

/// Share of a program of `lines` lines before `line`; 0 when the length is unknown.
fn percent(line: u32, lines: u32) -> f32 {
    if lines == 0 {
        return 0.0;
    }
    (100.0 * line.saturating_sub(1) as f32 / lines as f32).clamp(0.0, 100.0)
}

/// A goal's checks before it is accepted: the program must be stored (`known`).
pub fn check(goal: &RunProgramGoal, known: bool) -> Result<(), String> {
    if goal.cycles == 0 || goal.cycles > MAX_CYCLES {
        return Err(format!("cycles {}: 1..{MAX_CYCLES}", goal.cycles));
    }
    if goal.start_line != 0 && !goal.start_block.trim().is_empty() {
        return Err(format!(
            "start_line {} and start_block {:?}: give one of them",
            goal.start_line, goal.start_block
        ));
    }
    if goal.start_block.len() > MAX_START_BLOCK || goal.start_block.chars().any(char::is_control) {
        return Err(format!(
            "start_block: at most {MAX_START_BLOCK} characters, no control characters"
        ));
    }
    if !known {
        return Err(format!(
            "program {:?} not in program memory: load it first",
            goal.program
        ));
    }
    Ok(())
}

pub struct GoalRun {
    pub id: Uuid,
    pub goal: RunProgramGoal,
    status: i8,
    /// Cycle running now, from 1.
    cycle: u32,
    cycle_started: f64,
    /// The current cycle has been seen running (so a PROGRAM_COMPLETED is its own end, not
    /// the previous program's).
    seen_running: bool,
    program_lines: u32,
    /// Motion's run when the cycle was started: its block count belongs to the cycle before.
    stale_run: u64,
    last_feedback: Option<(u32, u64)>,
    result: RunProgramResult,
}

impl GoalRun {
    /// An accepted goal whose first cycle the shell has just started; `program_lines` is the
    /// program's length (0 if unknown).
    pub fn new(id: Uuid, goal: RunProgramGoal, program_lines: u32, run_id: u64, now: f64) -> Self {
        GoalRun {
            id,
            goal,
            status: GoalStatus::STATUS_EXECUTING,
            cycle: 1,
            cycle_started: now,
            seen_running: false,
            program_lines,
            stale_run: run_id,
            last_feedback: None,
            result: RunProgramResult::default(),
        }
    }

    pub fn status(&self) -> i8 {
        self.status
    }

    pub fn result(&self) -> &RunProgramResult {
        &self.result
    }

    pub fn finished(&self) -> bool {
        matches!(
            self.status,
            GoalStatus::STATUS_SUCCEEDED | GoalStatus::STATUS_CANCELED | GoalStatus::STATUS_ABORTED
        )
    }

    /// The shell started the next cycle while motion reported run `run_id`.
    pub fn cycle_started(&mut self, now: f64, run_id: u64) {
        self.cycle_started = now;
        self.stale_run = run_id;
        self.seen_running = false;
        self.last_feedback = None;
    }

    /// Ends the goal as aborted with `why` and the alarms active now.
    pub fn abort(&mut self, why: &str, alarms: &[Alarm]) {
        self.status = GoalStatus::STATUS_ABORTED;
        self.result.alarms = alarms.to_vec();
        self.result.message = format!(
            "aborted in cycle {} of {}: {why}",
            self.cycle, self.goal.cycles
        );
    }

    /// A cancel request was accepted; the shell stops the machine, then calls [`canceled`].
    ///
    /// [`canceled`]: GoalRun::canceled
    pub fn cancel(&mut self) {
        if !self.finished() {
            self.status = GoalStatus::STATUS_CANCELING;
        }
    }

    /// The machine has been stopped and reset for a cancel.
    pub fn canceled(&mut self, outcome: &str) {
        self.status = GoalStatus::STATUS_CANCELED;
        self.result.message = format!(
            "canceled in cycle {} of {}: {outcome}",
            self.cycle, self.goal.cycles
        );
    }

    /// Follows the machine: feedback while a cycle runs, the next cycle when one ends, the
    /// end of the goal when the last one ends or the program stops.
    pub fn update(&mut self, v: &View) -> Vec<Step> {
        let mut steps = Vec::new();
        if self.status != GoalStatus::STATUS_EXECUTING {
            return steps;
        }
        let s = v.state;
        let ours = s.program == self.goal.program;
        match s.execution {
            MachineState::ACTIVE | MachineState::FEED_HOLD | MachineState::INTERRUPTED if ours => {
                self.seen_running = true;
                let blocks = if v.run_id == self.stale_run {
                    0
                } else {
                    v.done_blocks
                };
                if self.last_feedback != Some((s.line, blocks)) {
                    self.last_feedback = Some((s.line, blocks));
                    steps.push(Step::Feedback(RunProgramFeedback {
                        line: s.line,
                        block: blocks,
                        percent: percent(s.line, self.program_lines),
                        cycle: self.cycle,
                        part_count: v.part_count,
                    }));
                }
            }
            MachineState::PROGRAM_COMPLETED if ours && self.seen_running => {
                self.result.parts_made += 1;
                self.result.cycle_times.push(v.now - self.cycle_started);
                if self.cycle < self.goal.cycles {
                    self.cycle += 1;
                    steps.push(Step::StartCycle);
                } else {
                    self.status = GoalStatus::STATUS_SUCCEEDED;
                    self.result.message =
                        format!("{} cycles of {} done", self.goal.cycles, self.goal.program);
                }
            }
            MachineState::STOPPED | MachineState::PROGRAM_STOPPED if self.seen_running => {
                let why = match v.alarms.first() {
                    Some(a) => format!("alarm {} at line {}: {}", a.number, a.line, a.text),
                    None => format!("program stopped at line {}", s.line),
                };
                self.abort(&why, v.alarms);
            }
            MachineState::READY | MachineState::WAIT if self.seen_running => {
                self.abort("the machine was reset", v.alarms);
            }
            _ => {}
        }
        if s.emergency_stop && !self.finished() {
            self.abort("emergency stop", v.alarms);
        }
        steps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(execution: u8, line: u32) -> MachineState {
        MachineState {
            execution,
            line,
            program: "p.nc".into(),
            ..MachineState::default()
        }
    }

    fn goal(cycles: u32) -> RunProgramGoal {
        RunProgramGoal {
            program: "p.nc".into(),
            cycles,
            start_line: 0,
            start_block: String::new(),
        }
    }

    /// Motion in run 7 (this goal's), `blocks` finished.
    fn view(s: &MachineState, blocks: u64, now: f64) -> View<'_> {
        View {
            state: s,
            run_id: 7,
            done_blocks: blocks,
            part_count: 0,
            alarms: &[],
            now,
        }
    }

    #[test]
    fn goals_are_checked() {
        assert!(check(&goal(1), true).is_ok());
        assert!(check(&goal(0), true).is_err());
        assert!(check(&goal(MAX_CYCLES + 1), true).is_err());
        assert!(check(&goal(1), false)
            .unwrap_err()
            .contains("load it first"));
        let mut g = goal(1);
        g.start_line = 5;
        assert!(check(&g, true).is_ok());
        assert_eq!(start_at(&g), "line 5");
        g.start_block = "N40".into();
        assert!(check(&g, true).unwrap_err().contains("one of them"));
        g.start_line = 0;
        assert_eq!(start_at(&g), "N40");
        g.start_block = "x".repeat(65);
        assert!(check(&g, true).is_err());
        g.start_block = "interrupted\n".into();
        assert!(check(&g, true).is_err());
    }

    #[test]
    fn two_cycles_with_feedback_per_block_then_success() {
        let mut run = GoalRun::new([1; 16], goal(2), 10, 6, 0.0);
        // The previous program's completion is not this goal's.
        assert!(run
            .update(&view(&state(MachineState::PROGRAM_COMPLETED, 9), 0, 0.1))
            .is_empty());
        let mut feedback = 0;
        for (line, block) in [(2, 0), (3, 1), (3, 1), (4, 2)] {
            for s in run.update(&view(&state(MachineState::ACTIVE, line), block, 0.5)) {
                assert!(matches!(s, Step::Feedback(ref f) if f.line == line && f.cycle == 1));
                feedback += 1;
            }
        }
        assert_eq!(feedback, 3, "one per change of line or block");
        let steps = run.update(&view(&state(MachineState::PROGRAM_COMPLETED, 9), 3, 2.0));
        assert_eq!(steps, vec![Step::StartCycle]);
        run.cycle_started(2.0, 7);
        // Completion still showing before the restart took: not counted twice.
        assert!(run
            .update(&view(&state(MachineState::PROGRAM_COMPLETED, 9), 3, 2.01))
            .is_empty());
        // The new cycle runs before motion reports its run: the old run's count is not shown.
        let steps = run.update(&view(&state(MachineState::ACTIVE, 2), 3, 2.5));
        assert!(matches!(&steps[..], [Step::Feedback(f)] if f.block == 0 && f.cycle == 2));
        run.update(&view(&state(MachineState::PROGRAM_COMPLETED, 9), 3, 4.5));
        assert_eq!(run.status(), GoalStatus::STATUS_SUCCEEDED);
        assert_eq!(run.result().parts_made, 2);
        assert_eq!(run.result().cycle_times, vec![2.0, 2.5]);
    }

    #[test]
    fn an_alarm_aborts_with_the_alarm_and_a_cancel_ends_canceled() {
        let mut run = GoalRun::new([2; 16], goal(3), 10, 6, 0.0);
        run.update(&view(&state(MachineState::ACTIVE, 4), 1, 0.5));
        let alarm = Alarm {
            number: 33,
            text: "bad".into(),
            line: 4,
            ..Alarm::default()
        };
        run.update(&View {
            state: &state(MachineState::STOPPED, 4),
            run_id: 7,
            done_blocks: 1,
            part_count: 0,
            alarms: std::slice::from_ref(&alarm),
            now: 1.0,
        });
        assert_eq!(run.status(), GoalStatus::STATUS_ABORTED);
        assert_eq!(run.result().alarms, vec![alarm]);
        assert!(run.result().message.contains("alarm 33 at line 4"));

        let mut run = GoalRun::new([3; 16], goal(3), 10, 6, 0.0);
        run.update(&view(&state(MachineState::ACTIVE, 4), 1, 0.5));
        run.cancel();
        assert_eq!(run.status(), GoalStatus::STATUS_CANCELING);
        // While canceling, the stop it caused is not an abort.
        run.update(&view(&state(MachineState::STOPPED, 4), 1, 0.6));
        assert_eq!(run.status(), GoalStatus::STATUS_CANCELING);
        run.canceled("stopped and reset");
        assert_eq!(run.status(), GoalStatus::STATUS_CANCELED);
        assert_eq!(run.result().parts_made, 0);
    }
}
