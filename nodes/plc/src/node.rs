//! plc node shell: scans the ladder every `plc.scan_ms` over the F/G and X/Y images
//! (iceoryx2), and publishes spindle, part count, PLC messages and scan statistics on DDS.
//!
//! The program is `plc.program` (default: the built-in standard lathe program). The node
//! reloads it when the file changes; a program with an error is refused with its line and
//! reason, and the running program goes on. Keep relays, data registers and presets are
//! saved to `plc.memory_file` (atomically) when they change.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use cnc_msgs::msg::{
    Alarm, PartCount, PlcProgram, PlcSignals, PlcStatus, RobotHandshake, SpindleState,
};
use cnc_msgs::signals::{f, g, x, y, FImage, SignalTable, XImage};
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::{monotonic_ns, sleep_until_ns};
use cnc_runtime::dds::{stamp, RosNode};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::address::Space;
use crate::memory::Retained;
use crate::scan::{PlcEvent, EMERGENCY_STOP_ALARM, PLC_FAULT_ALARM};
use crate::{Plc, Program, LATHE_STANDARD};

/// Alarm raised (as a warning) when a new program is refused.
pub const PROGRAM_REFUSED_ALARM: u32 = 1091;
/// The symbol a program names its part counter with (4 bytes).
pub const PART_COUNT_SYMBOL: &str = "PART_COUNT";

/// Reads the program text: the configured file, or the built-in standard program.
pub fn program_text(path: Option<&Path>) -> Result<String, String> {
    match path {
        None => Ok(LATHE_STANDARD.to_string()),
        Some(p) => std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display())),
    }
}

fn load_retained(path: Option<&Path>) -> Option<Retained> {
    let text = std::fs::read_to_string(path?).ok()?;
    match serde_yaml::from_str(&text) {
        Ok(r) => Some(r),
        Err(e) => {
            log::warn!("PLC memory file ignored: {e}");
            None
        }
    }
}

