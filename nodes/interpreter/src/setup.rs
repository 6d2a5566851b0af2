//! The machine description the interpreter runs on (the core's [`Setup`]), and what the
//! control keeps between programs ([`Memory`]).

use std::collections::BTreeMap;

use cnc_machine::MachineConfig;
use serde::{Deserialize, Serialize};

pub use cnc_interpreter_core::setup::{Offsets, Setup, ToolOffset};

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
    /// The tool in the spindle, 0 none: a machine that changes tools with M6 starts every
    /// program with the tool it holds (`001` §9.6.2: "the tool stays active after the program's
    /// end and after power-off"; issue 46).
    pub spindle_tool: u32,
}

impl Memory {
    /// The macro variables kept across power-off: Huaxing's #200–#289, FANUC's #500–#999,
    /// the 802D's R0–R299, part counters and tool monitoring data (each control reads only
    /// its own).
    pub fn is_kept(n: i64) -> bool {
        (200..=289).contains(&n)
            || (500..=999).contains(&n)
            || (10_000..=10_299).contains(&n)
            || (11_000..=11_008).contains(&n)
            || crate::sinumerik::monitor::KEYS.contains(&n)
    }

    /// Only what a program may store there, with finite values.
    pub fn sanitized(mut self) -> Memory {
        self.kept
            .retain(|&n, v| Memory::is_kept(n) && v.is_finite());
        self.tools.retain(|n, t| {
            // Entries the offset page or a program of any dialect could have stored.
            (1..=cnc_machine::tools::MAX_EDGE_ENTRY).contains(n)
                && [t.x, t.z, t.wear_x, t.wear_z, t.radius]
                    .iter()
                    .all(|v| v.is_finite())
                && t.tip <= 9
        });
        self.work.retain(|n, _| *n <= 5);
        if self.spindle_tool > 32_000 {
            self.spindle_tool = 0;
        }
        for row in self.work.values_mut() {
            row.retain(|c, v| "XYZABC".contains(*c) && v.is_finite());
        }
        self
    }
}

/// The interpreter's view of the machine from the launch config's machine section: axes,
/// reference point, tool post, the offset page and the work offsets; the program starts at
/// `start`.
pub fn of_machine(machine: &MachineConfig, start: &[f64]) -> Setup {
    let letters = machine.axis_letters();
    let mut setup = Setup::new(&letters, &machine.diameter_axes(), start);
    setup.reference = machine.home();
    setup.second_reference = machine.second_reference();
    setup.fixed_points = machine.fixed_points();
    setup.front_tool_post = machine.tool_post == cnc_machine::ToolPost::Front;
    setup.tool_change_macro = machine.tool_change_macro;
    setup.tool_change_with_m6 = machine.tool_change_with_m6;
    if machine.spindle_c_axis {
        setup = setup.with_spindle_c_axis();
        setup.c_rapid_rpm = machine.c_axis.max_velocity / 360.0;
    }
    if let Some(t) = &machine.live_tool {
        if let Some(n) = t.number() {
            setup = setup.with_live_tool(t.letter(), n, t.max_rpm);
        }
    }
    setup.skip_input = machine.skip_input.as_deref().and_then(x_input);
    setup.skip_keeps_actual = machine.skip_keeps_actual;
    setup.active_tool = machine.tool_in_spindle;
    setup.contour_tolerance = machine.contour_tolerance;
    setup.calculator_decimal_point = machine
        .decimal_point
        .map(|d| d == cnc_machine::DecimalPoint::Calculator);
    for (&n, t) in &machine.tools {
        setup.offsets.tools.insert(
            n,
            ToolOffset {
                x: t.x,
                z: t.z,
                wear_x: t.wear_x,
                wear_z: t.wear_z,
                radius: t.radius,
                tip: t.tip,
            },
        );
    }
    for (code, axes) in &machine.work_offsets {
        if let Some(i) = cnc_machine::work_offset_index(code) {
            let row = setup.offsets.work.entry(i).or_default();
            for (axis, &v) in axes {
                if let Some(c) = axis.chars().next() {
                    row.insert(c, v);
                }
            }
        }
    }
    setup
}

/// An X-table input written `X11.5` (byte 11, bit 5; bits 0–7).
pub fn x_input(text: &str) -> Option<(u32, u32)> {
    let (byte, bit) = text.trim().strip_prefix(['X', 'x'])?.split_once('.')?;
    let (byte, bit) = (byte.parse().ok()?, bit.parse().ok()?);
    (bit < 8).then_some((byte, bit))
}
