//! `cnc simulate`: the interpreter and the motion planner on a simulated clock, without
//! drives, PLC or DDS. It gives the programmer the cycle time and a picture of the part before
//! cutting it.
//!
//! What the estimate includes: every move as motion plans it (acceleration, per-axis rapids,
//! feed per revolution and threads at the programmed spindle speed, threads waiting for the
//! spindle's index pulse), dwells and program end.
//! What it leaves out: the PLC's own time for M, S and T codes (spindle ramps, turret
//! indexing, chuck), which are answered at once here; the simulated machine of `cnc run`
//! includes them.

use std::collections::VecDeque;
use std::time::Instant;

use cnc_interpreter::{Canon, Dialect, Interpreter, Library};
use cnc_io::sim::spindle_position::{Positioning, StopCommand};
use cnc_motion::path::{self, Point, Segment, MAX_AXES};
use cnc_motion::{Aux, Block, Command, FromLaunch, Motion, MotionConfig, MotionEvent, RunState};
use cnc_msgs::signals::{f, g, y, FImage, GImage, SignalTable, YImage};
use cnc_runtime::config::ProfileShape;
use cnc_runtime::LaunchConfig;
use cnc_task::run::ProgramRun;

/// Simulated time after which a program is taken as endless (a real cycle is minutes).
const MAX_SIMULATED_SECONDS: f64 = 24.0 * 3600.0;

/// A tool position in the turning plane: Z and X (diameter), and whether the tool was cutting
/// (feeding) to get there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    pub z: f64,
    pub x: f64,
    pub cutting: bool,
}

/// What to change for one simulation, besides the launch config.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options {
    /// Velocity profile instead of the config's `servo.profile`.
    pub profile: Option<ProfileShape>,
    /// Measure the planner's CPU time per servo tick.
    pub timing: bool,
}

/// Figures measured from the setpoint trace, each axis against its own limits.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TraceStats {
    /// Largest |Δp/dt| over the axis's rapid rate.
    pub max_velocity_ratio: f64,
    /// Largest |Δ²p/dt²| over the axis's acceleration limit.
    pub max_acceleration_ratio: f64,
    /// Largest distance of a setpoint of a feed move from the programmed path, mm.
    pub max_deviation: f64,
    /// Time spent in feed moves, s, and the same at the programmed feed with no
    /// acceleration (length / feed).
    pub cutting_time: f64,
    pub ideal_cutting_time: f64,
}

#[derive(Debug, Clone)]
pub struct Simulation {
    /// Seconds from cycle start to the end of the program.
    pub cycle_time: f64,
    /// The tool path in the turning plane, one point per servo period in which the tool moved
    /// (lathes only: machines with X and Z).
    pub path: Vec<PathPoint>,
    /// Canonical commands executed.
    pub commands: usize,
    pub stats: TraceStats,
    /// Motion's CPU time per servo tick, ns (with `Options::timing`).
    pub tick_nanos: Vec<u64>,
    /// Program stops (M0, M1 with optional stop on), each ended at once by cycle start as an
    /// operator with nothing to do at them would: the cycle time leaves out their waiting.
    pub program_stops: usize,
}

/// Programmed feed moves near the one being cut, to measure how far the setpoints leave them.
struct ProgrammedPath {
    segments: VecDeque<(u64, Segment)>,
    end: Point,
    ideal_time: f64,
}

impl ProgrammedPath {
    /// Takes in a command sent to motion (positions in slide units).
    fn push(
        &mut self,
        seq: u64,
        command: &Command,
        slide: &dyn Fn(&[f64]) -> Point,
        plane: (usize, usize),
    ) {
        let (seg, feed) = match command {
            Command::Linear { end, feed } => (
                Some(Segment::Line {
                    start: self.end,
                    end: slide(end),
                }),
                *feed,
            ),
            Command::Thread { end, .. } => (
                Some(Segment::Line {
                    start: self.end,
                    end: slide(end),
                }),
                0.0,
            ),
            Command::Arc {
                end,
                center,
                clockwise,
                feed,
                plane: arc_plane,
            } => {
                let plane = arc_plane.map_or(plane, |[h, v]| (usize::from(h), usize::from(v)));
                (
                    path::arc(&self.end, &slide(end), &slide(center), plane, *clockwise),
                    *feed,
                )
            }
            Command::Rapid { end } => {
                self.end = slide(end);
                return;
            }
            _ => return,
        };
        if let Some(seg) = seg {
            if feed > 0.0 {
                self.ideal_time += seg.length() / (feed / 60.0);
            }
            self.end = seg.end();
            self.segments.push_back((seq, seg));
        }
    }