fn modified(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<(), String> {
    let program_path: Option<PathBuf> = cfg.plc.program.clone();
    let text = program_text(program_path.as_deref())?;
    // The first program must be good: a machine without machine logic does not start.
    let program = Program::parse(&text).map_err(|e| {
        format!(
            "PLC program {}: {e}",
            program_path
                .as_ref()
                .map_or("(built in)".into(), |p| p.display().to_string())
        )
    })?;
    let memory_file = cfg.plc.memory_file.clone();
    let mut saved = load_retained(memory_file.as_deref());
    if saved.is_none() && !cfg.plc.keep_relays.is_empty() {
        saved = Some(
            Retained::first_power_up(&cfg.plc.keep_relays)
                .map_err(|e| format!("plc.keep_relays: {e}"))?,
        );
    }
    let mut plc = Plc::new(program, saved.as_ref(), cfg.plc.level2_divisions as usize);
    plc.set_spindle_limit(cfg.limits.spindle_max_rpm);
    let mut program_mtime = program_path.as_deref().and_then(modified);

    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "plc")?;
    // The scan runs in real time: its DDS writes go through a relay thread.
    ros.relay_dds("plc")?;
    let spindle_pub = ros.publisher::<SpindleState>(&topics::SPINDLE)?;
    let parts_pub = ros.publisher::<PartCount>(&topics::PART_COUNT)?;
    let status_pub = ros.publisher::<PlcStatus>(&topics::PLC_STATUS)?;
    let robot_pub = ros.publisher::<RobotHandshake>(&topics::ROBOT_HANDSHAKE)?;
    let signals_pub = ros.publisher::<PlcSignals>(&topics::PLC_SIGNALS)?;
    let program_pub = ros.publisher::<PlcProgram>(&topics::PLC_PROGRAM)?;
    let source = program_path
        .as_ref()
        .map_or("(built in)".into(), |p| p.display().to_string());
    publish_program(&program_pub, &plc, &source);
    let mut last_robot: Option<RobotHandshake> = None;
    let alarms = AlarmReporter::new(&mut ros, "plc")?;
    let shm = ShmNode::new(&instance, "plc")?;
    let f_in = shm.receiver::<FImage>(channel::F_IMAGE, false)?;
    let x_in = shm.receiver::<XImage>(channel::X_IMAGE, false)?;
    let g_out = shm.sender::<cnc_msgs::signals::GImage>(channel::G_IMAGE, false)?;
    let y_out = shm.sender::<cnc_msgs::signals::YImage>(channel::Y_IMAGE, false)?;
    let (mut fi, mut xi) = (FImage::default(), XImage::default());
    let period = (cfg.plc.scan_ms * 1e6) as u64;
    let t0 = monotonic_ns();
    let mut next = t0;
    let mut scan_times = ScanTimes::default();
    let mut parts = PartCounter::default();
    let mut kept = Kept {
        keeper: memory_file
            .clone()
            .map(|p| cnc_runtime::persist::Keeper::new(p, "PLC memory")),
        saved,
        held_parts: None,
    };
    let mut last_spindle = None;
    // The scan keeps the machine's I/O in time: real time below the servo and drive loops.
    let rt = &cfg.realtime;
    cnc_runtime::realtime::enter("PLC scan", rt.plc_priority, None, rt.lock_memory);
    while !shutdown.requested() {
        ros.refresh();
        next += period;
        sleep_until_ns(next);
        if monotonic_ns() > next + 10 * period {
            next = monotonic_ns();
        }
        if let Some(v) = f_in.latest()? {
            fi = v;
        }
        if let Some(v) = x_in.latest()? {
            xi = v;
        }
        if xi.seq == 0 {
            // The machine's inputs have not arrived yet: no scan, so no emergency stop is
            // reported for a machine that is only starting (G stays all zero: `*ESP`).
            continue;
        }
        let start = monotonic_ns();
        plc.scan(&fi, &xi, (start - t0) / 1_000_000);
        scan_times.record((monotonic_ns() - start) as f64 / 1000.0);
        g_out.send(*plc.to_nc())?;
        y_out.send(*plc.outputs())?;
        raise_events(&mut plc, &alarms);
        let scans = plc.scans();
        let now_s = (monotonic_ns() - t0) as f64 * 1e-9;
        kept.keep_and_count(&plc, &mut parts, &fi, now_s, &parts_pub);
        publish_spindle(
            &spindle_pub,
            plc.outputs(),
            &xi,
            &mut last_spindle,
            scans,
            f32::from(plc.to_nc().bytes[g::SPINDLE_OVERRIDE as usize]),
        );
        let robot = handshake(plc.outputs(), &xi, &fi);
        if last_robot.as_ref() != Some(&robot) || scans.is_multiple_of(100) {
            let _ = robot_pub.publish(RobotHandshake {
                stamp: stamp(),
                ..robot.clone()
            });
            last_robot = Some(robot);
        }
        if scans.is_multiple_of(SIGNALS_EVERY) {
            publish_signals(&plc, &signals_pub);
        }
        if scans.is_multiple_of(100) {
            // Once a second at 10 ms: status, program file, parameters.
            let _ = status_pub.publish(scan_times.message(
                &plc,
                &program_path,
                cfg.plc.level2_divisions,
            ));
            if let Some(p) = program_path.as_deref() {
                let m = modified(p);
                if m != program_mtime {
                    program_mtime = m;
                    if reload(&mut plc, p, &alarms) {
                        publish_program(&program_pub, &plc, &source);
                    }
                }
            }
        }
    }
    Ok(())
}

/// The scan's messages, emergency stop and faults as alarms.
fn raise_events(plc: &mut Plc, alarms: &AlarmReporter) {
    for e in plc.take_events() {
        match e {
            PlcEvent::MessageOn {
                number,
                address,
                text,
                alarm,
            } => {
                let severity = if alarm {
                    Alarm::SEVERITY_ERROR
                } else {
                    Alarm::SEVERITY_INFO
                };
                alarms.raise(alarms.alarm(number, severity, &format!("{address} {text}"), "", 0))
            }
            PlcEvent::MessageOff { number } => alarms.clear(number),
            PlcEvent::EmergencyStop(true) => alarms.raise(alarms.alarm(
                EMERGENCY_STOP_ALARM,
                Alarm::SEVERITY_FATAL,
                "emergency stop",
                "",
                0,
            )),
            PlcEvent::EmergencyStop(false) => alarms.clear(EMERGENCY_STOP_ALARM),
            PlcEvent::Fault { text } => {
                alarms.raise(alarms.alarm(PLC_FAULT_ALARM, Alarm::SEVERITY_FATAL, &text, "", 0))
            }
        }
    }
}

