//! Blocks as motion keeps them: the canonical command plus where it came from.

/// What a block does.
#[derive(Debug, Clone, PartialEq)]
pub enum BlockKind {
    Rapid {
        end: Vec<f64>,
    },
    Linear {
        end: Vec<f64>,
        feed: f64,
    },
    Arc {
        end: Vec<f64>,
        center: Vec<f64>,
        clockwise: bool,
        feed: f64,
    },
    Dwell {
        seconds: f64,
    },
    Aux(AuxCode),
    ProgramEnd,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AuxCode {
    M(i32),
    S(f64),
    T(i32),
}

/// A queued block. Positions are in display units (X in diameter).
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub run_id: u64,
    pub seq: u64,
    pub line: u32,
    pub kind: BlockKind,
}
