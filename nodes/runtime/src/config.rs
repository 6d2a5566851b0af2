//! The launch config: one YAML file describes the machine, the network and the nodes.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::net::IpAddr;
use std::path::Path;

/// Top level of `launch_configs/*.yaml`.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LaunchConfig {
    pub machine: MachineConfig,
    #[serde(default)]
    pub network: NetworkConfig,
    #[serde(default)]
    pub servo: ServoConfig,
    #[serde(default)]
    pub sim: SimConfig,
    #[serde(default)]
    pub plc: PlcConfig,
    #[serde(default)]
    pub recorder: RecorderConfig,
    #[serde(default)]
    pub hmi: HmiConfig,
    #[serde(default)]
    pub realtime: RealtimeConfig,
    /// The machine builder's ratings (travel, drives, spindle): set by this file only,
    /// never a parameter ([`crate::limits`]).
    #[serde(default)]
    pub limits: crate::limits::MachineLimits,
}

/// Real-time treatment of the loops that keep the machine's time ([`crate::realtime`]).
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RealtimeConfig {
    /// `SCHED_FIFO` priority of the servo loop (1–99; 0: an ordinary thread). Default 80.
    #[serde(default = "default_servo_priority")]
    pub servo_priority: i32,
    /// Of the io node's drive loop, which answers the servo loop each tick. Default 79.
    #[serde(default = "default_io_priority")]
    pub io_priority: i32,
    /// Of the PLC scan. Default 70.
    #[serde(default = "default_plc_priority")]
    pub plc_priority: i32,
    /// Lock the process's memory (`mlockall`) so no page fault stalls a tick. Default true.
    #[serde(default = "default_true")]
    pub lock_memory: bool,
    /// CPU for the servo and io loops (an isolated core: `isolcpus=`); default: any.
    #[serde(default)]
    pub servo_cpu: Option<usize>,
}

fn default_servo_priority() -> i32 {
    80
}
fn default_io_priority() -> i32 {
    79
}
fn default_plc_priority() -> i32 {
    70
}

impl Default for RealtimeConfig {
    fn default() -> Self {
        RealtimeConfig {
            servo_priority: default_servo_priority(),
            io_priority: default_io_priority(),
            plc_priority: default_plc_priority(),
            lock_memory: true,
            servo_cpu: None,
        }
    }
}

/// Who may command the machine from outside.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct HmiConfig {
    /// ROS 2 node names (`/cell/supervisor`; `*` matches anything) whose commands that move
    /// the machine (program start, RunProgram goals) are accepted. Stop, feed hold and reset
    /// are taken from anyone: stopping a machine is never refused. Default `["*"]`.
    #[serde(default = "default_allowed")]
    pub allowed_clients: Vec<String>,
    /// Where the operator's web HMI is served (`host:port`); empty: no web HMI. Default
    /// `127.0.0.1:8080`: the machine's own panel PC, nothing off the machine.
    #[serde(default = "default_web_address")]
    pub web_address: String,
    /// The operators who may log in to the web HMI (`cnc operator set <name>` writes it: names
    /// and salted password hashes); default `operators.yaml` beside the config, absent means
    /// none. Needed when `web_address` is not a loopback address: the cell refuses to serve
    /// the panel to the network without logins.
    #[serde(default = "default_operators_file")]
    pub operators_file: Option<std::path::PathBuf>,
    /// How long a web HMI login lasts, seconds (default 8 h, a shift).
    #[serde(default = "default_session_seconds")]
    pub session_seconds: u64,
    /// Page origins allowed to open the panel's WebSocket and log in (`http://panel.cell:8080`).
    /// Empty: the address the panel listens on (and `localhost` for a loopback address). A
    /// panel on an unspecified address (`0.0.0.0`) must name them.
    #[serde(default)]
    pub web_origins: Vec<String>,
}

fn default_operators_file() -> Option<std::path::PathBuf> {
    Some("operators.yaml".into())
}

fn default_session_seconds() -> u64 {
    8 * 3600
}

fn default_web_address() -> String {
    "127.0.0.1:8080".into()
}

fn default_allowed() -> Vec<String> {
    vec!["*".into()]
}

