//! The machine section: axes, offset pages, kept-memory and program files, dialect.

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MachineConfig {
    /// ROS 2 namespace of every topic and service, e.g. `lathe1` → `/lathe1/spindle`.
    pub namespace: String,
    /// Program dialect: one of [`DIALECTS`].
    pub dialect: String,
    pub axes: Vec<AxisEntry>,
    /// Arc plane as (horizontal, vertical) axis names; G02 is clockwise seen this way.
    #[serde(default = "default_arc_plane")]
    pub arc_plane: [String; 2],
    /// Where the turret sits: `rear` (behind the spindle axis, X up in the drawing) or
    /// `front` (toward the operator). G41/G42 swap sides with it (`000` §6.1, decision D30).
    #[serde(default)]
    pub tool_post: ToolPost,
    /// The offset page: tool offsets by offset number (T0101 → 1; on the mill H/D 1–200).
    #[serde(default)]
    pub tools: BTreeMap<u32, ToolEntry>,
    /// A mill tool table file (`number length_mm diameter_mm` per line, (`cnc_runtime::tool_table`)),
    /// relative to the config file's folder; its entries join `tools` when the config loads.
    #[serde(default)]
    pub tool_table: Option<std::path::PathBuf>,
    /// Work offsets by code (`G54`…`G59`; on GTC2E the offset groups of G54–G57), per axis.
    #[serde(default)]
    pub work_offsets: BTreeMap<String, BTreeMap<String, f64>>,
    /// Where the kept variables (#200–#289) and the offset page as programs leave them are
    /// stored (YAML, relative to the config file's folder); absent: kept for this run of the
    /// cell only.
    #[serde(default)]
    pub memory_file: Option<std::path::PathBuf>,
    /// Where the program in automatic operation and its line are kept (within 0.1 s), for a
    /// restart after a power loss (YAML, relative to the config file's folder; decisions D64);
    /// absent: not kept.
    #[serde(default)]
    pub position_file: Option<std::path::PathBuf>,
    /// The message service's file (`001` §8.4.4, `MSG("File: …")`): a line per text, kept to
    /// `msg_file_kib` by dropping its oldest lines (relative to the config file's folder);
    /// absent: the file output is off.
    #[serde(default)]
    pub msg_file: Option<std::path::PathBuf>,
    /// Its largest size: 10, 100 or 1024 KiB (the manual's choices).
    #[serde(default = "default_msg_file_kib")]
    pub msg_file_kib: u32,
    /// Program memory: a folder of plain program files, relative to the config file's
    /// folder ((`cnc_runtime::program_store`)); absent: programs are kept for this run only.
    #[serde(default)]
    pub program_directory: Option<std::path::PathBuf>,
    /// External drives for EXTCALL (the 802D's CF card `D:`, USB device `G:`): a drive letter
    /// and its folder, relative to the config file's folder; read when a program starts, never
    /// written (decisions D110).
    #[serde(default)]
    pub external_drives: BTreeMap<String, std::path::PathBuf>,
    /// The program memory's capacity in KiB (all programs together; alarm 70 when full).
    #[serde(default = "default_program_capacity")]
    pub program_capacity_kib: u64,
    /// Huaxing S#170: a T word calls this program (O number, 1–9999) as the tool-change
    /// macro; absent: T goes to the PLC.
    #[serde(default)]
    pub tool_change_macro: Option<u32>,
    /// T only preselects the tool and M6 changes it (the 802D's machine data for a mill
    /// with a magazine); false: T changes the tool at once (D94).
    #[serde(default)]
    pub tool_change_with_m6: bool,
    /// A turn-mill lathe: the main spindle is also the C axis, positioned by its drive
    /// (M14.6, G08 on the Huaxing control, `000` §4.2.6–4.2.7, D138).
    #[serde(default)]
    pub spindle_c_axis: bool,
    /// The C axis's rates in contour control (polar interpolation, D141): degrees/min and
    /// degrees/s². Absent: [`CAxisEntry::default`].
    #[serde(default)]
    pub c_axis: CAxisEntry,
    /// The live tool (飞刀盘, `000` §5.9, D142): a tool spindle on a drive of its own, the
    /// axis G14.n names. None: the machine has none.
    #[serde(default)]
    pub live_tool: Option<LiveToolEntry>,
    /// The X-table input a skip move (the Huaxing's G31) stops on, e.g. `X11.5` (S#46): the
    /// input wired to the drives' measuring input, which latches the axes at its edge. None:
    /// the machine has no skip input (D139).
    #[serde(default)]
    pub skip_input: Option<String>,
    /// After a skip, the axes' coordinates stay the actual ones where the input came (B19.6 =
    /// 1); false: the programmed end point is written over them (B19.6 = 0, D139).
    #[serde(default = "default_true")]
    pub skip_keeps_actual: bool,
    /// The tool in the spindle when the kept memory says none (the machine's first power-up,
    /// and `cnc check`/`simulate`, which read no kept memory; `--tool-in-spindle` overrides):
    /// a program that selects its edge before M6 finds the tool it expects (issue 46).
    #[serde(default)]
    pub tool_in_spindle: u32,
    /// Where parameters written from the cell (SetParameter) are stored; they are applied over
    /// this file at start (decisions D44), relative to the config file's folder. Absent:
    /// parameters cannot be written.
    #[serde(default)]
    pub parameter_file: Option<std::path::PathBuf>,
    /// How far a lathe roughing contour (G71/G72) may leave its start point or turn back
    /// before the cycle is refused, mm (Huaxing GS#33).
    #[serde(default = "default_contour_tolerance")]
    pub contour_tolerance: f64,
    /// How a number without a decimal point reads: `calculator` (X50 is 50 mm) or
    /// `increment` (X50 is 50 least input increments, 0.050 mm on the mill); absent: as the
    /// dialect's manual says (decision D52).
    #[serde(default)]
    pub decimal_point: Option<DecimalPoint>,
    /// How a program restarted at a block (block search) approaches it (decisions D67).
    #[serde(default)]
    pub restart: RestartConfig,
    /// The order of the reference return, axis names; default: Z first on a machine with a
    /// Y axis (the tool leaves the work first), else the order of `axes` (decisions D68).
    #[serde(default)]
    pub reference_order: Vec<String>,
}

