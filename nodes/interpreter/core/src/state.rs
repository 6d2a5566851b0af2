//! [`Core`]: the machine as a program sees it while it runs, and the stream of canonical
//! commands the program has produced so far.

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

use crate::canon::{Aux, Canon, Command, Turn};
use crate::chip_break::ChipBreak;
use crate::comp::RadiusComp;
use crate::corner::Corner;
use crate::error::{AlarmTable, Fault, ProgramError};
use crate::flow::CallLevel;
use crate::geometry::Pt;
use crate::setup::Setup;
use crate::text::{Library, Pos};
use crate::transform::Frame;

/// The working plane: the axis letters of its horizontal and vertical axes (arcs turn
/// counter-clockwise from the first toward the second), the axis along its normal, and what
/// to say when the machine lacks one of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub h: char,
    pub v: char,
    /// The axis along the normal (drilling axis, carried along by compensation); `None`
    /// where the plane has no third axis (a lathe).
    pub normal: Option<char>,
    pub missing: (Fault, &'static str),
}

/// How constant surface speed turns the X position into a spindle speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CssRule {
    /// rpm = speed × 1000 / (π × diameter), clamped by the maximum spindle speed, at least 10.
    SurfaceSpeed,
    /// The speed programmed is the rpm at X0; from the rpm `rpm0` at diameter `x0` (where
    /// constant surface speed was given) the speed changes linearly toward it.
    LinearToCenter { rpm0: f64, x0: f64 },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpindleDir {
    Stopped,
    Cw,
    Ccw,
}

/// Where the control's message service sends a program's text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ServiceOutput {
    /// The serial line (RS232).
    Serial,
    /// A file of the machine's.
    File,
}

/// What radius compensation allows and how its alarms name it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompRules {
    /// A rapid move while compensation is active is refused (alarm [`Fault::CompRapid`]).
    pub refuse_rapid: bool,
    /// "tool-nose compensation" or "cutter compensation".
    pub name: &'static str,
}

/// What a front end tells the core about its control.
#[derive(Debug, Clone, Copy)]
pub struct Rules {
    pub alarms: AlarmTable,
    /// Largest programmable feed per minute, mm/min.
    pub max_feed: f64,
    /// Feed at program start, mm/min.
    pub initial_feed: f64,
    /// A program that runs off its end without a program end is an alarm with this text.
    pub needs_end: Option<&'static str>,
    /// Local variables per call level.
    pub locals: usize,
    /// The active work system's offset is part of the transform chain.
    pub work_offsets: bool,
    pub plane: Plane,
    pub comp: CompRules,
    /// Deepest program call nesting below the main program.
    pub max_call_depth: usize,
}

/// Most blocks read without producing a command before the program is judged stuck in a loop
/// that never moves (a macro jump loop): an alarm instead of a hang.
pub const MAX_SILENT_BLOCKS: u32 = 1_000_000;

/// A following axis coupled to a leading one: it travels `factor` times the leader's travel
/// in machine coordinates, block by block, besides its own programmed path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    pub follow: usize,
    pub lead: usize,
    pub factor: f64,
}

