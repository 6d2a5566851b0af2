//! The Huaxing turn-mill's live tool in speed mode (`000` §4.1.5's M65/M66, decision D143)
//! and the drilling cycles' C (`000` §5.22.7): cross and face holes drilled with the live
//! tool turning, as a shop writes them.

#[path = "support/huaxing.rs"]
mod huaxing;
use huaxing::{assert_alarms, hx, turn_mill, with_live_tool};

use cnc_interpreter::{Aux, Canon, Command, Setup};

/// The stream in short: rapids and feeds by their ends (X, Z, C), rotaries, the live tool's
/// speed, M and S codes for the PLC.
fn steps(cmds: &[Canon]) -> Vec<String> {
    cmds.iter()
        .filter_map(|c| match &c.command {
            Command::Rapid { end } => Some(format!("G00 X{} Z{} C{}", end[0], end[1], end[2])),
            Command::Linear { end, feed } => {
                Some(format!("G01 X{} Z{} C{} F{feed}", end[0], end[1], end[2]))
            }
            Command::Rotary {
                degrees, way, rpm, ..
            } => Some(format!("C {degrees} {way:?} {rpm}")),
            Command::LiveTool { rpm } => Some(format!("LIVE {rpm}")),
            Command::Aux(Aux::M(m)) => Some(format!("M{m}")),
            Command::Aux(Aux::S(s)) => Some(format!("S{s}")),
            _ => None,
        })
        .collect()
}

/// A flange's cross holes and face holes: C as an indexed axis (M14.6), the live tool at
/// 1500 r/min (M65 S1500); G87 drills four Ø radial holes at Z−10 from X60 to X30, 90°
/// apart (C0, then H90 K3), clamped by M20 (M21 unclamps); M66 stops the tool; at 2000 r/min
/// G83 drills two face holes at X20 on C45 and C225 pecking 3 mm (Q30000 least increments of 0.0001 mm, D12),
/// R0.5 back; M05 stops the spindle and the tool with it (B12.7 = 0). The PLC gets neither
/// M65 nor the tool's S.
#[test]
fn cross_and_face_holes_are_drilled_with_the_live_tool_turning() {
    let text = "T0101\nG98\nG00 X60 Z5\nM14.6\nM65 S1500\nG00 Z-10\n\
                G87 Z-10 C0 X30 F60 M20\nH90 K3 M20\nG00 X60 Z5\nM66\nM65 S2000\n\
                G83 X20 C45 Z-8 Q30000 R0.5 F80\nH180\nG00 X100 Z50\nM05\nM15\nM30\n";
    let cmds = hx(text, with_live_tool()).unwrap();
    let s: Vec<String> = steps(&cmds)
        .into_iter()
        .filter(|l| !["M14", "M15", "M30"].contains(&l.as_str()))
        .collect();
    let mut want: Vec<String> = ["G00 X60 Z5 C0", "LIVE 1500", "G00 X60 Z-10 C0"]
        .map(String::from)
        .to_vec();
    for (k, c) in [0.0, 90.0, 180.0, 270.0].iter().enumerate() {
        want.push(match k {
            0 => "C 0 Plus 100".into(),
            _ => "C 90 Incremental 100".into(),
        });
        want.extend([
            "M20".into(),
            format!("G01 X30 Z-10 C{c} F60"),
            format!("G00 X60 Z-10 C{c}"),
            "M21".into(),
        ]);
    }
    want.extend(
        [
            "G00 X60 Z5 C270",
            "LIVE 0",
            "LIVE 2000",
            "G00 X20 Z5 C270",
            "C 45 Plus 100",
        ]
        .map(String::from),
    );
    // Pecks of 3 mm from Z5 to Z−8, 0.5 mm back after each (J0), then out to Z5.
    for (down, back) in [(2.0, 2.5), (-1.0, -0.5), (-4.0, -3.5), (-7.0, -6.5)] {
        want.push(format!("G01 X20 Z{down} C45 F80"));
        want.push(format!("G00 X20 Z{back} C45"));
    }
    want.extend(["G01 X20 Z-8 C45 F80", "G00 X20 Z5 C45"].map(String::from));
    let face = want.len();
    assert_eq!(s[..face.min(s.len())], want[..], "{s:#?}");
    // H180: the second face hole on C225, the same pecks.
    assert_eq!(s[face], "C 180 Incremental 100");
    assert!(s[face + 1..].contains(&"G01 X20 Z-8 C225 F80".to_string()));
    let tail: Vec<&str> = s[s.len() - 3..].iter().map(String::as_str).collect();
    assert_eq!(tail, ["G00 X100 Z50 C225", "LIVE 0", "M5"]);
    assert!(
        !s.iter().any(|l| l == "M65" || l.starts_with('S')),
        "the PLC gets no M65 and no S: {s:?}"
    );
}

/// While the tool turns every S is its speed (but G50's and G97's); after M66 S is the
/// spindle's again. On a lathe
/// without a live tool M65 stays the second spindle's stop for the PLC.
#[test]
fn s_is_the_live_tools_speed_while_it_turns_and_m65_is_the_plcs_elsewhere() {
    // G50's S stays the spindle's clamp and G97's its r/min, also while the tool turns.
    let cmds = hx(
        "M65 S1000\nS1800\nG50 S2000\nG97 S300\nM66\nS500 M03\nM30\n",
        with_live_tool(),
    )
    .unwrap();
    assert_eq!(
        steps(&cmds),
        [
            "LIVE 1000",
            "LIVE 1800",
            "S300",
            "LIVE 0",
            "S500",
            "M3",
            "M30"
        ]
    );
    let plain = Setup::lathe([200.0, 100.0]);
    let cmds = hx("M63\nS1000 M65\nM30\n", plain).unwrap();
    assert_eq!(steps(&cmds), ["M63", "S1000", "M65", "M30"]);
}

/// The alarms: M65 without a speed or above S#122's 2500 r/min, S0 while it turns, a tap
/// (G14, M29 with G84) while it turns (73); M66 on a lathe without a live tool (74); C in a
/// drilling block of a lathe without a C axis (74, as the tapping cycles).
#[test]
fn live_tool_speed_alarms() {
    let cases = [
        ("M65\n", with_live_tool(), 73, 1),
        ("M65 S0\n", with_live_tool(), 73, 1),
        ("M65 S3000\n", with_live_tool(), 73, 1),
        ("M65 S1000\nS0\n", with_live_tool(), 73, 2),
        ("M65 S1000\nG14.4 Z-10 R500 F1\n", with_live_tool(), 73, 2),
        (
            "M65 S1000\nM29 S800\nG84 X20 C0 Z-10 F1\n",
            with_live_tool(),
            73,
            2,
        ),
        ("M66\n", turn_mill(), 74, 1),
        (
            "G00 X60 Z5\nG87 Z-10 C90 X30 F60\n",
            Setup::lathe([200.0, 100.0]),
            74,
            2,
        ),
    ];
    assert_alarms(cases);
}
