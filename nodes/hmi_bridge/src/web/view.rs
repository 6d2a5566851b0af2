//! What the operator's page shows, kept from the machine's topics: positions (machine, work,
//! distance to go), mode and execution, spindle and feed, overrides, alarms and their history,
//! part count, the tool path so far and the PLC's signals. Pure: the shell feeds it messages
//! and sends the frames it makes.

use std::collections::{BTreeMap, VecDeque};

use cnc_msgs::msg::{
    AlarmEvent, AxisState, CommandEvent, MachineState, MotionBlock, MotionStatus, Overrides,
    PartCount, PlcSignals, SpindleState,
};
use serde_json::{json, Value};

/// Alarm history entries kept (oldest dropped).
pub const HISTORY: usize = 200;
/// Tool path points kept; a longer path keeps its newest half.
pub const PATH_POINTS: usize = 50_000;
/// A new path point is taken when the tool has moved this far (mm).
const PATH_STEP: f64 = 0.01;
/// Blocks kept for distance to go: more than motion's queue holds.
const BLOCKS_KEPT: usize = 512;
/// Command events kept.
const COMMANDS: usize = 20;

/// The newest entries of a history, counting every entry ever added, so frames carry exactly
/// the entries pages have not had yet.
#[derive(Debug, Default)]
struct Log {
    entries: VecDeque<Value>,
    added: usize,
    sent: usize,
}

impl Log {
    fn push(&mut self, entry: Value, keep: usize) {
        self.entries.push_back(entry);
        self.added += 1;
        while self.entries.len() > keep {
            self.entries.pop_front();
        }
    }

    /// Entries added since the last call (those still kept).
    fn take_new(&mut self) -> Vec<Value> {
        let new = (self.added - self.sent).min(self.entries.len());
        self.sent = self.added;
        self.entries
            .iter()
            .skip(self.entries.len() - new)
            .cloned()
            .collect()
    }
}

#[derive(Debug, Default)]
pub struct View {
    names: Vec<String>,
    /// Per axis: programmed and shown as a diameter (a lathe's X).
    diameter: Vec<bool>,
    /// The two axes the tool path is drawn in: (horizontal, vertical).
    plot: (usize, usize),
    machine: Option<MachineState>,
    axes: Option<AxisState>,
    status: MotionStatus,
    blocks: BTreeMap<(u64, u64), MotionBlock>,
    spindle: Option<SpindleState>,
    parts: Option<PartCount>,
    overrides: Option<Overrides>,
    /// The bridge's active list (`AlarmList`), acknowledgements included.
    active: Vec<cnc_msgs::msg::Alarm>,
    history: Log,
    commands: Log,
    path: Vec<[f64; 2]>,
    /// Points already sent to every page.
    path_sent: usize,
    path_run: u64,
    /// The path was cut or restarted since the last frame: pages start over.
    path_reset: bool,
    signals: Option<PlcSignals>,
    signals_sent: u64,
    /// A turn-mill's polar interpolation blocks (run, seq, on) as they come (D141): while
    /// the last one done is on, the path shows the face, X and C as Cartesian.
    contour: Vec<(u64, u64, bool)>,
    face: bool,
}

/// Which machine axes a 2-D tool path shows: a lathe's Z across and X (as radius) up; a mill's
/// X across and Y up.
pub fn plot_axes(names: &[String]) -> (usize, usize) {
    let find = |n: &str| names.iter().position(|a| a.eq_ignore_ascii_case(n));
    match (find("X"), find("Y"), find("Z")) {
        (Some(x), None, Some(z)) => (z, x),
        (Some(x), Some(y), _) => (x, y),
        _ => (0, 1.min(names.len().saturating_sub(1))),
    }
}

fn stamp_seconds(t: &cnc_msgs::msg::Time) -> f64 {
    f64::from(t.sec) + f64::from(t.nanosec) * 1e-9
}

impl View {
    pub fn new(names: Vec<String>, diameter: Vec<bool>) -> View {
        View {
            plot: plot_axes(&names),
            names,
            diameter,
            ..View::default()
        }
    }

    pub fn on_machine_state(&mut self, m: MachineState) {
        self.machine = Some(m);
    }

    pub fn on_motion_status(&mut self, s: MotionStatus) {
        if s.run_id != self.path_run && s.run_id != 0 {
            // A new run draws a new path.
            self.path_run = s.run_id;
            self.path.clear();
            self.path_sent = 0;
            self.path_reset = true;
        }
        self.status = s;
    }

