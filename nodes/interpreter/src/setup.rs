//! What the interpreter needs to know about the machine and its stored data: axes, the
//! reference point, tool offsets, work offsets, kept macro variables and the switches that
//! change how a program runs. The shell fills it from the launch config and the data files.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

/// What the control keeps across power-off and between programs (`000` §5.27: #200–#289;
/// `003` inventory A.3: #500–#999 on the FANUC mill;
/// the offset page, which programs write through #4001–#4499). The node shell stores it in
/// the launch config's `machine.memory_file`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Memory {
    /// Kept macro variables by number.
    pub kept: BTreeMap<i64, f64>,
    /// Tool offsets by offset number.
    pub tools: BTreeMap<u32, ToolOffset>,
    /// Work offsets G54–G59 (0–5) per axis letter.
    pub work: BTreeMap<u8, BTreeMap<char, f64>>,
}

impl Memory {
    /// The macro variables kept across power-off: Huaxing's #200–#289, FANUC's #500–#999
    /// (each control reads only its own).
    pub fn is_kept(n: i64) -> bool {
        (200..=289).contains(&n) || (500..=999).contains(&n)
    }

    /// Only what a program may store there, with finite values.
    pub fn sanitized(mut self) -> Memory {
        self.kept
            .retain(|&n, v| Memory::is_kept(n) && v.is_finite());
        self.tools.retain(|n, t| {
            (1..=cnc_runtime::tool_table::MAX_TOOL_NUMBER).contains(n)
                && [t.x, t.z, t.wear_x, t.wear_z, t.radius]
                    .iter()
                    .all(|v| v.is_finite())
                && t.tip <= 9
        });
        self.work.retain(|n, _| *n <= 5);
        for row in self.work.values_mut() {
            row.retain(|c, v| "XYZABC".contains(*c) && v.is_finite());
        }
        self
    }
}

/// One row of the tool offset table (`000` §5.2: X, Z, R, PH; `002` §4.4: tool setting plus
/// wear, entered separately and added).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ToolOffset {
    /// X geometry offset, diameter, mm.
    pub x: f64,
    pub z: f64,
    /// X wear, diameter, mm (added to `x`).
    pub wear_x: f64,
    pub wear_z: f64,
    /// Nose radius, mm.
    pub radius: f64,
    /// Imaginary tool tip direction 0–9.
    pub tip: u8,
}

/// Largest offset number (`000` #4001–#4099: 99 offsets).
pub const MAX_OFFSET: u32 = 99;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Offsets {
    /// Tool offsets by number 1–99.
    pub tools: BTreeMap<u32, ToolOffset>,
    /// Work offsets G54–G59 (Huaxing) or offset groups 1–4 (GTC2E G54–G57), per axis letter.
    pub work: BTreeMap<u8, BTreeMap<char, f64>>,
}

impl Offsets {
    pub fn tool(&self, n: u32) -> ToolOffset {
        self.tools.get(&n).copied().unwrap_or_default()
    }

    /// Work offset `index` (0 = G54) of axis `letter`.
    pub fn work(&self, index: u8, letter: char) -> f64 {
        self.work
            .get(&index)
            .and_then(|w| w.get(&letter))
            .copied()
            .unwrap_or(0.0)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// Machine axis letters in machine order, e.g. `['X', 'Z']`.
    pub axes: Vec<char>,
    /// Axes programmed in diameter (lathe X).
    pub diameter: Vec<bool>,
    /// The machine position when the program starts (X as diameter).
    pub start: Vec<f64>,
    /// Machine coordinates of the reference point (G28).
    pub reference: Vec<f64>,
    /// Machine coordinates of the second reference point (G30, where the mill changes
    /// tools).
    pub second_reference: Vec<f64>,
    pub offsets: Offsets,
    /// Kept macro variables (#200–#289 on Huaxing), by number.
    pub kept: BTreeMap<i64, f64>,
    /// Input bits that are on, as `(byte, bit)` of the X table (G21/G23).
    pub inputs: BTreeSet<(u32, u8)>,
    /// Block skip switch: blocks starting with `/` are skipped.
    pub block_skip: bool,
    /// Stop where the program would start over (M99 in a main program, G27 without L,
    /// GTC2E M20): for checks and simulation, which must end.
    pub single_pass: bool,
    /// Active work system at start (0 = G54).
    pub work_system: u8,
    /// The turret is in front of the spindle axis: G41/G42 swap sides (decision D30).
    pub front_tool_post: bool,
    /// Huaxing S#170: a T word calls this program as the tool-change macro (`000` §4.3.1).
    pub tool_change_macro: Option<u32>,
}

impl Setup {
    /// A lathe with X (diameter) and Z at the given start position, no offsets.
    pub fn lathe(start: [f64; 2]) -> Setup {
        Setup::new(&['X', 'Z'], &[true, false], &start)
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
            start,
            offsets: Offsets::default(),
            kept: BTreeMap::new(),
            inputs: BTreeSet::new(),
            block_skip: true,
            single_pass: true,
            work_system: 0,
            front_tool_post: false,
            tool_change_macro: None,
        }
    }
}