impl Default for HmiConfig {
    fn default() -> Self {
        HmiConfig {
            allowed_clients: default_allowed(),
            web_address: default_web_address(),
            operators_file: default_operators_file(),
            session_seconds: default_session_seconds(),
            web_origins: Vec::new(),
        }
    }
}

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
    /// A mill tool table file (`number length_mm diameter_mm` per line, [`crate::tool_table`]),
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
    /// Program memory: a folder of plain program files, relative to the config file's
    /// folder ([`crate::program_store`]); absent: programs are kept for this run only.
    #[serde(default)]
    pub program_directory: Option<std::path::PathBuf>,
    /// The program memory's capacity in KiB (all programs together; alarm 70 when full).
    #[serde(default = "default_program_capacity")]
    pub program_capacity_kib: u64,
    /// Huaxing S#170: a T word calls this program (O number, 1–9999) as the tool-change
    /// macro; absent: T goes to the PLC.
    #[serde(default)]
    pub tool_change_macro: Option<u32>,
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
pub const DIALECTS: [&str; 4] = ["huaxing-lathe", "gtc2e-lathe", "iso-lathe", "fanuc-mill"];

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
}

impl AxisEntry {
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

fn default_in_position() -> f64 {
    0.0005
}
fn default_drive_lag() -> f64 {
    0.008
}

/// Where DDS may send traffic.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkConfig {
    /// DDS domain; when absent, `ROS_DOMAIN_ID`, else 0.
    #[serde(default)]
    pub domain_id: Option<u16>,
    /// Addresses of the interfaces DDS uses for multicast and advertises. Default: loopback only.
    #[serde(default = "default_interfaces")]
    pub interfaces: Vec<IpAddr>,
}

fn default_interfaces() -> Vec<IpAddr> {
    vec![IpAddr::from([127, 0, 0, 1])]
}

impl Default for NetworkConfig {
    fn default() -> Self {
        NetworkConfig {
            domain_id: None,
            interfaces: default_interfaces(),
        }
    }
}

impl NetworkConfig {
    /// The domain to join: the config's, else `ROS_DOMAIN_ID`, else 0.
    pub fn effective_domain_id(&self) -> Result<u16, String> {
        if let Some(d) = self.domain_id {
            return valid_domain(d);
        }
        match std::env::var("ROS_DOMAIN_ID") {
            Ok(v) if !v.trim().is_empty() => {
                let d: u16 = v
                    .trim()
                    .parse()
                    .map_err(|_| format!("ROS_DOMAIN_ID={v:?} is not a number"))?;
                valid_domain(d)
            }
            _ => Ok(0),
        }
    }
}

fn valid_domain(d: u16) -> Result<u16, String> {
    // RTPS port mapping: 7400 + 250·domain must stay below 65535.
    if d > 232 {
        Err(format!("DDS domain id {d} out of range 0..232"))
    } else {
        Ok(d)
    }
}

#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ServoConfig {
    /// Servo period, ms (1..8).
    #[serde(default = "default_period")]
    pub period_ms: f64,
    /// Blocks motion accepts ahead of the one being cut (at least `lookahead`).
    #[serde(default = "default_queue")]
    pub queue_capacity: usize,
    /// Blocks the planner plans ahead.
    #[serde(default = "default_lookahead")]
    pub lookahead: usize,
    /// Largest distance a blended (G64) corner may leave the programmed path, mm.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Velocity profile: `s_curve` (jerk limited) or `trapezoidal` (acceleration limited).
    #[serde(default)]
    pub profile: ProfileShape,
    /// Servo ticks without drive feedback after which motion switches the servo off with
    /// an alarm.
    #[serde(default = "default_feedback_lost")]
    pub feedback_lost_ticks: u32,
    /// Feed of every feed move under dry run, mm/min (`000` S#45, default 1000).
    #[serde(default = "default_dry_run_feed")]
    pub dry_run_feed: f64,
    /// A servo tick this long after the last (ms) is a warning alarm. Default 3 periods.
    #[serde(default)]
    pub late_warning_ms: Option<f64>,
    /// This many late ticks (more than half a period late) within one second is the servo
    /// alarm, and the machine stops ([D57](docs/decisions.md)). Default 125: half the ticks
    /// of a second.
    #[serde(default = "default_late_alarm_ticks")]
    pub late_alarm_ticks: u32,
}

fn default_late_alarm_ticks() -> u32 {
    125
}

fn default_feedback_lost() -> u32 {
    3
}
fn default_dry_run_feed() -> f64 {
    1000.0
}

/// How speed changes along the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileShape {
    /// Acceleration limited: the acceleration jumps between +a, 0 and −a.
    Trapezoidal,
    /// Jerk limited: the acceleration ramps, so the drives see no steps in force.
    #[default]
    SCurve,
}