    /// Distance of `p` from the programmed moves around block `done + 1`. Motion cuts up to
    /// 32 merged lines as one chord and reports them done when the blend into the next chord
    /// begins, so 40 blocks either side are looked at.
    fn deviation(&mut self, done: u64, p: &Point) -> f64 {
        while self
            .segments
            .front()
            .is_some_and(|(seq, _)| *seq + 40 < done)
        {
            self.segments.pop_front();
        }
        self.segments
            .iter()
            .take_while(|(seq, _)| *seq <= done + 40)
            .map(|(_, seg)| path::distance_to(seg, p))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Interprets `text` and runs its blocks through the planner from the config's home position.
pub fn simulate(
    cfg: &LaunchConfig,
    dialect: Dialect,
    text: &str,
    library: Library,
    options: Options,
) -> Result<Simulation, String> {
    let lathe_plane = match (cfg.axis_index("X"), cfg.axis_index("Z")) {
        (Some(x), Some(z)) if dialect.is_lathe() => Some((x, z)),
        _ => None,
    };
    let setup = cnc_task::node::setup_from_config(cfg, &cfg.home());
    let mut stream = ProgramRun::new(Interpreter::with_library(dialect, text, setup, library));
    let mut mcfg = MotionConfig::from_launch(cfg);
    if let Some(shape) = options.profile {
        mcfg.shape = shape;
    }
    let axes = mcfg.axes.clone();
    let n = axes.len().min(MAX_AXES);
    let plane = mcfg.arc_plane;
    let slide = |p: &[f64]| -> Point {
        let mut out = [0.0; MAX_AXES];
        for i in 0..n {
            out[i] = p.get(i).copied().unwrap_or(0.0) * axes[i].scale();
        }
        out
    };
    let start = cfg.home_slide();
    let period = mcfg.period;
    let capacity = mcfg.queue_capacity.max(2) as u64;
    let mut motion = Motion::new(mcfg, &start);
    // Ideal drives: each axis is where it was commanded one period earlier.
    let mut actual = start.clone();
    let mut plc = GImage::released();
    let mut ticks = 0u64;
    let mut lathe_path = Vec::new();
    let mut last = motion.commanded_display();
    let mut spindle = IdealSpindle {
        acceleration: cfg.sim.spindle_acceleration,
        direction: 1.0,
        ..IdealSpindle::default()
    };
    let max_ticks = (MAX_SIMULATED_SECONDS / period) as u64;
    let mut programmed = ProgrammedPath {
        segments: VecDeque::new(),
        end: slide(&cfg.home()),
        ideal_time: 0.0,
    };
    let mut stats = TraceStats::default();
    let mut tick_nanos = Vec::new();
    let mut program_stops = 0;
    // The last two setpoints, for velocity and acceleration.
    let (mut p1, mut p2) = (start.clone(), start.clone());
    loop {
        // Keep motion's queue full, with the interpreter node's credit loop.
        let done = motion.done_seq();
        stream
            .feed(done, capacity, |seq, Canon { line, command, .. }, _| {
                if let Command::Aux(Aux::S(s)) = command {
                    spindle.commanded = s;
                }
                programmed.push(seq, &command, &slide, plane);
                motion.push(Block {
                    run_id: 1,
                    seq,
                    line,
                    kind: command,
                });
            })
            .map_err(|e| format!("alarm {} at line {}: {}", e.number, e.line, e.text))?;
        if stream.all_sent()
            && motion.done_seq() == stream.sent()
            && motion.state() == RunState::Idle
        {
            break;
        }
        if ticks >= max_ticks {
            return Err(format!(
                "program still running after {MAX_SIMULATED_SECONDS} s of simulated time"
            ));
        }
        if motion.state() == RunState::Hold {
            motion.cycle_start();
            program_stops += 1;
        }
        // The simulated PLC answers every strobe at once and the spindle is at speed; a
        // positioning once the spindle stands at its angle.
        let (rpm, angle) = spindle.answer(motion.f_image(), &mut plc, period);
        motion.spindle_feedback(rpm, angle);
        let before = motion.active_cutting();
        let clock = options.timing.then(Instant::now);
        let commanded = motion.tick(Some(&actual), &plc);
        if let Some(t) = clock {
            tick_nanos.push(t.elapsed().as_nanos() as u64);
        }
        actual.copy_from_slice(commanded);
        ticks += 1;
        if let Some(MotionEvent::Alarm { number, text, line }) =
            motion.take_events().into_iter().next()
        {
            return Err(format!("motion alarm {number} at line {line}: {text}"));
        }
        let cutting = before.or(motion.active_cutting()).unwrap_or(false);
        for (i, a) in axes.iter().enumerate() {
            let v = (actual[i] - p1[i]) / period;
            let acc = (actual[i] - 2.0 * p1[i] + p2[i]) / (period * period);
            stats.max_velocity_ratio = stats
                .max_velocity_ratio
                .max(v.abs() / (a.max_velocity / 60.0));
            stats.max_acceleration_ratio = stats
                .max_acceleration_ratio
                .max(acc.abs() / a.max_acceleration);
        }
        let moved = actual != p1;
        p2.clone_from(&p1);
        p1.clone_from(&actual);
        if cutting {
            stats.cutting_time += period;
            if moved {
                let d = programmed.deviation(motion.done_seq(), &path::point_from(&actual));
                if d.is_finite() {
                    stats.max_deviation = stats.max_deviation.max(d);
                }
            }
        }
        if let Some((xi, zi)) = lathe_plane {
            let now = motion.commanded_display();
            if now != last {
                lathe_path.push(PathPoint {
                    z: now[zi],
                    x: now[xi],
                    cutting,
                });
                last = now;
            }
        }
    }
    stats.ideal_cutting_time = programmed.ideal_time;
    Ok(Simulation {
        cycle_time: ticks as f64 * period,
        path: lathe_path,
        commands: stream.sent() as usize,
        stats,
        tick_nanos,
        program_stops,
    })
}

/// The figures `cnc simulate` prints, one per line.
pub fn report(sim: &Simulation) -> String {
    let st = &sim.stats;
    let mut out = format!(
        "cycle time: {:.3} s\n\
         max axis velocity / limit: {:.4}\n\
         max axis acceleration / limit: {:.4}\n\
         max path deviation: {:.5} mm\n",
        sim.cycle_time, st.max_velocity_ratio, st.max_acceleration_ratio, st.max_deviation
    );
    if st.ideal_cutting_time > 0.0 {
        out.push_str(&format!(
            "feed moves: {:.3} s, {:.3} s at the programmed feed without acceleration\n",
            st.cutting_time, st.ideal_cutting_time
        ));
    }
    if sim.program_stops > 0 {
        out.push_str(&format!(
            "program stops: {}, each ended at once by cycle start\n",
            sim.program_stops
        ));
    }
    if !sim.tick_nanos.is_empty() {
        let mut t = sim.tick_nanos.clone();
        t.sort_unstable();
        let at = |q: f64| t[((t.len() - 1) as f64 * q).round() as usize] as f64 / 1000.0;
        out.push_str(&format!(
            "motion CPU per servo tick: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs over {} ticks\n",
            at(0.5),
            at(0.99),
            at(1.0),
            t.len()
        ));
    }
    out
}

/// The finished outside profile: for each Z step, the smallest diameter the tool reached
/// while cutting there (the stock turned away by the tool), between the extremes of the cuts.
pub fn turned_profile(path: &[PathPoint], step: f64) -> Vec<(f64, f64)> {
    let cuts: Vec<&PathPoint> = path.iter().filter(|p| p.cutting).collect();
    let (Some(z0), Some(z1)) = (
        cuts.iter().map(|p| p.z).reduce(f64::min),
        cuts.iter().map(|p| p.z).reduce(f64::max),
    ) else {
        return Vec::new();
    };
    let n = (((z1 - z0) / step).ceil() as usize).clamp(1, 100_000);
    let mut min_x = vec![f64::INFINITY; n + 1];
    for w in path.windows(2) {
        if !w[1].cutting {
            continue;
        }
        // Every station the segment passes over, so a long cut is not sampled at its ends only.
        let (a, b) = (w[0], w[1]);
        let (lo, hi) = (a.z.min(b.z), a.z.max(b.z));
        let i0 = ((lo - z0) / step).ceil().max(0.0) as usize;
        let i1 = (((hi - z0) / step).floor().max(0.0) as usize).min(n);
        for (i, slot) in min_x.iter_mut().enumerate().take(i1 + 1).skip(i0) {
            let z = z0 + i as f64 * step;
            let x = if (b.z - a.z).abs() < 1e-12 {
                a.x.min(b.x)
            } else {
                a.x + (b.x - a.x) * (z - a.z) / (b.z - a.z)
            };
            *slot = slot.min(x);
        }
        for p in [a, b] {
            let i = (((p.z - z0) / step).round().max(0.0) as usize).min(n);
            min_x[i] = min_x[i].min(p.x);
        }
    }
    min_x
        .iter()
        .enumerate()
        .filter(|(_, x)| x.is_finite())
        .map(|(i, x)| (z0 + i as f64 * step, *x))
        .collect()
}

/// The part (upper half, X as radius) and the tool path as an SVG drawing, Z to the right.
pub fn svg(sim: &Simulation) -> String {
    let profile = turned_profile(&sim.path, 0.1);
    let pts = sim.path.iter().map(|p| (p.z, p.x / 2.0));
    let (mut zmin, mut zmax, mut rmax) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for (z, r) in pts.chain(profile.iter().map(|&(z, x)| (z, x / 2.0))) {
        zmin = zmin.min(z);
        zmax = zmax.max(z);
        rmax = rmax.max(r);
    }
    if !zmin.is_finite() {
        (zmin, zmax, rmax) = (0.0, 1.0, 1.0);
    }
    let margin = 5.0;
    let scale = 800.0 / (zmax - zmin + 2.0 * margin).max(1.0);
    let width = (zmax - zmin + 2.0 * margin) * scale;
    let height = (rmax + 2.0 * margin) * scale;
    let px = |z: f64| (z - zmin + margin) * scale;
    let py = |r: f64| height - (r + margin) * scale;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\" \
         viewBox=\"0 0 {width:.1} {height:.1}\">\n\
         <title>cycle time {:.1} s, {} commands</title>\n\
         <line x1=\"0\" y1=\"{:.1}\" x2=\"{width:.1}\" y2=\"{:.1}\" stroke=\"#888\" \
         stroke-dasharray=\"8 4\"/>\n",
        sim.cycle_time,
        sim.commands,
        py(0.0),
        py(0.0)
    );
    if let (Some(first), Some(last)) = (profile.first(), profile.last()) {
        let mut d = format!("M{:.2} {:.2}", px(first.0), py(0.0));
        for &(z, x) in &profile {
            d.push_str(&format!(" L{:.2} {:.2}", px(z), py(x / 2.0)));
        }
        d.push_str(&format!(" L{:.2} {:.2} Z", px(last.0), py(0.0)));
        out.push_str(&format!(
            "<path class=\"part\" d=\"{d}\" fill=\"#c8ccd4\" stroke=\"#333\"/>\n"
        ));
    }
    for cutting in [false, true] {
        let mut d = String::new();
        let mut pen_down = false;
        for w in sim.path.windows(2) {
            if w[1].cutting == cutting {
                if !pen_down {
                    d.push_str(&format!("M{:.2} {:.2}", px(w[0].z), py(w[0].x / 2.0)));
                    pen_down = true;
                }
                d.push_str(&format!(" L{:.2} {:.2}", px(w[1].z), py(w[1].x / 2.0)));
            } else {
                pen_down = false;
            }
        }
        let (class, style) = if cutting {
            ("feed", "stroke=\"#1f5fbf\"")
        } else {
            ("rapid", "stroke=\"#d0342c\" stroke-dasharray=\"4 3\"")
        };
        out.push_str(&format!(
            "<path class=\"{class}\" d=\"{d}\" fill=\"none\" {style} stroke-width=\"1\"/>\n"
        ));
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> LaunchConfig {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/launch_configs/sim_lathe.yaml");
        LaunchConfig::load(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn cycle_time_of_a_long_feed_is_its_length_over_the_feed() {
        let cfg = config();
        // 100 mm at 600 mm/min = 10 s, plus the rapids and the accelerations.
        let text = "G00 X50 Z5\nG01 Z-95 F600\nG00 X100\nM30\n";
        let sim = simulate(
            &cfg,
            Dialect::HuaxingLathe,
            text,
            Library::new(),
            Options::default(),
        )
        .unwrap();
        assert!(
            sim.cycle_time > 10.0 && sim.cycle_time < 13.0,
            "{}",
            sim.cycle_time
        );
        // The turned profile is the diameter 50 over the cut.
        let profile = turned_profile(&sim.path, 1.0);
        assert!(profile.len() > 90, "{}", profile.len());
        assert!(profile.iter().all(|&(_, x)| (x - 50.0).abs() < 1e-6));
        let picture = svg(&sim);
        assert!(picture.starts_with("<svg") && picture.contains("class=\"part\""));
    }

    #[test]
    fn an_alarm_is_reported_with_its_line() {
        let cfg = config();
        let e = simulate(
            &cfg,
            Dialect::HuaxingLathe,
            "G00 X50\nG02 X60 Z-10 R1\nM30\n",
            Library::new(),
            Options::default(),
        )
        .unwrap_err();
        assert!(e.contains("line 2"), "{e}");
    }
}

/// The spindle as `cnc simulate` has it: at the commanded speed at once, positioned (M19 with
/// a stop position: SPOS, a rigid tap, the turn-mill's C) as the simulated drive positions it.
#[derive(Debug, Default)]
struct IdealSpindle {
    /// The programmed S, rpm, and the direction M03/M04/M05 gave (1, −1, 0).
    commanded: f64,
    direction: f64,
    angle: f64,
    positioning: IdealPositioning,
    /// The drive's rated acceleration, rpm/s (`sim.spindle_acceleration`).
    acceleration: f64,
}

impl IdealSpindle {
    /// One period: answers the NC's strobes in `plc` (a positioning's once it stands) and
    /// returns the encoder's speed and angle.
    fn answer(&mut self, fi: &FImage, plc: &mut GImage, period: f64) -> (f64, f64) {
        let orienting = fi.get(f::MF) && fi.read_i32(f::M_CODE) == 19;
        if orienting {
            self.direction = 0.0;
            self.positioning.take(fi, self.angle, self.acceleration);
        }
        let rpm = match self
            .positioning
            .turn(&mut self.angle, period, self.acceleration)
        {
            Some(rpm) => rpm,
            None => {
                let rpm = self.commanded * self.direction;
                self.angle = (self.angle + rpm / 60.0 * 360.0 * period).rem_euclid(360.0);
                rpm
            }
        };
        let answered = !orienting || !self.positioning.moving();
        plc.set(
            g::FIN,
            (fi.get(f::MF) && answered) || fi.get(f::SF) || fi.get(f::TF),
        );
        if fi.get(f::MF) {
            match fi.read_i32(f::M_CODE) {
                3 => self.direction = 1.0,
                4 => self.direction = -1.0,
                5 => self.direction = 0.0,
                _ => {}
            }
        }
        (rpm, self.angle)
    }
}

/// The spindle drive's positioning in `cnc simulate`: the simulated drive's own (D100), at its
/// rated acceleration, on the stop position the ladder would copy from F30–F39 to Y8–Y17.
#[derive(Debug, Default)]
struct IdealPositioning {
    active: Option<Positioning>,
    /// Degrees turned (unwrapped) and the speed, rpm, while positioning.
    turned: f64,
    rpm: f64,
}

impl IdealPositioning {
    /// A new stop position (a new count) starts its positioning from `angle`.
    fn take(&mut self, fi: &FImage, angle: f64, acceleration: f64) {
        let mut yi = YImage::default();
        yi.bytes[y::ORIENT_ANGLE..y::ORIENT_ANGLE + 10]
            .copy_from_slice(&fi.bytes[f::ORIENT_ANGLE..f::ORIENT_ANGLE + 10]);
        let command = StopCommand::of(&yi);
        if self.active.is_some_and(|p| p.command == command) {
            return;
        }
        self.turned = angle;
        self.active = Some(Positioning::start(command, angle, 0.0, acceleration));
    }

    fn moving(&self) -> bool {
        self.active.is_some()
    }

    /// One period: the spindle's angle and speed; none when nothing is positioning.
    fn turn(&mut self, angle: &mut f64, period: f64, acceleration: f64) -> Option<f64> {
        let p = self.active?;
        let step = acceleration * period;
        self.rpm += (p.speed(self.turned, acceleration) - self.rpm).clamp(-step, step);
        self.turned += self.rpm / 60.0 * 360.0 * period;
        if p.reached(self.turned, self.rpm) {
            (self.turned, self.rpm) = (p.goal, 0.0);
            self.active = None;
        }
        *angle = self.turned.rem_euclid(360.0);
        Some(self.rpm)
    }
}
