//! The names the 802D reserves: its multi-letter addresses, the keywords this front end runs,
//! those of the manual it refuses (each with its reason), and the test a variable's name
//! must pass.

/// Multi-letter addresses the control reads with `=` (§9.1.3, §9.1.6).
pub(super) const ADDRESSES: [&str; 25] = [
    "CR", "AR", "AP", "RP", "TURN", "RPL", "I1", "J1", "K1", "SF", "CHF", "CHR", "RND", "RNDM",
    "FRC", "FRCM", "ANG", "OFFN", "SPOS", "FP", "DISR", "DISCL", "FAD", "MEAS", "MEAW",
];

/// Keywords this front end runs.
pub(super) const KEYWORDS: [&str; 26] = [
    "CIP",
    "CT",
    "TRANS",
    "ATRANS",
    "ROT",
    "AROT",
    "SCALE",
    "ASCALE",
    "MIRROR",
    "AMIRROR",
    "STOPRE",
    "RET",
    "CFTCP",
    "CFC",
    "BRISK",
    "SOFT",
    "FFWOF",
    "COMPOF",
    "WALIMOF",
    "FENDNORM",
    "MCALL",
    "WALIMON",
    "FFWON",
    "COMPCAD",
    "STOPFIFO",
    "STARTFIFO",
];

const LETTERS: &str = "ABCDEFGHIJKLMNOPQRSTUVWXYZ";

/// An address's name as a constant: one letter or one of [`ADDRESSES`].
#[inline]
pub(super) fn address_name(name: &str) -> Option<&'static str> {
    match name.as_bytes() {
        [c] if c.is_ascii_uppercase() => {
            let i = usize::from(c - b'A');
            Some(&LETTERS[i..=i])
        }
        _ => ADDRESSES.iter().copied().find(|a| *a == name),
    }
}

/// Tangential control is not for the milling technology (§9.3.13, decision D112).
const TANG_ON_A_MILL: &str =
    "tangential control is not available on the milling technology (the manual, §9.3.13)";

/// Keywords of the manual this controller does not run, each with the reason (the alarm says
/// it; the coverage table lists them).
pub const NOT_BUILT: [(&str, &str); 13] = [
    // §9.3.13: "该功能不适用于铣削工艺" (D112).
    ("TANG", TANG_ON_A_MILL),
    ("TANGON", TANG_ON_A_MILL),
    ("TANGOF", TANG_ON_A_MILL),
    ("TLIFT", TANG_ON_A_MILL),
    ("TANGDEL", TANG_ON_A_MILL),
    ("MASLDEF", "master-slave coupling is not built"),
    ("MASLDEL", "master-slave coupling is not built"),
    ("MASLON", "master-slave coupling is not built"),
    ("MASLOF", "master-slave coupling is not built"),
    ("MASLOFS", "master-slave coupling is not built"),
    ("PRESETON", "setting actual values (PRESETON) is not built"),
    ("AXCTSWE", "axis containers are not built"),
    ("NEWCONF", "machine data are not set from a program here"),
];

/// G functions of the manual this controller does not run, each with the reason (the
/// alarm 12140 says it; the code table lists them).
pub const NOT_BUILT_G: [(u32, &str); 3] = [
    (
        291,
        "G291 (the ISO dialect mode) is not built: run the program as fanuc-mill",
    ),
    (62, "corner deceleration G62/G621 is not built"),
    (621, "corner deceleration G62/G621 is not built"),
];

/// A name the control reserves: an address or a keyword (no variable may take it).
pub fn is_address(name: &str) -> bool {
    ADDRESSES.contains(&name)
        || KEYWORDS.contains(&name)
        || NOT_BUILT.iter().any(|(k, _)| *k == name)
        || [
            "DEF", "IF", "GOTOF", "GOTOB", "MSG", "SET", "REP", "AC", "IC", "DC", "ACP", "ACN",
            "PROC", "ACC", "TRAILON", "TRAILOF", "TRACYL", "TRAFOOF", "TRAFOFF", "FXS", "FXST",
            "FXSW",
        ]
        .contains(&name)
}
