//! Hard overtravel (issue 28; decisions D70; Huaxing `000` §2.3.1, alarms 40 and 66): an axis
//! that reaches a limit switch stops at once, whatever moved it, with the alarm; after the
//! reset it may be jogged off the switch in the opposite direction only, and no program runs
//! while a switch is pressed.

use super::{alarm, Motion};

impl Motion {
    /// The drives' overtravel switches of the latest feedback, bits per axis. A switch newly
    /// pressed stops the machine with the alarm.
    pub fn overtravel_inputs(&mut self, plus: u32, minus: u32) {
        let (new_plus, new_minus) = (plus & !self.overtravel.0, minus & !self.overtravel.1);
        self.overtravel = (plus, minus);
        if new_plus | new_minus == 0 {
            return;
        }
        // Stop: the setpoint stays where it is (the slides, a drive lag behind it, come to
        // rest on it, past the switch); the run, a jog or a reference return is dropped.
        self.dead_run = self.run_id;
        self.drop_run();
        self.jog = None;
        self.reference = None;
        let (number, text) = self.overtravel_alarm(new_plus, new_minus);
        self.raise(number, text, self.line);
    }

    /// Whether `axis` stands on its switch in the `positive` (or negative) direction.
    pub fn on_overtravel_switch(&self, axis: usize, positive: bool) -> bool {
        let bits = if positive {
            self.overtravel.0
        } else {
            self.overtravel.1
        };
        bits & (1 << axis) != 0
    }

    /// Whether any axis stands on a switch.
    pub fn overtravel_pressed(&self) -> bool {
        self.overtravel.0 | self.overtravel.1 != 0
    }

    /// The alarm for the switches `plus` and `minus` (bits per axis): 40 for a + switch, 66
    /// (the manual's "limit alarm") for a − one.
    pub(super) fn overtravel_alarm(&self, plus: u32, minus: u32) -> (u32, String) {
        let names = |bits: u32| -> Vec<String> {
            self.cfg
                .axes
                .iter()
                .enumerate()
                .filter(|(i, _)| bits & (1 << i) != 0)
                .map(|(_, a)| a.name.clone())
                .collect()
        };
        if plus != 0 {
            let axes = names(plus).join(", ");
            (
                alarm::OVERTRAVEL_PLUS,
                format!(
                    "+ hardware limit: {axes} on its + overtravel switch; reset, then jog it in −"
                ),
            )
        } else {
            let axes = names(minus).join(", ");
            (
                alarm::OVERTRAVEL_MINUS,
                format!(
                    "− hardware limit: {axes} on its − overtravel switch; reset, then jog it in +"
                ),
            )
        }
    }
}