/// The approach to a restart block: first the retract axis away from the work, then the other
/// axes, then the retract axis at rapid to `clearance` from the block's start and onto it at
/// `approach_feed`.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RestartConfig {
    /// The retract axis and the direction away from the work, e.g. `+X` (a lathe's
    /// outside work), `-X` (its boring), `+Z` (a mill); absent: `+Z` on a machine with a Y
    /// axis, else `+X`.
    #[serde(default)]
    pub retract: Option<String>,
    /// mm/min for the last leg onto the restart point; absent: 500.
    #[serde(default)]
    pub approach_feed: Option<f64>,
    /// The last leg's length in mm (the retract axis comes at rapid to this distance from
    /// the point); absent: 1.
    #[serde(default)]
    pub clearance: Option<f64>,
}

impl RestartConfig {
    /// The retract axis (index among `axes`) and whether away is positive, when given.
    pub fn retract_axis(&self, axes: &[AxisEntry]) -> Result<Option<(usize, bool)>, String> {
        let Some(r) = self.retract.as_deref() else {
            return Ok(None);
        };
        let bad = || format!("machine.restart.retract {r:?}: a sign and an axis, e.g. +X or -Z");
        let (positive, letter) = match r.trim().split_at_checked(1) {
            Some(("+", l)) => (true, l),
            Some(("-", l)) => (false, l),
            _ => return Err(bad()),
        };
        let index = axes.iter().position(|a| a.name == letter).ok_or_else(bad)?;
        Ok(Some((index, positive)))
    }
}

/// How a number without a decimal point reads (FANUC's parameter DPI).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DecimalPoint {
    Calculator,
    Increment,
}

fn default_program_capacity() -> u64 {
    64 * 1024
}

fn default_contour_tolerance() -> f64 {
    0.05
}

/// `G54` → 0 … `G59` → 5 (case and surrounding blanks ignored).
pub fn work_offset_index(code: &str) -> Option<u8> {
    match code.trim().to_ascii_uppercase().as_str() {
        "G54" => Some(0),
        "G55" => Some(1),
        "G56" => Some(2),
        "G57" => Some(3),
        "G58" => Some(4),
        "G59" => Some(5),
        _ => None,
    }
}