/// The core's state; front ends read and change it through its fields and methods.
pub struct Core {
    pub rules: Rules,
    pub setup: Setup,
    pub library: Library,
    /// The main program and the programs it has called, innermost last.
    pub levels: Vec<CallLevel>,
    /// Every program this run has called so far, by the name the library gives it, with the
    /// text it was read from: a restart at an interrupted block checks that none was edited
    /// since (issue 45).
    pub called: std::collections::BTreeMap<String, Arc<str>>,
    /// Commanded machine position per axis (X as diameter on a diameter axis).
    pub pos: Vec<f64>,
    /// Work position at the program start.
    pub program_start: Vec<f64>,
    // The transform chain (`transform.rs`).
    pub work_system: u8,
    pub shift: Vec<f64>,
    pub local: Vec<f64>,
    /// Coupled motion: following axes that travel a factor of their leading axes' travel,
    /// on top of their own programmed path (see [`Coupling`]).
    pub couplings: Vec<Coupling>,
    /// The travel each following axis has made through its couplings: part of its program
    /// zero, so the program goes on writing the axis's own path.
    pub coupled: Vec<f64>,
    pub frame: Frame,
    pub tool_offset: Vec<f64>,
    pub plane: Plane,
    // Modal motion state.
    pub feed: f64,
    // G95/G94 and G61/G64: changed only with the command that tells motion
    // ([`Core::set_feed_mode`], [`Core::set_path_mode`]).
    pub(crate) feed_per_rev: bool,
    pub(crate) exact_stop_mode: bool,
    /// Under radius compensation the feed holds on the programmed contour, not at the
    /// cutter centre (decision D98).
    pub feed_on_contour: bool,
    /// Under radius compensation outer corners meet at the offsets' intersection (below the
    /// limit of decision D103), not on an arc around the corner.
    pub outer_intersection: bool,
    // The spindle: its direction changes only with what the machine is told
    // ([`Core::spindle_code`], [`Core::orient_spindle`], [`Core::spindle_left_by_code`]).
    spindle: SpindleDir,
    /// Constant surface speed in force, with its rule.
    pub css: Option<CssRule>,
    /// The surface speed (or rpm at X0) constant surface speed keeps.
    pub css_speed: f64,
    /// Last programmed spindle speed, rpm.
    pub rpm: f64,
    /// Last spindle speed sent, rpm.
    pub sent_rpm: Option<f64>,
    /// Maximum spindle speed under constant surface speed.
    pub max_rpm: Option<f64>,
    // Path filters (`emit.rs`).
    pub comp: Option<RadiusComp>,
    /// Compensation ends with the next move.
    pub comp_cancel: bool,
    /// Compensation starts over on this side with this radius at the next move, without a
    /// cancel (decision D104).
    pub comp_restart: Option<(crate::comp::Side, f64)>,
    pub corner: Option<Corner>,
    pub chip_break: Option<ChipBreak>,
    /// While compensation holds an element back, commands from this index of `pending` on
    /// wait for it (they come after it in the program).
    pub(crate) hold_at: Option<usize>,
    /// While a chamfered or rounded corner's element is held, the index of `pending` where its
    /// moves belong (commands from it on came after it in the program).
    pub(crate) corner_slot: Option<usize>,
    /// The place a front end keeps for moves it can only make once a later block is read
    /// (an approach that ends tangent to the next element): commands from it on wait.
    pub(crate) reserved: Option<usize>,
    /// Common variables by number.
    pub common: HashMap<i64, f64>,
    // The stream.
    pub(crate) pending: VecDeque<Canon>,
    /// The source line of the block being run.
    pub line: u32,
    /// Where the line being run starts (a loop comes back to it).
    pub block_start: Pos,
    pub(crate) done: bool,
    pub(crate) error: Option<ProgramError>,
    pub(crate) silent_blocks: u32,
    /// How far into each program text (by the text's address) reading has come, and whether
    /// the silent blocks since the last command read any text again: only a stretch that did
    /// is a loop (2,000,000 blank lines read once are none).
    pub(crate) furthest: std::collections::HashMap<usize, usize>,
    pub(crate) silent_reread: bool,
    /// A program end has been read.
    pub saw_end: bool,
    /// Commands handed out by [`crate::next_command`] so far.
    pub emitted: u64,
    /// Messages a program shows the operator, each with the number of commands that
    /// come before it: it shows once the machine has finished those.
    pub operator_messages: Vec<(u64, String)>,
    /// Texts a program sends out through the control's message service (a serial line, a
    /// file), each with the number of commands before it, as `operator_messages`.
    pub service_messages: Vec<(u64, ServiceOutput, String)>,
    /// A block search runs the program without motion: what the machine's work counts
    /// (pieces on a tool) does not count again.
    pub searching: bool,
    /// Blocks whose end the machine decides (a measuring move, a travel to a fixed stop) wait
    /// for its result (a running cell); otherwise their event is taken as coming at the
    /// move's end (a check, a simulation, a block search: D116).
    pub on_machine: bool,
    /// Such a block has gone out and its result has not come: nothing is read on. With the
    /// move's number among the program's commands.
    pub(crate) awaiting: Option<(crate::measure::Awaited, u64)>,
    /// The last measuring move's result.
    pub measurement: Option<crate::measure::Measurement>,
    /// The timers the last preprocessing stop read from the machine, until taken.
    pub(crate) timers_read: Option<crate::measure::MachineTimers>,
    /// Per axis, its travel to a fixed stop as the program sees it.
    pub fixed_stops: Vec<crate::measure::FixedStop>,
    /// Where the probe last switched (machine coordinates): a job in which it did not
    /// switch leaves it.
    pub measured_at: Option<Vec<f64>>,
    /// The cylinder surface transformation in force ([`crate::cylinder`]): `pos` is then
    /// the basic system's position.
    pub cylinder: Option<crate::cylinder::Cylinder>,
    /// Polar interpolation in force ([`crate::polar`]): `pos` is then the face's position.
    pub polar: Option<crate::polar::Polar>,
    /// The live tool's speed in speed mode, r/min; 0 in position control (D143).
    pub live_tool_rpm: f64,
    /// Under it, the compensation's offset at the end of the last move, and the one the move
    /// being queued ends with.
    pub(crate) wall: Pt,
    pub(crate) out_offset: Option<Pt>,
    /// Under it, where the controlled point stands in the basic system.
    pub(crate) controlled: Vec<f64>,
}