fn default_period() -> f64 {
    4.0
}
fn default_queue() -> usize {
    256
}
fn default_lookahead() -> usize {
    200
}
fn default_tolerance() -> f64 {
    0.01
}

impl Default for ServoConfig {
    fn default() -> Self {
        ServoConfig {
            period_ms: default_period(),
            queue_capacity: default_queue(),
            lookahead: default_lookahead(),
            tolerance: default_tolerance(),
            profile: ProfileShape::default(),
            feedback_lost_ticks: default_feedback_lost(),
            dry_run_feed: default_dry_run_feed(),
            late_warning_ms: None,
            late_alarm_ticks: default_late_alarm_ticks(),
        }
    }
}

#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SimConfig {
    #[serde(default = "default_spindle_acc")]
    pub spindle_acceleration: f64,
    #[serde(default = "default_at_speed")]
    pub at_speed_tolerance: f64,
    #[serde(default = "default_coolant_delay")]
    pub coolant_delay: f64,
    /// Stations of the electric turret (4, 6 or 8).
    #[serde(default = "default_turret_stations")]
    pub turret_stations: u8,
    /// Whether allowed clients may set the simulated machine's inputs (`sim/input`: emergency
    /// stop, forced door, stuck turret, keys). A machine whose io is real hardware has no such
    /// topic: set false, and the bridge does not even subscribe to it.
    #[serde(default = "default_true")]
    pub client_inputs: bool,
}

fn default_true() -> bool {
    true
}

fn default_turret_stations() -> u8 {
    8
}

fn default_spindle_acc() -> f64 {
    3000.0
}
fn default_at_speed() -> f64 {
    0.02
}
fn default_coolant_delay() -> f64 {
    0.1
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            spindle_acceleration: default_spindle_acc(),
            at_speed_tolerance: default_at_speed(),
            coolant_delay: default_coolant_delay(),
            turret_stations: default_turret_stations(),
            client_inputs: true,
        }
    }
}

#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlcConfig {
    /// Level-1 scan period, ms.
    #[serde(default = "default_scan")]
    pub scan_ms: f64,
    /// Level 2 runs in this many slices, one per scan.
    #[serde(default = "default_level2_divisions")]
    pub level2_divisions: u32,
    /// The ladder program (mnemonic text), relative to the config file's folder; default: the
    /// built-in standard lathe program.
    /// The node reloads it when the file changes; a program with an error is refused and the
    /// running one stays.
    #[serde(default)]
    pub program: Option<std::path::PathBuf>,
    /// Keep relays, data registers and timer/counter presets (the PLC parameter page).
    #[serde(default)]
    pub memory_file: Option<std::path::PathBuf>,
}

fn default_level2_divisions() -> u32 {
    2
}

fn default_scan() -> f64 {
    10.0
}

impl Default for PlcConfig {
    fn default() -> Self {
        PlcConfig {
            scan_ms: default_scan(),
            level2_divisions: default_level2_divisions(),
            program: None,
            memory_file: None,
        }
    }
}

/// The recorder: which topics go into the audit recording, where, and how files are cut.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RecorderConfig {
    /// Record at all (the launch configs do; a test cell may not).
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Folder of the bags: one bag (a folder with `metadata.yaml` and `.mcap` files) per start
    /// of the cell; relative to the config file's folder.
    #[serde(default = "default_records")]
    pub directory: std::path::PathBuf,
    /// Topic paths under the namespace to record (`*` matches anything); default all.
    #[serde(default = "default_include")]
    pub include: Vec<String>,
    /// Topic paths not to record, applied after `include`.
    #[serde(default)]
    pub exclude: Vec<String>,
    /// Chunk compression: `zstd`, `lz4` or `none`.
    #[serde(default = "default_compression")]
    pub compression: String,
    /// Everything received more than this long ago is on disk, ms.
    #[serde(default = "default_flush_ms")]
    pub flush_ms: u64,
    /// A new file when the current one reaches this size, MiB…
    #[serde(default = "default_split_mib")]
    pub split_mib: u64,
    /// …or this age, s.
    #[serde(default = "default_split_s")]
    pub split_seconds: u64,
    /// The oldest bags are deleted while the folder holds more than this, MiB.
    #[serde(default = "default_cap_mib")]
    pub max_total_mib: u64,
}

