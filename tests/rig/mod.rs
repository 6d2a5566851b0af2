//! The rig the PLC tests step: the interpreter, motion, the ladder PLC and the simulated
//! machine with its devices, each core as the cell runs it, on one simulated clock (servo
//! 4 ms, PLC scan 10 ms). Shared by `plc_cell.rs` (the lathe's ladder) and `plc_cell_mill.rs`
//! (the 802D mill's spindle, taps, H functions, feedforward).
#![allow(dead_code)]

use cnc_interpreter::{Canon, Dialect, Interpreter, Library, MachineTimers, Measurement};
use cnc_io::node::sim_config;
use cnc_io::sim::SimLathe;
use cnc_task::run::ProgramRun;

use cnc_motion::motion::ProbeInput;
use cnc_motion::{Block, FromLaunch, Motion, MotionConfig, RunState};
use cnc_msgs::servo::{ServoFeedback, ServoSetpoint, MAX_AXES};
use cnc_msgs::signals::{g, FImage, GImage, SignalTable, XImage, YImage};
use cnc_plc::memory::Retained;
use cnc_plc::{Plc, PlcEvent, Program, Value};
use cnc_runtime::LaunchConfig;

pub const DT: f64 = 0.004;
pub const SCAN: f64 = 0.010;

pub struct Rig {
    pub stream: ProgramRun,
    pub motion: Motion,
    pub plc: Plc,
    pub sim: SimLathe,
    pub t: f64,
    pub next_scan: f64,
    pub gi: GImage,
    pub yi: YImage,
    pub xi: XImage,
    pub fb: ServoFeedback,
    pub events: Vec<(f64, PlcEvent)>,
    pub n: usize,
    /// Cycle start given: the interpreter feeds motion.
    pub started: bool,
}

/// A launch config of `launch_configs/` (`sim_lathe`, `sim_mill`).
pub fn config(name: &str) -> LaunchConfig {
    let path = format!("{}/launch_configs/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    LaunchConfig::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

impl Rig {
    pub fn new(program: &str, retained: Option<&Retained>) -> Rig {
        Rig::on(config("sim_lathe"), program, retained)
    }

    pub fn on(cfg: LaunchConfig, program: &str, retained: Option<&Retained>) -> Rig {
        let setup = cnc_task::node::setup_from_config(&cfg, &cfg.home());
        let dialect = Dialect::from_name(&cfg.machine.dialect).unwrap();
        let interp = Interpreter::with_library(dialect, program, setup, Library::new());
        let mcfg = MotionConfig::from_launch(&cfg);
        let n = mcfg.axes.len();
        let start = cfg.home_slide();
        let mut sim = SimLathe::new(sim_config(&cfg), &start);
        let fb = sim.step(&ServoSetpoint::default(), &YImage::default(), 0.0);
        let plc = Plc::new(
            Program::parse(cnc_plc::LATHE_STANDARD).unwrap(),
            retained,
            2,
        );
        let mut stream = ProgramRun::new(interp);
        stream.on_machine();
        Rig {
            stream,
            motion: Motion::new(mcfg, &start),
            plc,
            sim,
            t: 0.0,
            next_scan: 0.0,
            gi: GImage::default(),
            yi: YImage::default(),
            xi: XImage::default(),
            fb,
            events: Vec::new(),
            n,
            started: false,
        }
    }

    /// One servo period; the PLC scans when its 10 ms are due.
    pub fn tick(&mut self) {
        if self.started {
            // A block's result (a measuring block, a preprocessing stop), once motion has it,
            // with the timers, as the interpreter node takes it from motion's status.
            if let (Some(seq), Some(r)) =
                (self.stream.awaiting_machine(), self.motion.block_result())
            {
                if r.seq == seq {
                    let t = self.motion.timers();
                    let m = Measurement {
                        triggered: r.triggered,
                        position: r.position[..self.n].to_vec(),
                        rest: r.rest[..self.n].to_vec(),
                        timers: Some(MachineTimers {
                            cutting: t.cutting,
                            cycle: t.cycle,
                            operating: t.operating,
                            power_on: t.power_on,
                        }),
                    };
                    self.stream
                        .machine_result(seq, m)
                        .unwrap_or_else(|e| panic!("alarm {}: {}", e.number, e.text));
                }
            }
            let done = self.motion.done_seq();
            let motion = &mut self.motion;
            self.stream
                .feed(done, 32, |seq, Canon { line, command, .. }, _| {
                    motion.push(Block {
                        run_id: 1,
                        seq,
                        line,
                        kind: command,
                    })
                })
                .unwrap_or_else(|e| panic!("alarm {} at line {}: {}", e.number, e.line, e.text));
        }
        let mut actual = [0.0; MAX_AXES];
        actual[..self.n].copy_from_slice(&self.fb.position[..self.n]);
        self.motion.plc_signals(&self.gi);
        self.motion
            .spindle_feedback(self.fb.spindle_rpm, self.fb.spindle_angle_deg);
        self.motion.handwheel_input(self.fb.handwheel_count);
        self.motion.probe_input(ProbeInput::from_feedback(&self.fb));
        let mut sp = ServoSetpoint {
            axis_count: self.n as u32,
            ..Default::default()
        };
        sp.position[..self.n].copy_from_slice(self.motion.tick(Some(&actual[..self.n]), &self.gi));
        self.motion.fill_setpoint(&mut sp);
        self.fb = self.sim.step(&sp, &self.yi, DT);
        self.t += DT;
        if self.t + 1e-9 >= self.next_scan {
            self.next_scan += SCAN;
            self.xi = self.sim.x_image(&self.yi);
            self.plc.scan(
                self.motion.f_image(),
                &self.xi,
                (self.t * 1000.0).round() as u64,
            );
            self.gi = *self.plc.to_nc();
            self.yi = *self.plc.outputs();
            let t = self.t;
            self.events
                .extend(self.plc.take_events().into_iter().map(|e| (t, e)));
        }
    }

    /// Ticks until `done` or `seconds` pass; true if `done`.
    pub fn run_until(&mut self, seconds: f64, mut done: impl FnMut(&Rig) -> bool) -> bool {
        let end = self.t + seconds;
        while self.t < end {
            self.tick();
            if done(self) {
                return true;
            }
        }
        false
    }

    pub fn program_done(&self) -> bool {
        self.stream.all_sent()
            && self.motion.done_seq() == self.stream.sent()
            && self.motion.state() == RunState::Idle
    }

    pub fn nc(&self) -> &FImage {
        self.motion.f_image()
    }

    pub fn turret_station(&self) -> Option<u8> {
        self.sim.devices.turret_station()
    }

    pub fn message(&self, address: &str) -> Option<f64> {
        self.events.iter().find_map(|(t, e)| match e {
            PlcEvent::MessageOn { address: a, .. } if a == address => Some(*t),
            _ => None,
        })
    }

    pub fn bit(&self, name: &str) -> bool {
        matches!(self.plc.read(name), Ok(Value::Bit(true)))
    }
}

/// Power-on: the PLC's first scans release the emergency stop and the machine settles.
pub fn powered(program: &str) -> Rig {
    let mut r = Rig::new(program, None);
    r.run_until(0.1, |_| false);
    assert!(r.gi.get(g::ESP_N), "E-stop released after power-on");
    r.started = true;
    r
}