impl Core {
    /// The core for the program `text` on the machine `setup`, with the called programs of
    /// `library`.
    pub fn new(rules: Rules, text: &str, setup: Setup, library: Library) -> Core {
        let n = setup.axes.len();
        let common = setup.kept.iter().map(|(&k, &v)| (k, v)).collect();
        let mut core = Core {
            levels: vec![CallLevel::main(Arc::from(text), rules.locals)],
            called: std::collections::BTreeMap::new(),
            pos: setup.start.clone(),
            program_start: Vec::new(),
            work_system: setup.work_system.min(5),
            shift: vec![0.0; n],
            couplings: Vec::new(),
            coupled: vec![0.0; n],
            local: vec![0.0; n],
            frame: Frame::identity(n),
            tool_offset: vec![0.0; n],
            plane: rules.plane,
            feed: rules.initial_feed,
            feed_per_rev: false,
            exact_stop_mode: false,
            feed_on_contour: false,
            outer_intersection: false,
            spindle: SpindleDir::Stopped,
            css: None,
            css_speed: 0.0,
            rpm: 0.0,
            sent_rpm: None,
            max_rpm: None,
            comp: None,
            comp_cancel: false,
            comp_restart: None,
            corner: None,
            chip_break: None,
            hold_at: None,
            corner_slot: None,
            reserved: None,
            common,
            pending: VecDeque::new(),
            line: 0,
            block_start: Pos::default(),
            done: false,
            error: None,
            silent_blocks: 0,
            furthest: std::collections::HashMap::new(),
            silent_reread: false,
            saw_end: false,
            emitted: 0,
            operator_messages: Vec::new(),
            service_messages: Vec::new(),
            searching: false,
            on_machine: false,
            awaiting: None,
            fixed_stops: vec![crate::measure::FixedStop::Off; n],
            measurement: None,
            timers_read: None,
            measured_at: None,
            cylinder: None,
            polar: None,
            live_tool_rpm: 0.0,
            wall: Pt::new(0.0, 0.0),
            out_offset: None,
            controlled: Vec::new(),
            rules,
            setup,
            library,
        };
        core.program_start = core.work_position();
        core
    }

