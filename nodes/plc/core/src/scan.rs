//! The PLC: one program over one memory, scanned in two levels (`000` §18.1).
//!
//! Each scan copies the X and F images in, runs level 1 whole and the next slice of level 2,
//! and copies Y and G out. Level 2 is cut into `level2_divisions` slices at rung boundaries,
//! so a long level 2 spreads over several scans while level 1 (the fast signals: emergency
//! stop, FIN, feed hold) runs every scan. Pure: time comes in as `now_ms`.

use cnc_msgs::signals::{self, FImage, GImage, SignalTable, XImage, YImage};

use crate::address::{self, Address, BitAddr, ByteAddr, Space, Unit};
use crate::engine::{Engine, Fault};
use crate::memory::{Memory, Retained};
use crate::program::{LoadError, Program};

/// Alarm numbers of PLC messages: A0.0 is 1000, A0.1 1001, … A9.7 1079.
pub const MESSAGE_ALARM_BASE: u32 = 1000;
/// Bytes of the A table (A0–A9), kept without allocating every scan.
const MESSAGE_BYTES: usize = 10;
/// The PLC stopped itself (watchdog): emergency stop until a program is loaded.
pub const PLC_FAULT_ALARM: u32 = 1090;

#[derive(Debug, Clone, PartialEq)]
pub enum PlcEvent {
    /// An A bit came on: its alarm number, address, text, and whether it is an alarm.
    MessageOn {
        number: u32,
        address: String,
        text: String,
        alarm: bool,
    },
    MessageOff {
        number: u32,
    },
    Fault {
        text: String,
    },
    /// The NC's emergency stop (`*ESP`) went active (true) or was released.
    EmergencyStop(bool),
}

/// The emergency-stop alarm (`000` Appendix 1, inventory §11.5).
pub const EMERGENCY_STOP_ALARM: u32 = 65;

/// One address's value for a monitor: a bit, a byte, or a timer/counter.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bit(bool),
    Byte(u8),
    Timer { preset_ms: u32, elapsed_ms: u64 },
    Counter { preset: i64, current: i64 },
}

#[derive(Debug, Clone)]
pub struct Plc {
    program: Program,
    mem: Memory,
    level2_divisions: usize,
    level2_pc: usize,
    /// The emergency-stop input (normally closed): while it reads 0 every output is off and
    /// the NC sees `*ESP`, whatever the program does.
    estop_input: Option<BitAddr>,
    spindle_command: f64,
    /// The spindle drive's rating (`limits.spindle_max_rpm`): no program, override or ladder
    /// arithmetic commands more.
    spindle_max_rpm: f64,
    y: YImage,
    g: GImage,
    /// A table at the end of the last scan, for message events.
    messages: [u8; MESSAGE_BYTES],
    fault: Option<String>,
    events: Vec<PlcEvent>,
    scans: u64,
    last_now: u64,
    /// `*ESP` low at the end of the last scan.
    emergency_stop: bool,
}

impl Plc {
    /// A PLC running `program`, with `retained` memory from an earlier run if there is one.
    pub fn new(program: Program, retained: Option<&Retained>, level2_divisions: usize) -> Plc {
        let mut mem = Memory::default();
        apply_defaults(&program, &mut mem);
        if let Some(r) = retained {
            mem.restore(r);
        }
        mem.step_act = vec![false; program.steps.len()];
        let estop = BitAddr {
            byte: ByteAddr {
                space: Space::X,
                index: signals::x::ESP_N.byte,
            },
            bit: signals::x::ESP_N.bit,
        };
        Plc {
            level2_pc: program.level2().start,
            program,
            mem,
            level2_divisions: level2_divisions.max(1),
            estop_input: Some(estop),
            spindle_command: 0.0,
            spindle_max_rpm: f64::INFINITY,
            y: YImage::default(),
            g: GImage::default(),
            messages: [0; MESSAGE_BYTES],
            fault: None,
            events: Vec::new(),
            scans: 0,
            last_now: 0,
            emergency_stop: false,
        }
    }

    /// Sets the spindle drive's top speed, rpm; every command is clamped to it.
    pub fn set_spindle_limit(&mut self, rpm: f64) {
        self.spindle_max_rpm = rpm;
    }

