//! The sections of the cell's nodes: network, servo, simulator, PLC, recorder, HMI and real
//! time, with their defaults and each section's own rules.

use serde::Deserialize;
use std::net::IpAddr;

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
    /// are taken from anyone: stopping a machine is never refused. Absent: `["*"]` while DDS
    /// stays on loopback; a config whose DDS leaves loopback must name them (`["*"]` too, but
    /// deliberately), as the web panel must name its operators there (issue 45).
    #[serde(default)]
    pub allowed_clients: Option<Vec<String>>,
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
    /// The panels of the cell's machines (this one among them), offered by the panel's
    /// machine selector; empty: no selector.
    #[serde(default)]
    pub cell_panels: Vec<CellPanel>,
}

/// One machine's web panel in the cell.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
pub struct CellPanel {
    /// The machine's namespace, `lathe2`.
    pub name: String,
    /// Its panel, `http://127.0.0.1:8081/`.
    pub url: String,
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

impl HmiConfig {
    /// Who may move the machine: the config's list, else anyone (a loopback-only machine).
    pub fn allowed_clients(&self) -> Vec<String> {
        self.allowed_clients
            .clone()
            .unwrap_or_else(|| vec!["*".into()])
    }
}

impl Default for HmiConfig {
    fn default() -> Self {
        HmiConfig {
            allowed_clients: None,
            web_address: default_web_address(),
            operators_file: default_operators_file(),
            session_seconds: default_session_seconds(),
            web_origins: Vec::new(),
            cell_panels: Vec::new(),
        }
    }
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
    /// DDS Security: absent, the cell's DDS traffic is open to anyone on the network (names
    /// are claims); present, every participant authenticates with an enclave of the cell's
    /// keystore and may do only what its permissions grant (`cnc security init`).
    #[serde(default)]
    pub security: Option<DdsSecurity>,
}

/// Where a participant's credentials are: an enclave of an SROS2-layout keystore.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DdsSecurity {
    /// The keystore folder (`public/`, `private/`, `enclaves/`).
    pub keystore: std::path::PathBuf,
    /// The identity, e.g. `/lathe1` or `/cell/robot`. Absent: a machine's nodes take
    /// `/<namespace>`; a client must name one.
    #[serde(default)]
    pub enclave: Option<String>,
}

impl DdsSecurity {
    /// The enclave's folder, `enclave` taken when none is configured; refused with the reason
    /// when the path is malformed or holds no credentials.
    pub fn enclave_dir(&self, default: Option<&str>) -> Result<std::path::PathBuf, String> {
        let enclave = self.enclave.as_deref().or(default).ok_or(
            "DDS Security is on but this client names no enclave \
             (network.security.enclave, or ROS_SECURITY_ENCLAVE_OVERRIDE)",
        )?;
        let rel = enclave.trim_start_matches('/');
        if rel.is_empty()
            || rel
                .split('/')
                .any(|s| s.is_empty() || s == "." || s == "..")
        {
            return Err(format!("enclave {enclave:?}: not a path like /lathe1"));
        }
        let dir = self.keystore.join("enclaves").join(rel);
        for file in ["cert.pem", "key.pem", "permissions.p7s", "governance.p7s"] {
            if !dir.join(file).is_file() {
                return Err(format!(
                    "enclave {enclave}: {} is missing (made by `cnc security init`)",
                    dir.join(file).display()
                ));
            }
        }
        Ok(dir)
    }
}

fn default_interfaces() -> Vec<IpAddr> {
    vec![IpAddr::from([127, 0, 0, 1])]
}

impl Default for NetworkConfig {
    fn default() -> Self {
        NetworkConfig {
            domain_id: None,
            interfaces: default_interfaces(),
            security: None,
        }
    }
}

impl NetworkConfig {
    /// DDS Security as configured, else as ROS 2 takes it from the environment
    /// (`ROS_SECURITY_ENABLE=true`, `ROS_SECURITY_KEYSTORE`, `ROS_SECURITY_ENCLAVE_OVERRIDE`).
    pub fn effective_security(&self) -> Result<Option<DdsSecurity>, String> {
        if self.security.is_some() {
            return Ok(self.security.clone());
        }
        let var = |n: &str| std::env::var(n).ok().filter(|v| !v.trim().is_empty());
        if var("ROS_SECURITY_ENABLE").as_deref() != Some("true") {
            return Ok(None);
        }
        let keystore = var("ROS_SECURITY_KEYSTORE")
            .ok_or("ROS_SECURITY_ENABLE=true but ROS_SECURITY_KEYSTORE is not set")?;
        Ok(Some(DdsSecurity {
            keystore: keystore.into(),
            enclave: var("ROS_SECURITY_ENCLAVE_OVERRIDE"),
        }))
    }

