//! The dialects: each a front end over the core, named here once. To add a dialect, add its
//! folder, a variant, and a line in each `match` below.

use cnc_interpreter_core::{Fault, FrontEnd, Library, ProgramError, Setup};

use crate::fanuc::codes::{G, M};
use crate::fanuc::{Family, Fanuc};
use crate::gtc2e::Gtc2e;
use crate::huaxing::Huaxing;
use crate::iso::IsoLathe;
use crate::mill::Mill;
use crate::sinumerik::{self, Sinumerik};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// The Huaxing WA-N7xx lathe (`000`).
    HuaxingLathe,
    /// The GTC2E lathe (`002`).
    Gtc2eLathe,
    /// The skeleton's ISO lathe subset (decision D1).
    IsoLathe,
    /// The FANUC 0-M mill (`003`).
    FanucMill,
    /// The SINUMERIK 802D sl mill (`001`).
    Sinumerik802d,
}

/// A running front end, as the interpreter drives it.
pub trait Engine: FrontEnd + Send {}

impl<T: FrontEnd + Send> Engine for T {}

/// What a code table says of one code, for the code table document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CodeStatus {
    /// The controller runs it.
    Built,
    /// Defined by the manual, not built: the reason.
    Unsupported(&'static str),
}

fn g_status<D: Family>(x10: u32) -> Option<CodeStatus> {
    D::g_code(x10).map(|c| match c.meaning {
        G::Unsupported(why) => CodeStatus::Unsupported(why),
        _ => CodeStatus::Built,
    })
}

fn m_status<D: Family>(x10: u32) -> Option<CodeStatus> {
    D::m_code(x10).map(|m| match m {
        M::Unsupported(why) => CodeStatus::Unsupported(why),
        _ => CodeStatus::Built,
    })
}

impl Dialect {
    pub const ALL: [Dialect; 5] = [
        Dialect::HuaxingLathe,
        Dialect::Gtc2eLathe,
        Dialect::IsoLathe,
        Dialect::FanucMill,
        Dialect::Sinumerik802d,
    ];

    /// A lathe's dialect: X in diameter, the Z-X plane.
    pub fn is_lathe(self) -> bool {
        !matches!(self, Dialect::FanucMill | Dialect::Sinumerik802d)
    }

    /// A dialect by its name; `sinumerik` is short for `sinumerik-802d`.
    pub fn from_name(name: &str) -> Option<Dialect> {
        let name = if name == "sinumerik" {
            "sinumerik-802d"
        } else {
            name
        };
        Dialect::ALL.into_iter().find(|d| d.name() == name)
    }

    pub fn name(self) -> &'static str {
        match self {
            Dialect::HuaxingLathe => "huaxing-lathe",
            Dialect::Gtc2eLathe => "gtc2e-lathe",
            Dialect::IsoLathe => "iso-lathe",
            Dialect::FanucMill => "fanuc-mill",
            Dialect::Sinumerik802d => "sinumerik-802d",
        }
    }

    /// The front end that runs `text` in this dialect.
    pub fn front_end(self, text: &str, setup: Setup, library: Library) -> Box<dyn Engine> {
        match self {
            Dialect::HuaxingLathe => Box::new(Fanuc::<Huaxing>::new(text, setup, library)),
            Dialect::Gtc2eLathe => Box::new(Fanuc::<Gtc2e>::new(text, setup, library)),
            Dialect::IsoLathe => Box::new(Fanuc::<IsoLathe>::new(text, setup, library)),
            Dialect::FanucMill => Box::new(Fanuc::<Mill>::new(text, setup, library)),
            Dialect::Sinumerik802d => Box::new(Sinumerik::new(text, setup, library)),
        }
    }

    /// The alarm number of a fault in this dialect's manual.
    pub fn alarm(self, f: Fault) -> u32 {
        match self {
            Dialect::HuaxingLathe => Huaxing::alarm(f),
            Dialect::Gtc2eLathe => Gtc2e::alarm(f),
            Dialect::IsoLathe => IsoLathe::alarm(f),
            Dialect::FanucMill => Mill::alarm(f),
            Dialect::Sinumerik802d => sinumerik::alarms::alarm(f),
        }
    }

    /// `G<number>` in the dialect's table (the number ×10, G50.1 is 501).
    pub fn g_code(self, x10: u32) -> Option<CodeStatus> {
        match self {
            Dialect::HuaxingLathe => g_status::<Huaxing>(x10),
            Dialect::Gtc2eLathe => g_status::<Gtc2e>(x10),
            Dialect::IsoLathe => g_status::<IsoLathe>(x10),
            Dialect::FanucMill => g_status::<Mill>(x10),
            Dialect::Sinumerik802d => {
                let g = x10 / 10;
                (x10.is_multiple_of(10) && sinumerik::g_group(g).is_some()).then(|| {
                    match sinumerik::NOT_BUILT_G.iter().find(|(n, _)| *n == g) {
                        Some((_, why)) => CodeStatus::Unsupported(why),
                        None => CodeStatus::Built,
                    }
                })
            }
        }
    }

    /// `M<number>` in the dialect's table (the number ×10).
    pub fn m_code(self, x10: u32) -> Option<CodeStatus> {
        match self {
            Dialect::HuaxingLathe => m_status::<Huaxing>(x10),
            Dialect::Gtc2eLathe => m_status::<Gtc2e>(x10),
            Dialect::IsoLathe => m_status::<IsoLathe>(x10),
            Dialect::FanucMill => m_status::<Mill>(x10),
            Dialect::Sinumerik802d => {
                (x10.is_multiple_of(10) && x10 <= 990).then_some(CodeStatus::Built)
            }
        }
    }

    /// The errors each line shows on its own (syntax, unknown codes), without running it.
    pub fn line_errors(self, text: &str) -> Vec<ProgramError> {
        match self {
            Dialect::HuaxingLathe => Fanuc::<Huaxing>::line_errors(text),
            Dialect::Gtc2eLathe => Fanuc::<Gtc2e>::line_errors(text),
            Dialect::IsoLathe => Fanuc::<IsoLathe>::line_errors(text),
            Dialect::FanucMill => Fanuc::<Mill>::line_errors(text),
            Dialect::Sinumerik802d => sinumerik::line_errors(text),
        }
    }

    /// Every G code of the table, as `(number ×10, status)`, for the code table document.
    pub fn all_g(self) -> Vec<(u32, CodeStatus)> {
        (0..1000)
            .filter_map(|n| Some((n, self.g_code(n)?)))
            .collect()
    }

    pub fn all_m(self) -> Vec<(u32, CodeStatus)> {
        (0..1000)
            .filter_map(|n| Some((n, self.m_code(n)?)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The launch config accepts exactly the dialects the interpreter knows.
    #[test]
    fn the_configs_dialect_list_is_the_interpreters() {
        let names: Vec<&str> = Dialect::ALL.iter().map(|d| d.name()).collect();
        assert_eq!(names, cnc_machine::DIALECTS);
    }
}