/// The program dialects a launch config may name (the interpreter's `Dialect::from_name`
/// knows each; its tests check that).
pub const DIALECTS: [&str; 5] = [
    "huaxing-lathe",
    "gtc2e-lathe",
    "iso-lathe",
    "fanuc-mill",
    "sinumerik-802d",
];

/// One row of the offset page (`000` §5.2, `002` §3.7): geometry and wear (X as diameter),
/// nose radius and imaginary tip direction 0–9.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ToolEntry {
    #[serde(default)]
    pub x: f64,
    #[serde(default)]
    pub z: f64,
    #[serde(default)]
    pub wear_x: f64,
    #[serde(default)]
    pub wear_z: f64,
    #[serde(default)]
    pub radius: f64,
    #[serde(default)]
    pub tip: u8,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ToolPost {
    #[default]
    Rear,
    Front,
}

fn default_arc_plane() -> [String; 2] {
    ["Z".into(), "X".into()]
}

/// The turn-mill's C axis (the main spindle in position control) as a contouring axis.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CAxisEntry {
    /// Fastest C turns in contour control, degrees/min (also its rapid, G00 C).
    pub max_velocity: f64,
    /// degrees/s².
    pub max_acceleration: f64,
}

impl Default for CAxisEntry {
    /// 100 r/min and 0.1 s to reach it: what a lathe's main spindle gives as a position-
    /// controlled axis with its gearing.
    fn default() -> Self {
        CAxisEntry {
            max_velocity: 36_000.0,
            max_acceleration: 6_000.0,
        }
    }
}

/// A live tool's drive: the axis letter the program's G14.n names (n = 1…6 for X…C), its top
/// speed (S#122) and the time it takes to reach it (S#123).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LiveToolEntry {
    pub axis: String,
    pub max_rpm: f64,
    pub time_constant: f64,
    /// Simulated drive time constant, s: a tool spindle's position loop is slower than a
    /// slide's.
    #[serde(default = "default_live_tool_lag")]
    pub drive_lag: f64,
}

fn default_live_tool_lag() -> f64 {
    0.012
}

impl LiveToolEntry {
    /// The axis number G14.n names: 1…6 for X, Y, Z, A, B, C.
    pub fn number(&self) -> Option<u8> {
        let i = ["X", "Y", "Z", "A", "B", "C"]
            .iter()
            .position(|a| *a == self.axis)?;
        u8::try_from(i + 1).ok()
    }

    /// The drive's acceleration, degrees/s²: top speed in the time constant.
    pub fn acceleration(&self) -> f64 {
        self.max_rpm * 6.0 / self.time_constant.max(1e-3)
    }

    /// The letter the program's position carries it under.
    pub fn letter(&self) -> char {
        self.axis.chars().next().unwrap_or('A')
    }
}

/// One axis: limits in display units (X as diameter when `diameter`).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct AxisEntry {
    pub name: String,
    #[serde(default)]
    pub diameter: bool,
    pub min: f64,
    pub max: f64,
    /// Rapid rate, mm/min of slide travel.
    pub max_velocity: f64,
    /// mm/s² of slide travel.
    pub max_acceleration: f64,
    /// mm/s³ of slide travel, for S-curve profiles; default: the acceleration reached in
    /// [`DEFAULT_JERK_TIME`].
    #[serde(default)]
    pub max_jerk: Option<f64>,
    #[serde(default = "default_in_position")]
    pub in_position: f64,
    /// Largest distance the slide may lag its setpoint, mm; default: 1.5 × what the rapid
    /// rate gives over the drive lag and ten servo periods of 4 ms (feedback may come a few
    /// ticks late on a machine without a real-time kernel), at least 1 mm.
    #[serde(default)]
    pub following_error: Option<f64>,
    /// Simulated drive time constant, s.
    #[serde(default = "default_drive_lag")]
    pub drive_lag: f64,
    /// Simulated power-on position, display units.
    #[serde(default)]
    pub home: f64,
    /// The second reference point (FANUC G30, the mill's tool-change position), machine
    /// coordinates, display units; default: the reference point (`home`).
    #[serde(default)]
    pub second_reference: Option<f64>,
    /// Fixed points 1–4 (SINUMERIK MD30600 `$MA_FIX_POINT_POS`, approached by G75 FP=n),
    /// machine coordinates, display units (decisions D102).
    #[serde(default)]
    pub fixed_points: Vec<f64>,
    /// An incremental encoder with a deceleration dog and index marks: the axis must return
    /// to its reference point (`home`) after power-on (decisions D68). Absent: an absolute
    /// encoder, referenced at power-on.
    #[serde(default)]
    pub reference: Option<ReferenceEntry>,
    /// Where the hard overtravel switches sit, display units, machine coordinates (the
    /// simulator presses them there; decisions D70); default 1 mm (slide) beyond `min` and
    /// `max`.
    #[serde(default)]
    pub overtravel: Option<[f64; 2]>,
}

