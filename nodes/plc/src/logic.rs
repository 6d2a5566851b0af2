//! The machine logic in plain Rust, scanned like a PLC program: read inputs, decide, write
//! outputs. The ladder engine of issue 5 replaces this module with `programs/lathe_standard.plc`.
//!
//! M/S/T handshake (`000` §4.2.1, inventory §9.2): motion raises a strobe with a new
//! `strobe_seq`; the logic starts the actuator, and answers FIN (`fin_seq = strobe_seq`) only once
//! the machine reports it done (spindle at speed, coolant pressure, spindle stopped).

use cnc_msgs::signals::{FImage, GImage, XImage, YImage};

/// Alarm numbers raised by the PLC (`000` Appendix 1, inventory §11.5).
pub mod alarm {
    pub const EMERGENCY_STOP: u32 = 65;
}

#[derive(Debug, Clone, PartialEq)]
pub enum PlcEvent {
    AlarmRaised { number: u32, text: String },
    AlarmCleared { number: u32 },
    PartCounted { count: u32, cycle_time: f64 },
}

/// What a pending strobe waits for before FIN.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Waiting {
    SpindleAtSpeed,
    SpindleStopped,
    CoolantPressure,
    Nothing,
}

#[derive(Debug, Clone)]
pub struct Plc {
    y: YImage,
    g: GImage,
    /// S value latched for the next M03/M04.
    speed: f64,
    pending: Option<(u64, Waiting)>,
    last_strobe: u64,
    part_count: u32,
    cycle_started_at: Option<f64>,
    emergency_stop: bool,
    events: Vec<PlcEvent>,
}

impl Default for Plc {
    fn default() -> Self {
        Self::new(0)
    }
}

impl Plc {
    pub fn new(part_count: u32) -> Self {
        Plc {
            y: YImage::default(),
            g: GImage::default(),
            speed: 0.0,
            pending: None,
            last_strobe: 0,
            part_count,
            cycle_started_at: None,
            emergency_stop: false,
            events: Vec::new(),
        }
    }

    pub fn part_count(&self) -> u32 {
        self.part_count
    }
    pub fn outputs(&self) -> &YImage {
        &self.y
    }
    pub fn to_nc(&self) -> &GImage {
        &self.g
    }
    /// Speed the spindle is commanded to turn, rpm (0 when stopped).
    pub fn commanded_rpm(&self) -> f64 {
        if self.y.spindle_direction == 0 {
            0.0
        } else {
            self.y.spindle_rpm
        }
    }
    pub fn take_events(&mut self) -> Vec<PlcEvent> {
        std::mem::take(&mut self.events)
    }

    /// One scan at time `now` (s, any epoch).
    pub fn scan(&mut self, f: &FImage, x: &XImage, now: f64) {
        self.g.spindle_actual_rpm = x.spindle_actual_rpm;
        // Emergency stop: every output off in this scan, the NC told to stop.
        if x.emergency_stop != 0 {
            if !self.emergency_stop {
                self.emergency_stop = true;
                self.events.push(PlcEvent::AlarmRaised {
                    number: alarm::EMERGENCY_STOP,
                    text: "emergency stop".into(),
                });
            }
            self.y = YImage::default();
            self.g.emergency_stop = 1;
            self.pending = None;
            self.cycle_started_at = None;
            return;
        }
        if self.emergency_stop {
            // Released: the alarm goes, the machine stays stopped until reset and cycle start.
            self.emergency_stop = false;
            self.g.emergency_stop = 0;
            self.events.push(PlcEvent::AlarmCleared {
                number: alarm::EMERGENCY_STOP,
            });
        }
        if f.op != 0 && self.cycle_started_at.is_none() {
            self.cycle_started_at = Some(now);
        }
        let strobe = f.mf != 0 || f.sf != 0 || f.tf != 0;
        if strobe && f.strobe_seq != self.last_strobe {
            self.last_strobe = f.strobe_seq;
            let waiting = self.start(f, now);
            self.pending = Some((f.strobe_seq, waiting));
        }
        if let Some((seq, waiting)) = self.pending {
            let done = match waiting {
                Waiting::SpindleAtSpeed => x.spindle_at_speed != 0,
                Waiting::SpindleStopped => x.spindle_actual_rpm.abs() < 1.0,
                Waiting::CoolantPressure => x.coolant_pressure != 0,
                Waiting::Nothing => true,
            };
            if done {
                self.g.fin_seq = seq;
                self.pending = None;
            }
        }
        if f.op == 0 && self.pending.is_none() {
            self.cycle_started_at = None;
        }
    }

