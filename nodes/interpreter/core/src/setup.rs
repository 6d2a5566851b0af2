//! What the interpreter needs to know about the machine and its stored data: axes, the
//! reference points, tool offsets, work offsets, kept macro variables and the switches that
//! change how a program runs. The shell fills it from the launch config and the data files.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

/// One row of the tool offset page: geometry plus wear, entered separately and added.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ToolOffset {
    /// X geometry offset, diameter on a diameter axis, mm.
    pub x: f64,
    /// Z geometry offset (a mill's tool length), mm.
    pub z: f64,
    /// X wear (added to `x`).
    pub wear_x: f64,
    pub wear_z: f64,
    /// Nose or cutter radius, mm.
    pub radius: f64,
    /// Imaginary tool tip direction 0–9 (0: the programmed point is the centre).
    pub tip: u8,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Offsets {
    /// Tool offsets by number.
    pub tools: BTreeMap<u32, ToolOffset>,
    /// Work offsets by index (0 = the first work system), per axis letter.
    pub work: BTreeMap<u8, BTreeMap<char, f64>>,
}

impl Offsets {
    pub fn tool(&self, n: u32) -> ToolOffset {
        self.tools.get(&n).copied().unwrap_or_default()
    }

    /// Work offset `index` (0 = the first work system) of axis `letter`.
    pub fn work(&self, index: u8, letter: char) -> f64 {
        self.work
            .get(&index)
            .and_then(|w| w.get(&letter))
            .copied()
            .unwrap_or(0.0)
    }
}

/// A live tool (D142): its axis letter, the axis number G14.n names, its top speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveTool {
    pub letter: char,
    pub number: u8,
    pub max_rpm: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// Machine axis letters in machine order, e.g. `['X', 'Z']`.
    pub axes: Vec<char>,
    /// Axes programmed in diameter (lathe X).
    pub diameter: Vec<bool>,
    /// The machine position when the program starts (X as diameter).
    pub start: Vec<f64>,
    /// Machine coordinates of the reference point.
    pub reference: Vec<f64>,
    /// Machine coordinates of the second reference point (where a mill changes tools).
    pub second_reference: Vec<f64>,
    /// Per axis, the machine's fixed points 1, 2, … (machine coordinates; none: empty).
    pub fixed_points: Vec<Vec<f64>>,
    pub offsets: Offsets,
    /// Kept macro variables, by number.
    pub kept: BTreeMap<i64, f64>,
    /// Input bits that are on, as `(byte, bit)` of the X table.
    pub inputs: BTreeSet<(u32, u8)>,
    /// Block skip switch: blocks starting with `/` are skipped.
    pub block_skip: bool,
    /// Stop where the program would start over (a return in a main program, an endless
    /// block-range repeat, an end-and-restart code): for checks and simulation, which must
    /// end.
    pub single_pass: bool,
    /// Active work system at start (0 = the first).
    pub work_system: u8,
    /// The turret is in front of the spindle axis: compensation sides swap (decision D30).
    pub front_tool_post: bool,
    /// A T word calls this program as the tool-change macro (a machine parameter).
    pub tool_change_macro: Option<u32>,
    /// Numbers without a decimal point are millimetres (`Some(true)`, calculator type) or
    /// least input increments (`Some(false)`); `None`: as the control's manual says.
    pub calculator_decimal_point: Option<bool>,
    /// A T word only preselects the tool and M6 changes it (a machine datum); else T
    /// changes the tool at once.
    pub tool_change_with_m6: bool,
    /// The main spindle is also the C axis (a turn-mill lathe, D138).
    pub spindle_c_axis: bool,
    /// The C axis's rapid rate (G00 C), r/min.
    pub c_rapid_rpm: f64,
    /// The live tool (D142): the program's last axis, in degrees, which only a live-tool tap
    /// turns.
    pub live_tool: Option<LiveTool>,
    /// The skip input (G31) as X-table byte and bit, and whether a skip keeps the actual
    /// coordinates (B19.6, D139).
    pub skip_input: Option<(u32, u32)>,
    pub skip_keeps_actual: bool,
    /// The tool in the spindle when the program starts, as the last program or the operator
    /// left it (0: none); a control that keeps it across power-off starts with it.
    pub active_tool: u32,
    /// How far a roughing contour may leave its start or turn back before it is refused,
    /// mm (a machine parameter; 0.05 unless set).
    pub contour_tolerance: f64,
}

impl Setup {
    /// A lathe with X (diameter) and Z at the given start position, no offsets.
    pub fn lathe(start: [f64; 2]) -> Setup {
        Setup::new(&['X', 'Z'], &[true, false], &start)
    }

    /// A turn-mill: the main spindle is also the C axis (D138), which the program sees as its
    /// last axis, in degrees (at 0 when the program starts), and polar interpolation moves
    /// as an axis of the path (D141).
    pub fn with_spindle_c_axis(mut self) -> Setup {
        self.spindle_c_axis = true;
        if !self.axes.contains(&'C') {
            self.axes.push('C');
            self.diameter.push(false);
            self.start.push(0.0);
            self.reference.push(0.0);
            self.second_reference.push(0.0);
            self.fixed_points.push(Vec::new());
        }
        self
    }

    /// A live tool as axis `letter` (G14.n's n is `number`, 1…6 for X…C), up to `max_rpm`:
    /// the program's last axis, at 0° when the program starts.
    pub fn with_live_tool(mut self, letter: char, number: u8, max_rpm: f64) -> Setup {
        if !self.axes.contains(&letter) {
            self.axes.push(letter);
            self.diameter.push(false);
            self.start.push(0.0);
            self.reference.push(0.0);
            self.second_reference.push(0.0);
            self.fixed_points.push(Vec::new());
        }
        self.live_tool = Some(LiveTool {
            letter,
            number,
            max_rpm,
        });
        self
    }

    /// Whether `letter` is the live tool's axis (no program word moves it).
    pub fn is_live_tool(&self, letter: char) -> bool {
        self.live_tool.is_some_and(|t| t.letter == letter)
    }

    pub fn new(axes: &[char], diameter: &[bool], start: &[f64]) -> Setup {
        let n = axes.len();
        let start: Vec<f64> = (0..n)
            .map(|i| start.get(i).copied().unwrap_or(0.0))
            .collect();
        Setup {
            axes: axes.to_vec(),
            diameter: (0..n)
                .map(|i| diameter.get(i).copied().unwrap_or(false))
                .collect(),
            reference: start.clone(),
            second_reference: start.clone(),
            fixed_points: vec![Vec::new(); start.len()],
            start,
            offsets: Offsets::default(),
            kept: BTreeMap::new(),
            inputs: BTreeSet::new(),
            block_skip: true,
            single_pass: true,
            work_system: 0,
            front_tool_post: false,
            tool_change_macro: None,
            calculator_decimal_point: None,
            contour_tolerance: 0.05,
            tool_change_with_m6: false,
            spindle_c_axis: false,
            c_rapid_rpm: 100.0,
            live_tool: None,
            skip_input: None,
            skip_keeps_actual: true,
            active_tool: 0,
        }
    }
}