/// How an axis with an incremental encoder finds its reference point: at `fast_feed` toward
/// the dog, at `slow_feed` off it, then the first index mark is the reference point (`home`).
/// Feeds are mm/min and lengths mm of slide travel.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceEntry {
    /// The axis approaches the dog in its positive direction (else negative).
    #[serde(default = "default_true")]
    pub positive: bool,
    /// Default: half the rapid rate (Huaxing S#63, 50 % of G00).
    #[serde(default)]
    pub fast_feed: Option<f64>,
    #[serde(default = "default_slow_feed")]
    pub slow_feed: f64,
    /// Distance between index marks: one motor turn on the ball screw.
    #[serde(default = "default_grid")]
    pub grid: f64,
    /// The simulated dog's length; it ends half a grid before the reference point.
    #[serde(default = "default_dog_length")]
    pub dog_length: f64,
    /// Where the simulated slide stands at power-on, display units (the encoder counts from
    /// there); default 50 mm of slide before the dog.
    #[serde(default)]
    pub power_on: Option<f64>,
}

fn default_true() -> bool {
    true
}
fn default_slow_feed() -> f64 {
    200.0
}
fn default_grid() -> f64 {
    5.0
}
fn default_dog_length() -> f64 {
    20.0
}

impl ReferenceEntry {
    /// mm/min of the fast approach on an axis of rapid rate `rapid`.
    pub fn fast(&self, rapid: f64) -> f64 {
        self.fast_feed.unwrap_or(rapid * 0.5)
    }
}

impl AxisEntry {
    /// The overtravel switches' positions, display units: `overtravel`, else 1 mm of slide
    /// beyond the soft limits.
    pub fn overtravel_switches(&self) -> [f64; 2] {
        self.overtravel
            .unwrap_or([self.min - 1.0 / self.scale(), self.max + 1.0 / self.scale()])
    }

    /// The simulated slide's power-on position, display units: `home` for an absolute
    /// encoder; for an incremental one `reference.power_on`, else 50 mm of slide before the
    /// dog.
    pub fn power_on(&self) -> f64 {
        match &self.reference {
            None => self.home,
            Some(r) => r.power_on.unwrap_or_else(|| {
                let before = (r.grid / 2.0 + r.dog_length + 50.0) / self.scale();
                if r.positive {
                    self.home - before
                } else {
                    self.home + before
                }
            }),
        }
    }

    /// Display units → slide travel: a diameter axis moves half of what it shows.
    pub fn scale(&self) -> f64 {
        if self.diameter {
            0.5
        } else {
            1.0
        }
    }

    /// Following-error limit, mm of slide travel.
    pub fn following_error_limit(&self) -> f64 {
        self.following_error.unwrap_or_else(|| {
            (1.5 * self.max_velocity / 60.0 * (self.drive_lag + 10.0 * 0.004)).max(1.0)
        })
    }

    /// Jerk limit, mm/s³ of slide travel.
    pub fn jerk(&self) -> f64 {
        self.max_jerk
            .unwrap_or(self.max_acceleration / DEFAULT_JERK_TIME)
    }

    /// The axis's address letter (names are validated to be one letter).
    pub fn letter(&self) -> char {
        self.name.chars().next().unwrap_or('?')
    }
}

/// Time to ramp up to full acceleration when an axis names no jerk limit, s.
pub const DEFAULT_JERK_TIME: f64 = 0.05;