    pub fn on_block(&mut self, b: MotionBlock) {
        if b.kind == MotionBlock::KIND_CONTOUR {
            self.contour.push((b.run_id, b.seq, b.flag));
            if self.contour.len() > BLOCKS_KEPT {
                self.contour.remove(0);
            }
        }
        self.blocks.insert((b.run_id, b.seq), b);
        while self.blocks.len() > BLOCKS_KEPT {
            self.blocks.pop_first();
        }
    }

    /// Whether polar interpolation is on: the last contour block motion has done says so.
    fn face_now(&self) -> bool {
        let run = self.status.run_id;
        self.contour
            .iter()
            .filter(|(r, seq, _)| *r == run && *seq <= self.status.done_seq)
            .max_by_key(|(_, seq, _)| *seq)
            .is_some_and(|(_, _, on)| *on)
    }

    /// The point the path shows for `a`: the plot's two axes (a diameter axis at its
    /// radius), or under polar interpolation the face's point of X (radius) and C.
    fn path_point(&self, a: &AxisState) -> Option<[f64; 2]> {
        let by_name = |n: &str| a.axes.iter().find(|x| x.name == n);
        if self.face {
            let (x, c) = (by_name("X")?, by_name("C")?);
            let r = x.actual_position * 0.5;
            let (sin, cos) = c.actual_position.to_radians().sin_cos();
            return Some([r * cos, r * sin]);
        }
        let (h, v) = self.plot;
        let (ah, av) = (a.axes.get(h)?, a.axes.get(v)?);
        let scale = if self.diameter.get(v).copied().unwrap_or(false) {
            0.5
        } else {
            1.0
        };
        Some([ah.actual_position, av.actual_position * scale])
    }

    pub fn on_axes(&mut self, a: AxisState) {
        let face = self.face_now();
        if face != self.face {
            // The face's drawing replaces the turning one, and back.
            self.face = face;
            self.path.clear();
            self.path_sent = 0;
            self.path_reset = true;
        }
        if let Some(p) = self.path_point(&a) {
            let moved = self
                .path
                .last()
                .is_none_or(|q| (q[0] - p[0]).hypot(q[1] - p[1]) >= PATH_STEP);
            if moved && p.iter().all(|c| c.is_finite()) {
                self.path.push(p);
                if self.path.len() > PATH_POINTS {
                    self.path.drain(..PATH_POINTS / 2);
                    self.path_sent = 0;
                    self.path_reset = true;
                }
            }
        }
        self.axes = Some(a);
    }

    pub fn on_spindle(&mut self, s: SpindleState) {
        self.spindle = Some(s);
    }

    pub fn on_parts(&mut self, p: PartCount) {
        self.parts = Some(p);
    }

    pub fn on_overrides(&mut self, o: Overrides) {
        self.overrides = Some(o);
    }

    pub fn on_plc_signals(&mut self, s: PlcSignals) {
        self.signals = Some(s);
    }

    /// An alarm raised or cleared, for the history (the active list comes from the bridge).
    pub fn on_alarm_event(&mut self, e: &AlarmEvent) {
        let raised = e.kind == AlarmEvent::RAISED;
        let entry = json!({
            "time": stamp_seconds(&e.alarm.stamp),
            "raised": raised,
            "number": e.alarm.number,
            "text": e.alarm.text,
            "source": e.alarm.source,
        });
        self.history.push(entry, HISTORY);
    }

    pub fn set_active_alarms(&mut self, alarms: Vec<cnc_msgs::msg::Alarm>) {
        self.active = alarms;
    }

    pub fn on_command_event(&mut self, e: &CommandEvent) {
        let entry = json!({
            "time": stamp_seconds(&e.stamp),
            "command": e.command,
            "detail": e.detail,
            "client": e.client,
            "accepted": e.accepted,
            "message": e.message,
        });
        self.commands.push(entry, COMMANDS);
    }

    /// The block motion is executing, if its stream is known.
    fn current_block(&self) -> Option<&MotionBlock> {
        let s = &self.status;
        self.blocks.get(&(s.run_id, s.done_seq + 1))
    }