    /// Starts the actuator for a new strobe; returns what FIN waits for.
    fn start(&mut self, f: &FImage, now: f64) -> Waiting {
        if f.sf != 0 {
            self.speed = f.s_value;
            if self.y.spindle_direction != 0 {
                self.y.spindle_rpm = self.speed;
                return if self.speed > 0.0 {
                    Waiting::SpindleAtSpeed
                } else {
                    Waiting::SpindleStopped
                };
            }
            return Waiting::Nothing;
        }
        if f.tf != 0 {
            // No turret on the skeleton's simulated lathe: the tool is "there" at once.
            return Waiting::Nothing;
        }
        match f.m_code {
            3 | 4 => {
                self.y.spindle_direction = if f.m_code == 3 { 1 } else { 2 };
                self.y.spindle_rpm = self.speed;
                if self.speed > 0.0 {
                    Waiting::SpindleAtSpeed
                } else {
                    Waiting::Nothing
                }
            }
            5 => {
                self.y.spindle_direction = 0;
                Waiting::SpindleStopped
            }
            8 => {
                self.y.coolant = 1;
                Waiting::CoolantPressure
            }
            9 => {
                self.y.coolant = 0;
                Waiting::Nothing
            }
            10 => {
                self.y.chuck_clamp = 1;
                Waiting::Nothing
            }
            11 => {
                self.y.chuck_clamp = 0;
                Waiting::Nothing
            }
            2 | 30 => {
                // Program end: spindle and coolant off (`000` §3.3.3 example, N0110), part counted.
                self.y.spindle_direction = 0;
                self.y.coolant = 0;
                if f.m_code == 30 {
                    self.part_count += 1;
                    let cycle_time = self.cycle_started_at.map(|t| now - t).unwrap_or(0.0);
                    self.events.push(PlcEvent::PartCounted {
                        count: self.part_count,
                        cycle_time,
                    });
                }
                Waiting::Nothing
            }
            _ => Waiting::Nothing,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strobe_m(seq: u64, m: i32) -> FImage {
        FImage {
            strobe_seq: seq,
            mf: 1,
            m_code: m,
            op: 1,
            ..Default::default()
        }
    }

    #[test]
    fn m03_fins_only_at_speed() {
        let mut plc = Plc::new(0);
        let mut x = XImage::default();
        plc.scan(
            &FImage {
                strobe_seq: 1,
                sf: 1,
                s_value: 1200.0,
                op: 1,
                ..Default::default()
            },
            &x,
            0.0,
        );
        assert_eq!(
            plc.to_nc().fin_seq,
            1,
            "S with the spindle stopped only latches the speed"
        );
        plc.scan(&strobe_m(2, 3), &x, 0.01);
        assert_eq!(plc.outputs().spindle_direction, 1);
        assert_eq!(plc.outputs().spindle_rpm, 1200.0);
        assert_eq!(plc.to_nc().fin_seq, 1, "no FIN before at speed");
        x.spindle_at_speed = 1;
        plc.scan(&strobe_m(2, 3), &x, 0.02);
        assert_eq!(plc.to_nc().fin_seq, 2);
    }

    #[test]
    fn m30_counts_the_part_with_cycle_time() {
        let mut plc = Plc::new(4);
        let x = XImage::default();
        plc.scan(
            &FImage {
                op: 1,
                ..Default::default()
            },
            &x,
            10.0,
        );
        plc.scan(&strobe_m(1, 30), &x, 12.5);
        assert_eq!(plc.part_count(), 5);
        assert_eq!(
            plc.take_events(),
            vec![PlcEvent::PartCounted {
                count: 5,
                cycle_time: 2.5
            }]
        );
        assert_eq!(plc.to_nc().fin_seq, 1);
    }

    #[test]
    fn emergency_stop_turns_every_output_off_in_one_scan() {
        let mut plc = Plc::new(0);
        let mut x = XImage {
            spindle_at_speed: 1,
            coolant_pressure: 1,
            ..Default::default()
        };
        plc.scan(
            &FImage {
                strobe_seq: 1,
                sf: 1,
                s_value: 500.0,
                ..Default::default()
            },
            &x,
            0.0,
        );
        plc.scan(&strobe_m(2, 3), &x, 0.0);
        plc.scan(&strobe_m(3, 8), &x, 0.0);
        assert_ne!(plc.outputs(), &YImage::default());
        x.emergency_stop = 1;
        plc.scan(&FImage::default(), &x, 0.1);
        assert_eq!(plc.outputs(), &YImage::default());
        assert_eq!(plc.to_nc().emergency_stop, 1);
        assert!(matches!(
            plc.take_events()[..],
            [PlcEvent::AlarmRaised {
                number: alarm::EMERGENCY_STOP,
                ..
            }]
        ));
    }
}