    /// This config with `enclave` as the identity when security is on and none is named: the
    /// cell's own nodes (supervisor, robot) take theirs.
    pub fn with_default_enclave(&self, enclave: &str) -> Result<NetworkConfig, String> {
        let mut net = self.clone();
        if let Some(mut sec) = net.effective_security()? {
            sec.enclave.get_or_insert_with(|| enclave.to_string());
            net.security = Some(sec);
        }
        Ok(net)
    }

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
    /// How far ahead of the drives motion keeps their setpoint queue, ms (issue 48): the
    /// drives then run on their own clock and a host that wakes late costs nothing while the
    /// queue lasts. 0 (the default for now, D133): lock-step, the drives step once per
    /// setpoint.
    #[serde(default)]
    pub drive_queue_ms: f64,
    /// The drive trace: every drive tick's setpoints, actual positions, following errors,
    /// queue depth and underruns written to this CSV file (with the queue only). The machine
    /// builder's, like every path (issue 45).
    #[serde(default)]
    pub drive_trace: Option<std::path::PathBuf>,
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

pub use cnc_machine::ProfileShape;

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
            drive_queue_ms: 0.0,
            drive_trace: None,
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
    /// A mill's drum tool magazine of 24 pockets instead of the turret: it indexes as the
    /// turret does and reports its pocket as a binary code on X7; the standard ladder runs it
    /// with T preselection and M6 when the builder sets K1.2 (decision D94).
    #[serde(default)]
    pub tool_magazine: bool,
    /// Whether allowed clients may set the simulated machine's inputs (`sim/input`: emergency
    /// stop, forced door, stuck turret, keys). A machine whose io is real hardware has no such
    /// topic: set false, and the bridge does not even subscribe to it.
    #[serde(default = "default_true")]
    pub client_inputs: bool,
    /// The touch probe in the spindle (measuring input 1, MEAS/MEAW): boxes in the machine's
    /// coordinates as displayed, per axis in the machine's order, inside which its stylus is
    /// deflected: the work as the probe finds it, its length included. None: the probe never
    /// switches.
    #[serde(default)]
    pub probe: Vec<ProbeTarget>,
    /// Mechanical stops a slide cannot pass (a quill's workpiece, a clamp; FXS travels to
    /// them): the axis by name and where its slide meets the stop, machine coordinates as
    /// displayed. None: nothing stops a slide inside its travel.
    #[serde(default)]
    pub fixed_stops: Vec<FixedStopConfig>,
}

/// A mechanical stop of the simulated machine.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct FixedStopConfig {
    pub axis: String,
    pub at: f64,
}

/// A box of the simulated probe's work: per axis its lower and upper bound.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeTarget {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
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
            tool_magazine: false,
            client_inputs: true,
            probe: Vec::new(),
            fixed_stops: Vec::new(),
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
    /// Keep relays the machine builder turns on at the first power-up, while there is no
    /// memory file yet (`[K1.1]`: M02 counts a part); afterwards the kept memory rules.
    #[serde(default)]
    pub keep_relays: Vec<String>,
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
            keep_relays: Vec::new(),
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

impl RealtimeConfig {
    fn validate(&self) -> Result<(), String> {
        for (name, p) in [
            ("servo_priority", self.servo_priority),
            ("io_priority", self.io_priority),
            ("plc_priority", self.plc_priority),
        ] {
            if !(0..=99).contains(&p) {
                return Err(format!("realtime.{name} {p}: 0 (off) to 99"));
            }
        }
        Ok(())
    }
}

impl ServoConfig {
    /// The drives' queue in ticks (0: lock-step).
    pub fn drive_queue_ticks(&self) -> u64 {
        (self.drive_queue_ms / self.period_ms).ceil() as u64
    }

    /// The servo tick lateness that is a warning, ms: `late_warning_ms`, else three periods.
    pub fn late_warning(&self) -> f64 {
        self.late_warning_ms.unwrap_or(3.0 * self.period_ms)
    }