    /// Per axis: machine position, work position (machine minus the program origin of the
    /// executing block, under a rotating frame through the block's `work_frame`) and distance
    /// to go (end of that block minus the commanded position, turned by the same frame).
    fn positions(&self) -> Vec<Value> {
        let Some(a) = &self.axes else {
            return Vec::new();
        };
        let block = self.current_block();
        let last = self
            .blocks
            .range((self.status.run_id, 0)..=(self.status.run_id, self.status.done_seq))
            .next_back()
            .map(|(_, b)| b);
        let shown = block.or(last);
        let n = a.axes.len();
        let frame = shown
            .map(|b| b.work_frame.as_slice())
            .filter(|f| f.len() == n * (n + 1));
        let origin = |i: usize| shown.and_then(|b| b.origin.get(i)).copied().unwrap_or(0.0);
        let relative: Vec<f64> = (0..n)
            .map(|i| a.axes[i].actual_position - origin(i))
            .collect();
        let work = through(frame, &relative, true);
        let moving = block.is_some_and(|b| {
            b.kind <= MotionBlock::KIND_ARC_CCW || b.kind == MotionBlock::KIND_THREAD
        });
        let to_go: Vec<f64> = (0..n)
            .map(|i| match block.and_then(|b| b.end.get(i)) {
                Some(end) if moving => end - a.axes[i].commanded_position,
                _ => 0.0,
            })
            .collect();
        let to_go = through(frame, &to_go, false);
        a.axes
            .iter()
            .enumerate()
            .map(|(i, axis)| {
                json!({
                    "name": axis.name,
                    "machine": axis.actual_position,
                    "work": work[i],
                    "to_go": to_go[i],
                    "following_error": axis.following_error,
                    "homed": axis.homed,
                })
            })
            .collect()
    }

    /// The frame every page gets several times a second; the tool path and PLC signals carry
    /// only what is new since the previous frame.
    pub fn frame(&mut self) -> Value {
        let machine = self.machine.as_ref().map(|m| {
            json!({
                "mode": MachineState::mode_name_of(m.mode),
                "execution": m.execution_name,
                "program": m.program,
                "line": m.line,
                "emergency_stop": m.emergency_stop,
                "alarm": m.alarm_active,
                "message": m.message,
            })
        });
        let feed = self.current_block().map_or(0.0, |b| b.feed);
        let path_from = self.path_sent;
        let frame = json!({
            "type": "state",
            "machine": machine,
            "axes": self.positions(),
            "plot": match self.face {
                true => json!(["X", "C (face)"]),
                false => json!([self.names.get(self.plot.0), self.names.get(self.plot.1)]),
            },
            "feed": feed,
            "spindle": self.spindle.as_ref().map(|s| json!({
                "commanded_rpm": s.commanded_rpm,
                "actual_rpm": s.actual_rpm,
                "direction": s.direction,
                "override": s.override_percent,
                "at_speed": s.at_speed,
            })),
            "overrides": self.overrides.as_ref().map(|o| json!({
                "feed": o.feed_percent, "spindle": o.spindle_percent, "rapid": o.rapid_percent,
            })),
            "parts": self.parts.as_ref().map(|p| json!({"count": p.count, "target": p.target})),
            // The run-time timers motion counts, seconds (D121): AUTO shows the program's.
            "timers": {
                "cycle": self.status.cycle_time,
                "cutting": self.status.cutting_time,
                "operating": self.status.operating_time,
                "power_on": self.status.power_on_time,
            },
            "alarms": self.active.iter().map(|a| json!({
                "number": a.number, "severity": a.severity, "text": a.text,
                "source": a.source, "program": a.program, "line": a.line,
                "acknowledged": a.acknowledged,
            })).collect::<Vec<_>>(),
            "path_reset": self.path_reset,
            "path": &self.path[path_from.min(self.path.len())..],
            "history": self.history.take_new(),
            "commands": self.commands.take_new(),
        });
        self.path_sent = self.path.len();
        self.path_reset = false;
        frame
    }

    /// Every page has what there is (there are none: the next page gets the welcome).
    pub fn mark_sent(&mut self) {
        self.path_sent = self.path.len();
        self.path_reset = false;
        self.history.take_new();
        self.commands.take_new();
    }

    /// A new page's first frame: everything, the whole path and the histories.
    pub fn welcome(&self) -> Value {
        json!({
            "type": "welcome",
            "axes": self.names,
            "path": self.path,
            "history": self.history.entries,
            "commands": self.commands.entries,
        })
    }

    /// The PLC signals, when a new snapshot came since the last call.
    pub fn signals_frame(&mut self) -> Option<Value> {
        let s = self.signals.as_ref()?;
        if s.scan == self.signals_sent {
            return None;
        }
        self.signals_sent = s.scan;
        Some(json!({
            "type": "signals",
            "scan": s.scan,
            "X": s.x, "Y": s.y, "F": s.f, "G": s.g, "R": s.r, "A": s.a, "K": s.k,
        }))
    }
}