/// The retained memory, kept at every change, and the part count, published once its count
/// is on the disk: a part the cell was told of is never lost (decisions D59).
struct Kept {
    keeper: Option<cnc_runtime::persist::Keeper>,
    saved: Option<Retained>,
    held_parts: Option<(PartCount, u64)>,
}

impl Kept {
    fn keep_and_count(
        &mut self,
        plc: &Plc,
        parts: &mut PartCounter,
        fi: &FImage,
        now_s: f64,
        parts_pub: &cnc_runtime::dds::Publisher<PartCount>,
    ) {
        let scans = plc.scans();
        let kept_version = match self.keeper.as_mut() {
            Some(k) => {
                if !self.saved.as_ref().is_some_and(|s| plc.retains(s)) {
                    let now = plc.retained();
                    if let Ok(text) = serde_yaml::to_string(&now) {
                        k.keep(text.into_bytes());
                    }
                    self.saved = Some(now);
                }
                k.given()
            }
            None => 0,
        };
        if let Some(msg) = parts.update(plc, fi, now_s, scans.is_multiple_of(500)) {
            self.held_parts = Some((msg, kept_version));
        }
        // A disk that refuses the write (logged as an error) does not hold the count back.
        let durable = match &self.keeper {
            Some(k) if !k.failing() => k.durable(),
            _ => u64::MAX,
        };
        if let Some((msg, _)) = self.held_parts.take_if(|(_, v)| *v <= durable) {
            let _ = parts_pub.publish(msg);
        }
    }
}

fn publish_signals(plc: &Plc, publisher: &cnc_runtime::dds::Publisher<PlcSignals>) {
    let table = |s| plc.table(s).to_vec();
    let _ = publisher.publish(PlcSignals {
        stamp: stamp(),
        scan: plc.scans(),
        x: table(Space::X),
        y: table(Space::Y),
        f: table(Space::F),
        g: table(Space::G),
        r: table(Space::R),
        a: table(Space::A),
        k: table(Space::K),
    });
}

/// The signal snapshot goes out every this many scans (5 a second at the 10 ms default).
const SIGNALS_EVERY: u64 = 20;

fn publish_program(publisher: &cnc_runtime::dds::Publisher<PlcProgram>, plc: &Plc, source: &str) {
    let (rungs, lines) = crate::monitor::rungs(plc.program());
    let _ = publisher.publish(PlcProgram {
        stamp: stamp(),
        source: source.into(),
        rungs,
        lines,
    });
}

/// Loads the changed program file; false if it was refused and the old program runs on.
fn reload(plc: &mut Plc, path: &Path, alarms: &AlarmReporter) -> bool {
    let result = program_text(Some(path)).and_then(|t| plc.load(&t).map_err(|e| e.to_string()));
    match result {
        Ok(()) => {
            log::info!("PLC program {} loaded", path.display());
            alarms.clear(PROGRAM_REFUSED_ALARM);
            true
        }
        Err(e) => {
            let text = format!(
                "PLC program {} refused, the previous program runs on: {e}",
                path.display()
            );
            log::warn!("{text}");
            alarms.raise(alarms.alarm(
                PROGRAM_REFUSED_ALARM,
                Alarm::SEVERITY_WARNING,
                &text,
                "",
                0,
            ));
            false
        }
    }
}

/// Scan durations for the status topic.
#[derive(Default)]
struct ScanTimes {
    /// The last 1000 scans, µs.
    recent: std::collections::VecDeque<f64>,
    last: f64,
    max: f64,
}

impl ScanTimes {
    fn record(&mut self, us: f64) {
        self.last = us;
        self.max = self.max.max(us);
        if self.recent.len() >= 1000 {
            self.recent.pop_front();
        }
        self.recent.push_back(us);
    }

