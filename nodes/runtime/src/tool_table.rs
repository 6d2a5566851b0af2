//! The mill's tool table file (issue 7): one tool per line, `number length diameter`,
//! separated by blanks, `#` starting a comment; lengths in mm, or in inches after a line
//! `units inch` (until `units mm`), converted to mm as the table is read (decision D53). Entry n gives H<n> its length and D<n> its
//! radius (half the diameter), as FANUC 0-M's one offset memory shared by H and D does
//! (inventory `003` Appendix A.2; decision D47). Read by the launch config
//! (`machine.tool_table`) and by `cnc check --tools`.

use std::collections::BTreeMap;

use crate::config::ToolEntry;

pub use cnc_machine::tools::{check_entry, MAX_EDGE_ENTRY, MAX_TOOL_NUMBER};

/// Largest length or diameter accepted, mm.
const MAX_VALUE: f64 = 10_000.0;

/// The entries of a tool table text, or the first bad line with its number and reason.
pub fn parse(text: &str) -> Result<BTreeMap<u32, ToolEntry>, String> {
    let mut tools = BTreeMap::new();
    // Millimetres per unit of the values that follow.
    let mut unit = 1.0;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let body = raw.split('#').next().unwrap_or("");
        let fields: Vec<&str> = body.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        if fields[0] == "units" {
            unit = match fields[1..] {
                ["inch"] => 25.4,
                ["mm"] => 1.0,
                _ => {
                    return Err(format!(
                        "line {line}: `units inch` or `units mm`, found {body:?}"
                    ))
                }
            };
            continue;
        }
        let [number, length, diameter] = fields[..] else {
            return Err(format!(
                "line {line}: {} fields, expected `number length_mm diameter_mm`",
                fields.len()
            ));
        };
        let number: u32 = number
            .parse()
            .ok()
            .filter(|n| (1..=MAX_TOOL_NUMBER).contains(n))
            .ok_or_else(|| {
                format!("line {line}: tool number {number:?} is not 1-{MAX_TOOL_NUMBER}")
            })?;
        let value = |what: &str, text: &str| -> Result<f64, String> {
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() <= MAX_VALUE)
                .ok_or_else(|| {
                    format!("line {line}: {what} {text:?} is not a number within ±{MAX_VALUE} mm")
                })
        };
        let length = value("length", length)? * unit;
        let diameter = value("diameter", diameter)? * unit;
        if diameter < 0.0 {
            return Err(format!("line {line}: diameter {diameter} is negative"));
        }
        let entry = ToolEntry {
            z: length,
            radius: diameter / 2.0,
            ..ToolEntry::default()
        };
        if tools.insert(number, entry).is_some() {
            return Err(format!("line {line}: tool {number} is listed twice"));
        }
    }
    Ok(tools)
}

/// The tool table file at `path`.
pub fn load(path: &std::path::Path) -> Result<BTreeMap<u32, ToolEntry>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&text).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_give_length_and_radius() {
        let t = parse("# number length diameter\n1 50.5 10 # end mill\n\n200 -3 0\n").unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!((t[&1].z, t[&1].radius), (50.5, 5.0));
        assert_eq!((t[&200].z, t[&200].radius), (-3.0, 0.0));
        // An inch table is read in mm.
        let t = parse("units inch\n3 2.5 0.5\nunits mm\n4 10 6\n").unwrap();
        assert_eq!((t[&3].z, t[&3].radius), (63.5, 6.35));
        assert_eq!((t[&4].z, t[&4].radius), (10.0, 3.0));
        assert!(parse("units feet\n").is_err());
    }

    #[test]
    fn bad_rows_are_refused_with_their_line() {
        for (text, expect) in [
            ("1 50\n", "line 1: 2 fields"),
            ("\n0 50 10\n", "line 2: tool number \"0\""),
            ("201 50 10\n", "tool number \"201\""),
            ("1.5 50 10\n", "tool number \"1.5\""),
            ("1 fifty 10\n", "length \"fifty\""),
            ("1 NaN 10\n", "length \"NaN\""),
            ("1 50 -2\n", "diameter -2 is negative"),
            ("1 50 1e9\n", "diameter \"1e9\""),
            ("1 50 10\n1 60 10\n", "line 2: tool 1 is listed twice"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(expect), "{text:?}: {e}");
        }
    }
}
