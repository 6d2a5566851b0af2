//! What the family's G and M codes mean. The meanings every dialect of the family shares are
//! variants here; a dialect's own meanings are its own enum, carried in `Own`. Each dialect's
//! table (its `g_code`, `m_code`) maps code numbers onto them.

use std::fmt::Debug;

/// What a G code does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum G<O> {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    Dwell,
    ExactStopBlock,
    ExactStopMode,
    ContinuousMode,
    ReferenceReturn,
    /// G50 (lathe) / G92 (mill): the current point gets the given work coordinates; with S
    /// on a lathe, the maximum spindle speed.
    SetCoordinate,
    /// G54–G59 (index 0–5).
    WorkSystem(u8),
    FeedPerMinute,
    FeedPerRevolution,
    ConstantSurfaceSpeed,
    ConstantRpm,
    PlaneXy,
    PlaneZx,
    PlaneYz,
    /// G21: millimetre input.
    MetricInput,
    /// G20: inch input, converted to millimetres as the block is read (decision D53).
    InchInput,
    NoseCancel,
    NoseLeft,
    NoseRight,
    Absolute,
    Incremental,
    /// Defined by the manual but not implemented by this controller: alarm with the reason.
    Unsupported(&'static str),
    /// The dialect's own meaning.
    Own(O),
}

impl<O: Debug> G<O> {
    /// The meaning's name in alarm texts (a dialect's own meaning by its own name).
    pub fn name(&self) -> String {
        match self {
            G::Own(o) => format!("{o:?}"),
            other => format!("{other:?}"),
        }
    }
}

/// A G code's modal group (0: one-shot) and meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GCode<O> {
    pub group: u8,
    pub meaning: G<O>,
}

/// What the interpreter does with an M code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum M<O> {
    /// Sent to the PLC before the block's motion (spindle on, coolant on, clamp).
    AuxBefore,
    /// Sent to the PLC after the block's motion (spindle off, coolant off, part count).
    AuxAfter,
    /// Program stop M00 (sent to the PLC after motion; cycle start resumes).
    Stop,
    /// Optional stop M01.
    OptionalStop,
    /// M02/M30: sent to the PLC after motion, then the program ends.
    ProgramEnd,
    SubprogramCall,
    SubprogramReturn,
    /// Defined by the manual but not implemented by this controller.
    Unsupported(&'static str),
    /// The dialect's own meaning.
    Own(O),
}

/// What a word's number is, for the units it is read in (decisions D52, D53).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WordUnit {
    /// A length: in least input increments without a decimal point (where the machine
    /// reads numbers so), in inches under G20.
    Length,
    /// An angle (a rotary axis): in increments without a decimal point, never in inches.
    Angle,
    /// A time in seconds (G04 X): in increments (ms) without a decimal point.
    Time,
    /// A feed: in inches per minute or revolution under G20.
    Feed,
    /// A number (code, count, offset number, speed): as written.
    Plain,
}

/// A dialect without meanings of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nothing {}

/// What the family's reading and checking needs to know of a dialect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rules<O> {
    /// Macro statements (`#`, IF, GOTO, WHILE) exist.
    pub macros: bool,
    /// Least input increment, mm (for words that count increments without a decimal point).
    pub increment: f64,
    /// Largest coordinate value, mm.
    pub max_coordinate: f64,
    /// Power-on group-01 code (decision D14).
    pub initial_motion: G<O>,
}