/// `v` through a block's work frame (`n` rows of `n` coefficients and a constant): a
/// position with the constant, a difference of positions (a distance to go) without; `v`
/// itself without a frame.
fn through(frame: Option<&[f64]>, v: &[f64], position: bool) -> Vec<f64> {
    let Some(f) = frame else {
        return v.to_vec();
    };
    let n = v.len();
    (0..n)
        .map(|i| {
            let row = &f[i * (n + 1)..(i + 1) * (n + 1)];
            let linear: f64 = row[..n].iter().zip(v).map(|(c, x)| c * x).sum();
            if position {
                linear + row[n]
            } else {
                linear
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cnc_msgs::msg::Axis;

    fn axes(x: f64, z: f64) -> AxisState {
        let axis = |name: &str, p: f64| Axis {
            name: name.into(),
            commanded_position: p,
            actual_position: p,
            following_error: 0.0,
            homed: true,
            overtravel: 0,
            locked: false,
        };
        AxisState {
            axes: vec![axis("X", x), axis("Z", z)],
            ..AxisState::default()
        }
    }

    /// A turn-mill's polar interpolation (D141): once motion has done the contour-on block the
    /// path shows the face — X (diameter 30: radius 15) and C (90°) as the point (0, 15) — in
    /// a new drawing labelled X and C; once it has done the contour-off block, Z and X again.
    #[test]
    fn the_path_shows_the_face_while_polar_interpolation_runs() {
        let mut v = View::new(vec!["X".into(), "Z".into()], vec![true, false]);
        let with_c = |x: f64, c: f64| {
            let mut a = axes(x, 0.0);
            let mut axis = a.axes[0].clone();
            axis.name = "C".into();
            axis.actual_position = c;
            a.axes.push(axis);
            a
        };
        let status = |done_seq| MotionStatus {
            run_id: 3,
            done_seq,
            ..MotionStatus::default()
        };
        for (seq, on) in [(2, true), (10, false)] {
            v.on_block(MotionBlock {
                run_id: 3,
                seq,
                kind: MotionBlock::KIND_CONTOUR,
                flag: on,
                ..MotionBlock::default()
            });
        }
        v.on_motion_status(status(1));
        v.on_axes(with_c(40.0, 0.0));
        let f = v.frame();
        assert_eq!(
            (f["plot"].clone(), f["path"][0].clone()),
            (json!(["Z", "X"]), json!([0.0, 20.0]))
        );
        v.on_motion_status(status(2));
        v.on_axes(with_c(30.0, 90.0));
        let f = v.frame();
        assert_eq!(f["plot"], json!(["X", "C (face)"]));
        assert_eq!(f["path_reset"], true);
        let p = &f["path"][0];
        assert!(
            p[0].as_f64().unwrap().abs() < 1e-12 && (p[1].as_f64().unwrap() - 15.0).abs() < 1e-12,
            "{p}"
        );
        v.on_motion_status(status(10));
        v.on_axes(with_c(30.0, 90.0));
        let f = v.frame();
        assert_eq!(
            (f["plot"].clone(), f["path"][0].clone()),
            (json!(["Z", "X"]), json!([0.0, 15.0]))
        );
    }

    #[test]
    fn work_position_and_distance_to_go_come_from_the_executing_block() {
        let mut v = View::new(vec!["X".into(), "Z".into()], vec![true, false]);
        v.on_motion_status(MotionStatus {
            run_id: 7,
            done_seq: 1,
            ..MotionStatus::default()
        });
        v.on_block(MotionBlock {
            run_id: 7,
            seq: 2,
            kind: MotionBlock::KIND_LINEAR,
            end: vec![40.0, -30.0],
            origin: vec![-100.0, -200.0],
            feed: 120.0,
            ..MotionBlock::default()
        });
        v.on_axes(axes(50.0, -20.0));
        v.on_motion_status(MotionStatus {
            run_id: 7,
            done_seq: 1,
            cycle_time: 12.5,
            cutting_time: 8.25,
            ..MotionStatus::default()
        });
        let f = v.frame();
        assert_eq!(f["timers"]["cycle"], 12.5);
        assert_eq!(f["timers"]["cutting"], 8.25);
        assert_eq!(f["axes"][0]["work"], 150.0);
        assert_eq!(f["axes"][1]["work"], 180.0);
        assert_eq!(f["axes"][0]["to_go"], -10.0);
        assert_eq!(f["axes"][1]["to_go"], -10.0);
        assert_eq!(f["feed"], 120.0);
        // A lathe's path: Z across, X as radius up.
        assert_eq!(f["path"][0], json!([-20.0, 25.0]));
        assert_eq!(f["plot"], json!(["Z", "X"]));
    }

    /// Under a rotating frame the work position is the block's `work_frame` map of the machine
    /// position less the origin; a map of the wrong size is not used.
    #[test]
    fn the_work_position_under_a_rotation_comes_through_the_blocks_map() {
        for (frame, want) in [
            // ROT 90° in the plane: work X is machine Y, work Y is −machine X (less origin).
            (vec![0.0, 1.0, 0.0, -1.0, 0.0, 0.0], (5.0, -5.0)),
            // A constant in the map (a shift inside the frame).
            (vec![1.0, 0.0, 2.0, 0.0, 1.0, -3.0], (7.0, 2.0)),
            (vec![1.0, 2.0], (5.0, 5.0)),
        ] {
            let mut v = View::new(vec!["X".into(), "Z".into()], vec![false, false]);
            v.on_motion_status(MotionStatus {
                run_id: 3,
                ..MotionStatus::default()
            });
            v.on_block(MotionBlock {
                run_id: 3,
                seq: 1,
                kind: MotionBlock::KIND_LINEAR,
                end: vec![0.0, 0.0],
                origin: vec![10.0, 20.0],
                work_frame: frame.clone(),
                ..MotionBlock::default()
            });
            v.on_axes(axes(15.0, 25.0));
            let f = v.frame();
            assert_eq!(
                (f["axes"][0]["work"].clone(), f["axes"][1]["work"].clone()),
                (json!(want.0), json!(want.1)),
                "{frame:?}"
            );
            // The distance to go (end 0, 0 less 15, 25) turns with the frame, without its
            // constant.
            let to_go = (f["axes"][0]["to_go"].clone(), f["axes"][1]["to_go"].clone());
            let want_to_go = match frame.len() {
                6 if frame[1] == 1.0 => (-25.0, 15.0),
                _ => (-15.0, -25.0),
            };
            assert_eq!(
                to_go,
                (json!(want_to_go.0), json!(want_to_go.1)),
                "{frame:?}"
            );
        }
    }

    #[test]
    fn frames_carry_only_new_path_points_and_a_new_run_starts_over() {
        let mut v = View::new(vec!["X".into(), "Z".into()], vec![true, false]);
        v.on_motion_status(MotionStatus {
            run_id: 1,
            ..MotionStatus::default()
        });
        v.on_axes(axes(10.0, 0.0));
        v.on_axes(axes(10.0, 0.001)); // closer than PATH_STEP: not a new point
        v.on_axes(axes(10.0, -1.0));
        assert_eq!(v.frame()["path"].as_array().map(Vec::len), Some(2));
        v.on_axes(axes(10.0, -2.0));
        let f = v.frame();
        assert_eq!(f["path"], json!([[-2.0, 5.0]]));
        assert_eq!(f["path_reset"], false);
        v.on_motion_status(MotionStatus {
            run_id: 2,
            ..MotionStatus::default()
        });
        let f = v.frame();
        assert_eq!(f["path_reset"], true);
        assert_eq!(f["path"], json!([]));
        assert_eq!(v.welcome()["path"], json!([]));
    }

    #[test]
    fn alarm_history_keeps_raised_and_cleared_in_order() {
        let mut v = View::new(vec!["X".into(), "Z".into()], vec![true, false]);
        let alarm = cnc_msgs::msg::Alarm {
            number: 65,
            text: "emergency stop".into(),
            source: "plc".into(),
            ..Default::default()
        };
        let mut list = crate::alarm_list::AlarmList::default();
        for kind in [AlarmEvent::RAISED, AlarmEvent::CLEARED] {
            let e = AlarmEvent {
                kind,
                alarm: alarm.clone(),
            };
            v.on_alarm_event(&e);
            list.on_event(e);
            v.set_active_alarms(list.alarms());
            let active = v.frame()["alarms"].as_array().map_or(0, Vec::len);
            assert_eq!(active, usize::from(kind == AlarmEvent::RAISED));
        }
        // Entries that come between two frames all go out with the next one.
        for number in [1000, 1001] {
            v.on_alarm_event(&AlarmEvent {
                kind: AlarmEvent::RAISED,
                alarm: cnc_msgs::msg::Alarm {
                    number,
                    ..alarm.clone()
                },
            });
        }
        let f = v.frame();
        assert_eq!(f["history"].as_array().map(Vec::len), Some(2));
        assert_eq!(f["history"][1]["number"], 1001);
        assert_eq!(v.frame()["history"], json!([]));
        let w = v.welcome();
        assert_eq!(w["history"][0]["raised"], true);
        assert_eq!(w["history"][1]["raised"], false);
        assert_eq!(w["history"][1]["number"], 65);
    }
}