fn default_msg_file_kib() -> u32 {
    10
}

fn default_in_position() -> f64 {
    0.0005
}
fn default_drive_lag() -> f64 {
    0.008
}

impl MachineConfig {
    /// The axis address letters in machine order, e.g. `['X', 'Z']`.
    pub fn axis_letters(&self) -> Vec<char> {
        self.axes.iter().map(AxisEntry::letter).collect()
    }

    /// Per axis: programmed and displayed in diameter.
    pub fn diameter_axes(&self) -> Vec<bool> {
        self.axes.iter().map(|a| a.diameter).collect()
    }

    /// The second reference point per axis (G30), display units.
    pub fn second_reference(&self) -> Vec<f64> {
        self.axes
            .iter()
            .map(|a| a.second_reference.unwrap_or(a.home))
            .collect()
    }

    /// Each axis's fixed points (G75), machine coordinates, display units.
    pub fn fixed_points(&self) -> Vec<Vec<f64>> {
        self.axes.iter().map(|a| a.fixed_points.clone()).collect()
    }

    /// Power-on position in display units.
    pub fn home(&self) -> Vec<f64> {
        self.axes.iter().map(|a| a.home).collect()
    }

    /// The machine section's own rules; an error names the setting and what it may be.
    pub fn validate(&self) -> Result<(), String> {
        if ![10, 100, 1024].contains(&self.msg_file_kib) {
            return Err(format!(
                "machine.msg_file_kib {}: 10, 100 or 1024 (the MSG service's sizes)",
                self.msg_file_kib
            ));
        }
        let ns = &self.namespace;
        if !DIALECTS.contains(&self.dialect.as_str()) {
            return Err(format!(
                "machine.dialect {:?}: one of {}",
                self.dialect,
                DIALECTS.join(", ")
            ));
        }
        if ns.is_empty()
            || !ns.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            || ns.starts_with(|c: char| c.is_ascii_digit())
        {
            return Err(format!(
                "machine.namespace {ns:?}: letters, digits and _ only, not starting with a digit"
            ));
        }
        if let Some(bad) = self
            .external_drives
            .keys()
            .find(|k| !(k.len() == 1 && k.bytes().all(|b| b.is_ascii_alphabetic())))
        {
            return Err(format!(
                "machine.external_drives {bad:?}: a drive is one letter (D, G)"
            ));
        }
        let tol = self.contour_tolerance;
        if !(0.001..=1.0).contains(&tol) {
            return Err(format!(
                "machine.contour_tolerance {tol}: 0.001–1 mm (GS#33)"
            ));
        }
        self.restart.retract_axis(&self.axes)?;
        for name in &self.reference_order {
            if !self.axes.iter().any(|a| &a.name == name) {
                return Err(format!("machine.reference_order: no axis {name:?}"));
            }
        }
        if let Some(f) = self.restart.approach_feed {
            if !(f.is_finite() && f > 0.0 && f <= 100_000.0) {
                return Err(format!(
                    "machine.restart.approach_feed {f}: 0–100000 mm/min"
                ));
            }
        }
        if let Some(c) = self.restart.clearance {
            if !(c.is_finite() && (0.0..=100.0).contains(&c)) {
                return Err(format!("machine.restart.clearance {c}: 0–100 mm"));
            }
        }
        let n = self.axes.len();
        if n == 0 || n > cnc_msgs::servo::MAX_AXES {
            return Err(format!(
                "machine.axes: 1..{} axes, found {n}",
                cnc_msgs::servo::MAX_AXES
            ));
        }
        for (i, a) in self.axes.iter().enumerate() {
            if a.name.len() != 1
                || !a.name.chars().all(|c| c.is_ascii_uppercase())
                || self.axes[..i].iter().any(|b| b.name == a.name)
            {
                return Err(format!(
                    "axis name {:?}: one upper-case letter, each axis once",
                    a.name
                ));
            }
            let ok = a.min < a.max
                && a.max_velocity > 0.0
                && a.max_acceleration > 0.0
                && a.in_position > 0.0
                && a.drive_lag >= 0.0
                && a.max_jerk.is_none_or(|j| j > 0.0)
                && a.following_error.is_none_or(|f| f > 0.0);
            if !ok || a.home < a.min || a.home > a.max {
                return Err(format!("axis {}: need min < home < max and positive velocity, acceleration, jerk, in_position", a.name));
            }
            if a.fixed_points.len() > 4
                || a.fixed_points.iter().any(|p| !(a.min..=a.max).contains(p))
            {
                return Err(format!(
                    "axis {}: fixed_points {:?}: at most 4, each within min..max",
                    a.name, a.fixed_points
                ));
            }
            if let Some(r) = a.second_reference.filter(|r| !(a.min..=a.max).contains(r)) {
                return Err(format!(
                    "axis {}: second_reference {r} lies outside min..max",
                    a.name
                ));
            }
            if let Some(r) = &a.reference {
                let fast = r.fast(a.max_velocity);
                let ok = [r.slow_feed, r.grid, r.dog_length, fast]
                    .iter()
                    .all(|v| v.is_finite() && *v > 0.0)
                    && fast <= a.max_velocity
                    && r.slow_feed <= fast
                    && r.power_on.is_none_or(|p| (a.min..=a.max).contains(&p));
                if !ok {
                    return Err(format!(
                        "axis {}: reference needs positive grid, dog_length and feeds, \
                         slow_feed ≤ fast_feed ≤ max_velocity, power_on within min..max",
                        a.name
                    ));
                }
            }
        }
        let cap = self.program_capacity_kib;
        if !(1..=1024 * 1024).contains(&cap) {
            return Err(format!(
                "machine.program_capacity_kib {cap}: 1..1048576 (1 GiB)"
            ));
        }
        for p in &self.arc_plane {
            if !self.axes.iter().any(|a| &a.name == p) {
                return Err(format!(
                    "machine.arc_plane names axis {p}, which is not configured"
                ));
            }
        }
        if let Some(p) = self.tool_change_macro {
            if !(1..=9999).contains(&p) {
                return Err(format!(
                    "machine.tool_change_macro {p}: a program number 1..9999"
                ));
            }
        }
        self.validate_offsets()?;
        self.validate_spindle_axes()
    }