fn yes() -> bool {
    true
}
fn default_records() -> std::path::PathBuf {
    "records".into()
}
fn default_include() -> Vec<String> {
    vec!["*".into()]
}
fn default_compression() -> String {
    "zstd".into()
}
fn default_flush_ms() -> u64 {
    1000
}
fn default_split_mib() -> u64 {
    64
}
fn default_split_s() -> u64 {
    3600
}
fn default_cap_mib() -> u64 {
    2048
}

impl Default for RecorderConfig {
    fn default() -> Self {
        RecorderConfig {
            enabled: true,
            directory: default_records(),
            include: default_include(),
            exclude: Vec::new(),
            compression: default_compression(),
            flush_ms: default_flush_ms(),
            split_mib: default_split_mib(),
            split_seconds: default_split_s(),
            max_total_mib: default_cap_mib(),
        }
    }
}

impl RecorderConfig {
    /// Whether the topic at `path` (under the namespace) is recorded.
    pub fn records(&self, path: &str) -> bool {
        self.include.iter().any(|p| crate::topics::matches(p, path))
            && !self.exclude.iter().any(|p| crate::topics::matches(p, path))
    }
}

impl LaunchConfig {
    pub fn from_yaml(text: &str) -> Result<Self, String> {
        let mut cfg: LaunchConfig =
            serde_yaml::from_str(text).map_err(|e| format!("launch config: {e}"))?;
        // The machine's own file rates the axes it does not rate explicitly at its values.
        cfg.limits.complete(&cfg.machine.axes);
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads the launch config and applies the parameter file over it. A parameter file that
    /// does not apply stops the start with its entry named: the machine never runs on
    /// parameters nobody checked. Relative paths in the file are taken from its folder.
    pub fn load(path: &Path) -> Result<Self, String> {
        Self::load_with_tool_table(path, None)
    }

    /// [`LaunchConfig::load`], with `tool_table` (if given) read instead of the config's
    /// `machine.tool_table` (`cnc check --tools`).
    pub fn load_with_tool_table(path: &Path, tool_table: Option<&Path>) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Self::from_yaml_in(&text, dir, tool_table).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// A launch config read from `text` as if it were a file in `dir` (the built-in machines
    /// of the `cnc` binary have a data folder instead of a file): relative file paths in it
    /// are taken from `dir`; then the parameter file and the tool table (`tool_table` if
    /// given, as the command line names it, else the config's) are applied.
    pub fn from_yaml_in(text: &str, dir: &Path, tool_table: Option<&Path>) -> Result<Self, String> {
        let mut cfg = Self::from_yaml(text)?;
        cfg.resolve_paths(dir);
        if let Some(table) = tool_table {
            cfg.machine.tool_table = Some(table.to_path_buf());
        }
        let cfg = cfg.with_parameter_file()?;
        match cfg.machine.tool_table.clone() {
            Some(table) => cfg.with_tool_table(&table),
            None => Ok(cfg),
        }
    }

    /// Takes every relative file path of the config from `dir`: a config names its files
    /// from where it lies, so `cnc` finds them from any working directory.
    fn resolve_paths(&mut self, dir: &Path) {
        let m = &mut self.machine;
        let files = [
            &mut m.tool_table,
            &mut m.memory_file,
            &mut m.program_directory,
            &mut m.parameter_file,
            &mut self.plc.program,
            &mut self.plc.memory_file,
            &mut self.hmi.operators_file,
        ];
        for file in files.into_iter().flatten() {
            if file.is_relative() {
                *file = dir.join(&*file);
            }
        }
        if self.recorder.directory.is_relative() {
            self.recorder.directory = dir.join(&self.recorder.directory);
        }
    }

    /// The files this config writes, as `(what, path)`, for the user to know where they are.
    pub fn written_files(&self) -> Vec<(&'static str, &Path)> {
        let mut out = Vec::new();
        let m = &self.machine;
        if let Some(f) = &m.memory_file {
            out.push(("kept variables and offsets", f.as_path()));
        }
        if let Some(f) = &m.program_directory {
            out.push(("program memory", f.as_path()));
        }
        if let Some(f) = &m.parameter_file {
            out.push(("parameters", f.as_path()));
        }
        if let Some(f) = &self.plc.memory_file {
            out.push(("PLC memory", f.as_path()));
        }
        if self.recorder.enabled {
            out.push(("recordings", self.recorder.directory.as_path()));
        }
        out
    }

    /// This config with the tools of a tool table file added to the offset page; a number
    /// both name is refused.
    pub fn with_tool_table(mut self, path: &std::path::Path) -> Result<Self, String> {
        for (n, entry) in crate::tool_table::load(path)? {
            if self.machine.tools.insert(n, entry).is_some() {
                return Err(format!(
                    "{}: tool {n} is also in machine.tools",
                    path.display()
                ));
            }
        }
        Ok(self)
    }

    /// This config with the written parameters of `machine.parameter_file` applied.
    pub fn with_parameter_file(self) -> Result<Self, String> {
        let Some(file) = self.machine.parameter_file.clone() else {
            return Ok(self);
        };
        let overlay = crate::parameters::load_file(&file)?;
        crate::parameters::apply(self, &overlay).map_err(|e| {
            format!(
                "parameter file {}: {e} (correct or remove the entry)",
                file.display()
            )
        })
    }

    pub(crate) fn validate(&self) -> Result<(), String> {
        let ns = &self.machine.namespace;
        if !DIALECTS.contains(&self.machine.dialect.as_str()) {
            return Err(format!(
                "machine.dialect {:?}: one of {}",
                self.machine.dialect,
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
        let rt = &self.realtime;
        for (name, p) in [
            ("servo_priority", rt.servo_priority),
            ("io_priority", rt.io_priority),
            ("plc_priority", rt.plc_priority),
        ] {
            if !(0..=99).contains(&p) {
                return Err(format!("realtime.{name} {p}: 0 (off) to 99"));
            }
        }
        if self.servo.late_alarm_ticks == 0 {
            return Err("servo.late_alarm_ticks must be at least 1".into());
        }
        if let Some(w) = self.servo.late_warning_ms {
            if !(w.is_finite() && w > 0.0) {
                return Err(format!("servo.late_warning_ms {w}: a time above 0"));
            }
        }
        let r = &self.recorder;
        if !["zstd", "lz4", "none"].contains(&r.compression.as_str()) {
            return Err(format!(
                "recorder.compression {:?}: zstd, lz4 or none",
                r.compression
            ));
        }
        if r.flush_ms == 0 || r.split_mib == 0 || r.split_seconds == 0 || r.max_total_mib == 0 {
            return Err(
                "recorder: flush_ms, split_mib, split_seconds and max_total_mib must be > 0".into(),
            );
        }
        let tol = self.machine.contour_tolerance;
        if !(0.001..=1.0).contains(&tol) {
            return Err(format!(
                "machine.contour_tolerance {tol}: 0.001–1 mm (GS#33)"
            ));
        }
        let n = self.machine.axes.len();
        if n == 0 || n > cnc_msgs::servo::MAX_AXES {
            return Err(format!(
                "machine.axes: 1..{} axes, found {n}",
                cnc_msgs::servo::MAX_AXES
            ));
        }
        for (i, a) in self.machine.axes.iter().enumerate() {
            if a.name.len() != 1
                || !a.name.chars().all(|c| c.is_ascii_uppercase())
                || self.machine.axes[..i].iter().any(|b| b.name == a.name)
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
            if let Some(r) = a.second_reference.filter(|r| !(a.min..=a.max).contains(r)) {
                return Err(format!(
                    "axis {}: second_reference {r} lies outside min..max",
                    a.name
                ));
            }
        }
        self.limits.check(&self.machine.axes)?;
        let cap = self.machine.program_capacity_kib;
        if !(1..=1024 * 1024).contains(&cap) {
            return Err(format!(
                "machine.program_capacity_kib {cap}: 1..1048576 (1 GiB)"
            ));
        }
        let sim = &self.sim;
        for (name, v, range) in [
            ("spindle_acceleration", sim.spindle_acceleration, 10.0..=1e6),
            ("at_speed_tolerance", sim.at_speed_tolerance, 0.001..=0.5),
            ("coolant_delay", sim.coolant_delay, 0.0..=10.0),
        ] {
            if !range.contains(&v) {
                return Err(format!(
                    "sim.{name} {v}: {}..{}",
                    range.start(),
                    range.end()
                ));
            }
        }
        for p in &self.machine.arc_plane {
            if !self.machine.axes.iter().any(|a| &a.name == p) {
                return Err(format!(
                    "machine.arc_plane names axis {p}, which is not configured"
                ));
            }
        }
        if !(1.0..=8.0).contains(&self.servo.period_ms) {
            return Err(format!(
                "servo.period_ms {} outside 1..8",
                self.servo.period_ms
            ));
        }
        if self.servo.queue_capacity < 2 || self.servo.queue_capacity > 10_000 {
            return Err("servo.queue_capacity must be 2..10000".into());
        }
        if self.servo.lookahead < 1 || self.servo.lookahead > self.servo.queue_capacity {
            return Err("servo.lookahead must be 1..queue_capacity".into());
        }
        if !(1..=1000).contains(&self.servo.feedback_lost_ticks) {
            return Err("servo.feedback_lost_ticks must be 1..1000".into());
        }
        if !(self.servo.dry_run_feed.is_finite() && self.servo.dry_run_feed > 0.0) {
            return Err("servo.dry_run_feed must be a positive feed in mm/min".into());
        }
        if !(self.servo.tolerance > 0.0 && self.servo.tolerance <= 10.0) {
            return Err("servo.tolerance must be in (0, 10] mm".into());
        }
        if let Some(p) = self.machine.tool_change_macro {
            if !(1..=9999).contains(&p) {
                return Err(format!(
                    "machine.tool_change_macro {p}: a program number 1..9999"
                ));
            }
        }
        for (n, t) in &self.machine.tools {
            let finite = [t.x, t.z, t.wear_x, t.wear_z, t.radius]
                .iter()
                .all(|v| v.is_finite() && v.abs() <= 10_000.0);
            let max = crate::tool_table::MAX_TOOL_NUMBER;
            if !(1..=max).contains(n) || !finite || t.radius < 0.0 || t.tip > 9 {
                return Err(format!(
                    "machine.tools[{n}]: offset 1..{max}, finite values within ±10000, radius ≥ 0, tip 0..9"
                ));
            }
        }
        for (code, axes) in &self.machine.work_offsets {
            if work_offset_index(code).is_none() {
                return Err(format!("machine.work_offsets: {code:?} is not G54..G59"));
            }
            for (axis, v) in axes {
                if !self.machine.axes.iter().any(|a| &a.name == axis) || !v.is_finite() {
                    return Err(format!(
                        "machine.work_offsets.{code}: axis {axis:?} not configured or value not finite"
                    ));
                }
            }
        }
        if self.network.interfaces.is_empty() {
            return Err("network.interfaces must name at least one interface address".into());
        }
        if !(1..=16).contains(&self.plc.level2_divisions) {
            return Err(format!(
                "plc.level2_divisions {} outside 1..16",
                self.plc.level2_divisions
            ));
        }
        if ![4, 6, 8].contains(&self.sim.turret_stations) {
            return Err(format!(
                "sim.turret_stations {}: 4, 6 or 8",
                self.sim.turret_stations
            ));
        }
        if !(1.0..=100.0).contains(&self.plc.scan_ms) {
            return Err(format!("plc.scan_ms {} outside 1..100", self.plc.scan_ms));
        }
        self.network.effective_domain_id()?;
        Ok(())
    }

    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.machine.axes.iter().position(|a| a.name == name)
    }

    /// Power-on slide positions (X as radius).
    pub fn home_slide(&self) -> Vec<f64> {
        self.machine
            .axes
            .iter()
            .map(|a| a.home * a.scale())
            .collect()
    }

    /// The axis address letters in machine order, e.g. `['X', 'Z']`.
    pub fn axis_letters(&self) -> Vec<char> {
        self.machine.axes.iter().map(AxisEntry::letter).collect()
    }

    /// Per axis: programmed and displayed in diameter.
    pub fn diameter_axes(&self) -> Vec<bool> {
        self.machine.axes.iter().map(|a| a.diameter).collect()
    }

    /// Power-on position in display units.
    pub fn second_reference(&self) -> Vec<f64> {
        self.machine
            .axes
            .iter()
            .map(|a| a.second_reference.unwrap_or(a.home))
            .collect()
    }

    pub fn home(&self) -> Vec<f64> {
        self.machine.axes.iter().map(|a| a.home).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mill's config with `second_reference: z` on its Z axis.
    fn mill_with_second_reference(z: &str) -> Result<LaunchConfig, String> {
        let text = include_str!("../../../launch_configs/sim_mill.yaml").replace(
            "max: 100.0, home: 0.0,",
            &format!("max: 100.0, home: 0.0, second_reference: {z},"),
        );
        LaunchConfig::from_yaml(&text)
    }

    #[test]
    fn the_second_reference_point_must_lie_within_the_axis_travel() {
        let cfg = mill_with_second_reference("80.0").expect("within travel");
        assert_eq!(cfg.second_reference(), [0.0, 0.0, 80.0]);
        let e = mill_with_second_reference("150.0").unwrap_err();
        assert!(e.contains("second_reference 150"), "{e}");
    }
}