    fn validate(&self) -> Result<(), String> {
        if self.late_alarm_ticks == 0 {
            return Err("servo.late_alarm_ticks must be at least 1".into());
        }
        if let Some(w) = self.late_warning_ms {
            if !(w.is_finite() && w > 0.0) {
                return Err(format!("servo.late_warning_ms {w}: a time above 0"));
            }
        }
        if !(1.0..=8.0).contains(&self.period_ms) {
            return Err(format!("servo.period_ms {} outside 1..8", self.period_ms));
        }
        if self.queue_capacity < 2 || self.queue_capacity > 10_000 {
            return Err("servo.queue_capacity must be 2..10000".into());
        }
        if self.lookahead < 1 || self.lookahead > self.queue_capacity {
            return Err("servo.lookahead must be 1..queue_capacity".into());
        }
        if !(1..=1000).contains(&self.feedback_lost_ticks) {
            return Err("servo.feedback_lost_ticks must be 1..1000".into());
        }
        if !(self.dry_run_feed.is_finite() && self.dry_run_feed > 0.0) {
            return Err("servo.dry_run_feed must be a positive feed in mm/min".into());
        }
        if !(self.tolerance > 0.0 && self.tolerance <= 10.0) {
            return Err("servo.tolerance must be in (0, 10] mm".into());
        }
        let q = self.drive_queue_ms;
        if !(q == 0.0 || (q >= 2.0 * self.period_ms && q <= 1000.0)) {
            return Err(format!(
                "servo.drive_queue_ms {q}: 0 (lock-step) or two periods to 1000 ms"
            ));
        }
        Ok(())
    }
}

impl SimConfig {
    fn validate(&self) -> Result<(), String> {
        for (name, v, range) in [
            (
                "spindle_acceleration",
                self.spindle_acceleration,
                10.0..=1e6,
            ),
            ("at_speed_tolerance", self.at_speed_tolerance, 0.001..=0.5),
            ("coolant_delay", self.coolant_delay, 0.0..=10.0),
        ] {
            if !range.contains(&v) {
                return Err(format!(
                    "sim.{name} {v}: {}..{}",
                    range.start(),
                    range.end()
                ));
            }
        }
        if ![4, 6, 8].contains(&self.turret_stations) {
            return Err(format!(
                "sim.turret_stations {}: 4, 6 or 8",
                self.turret_stations
            ));
        }
        for (k, t) in self.probe.iter().enumerate() {
            let finite = t.min.iter().chain(&t.max).all(|v| v.is_finite());
            let ordered = t.min.iter().zip(&t.max).all(|(lo, hi)| lo <= hi);
            if t.min.len() != t.max.len() || t.min.is_empty() || !finite || !ordered {
                return Err(format!(
                    "sim.probe[{k}]: min and max need as many finite bounds (one per axis, in \
                     the machine's order), min ≤ max (min {:?}, max {:?})",
                    t.min, t.max
                ));
            }
        }
        Ok(())
    }
}

impl PlcConfig {
    fn validate(&self) -> Result<(), String> {
        if !(1..=16).contains(&self.level2_divisions) {
            return Err(format!(
                "plc.level2_divisions {} outside 1..16",
                self.level2_divisions
            ));
        }
        if !(1.0..=100.0).contains(&self.scan_ms) {
            return Err(format!("plc.scan_ms {} outside 1..100", self.scan_ms));
        }
        Ok(())
    }
}

impl RecorderConfig {
    fn validate(&self) -> Result<(), String> {
        if !["zstd", "lz4", "none"].contains(&self.compression.as_str()) {
            return Err(format!(
                "recorder.compression {:?}: zstd, lz4 or none",
                self.compression
            ));
        }
        if self.flush_ms == 0
            || self.split_mib == 0
            || self.split_seconds == 0
            || self.max_total_mib == 0
        {
            return Err(
                "recorder: flush_ms, split_mib, split_seconds and max_total_mib must be > 0".into(),
            );
        }
        Ok(())
    }
}

impl NetworkConfig {
    fn validate(&self) -> Result<(), String> {
        if self.interfaces.is_empty() {
            return Err("network.interfaces must name at least one interface address".into());
        }
        self.effective_domain_id().map(|_| ())
    }
}

/// Each node section's own rules, in the order the file lists them.
pub(super) fn validate(cfg: &super::LaunchConfig) -> Result<(), String> {
    cfg.network.validate()?;
    if cfg.hmi.allowed_clients.is_none() && cfg.network.interfaces.iter().any(|a| !a.is_loopback())
    {
        return Err(format!(
            "hmi.allowed_clients: DDS leaves loopback (network.interfaces {:?}): name the \
             clients that may move the machine, or [\"*\"] to let any participant do so",
            cfg.network.interfaces
        ));
    }
    cfg.servo.validate()?;
    cfg.sim.validate()?;
    for (k, stop) in cfg.sim.fixed_stops.iter().enumerate() {
        let axis = cfg.machine.axes.iter().find(|a| a.name == stop.axis);
        match axis {
            Some(a) if stop.at.is_finite() && (a.min..=a.max).contains(&stop.at) => {}
            _ => {
                return Err(format!(
                    "sim.fixed_stops[{k}]: {} at {} is no place within a machine axis's travel",
                    stop.axis, stop.at
                ))
            }
        }
    }
    cfg.plc.validate()?;
    cfg.recorder.validate()?;
    cfg.realtime.validate()
}