    /// Parses `text` and, if it is a valid program, runs it from the next scan on; otherwise
    /// the running program stays and the error says where and why.
    pub fn load(&mut self, text: &str) -> Result<(), LoadError> {
        let program = Program::parse(text)?;
        // The machine's parameters (presets, K, D) stay, as a PMC keeps them apart from the
        // ladder: the new program's PRESET and INIT only fill a machine with no PLC memory.
        self.mem.step_act = vec![false; program.steps.len()];
        self.level2_pc = program.level2().start;
        self.program = program;
        if self.fault.take().is_some() {
            self.events.push(PlcEvent::MessageOff {
                number: PLC_FAULT_ALARM,
            });
        }
        Ok(())
    }

    /// Changes which input is the emergency stop (None: the program alone decides).
    pub fn set_emergency_stop_input(&mut self, input: Option<BitAddr>) {
        self.estop_input = input;
    }

    pub fn program(&self) -> &Program {
        &self.program
    }
    /// One signal table as the ladder sees it (the ladder monitor's snapshot).
    pub fn table(&self, space: Space) -> &[u8] {
        self.mem.table(space)
    }
    pub fn outputs(&self) -> &YImage {
        &self.y
    }
    pub fn to_nc(&self) -> &GImage {
        &self.g
    }
    pub fn scans(&self) -> u64 {
        self.scans
    }
    pub fn take_events(&mut self) -> Vec<PlcEvent> {
        std::mem::take(&mut self.events)
    }
    pub fn retained(&self) -> Retained {
        self.mem.retained()
    }
    /// Whether `r` is what the PLC retains now ([`crate::memory::Memory::retains`]).
    pub fn retains(&self, r: &Retained) -> bool {
        self.mem.retains(r)
    }
    pub fn fault(&self) -> Option<&str> {
        self.fault.as_deref()
    }

    /// The value at an address or symbol: `Y2.5`, `D100`, `T1`, `C0`, `PART_COUNT`.
    pub fn read(&self, name: &str) -> Result<Value, String> {
        match Unit::parse(name) {
            Ok(Unit::Timer(n)) => {
                let t = &self.mem.timers[n as usize];
                return Ok(Value::Timer {
                    preset_ms: t.preset_ms,
                    elapsed_ms: t.elapsed(self.last_now),
                });
            }
            Ok(Unit::Counter(n)) => {
                let c = &self.mem.counters[n as usize];
                return Ok(Value::Counter {
                    preset: c.preset,
                    current: c.current,
                });
            }
            Err(_) => {}
        }
        Ok(match self.address(name)? {
            Address::Bit(b) => Value::Bit(self.mem.bit(b)),
            Address::Byte(b) => Value::Byte(self.mem.byte(b)),
        })
    }

    /// An address as written or by its symbol.
    fn address(&self, name: &str) -> Result<Address, String> {
        let upper = name.trim().to_ascii_uppercase();
        match self.program.symbols.get(&upper) {
            Some(a) => Ok(*a),
            None => address::parse(&upper),
        }
    }

    /// A binary value of `format` bytes at an address or symbol (e.g. the part count).
    pub fn read_value(&self, name: &str, format: u8) -> Result<i64, String> {
        match self.address(name)? {
            Address::Byte(b) => {
                b.span(format.into())?;
                Ok(self.mem.read(b, format))
            }
            Address::Bit(_) => Err(format!("{name} is a bit")),
        }
    }

    /// The parameter page: sets a timer's preset (ms) or a counter's.
    pub fn set_preset(&mut self, unit: &str, value: i64) -> Result<(), String> {
        let u = Unit::parse(unit)?;
        if !u.preset_ok(value) {
            return Err(format!("{unit} = {value}: out of range"));
        }
        match u {
            Unit::Timer(n) => self.mem.timers[n as usize].preset_ms = value as u32,
            Unit::Counter(n) => self.mem.counters[n as usize].preset = value,
        }
        Ok(())
    }