    // ------------------------------------------------------------------ errors

    /// The alarm of `f` in the front end's table, at the line being run, naming the called
    /// program it is in.
    pub fn fault(&self, f: Fault, text: impl Into<String>) -> ProgramError {
        let mut e = ProgramError::new((self.rules.alarms)(f), self.line, text);
        if let Some(level) = self.levels.last() {
            e.program.clone_from(&level.name);
        }
        e
    }

    // ------------------------------------------------------------------ coordinates

    pub fn axis(&self, letter: char) -> Option<usize> {
        self.setup.axes.iter().position(|&a| a == letter)
    }

    /// Program zero of axis `i` in machine coordinates, without the frame.
    pub fn origin(&self, i: usize) -> f64 {
        let letter = self.setup.axes[i];
        let work = if self.rules.work_offsets {
            self.setup.offsets.work(self.work_system, letter)
        } else {
            0.0
        };
        work + self.shift[i] + self.local[i] + self.tool_offset[i] + self.coupled[i]
    }

    /// Program zero per axis in machine coordinates (work offset, shifts, tool offset) as it
    /// stands after the blocks read so far: the HMI's work position is measured from it.
    pub fn program_origin(&self) -> Vec<f64> {
        (0..self.pos.len()).map(|i| self.origin(i)).collect()
    }

    /// The frame's map from a machine position less [`Core::program_origin`] to the work
    /// position, as `n` rows of `n` coefficients and a constant (row-major, `n × (n + 1)`),
    /// so that a display turns the slides' position into the work's under a rotating,
    /// scaling or mirroring frame; empty when the frame only shifts (the work position is
    /// then the machine's less the origin) or under the cylinder transformation, which is
    /// no linear map.
    pub fn work_frame(&self) -> Vec<f64> {
        if self.frame.is_identity() || self.cylinder.is_some() {
            return Vec::new();
        }
        let n = self.pos.len();
        let origin = self.program_origin();
        let constant = self.work_of(&origin);
        let mut rows = vec![0.0; n * (n + 1)];
        let mut m = origin.clone();
        for j in 0..n {
            m[j] += 1.0;
            let w = self.work_of(&m);
            m[j] = origin[j];
            for i in 0..n {
                rows[i * (n + 1) + j] = w[i] - constant[i];
            }
        }
        for i in 0..n {
            rows[i * (n + 1) + n] = constant[i];
        }
        rows
    }

    /// Current position in work coordinates (X as diameter).
    /// One allocation per call: asked for at every move.
    pub fn work_position(&self) -> Vec<f64> {
        self.work_of(&self.pos)
    }

    /// [`Core::work_position`] into `out`, whose room a caller keeps from block to block.
    pub fn work_position_into(&self, out: &mut Vec<f64>) {
        self.work_of_into(&self.pos, out);
    }

    /// The work coordinates of the machine position `machine` under the transform chain as
    /// it stands.
    pub fn work_of(&self, machine: &[f64]) -> Vec<f64> {
        let mut p = Vec::with_capacity(self.pos.len());
        self.work_of_into(machine, &mut p);
        p
    }