    fn message(&self, plc: &Plc, path: &Option<PathBuf>, divisions: u32) -> PlcStatus {
        let mut sorted: Vec<f64> = self.recent.iter().copied().collect();
        sorted.sort_by(f64::total_cmp);
        let p99 = sorted
            .get((sorted.len() * 99 / 100).min(sorted.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0);
        PlcStatus {
            stamp: stamp(),
            program: path
                .as_ref()
                .map_or("lathe_standard.plc (built in)".into(), |p| {
                    p.display().to_string()
                }),
            steps: plc.program().steps.len() as u32,
            scans: plc.scans(),
            level2_divisions: divisions,
            scan_time_last_us: self.last,
            scan_time_p99_us: p99,
            scan_time_max_us: self.max,
            fault: plc.fault().unwrap_or_default().to_string(),
        }
    }
}

/// The part count the program keeps at `PART_COUNT`, and the time of each cycle: from the
/// NC's OP signal coming on to the count going up.
#[derive(Default)]
struct PartCounter {
    last: Option<i64>,
    op: bool,
    cycle_started: Option<f64>,
    last_cycle_time: f64,
}

impl PartCounter {
    fn update(&mut self, plc: &Plc, fi: &FImage, now: f64, every: bool) -> Option<PartCount> {
        let count = plc.read_value(PART_COUNT_SYMBOL, 4).unwrap_or(0);
        let op = fi.get(f::OP);
        if op && !self.op {
            self.cycle_started = Some(now);
        }
        self.op = op;
        let changed = self.last != Some(count);
        if changed && self.last.is_some() {
            self.last_cycle_time = self.cycle_started.take().map_or(0.0, |t| now - t);
        }
        self.last = Some(count);
        (changed || every).then(|| PartCount {
            stamp: stamp(),
            count: count.clamp(0, i64::from(u32::MAX)) as u32,
            target: 0,
            last_cycle_time: self.last_cycle_time,
        })
    }
}

/// The robot's view of the machine from the I/O images (stamp left at zero, so two views
/// compare equal when the signals do).
fn handshake(yi: &cnc_msgs::signals::YImage, xi: &XImage, fi: &FImage) -> RobotHandshake {
    RobotHandshake {
        stamp: Default::default(),
        ready_for_load: yi.get(y::READY_FOR_LOAD),
        cycle_complete: yi.get(y::CYCLE_COMPLETE),
        door_open: xi.get(x::DOOR_OPEN),
        door_closed: xi.get(x::DOOR_CLOSED),
        chuck_clamped: xi.get(x::CHUCK_CLAMPED),
        chuck_unclamped: xi.get(x::CHUCK_UNCLAMPED),
        robot_clear: xi.get(x::ROBOT_CLEAR),
        spindle_turning: yi.get(y::SPINDLE_CW)
            || yi.get(y::SPINDLE_CCW)
            || xi.spindle_actual_rpm.abs() > 1.0,
        cycle_active: fi.get(f::OP),
        emergency_stop: !xi.get(x::ESP_N),
    }
}

/// Spindle state on change (to the rpm; standing positioned, to the 0.001°) and at least
/// every 100 scans.
fn publish_spindle(
    publisher: &cnc_runtime::dds::Publisher<SpindleState>,
    yi: &cnc_msgs::signals::YImage,
    xi: &XImage,
    last: &mut Option<(i64, u8, bool, i64, i64)>,
    scans: u64,
    override_percent: f32,
) {
    let direction = match (yi.get(y::SPINDLE_CW), yi.get(y::SPINDLE_CCW)) {
        (true, false) => SpindleState::DIRECTION_CW,
        (false, true) => SpindleState::DIRECTION_CCW,
        _ => SpindleState::DIRECTION_STOP,
    };
    let commanded = if direction == SpindleState::DIRECTION_STOP {
        0.0
    } else {
        yi.spindle_rpm
    };
    let at_speed = xi.get(x::SPINDLE_AT_SPEED) && direction != SpindleState::DIRECTION_STOP;
    let positioned = yi.get(y::SPINDLE_ORIENT) && xi.get(x::SPINDLE_ORIENTED);
    let key = (
        commanded.round() as i64,
        direction,
        at_speed,
        xi.spindle_actual_rpm.round() as i64,
        // 1 + the angle in 0.001° while positioned (0 while not).
        if positioned {
            1 + (xi.spindle_angle_deg * 1000.0).round() as i64
        } else {
            0
        },
    );
    if *last != Some(key) || scans.is_multiple_of(100) {
        *last = Some(key);
        let _ = publisher.publish(SpindleState {
            stamp: stamp(),
            commanded_rpm: commanded,
            actual_rpm: xi.spindle_actual_rpm.abs(),
            direction,
            // The simulated spindle models no cutting load yet.
            load: 0.0,
            override_percent,
            at_speed,
            positioned,
            position_deg: xi.spindle_angle_deg,
        });
    }
}
