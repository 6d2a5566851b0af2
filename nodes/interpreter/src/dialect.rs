//! Dialect tables: which G and M codes a control knows, their modal groups and meanings.
//!
//! The shared interpreter core works on [`GMeaning`]s; a dialect only maps its numbers onto them.
//! For now there is one table, `iso-lathe` (FANUC-style lathe, G-code system B: G90/G91 select
//! absolute/incremental). The Huaxing and GTC2E tables, where G90 is a turning cycle, come with
//! their own names (decision D1 in docs/decisions.md).

/// What a G code does in the shared core.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GMeaning {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    Dwell,
    Absolute,
    Incremental,
}

/// Modal group of a G code; group 0 is one-shot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GCode {
    pub group: u8,
    pub meaning: GMeaning,
}

/// What the interpreter does with an M code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MMeaning {
    /// Sent to the PLC before the block's motion (spindle on, coolant on, clamp).
    AuxBefore,
    /// Sent to the PLC after the block's motion (spindle off, coolant off).
    AuxAfter,
    /// Program end (M02, M30): sent to the PLC after motion, then the program ends.
    ProgramEnd,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    IsoLathe,
}

impl Dialect {
    pub fn from_name(name: &str) -> Option<Dialect> {
        match name {
            "iso-lathe" => Some(Dialect::IsoLathe),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Dialect::IsoLathe => "iso-lathe",
        }
    }

    /// Looks up `G<number>`; `number` is ×10 so G50.1 is 501.
    pub fn g_code(self, number_x10: u32) -> Option<GCode> {
        use GMeaning::*;
        let (group, meaning) = match number_x10 {
            0 => (1, Rapid),
            10 => (1, Linear),
            20 => (1, ArcCw),
            30 => (1, ArcCcw),
            40 => (0, Dwell),
            900 => (3, Absolute),
            910 => (3, Incremental),
            _ => return None,
        };
        Some(GCode { group, meaning })
    }

    pub fn m_code(self, number: u32) -> Option<MMeaning> {
        match number {
            2 | 30 => Some(MMeaning::ProgramEnd),
            3 | 4 | 8 | 10 => Some(MMeaning::AuxBefore),
            5 | 9 | 11 => Some(MMeaning::AuxAfter),
            _ => None,
        }
    }

    /// Axis words: absolute letter, incremental letter, and whether the axis is programmed in
    /// diameter (lathe X).
    pub fn axis_words(self) -> &'static [(char, char)] {
        &[('X', 'U'), ('Z', 'W')]
    }
}