    /// [`Core::work_of`] into `out` (emptied first).
    fn work_of_into(&self, machine: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            (0..self.pos.len()).map(|i| machine.get(i).copied().unwrap_or(0.0) - self.origin(i)),
        );
        if !self.frame.is_identity() {
            self.frame.invert_in_place(out);
        }
    }

    pub fn to_machine(&self, work: &[f64]) -> Vec<f64> {
        let mut m = if self.frame.is_identity() {
            work.to_vec()
        } else {
            self.frame.apply(work)
        };
        for (i, x) in m.iter_mut().enumerate() {
            *x += self.origin(i);
        }
        m
    }

    /// The X and Z axes' indices (alarm when the machine lacks one).
    pub fn xz(&self) -> Result<(usize, usize), ProgramError> {
        match (self.axis('X'), self.axis('Z')) {
            (Some(x), Some(z)) => Ok((x, z)),
            _ => Err(self.fault(Fault::AxisAddress, "this function needs the X and Z axes")),
        }
    }

    /// The working plane as (horizontal, vertical) axis indices.
    pub fn plane_axes(&self) -> Result<(usize, usize), ProgramError> {
        match (self.axis(self.plane.h), self.axis(self.plane.v)) {
            (Some(h), Some(v)) => Ok((h, v)),
            _ => Err(self.fault(self.plane.missing.0, self.plane.missing.1)),
        }
    }

    /// The axis along the plane's normal, if the plane has one and the machine has it.
    pub fn plane_normal(&self) -> Option<usize> {
        self.axis(self.plane.normal?)
    }

    /// Display units → plane units: a diameter axis counts half.
    pub fn axis_scale(&self, i: usize) -> f64 {
        if self.setup.diameter.get(i) == Some(&true) {
            0.5
        } else {
            1.0
        }
    }

    /// The scale of the X axis (0.5 when it is programmed in diameter).
    pub fn x_scale(&self) -> f64 {
        match self.axis('X') {
            Some(i) if self.setup.diameter.get(i) == Some(&true) => 0.5,
            _ => 1.0,
        }
    }

    /// Work position as a plane point (`z` horizontal, `r` vertical; X as radius).
    pub fn plane_point(&self, work: &[f64]) -> Result<Pt, ProgramError> {
        let (h, v) = self.plane_axes()?;
        Ok(Pt::new(
            work[h] * self.axis_scale(h),
            work[v] * self.axis_scale(v),
        ))
    }

    /// Sets the plane axes of work position `w` to the plane point `p`.
    pub fn set_plane_point(&self, w: &mut [f64], p: Pt) {
        if let Ok((h, v)) = self.plane_axes() {
            w[v] = p.r / self.axis_scale(v);
            w[h] = p.z / self.axis_scale(h);
        }
    }

    /// `base` with its plane axes at `p`.
    pub fn with_point(&self, base: &[f64], p: Pt) -> Vec<f64> {
        let mut w = base.to_vec();
        self.set_plane_point(&mut w, p);
        w
    }

    // ------------------------------------------------------------------ the stream

    /// Queues a command on the line being run.
    /// A message for the operator, in its place among the commands.
    pub fn operator_message(&mut self, text: String) {
        let before = self.emitted + self.pending.len() as u64;
        self.operator_messages.push((before, text));
    }

    /// A text for the message service's `output`, sent when the commands before it are done.
    pub fn service_message(&mut self, output: ServiceOutput, text: String) {
        let before = self.emitted + self.pending.len() as u64;
        self.service_messages.push((before, output, text));
    }

    pub fn push(&mut self, command: Command) {
        self.pending.push_back(Canon {
            line: self.line,
            main_line: self.main_line(),
            command,
        });
    }

    pub fn aux(&mut self, a: Aux) {
        self.push(Command::Aux(a));
    }

    /// Feed per revolution (G95) rather than per minute.
    pub fn feed_per_rev(&self) -> bool {
        self.feed_per_rev
    }

    /// Exact stop at every block end (G61/G60) rather than blending (G64).
    pub fn exact_stop_mode(&self) -> bool {
        self.exact_stop_mode
    }

    /// Feed per revolution or per minute, and motion told (rs274ngc's SET_FEED_MODE).
    pub fn set_feed_mode(&mut self, per_rev: bool) {
        self.feed_per_rev = per_rev;
        self.push(Command::FeedMode { per_rev });
    }

    /// Exact stop or blending from here on, and motion told (SET_MOTION_CONTROL_MODE).
    pub fn set_path_mode(&mut self, exact_stop: bool) {
        self.exact_stop_mode = exact_stop;
        self.push(Command::PathMode { exact_stop });
    }

    /// Which way the spindle turns, as the program has told the machine.
    pub fn spindle(&self) -> SpindleDir {
        self.spindle
    }

    /// A spindle code to the machine, M03 clockwise, M04 counter-clockwise, M05 stop, M19
    /// orient (any other M code goes as it is), with the direction it leaves: the spindle's
    /// modal state changes with the command that changes the machine, as rs274ngc's
    /// START_SPINDLE_… and STOP_SPINDLE_TURNING do.
    pub fn spindle_code(&mut self, m: i32) {
        self.spindle = match m {
            3 => SpindleDir::Cw,
            4 => SpindleDir::Ccw,
            5 | 19 => SpindleDir::Stopped,
            _ => self.spindle,
        };
        self.aux(Aux::M(m));
    }

    /// The spindle stopped at an angle, reached by `way` (ORIENT_SPINDLE).
    pub fn orient_spindle(&mut self, degrees: f64, way: Turn) {
        self.spindle = SpindleDir::Stopped;
        self.aux(Aux::Orient { degrees, way });
    }

    /// The direction a code of the dialect's own table leaves the spindle in (a program end
    /// stops it); the code itself went to the machine through the dialect's M table.
    pub fn spindle_left_by_code(&mut self, dir: SpindleDir) {
        self.spindle = dir;
    }

    /// The commands queued from index `from` on (what a block produced, when `from` is
    /// [`Core::queued`] before it).
    pub fn queued_since(&self, from: usize) -> impl Iterator<Item = &Command> {
        self.pending.iter().skip(from).map(|c| &c.command)
    }

    /// How many commands are queued: a front end compares it before and after a block to
    /// know what the block produced.
    pub fn queued(&self) -> usize {
        self.pending.len()
    }

    /// The block that produced the commands from index `from` of the queue on ends at rest
    /// (an exact stop for one block): its first motion is preceded by an exact-stop path mode
    /// and the block is followed by the continuous one.
    pub fn exact_stop_block(&mut self, from: usize) {
        let first = self
            .pending
            .iter()
            .skip(from)
            .position(|c| c.command.end().is_some());
        if let Some(i) = first {
            self.pending.insert(
                from + i,
                Canon {
                    line: self.line,
                    main_line: self.main_line(),
                    command: Command::PathMode { exact_stop: true },
                },
            );
            self.push(Command::PathMode { exact_stop: false });
        }
    }

    /// Sets the spindle speed, sending it when it changed.
    pub fn set_rpm(&mut self, rpm: f64) {
        self.rpm = rpm;
        if self.sent_rpm != Some(rpm) {
            self.sent_rpm = Some(rpm);
            self.aux(Aux::S(rpm));
        }
    }

    /// Sends the spindle speed for a block ending at work position `end` under constant
    /// surface speed: the speed at the end point (decision D17).
    pub fn spindle_for(&mut self, end: &[f64]) {
        let Some(rule) = self.css else {
            return;
        };
        let x = self.axis('X').map(|i| end[i].abs()).unwrap_or(0.0);
        let rpm = match rule {
            CssRule::LinearToCenter { rpm0, x0 } => {
                if x0 <= 0.0 {
                    self.css_speed
                } else {
                    self.css_speed + (rpm0 - self.css_speed) * (x / x0).min(1.0)
                }
            }
            CssRule::SurfaceSpeed => {
                let d = x.max(1e-3);
                let mut rpm = self.css_speed * 1000.0 / (std::f64::consts::PI * d);
                if let Some(m) = self.max_rpm {
                    rpm = rpm.min(m);
                }
                rpm.max(10.0)
            }
        };
        let rpm = (rpm * 10.0).round() / 10.0;
        if self.sent_rpm != Some(rpm) {
            self.sent_rpm = Some(rpm);
            self.aux(Aux::S(rpm));
        }
    }
}