    /// One scan at `now_ms` (ms on any monotonic clock).
    pub fn scan(&mut self, f: &FImage, x: &XImage, now_ms: u64) {
        self.last_now = now_ms;
        self.scans += 1;
        self.mem.table_mut(Space::F).copy_from_slice(&f.bytes);
        self.mem.table_mut(Space::X).copy_from_slice(&x.bytes);
        self.system_relays(now_ms);
        if self.fault.is_none() {
            let l1 = self.program.level1();
            let l2 = self.program.level2();
            let budget = l2.len().div_ceil(self.level2_divisions).max(1);
            let mut engine = Engine::new(
                &self.program,
                &mut self.mem,
                now_ms,
                &mut self.spindle_command,
            );
            let result = engine.run(l1.start, l1.end, usize::MAX).and_then(|_| {
                let pc = engine.run(self.level2_pc, l2.end, budget)?;
                Ok(if pc >= l2.end { l2.start } else { pc })
            });
            match result {
                Ok(pc) => self.level2_pc = pc,
                Err(Fault::Watchdog) => {
                    let text = format!(
                        "PLC watchdog: more than {} steps in one scan (a JMPB loop?); \
                         emergency stop until a program is loaded",
                        crate::engine::WATCHDOG_STEPS
                    );
                    self.events.push(PlcEvent::Fault { text: text.clone() });
                    self.fault = Some(text);
                }
            }
        }
        self.y.bytes.copy_from_slice(self.mem.table(Space::Y));
        self.y.spindle_rpm = if self.spindle_command.is_finite() {
            self.spindle_command.clamp(0.0, self.spindle_max_rpm)
        } else {
            0.0
        };
        self.g.bytes.copy_from_slice(self.mem.table(Space::G));
        let estop = self.estop_input.is_some_and(|b| !self.mem.bit(b));
        if estop || self.fault.is_some() {
            self.y.bytes = [0; signals::Y_BYTES];
            self.y.spindle_rpm = 0.0;
            self.g.set(signals::g::ESP_N, false);
        }
        let esp = !self.g.get(signals::g::ESP_N);
        if esp != self.emergency_stop {
            self.emergency_stop = esp;
            self.events.push(PlcEvent::EmergencyStop(esp));
        }
        self.y.seq = self.scans;
        self.g.seq = self.scans;
        self.message_events();
    }

    /// R9091: .0 always off, .1 always on, .5 a 200 ms clock, .6 a 1 s clock.
    fn system_relays(&mut self, now_ms: u64) {
        let r9091 = ByteAddr {
            space: Space::R,
            index: 1091,
        };
        let v =
            0b10 | u8::from((now_ms / 100) % 2 == 1) << 5 | u8::from((now_ms / 500) % 2 == 1) << 6;
        self.mem.set_byte(r9091, v);
    }

    fn message_events(&mut self) {
        let mut now = [0; MESSAGE_BYTES];
        now.copy_from_slice(self.mem.table(Space::A));
        for (byte, (old, new)) in self.messages.iter().zip(&now).enumerate() {
            if old == new {
                continue;
            }
            for bit in 0..8u8 {
                let (was, is) = (old >> bit & 1 == 1, new >> bit & 1 == 1);
                let number = MESSAGE_ALARM_BASE + 8 * byte as u32 + u32::from(bit);
                if is && !was {
                    let m = self.program.messages.get(&(byte as u16, bit));
                    self.events.push(PlcEvent::MessageOn {
                        number,
                        address: format!("A{byte}.{bit}"),
                        text: m.map_or_else(|| "PLC message".to_string(), |m| m.text.clone()),
                        alarm: m.is_none_or(|m| m.alarm),
                    });
                } else if was && !is {
                    self.events.push(PlcEvent::MessageOff { number });
                }
            }
        }
        self.messages = now;
    }
}

/// The program's PRESET and INIT values.
fn apply_defaults(program: &Program, mem: &mut Memory) {
    for (n, v) in &program.timer_presets {
        mem.timers[*n as usize].preset_ms = *v;
    }
    for (n, v) in &program.counter_presets {
        mem.counters[*n as usize].preset = *v;
    }
    for (a, format, v) in &program.init {
        mem.write(*a, *format, *v);
    }
}