    /// The offset page and the work offsets: finite values of configured axes.
    fn validate_offsets(&self) -> Result<(), String> {
        for (n, t) in &self.tools {
            let finite = [t.x, t.z, t.wear_x, t.wear_z, t.radius]
                .iter()
                .all(|v| v.is_finite() && v.abs() <= 10_000.0);
            crate::tools::check_entry(&self.dialect, *n)
                .map_err(|e| format!("machine.tools[{n}]: {e}"))?;
            if !finite || t.radius < 0.0 || t.tip > 9 {
                return Err(format!(
                    "machine.tools[{n}]: finite values within ±10000, radius ≥ 0, tip 0..9"
                ));
            }
        }
        for (code, axes) in &self.work_offsets {
            if work_offset_index(code).is_none() {
                return Err(format!("machine.work_offsets: {code:?} is not G54..G59"));
            }
            for (axis, v) in axes {
                if !self.axes.iter().any(|a| &a.name == axis) || !v.is_finite() {
                    return Err(format!(
                        "machine.work_offsets.{code}: axis {axis:?} not configured or value not finite"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The C axis's rates and the live tool: finite and above 0, the live tool's axis a
    /// letter the machine's slides do not use (nor C on a turn-mill).
    fn validate_spindle_axes(&self) -> Result<(), String> {
        let c = self.c_axis;
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(c.max_velocity) || !positive(c.max_acceleration) {
            return Err("machine.c_axis: max_velocity and max_acceleration above 0".into());
        }
        if let Some(t) = &self.live_tool {
            let taken = self.axes.iter().any(|a| a.name == t.axis)
                || (self.spindle_c_axis && t.axis == "C");
            if t.number().is_none() || taken {
                return Err(format!(
                    "machine.live_tool.axis {:?}: one of X Y Z A B C that no slide (nor the \
                     spindle's C) uses",
                    t.axis
                ));
            }
            if !positive(t.max_rpm) || t.max_rpm > 30_000.0 || !positive(t.time_constant) {
                return Err(
                    "machine.live_tool: max_rpm 0 < … ≤ 30000, time_constant above 0".into(),
                );
            }
        }
        Ok(())
    }
}
