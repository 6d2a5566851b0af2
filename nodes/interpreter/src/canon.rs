//! Canonical commands: what the interpreter hands to motion, dialect-free, in machine
//! coordinates (mm; lathe X as diameter, as the position display shows it).

/// One canonical command with the source line it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Canon {
    pub line: u32,
    pub command: Command,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Each axis at its own rapid rate (dog-leg path).
    Rapid {
        end: Vec<f64>,
    },
    /// Straight line at `feed` mm/min along the path.
    Linear {
        end: Vec<f64>,
        feed: f64,
    },
    /// Circular arc in the plane of axes `plane`, around `center`; `end == start` is a full circle.
    Arc {
        end: Vec<f64>,
        center: Vec<f64>,
        clockwise: bool,
        feed: f64,
    },
    Dwell {
        seconds: f64,
    },
    /// An M, S or T function for the PLC, which answers with FIN.
    Aux(Aux),
    /// M02/M30: the program is finished; motion completes everything before it.
    ProgramEnd,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Aux {
    M(i32),
    S(f64),
    T(i32),
}
