//! The offset pages as text, read and written from outside (the cell's services, the web HMI):
//! tool offsets (`000` §5.2, `002` §4.4: geometry, wear, nose radius, tip direction) and the
//! work offsets G54–G59. Every value is checked before anything changes, so a bad entry leaves
//! the page as it was.

use cnc_interpreter::fanuc::lathe::MAX_OFFSET;
use cnc_interpreter::setup::{Memory, ToolOffset};
use cnc_interpreter::Dialect;

/// Largest offset value accepted, mm (the address table's 4+3 digits).
pub const LIMIT_MM: f64 = 9999.999;

/// The whole page: `T n x z wear_x wear_z radius tip` per tool row, `W G5n X=.. Z=..` per work
/// offset, every configured axis given.
pub fn format(memory: &Memory, axes: &[char]) -> String {
    let mut out = String::new();
    for (n, t) in &memory.tools {
        out.push_str(&format!(
            "T {n} {:.3} {:.3} {:.3} {:.3} {:.3} {}\n",
            t.x, t.z, t.wear_x, t.wear_z, t.radius, t.tip
        ));
    }
    for index in 0..6u8 {
        let row = memory.work.get(&index);
        let values: Vec<String> = axes
            .iter()
            .map(|a| {
                let v = row.and_then(|r| r.get(a)).copied().unwrap_or(0.0);
                format!("{a}={v:.3}")
            })
            .collect();
        out.push_str(&format!("W G5{} {}\n", 4 + index, values.join(" ")));
    }
    out
}

fn value(word: &str, what: &str) -> Result<f64, String> {
    let v: f64 = word
        .trim()
        .parse()
        .map_err(|_| format!("{what}: {word:?} is not a number"))?;
    if !v.is_finite() || v.abs() > LIMIT_MM {
        return Err(format!("{what}: {word} is out of range (±{LIMIT_MM} mm)"));
    }
    Ok(v)
}

/// Sets tool offset `number` from `x z wear_x wear_z radius tip`.
/// The page is `dialect`'s: 1–99 on the lathes (alarm 62 beyond), 1–200 on FANUC 0-M,
/// T×10+D on the 802D.
pub fn set_tool(
    memory: &mut Memory,
    dialect: Dialect,
    number: &str,
    text: &str,
) -> Result<String, String> {
    let n: u32 = number
        .trim()
        .parse()
        .map_err(|_| format!("offset number {number:?} is not a number"))?;
    if dialect.is_lathe() && !(1..=MAX_OFFSET).contains(&n) {
        return Err(format!(
            "offset number {number:?} out of range 1-{MAX_OFFSET} (alarm 62)"
        ));
    }
    cnc_machine::tools::check_entry(dialect.name(), n)?;
    let words: Vec<&str> = text.split_whitespace().collect();
    let [x, z, wx, wz, r, tip] = words[..] else {
        return Err(format!(
            "tool offset needs 6 values: x z wear_x wear_z radius tip, got {}",
            words.len()
        ));
    };
    let radius = value(r, "nose radius")?;
    if radius < 0.0 {
        return Err(format!("nose radius {r} is negative"));
    }
    let tip: u8 = tip
        .parse()
        .ok()
        .filter(|t| *t <= 9)
        .ok_or_else(|| format!("tip direction {tip:?} out of range 0-9"))?;
    let row = ToolOffset {
        x: value(x, "X")?,
        z: value(z, "Z")?,
        wear_x: value(wx, "X wear")?,
        wear_z: value(wz, "Z wear")?,
        radius,
        tip,
    };
    memory.tools.insert(n, row);
    Ok(format!("tool offset {n} set"))
}

/// Sets the given axes of work offset `code` (G54–G59) from `X=.. Z=..`.
pub fn set_work(
    memory: &mut Memory,
    code: &str,
    text: &str,
    axes: &[char],
) -> Result<String, String> {
    let index = cnc_machine::work_offset_index(code)
        .ok_or_else(|| format!("work offset {code:?} is not G54-G59 (alarm 62)"))?;
    let mut changes = Vec::new();
    for word in text.split_whitespace() {
        let (axis, v) = word
            .split_once('=')
            .ok_or_else(|| format!("{word:?}: write axis=value, e.g. Z=-120.5"))?;
        let letter = axis
            .trim()
            .to_ascii_uppercase()
            .chars()
            .next()
            .filter(|c| axis.trim().len() == 1 && axes.contains(c))
            .ok_or_else(|| format!("axis {axis:?} is not an axis of this machine"))?;
        changes.push((letter, value(v, &format!("{code} {letter}"))?));
    }
    if changes.is_empty() {
        return Err("no axis value given".into());
    }
    let row = memory.work.entry(index).or_default();
    for (letter, v) in changes {
        row.insert(letter, v);
    }
    Ok(format!(
        "work offset {} set",
        code.trim().to_ascii_uppercase()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tool_row_is_set_read_back_and_a_bad_row_changes_nothing() {
        let mut m = Memory::default();
        assert_eq!(
            set_tool(
                &mut m,
                Dialect::HuaxingLathe,
                "3",
                "-120.5 40 0.02 -0.01 0.4 3"
            )
            .unwrap(),
            "tool offset 3 set"
        );
        let page = format(&m, &['X', 'Z']);
        assert!(
            page.contains("T 3 -120.500 40.000 0.020 -0.010 0.400 3\n"),
            "{page}"
        );
        let before = m.clone();
        for (n, text) in [
            ("0", "0 0 0 0 0 0"),
            ("100", "0 0 0 0 0 0"),
            ("3", "1 2 3"),
            ("3", "nan 0 0 0 0 0"),
            ("3", "10000 0 0 0 0 0"),
            ("3", "0 0 0 0 -0.4 3"),
            ("3", "0 0 0 0 0.4 10"),
        ] {
            assert!(
                set_tool(&mut m, Dialect::HuaxingLathe, n, text).is_err(),
                "{n} {text}"
            );
        }
        assert_eq!(m, before);
    }

    #[test]
    fn each_dialect_has_its_own_entries() {
        let mut m = Memory::default();
        let row = "0 60 0 0 6 0";
        // The 802D: T20 D1 is entry 201, T32000 D9 the last; D0 is no edge.
        for n in ["201", "320009"] {
            assert!(
                set_tool(&mut m, Dialect::Sinumerik802d, n, row).is_ok(),
                "{n}"
            );
        }
        for n in ["200", "5", "320010", "-1"] {
            assert!(
                set_tool(&mut m, Dialect::Sinumerik802d, n, row).is_err(),
                "{n}"
            );
        }
        // FANUC 0-M: H and D 1–200; the lathes 1–99.
        assert!(set_tool(&mut m, Dialect::FanucMill, "150", row).is_ok());
        assert!(set_tool(&mut m, Dialect::FanucMill, "201", row).is_err());
        assert!(set_tool(&mut m, Dialect::Gtc2eLathe, "150", row).is_err());
        assert_eq!(
            m.tools.keys().copied().collect::<Vec<_>>(),
            [150, 201, 320009]
        );
    }

    #[test]
    fn work_offsets_change_only_the_axes_given() {
        let mut m = Memory::default();
        set_work(&mut m, "g55", "X=10 Z=-200.25", &['X', 'Z']).unwrap();
        set_work(&mut m, "G55", "Z=-100", &['X', 'Z']).unwrap();
        assert!(format(&m, &['X', 'Z']).contains("W G55 X=10.000 Z=-100.000\n"));
        let before = m.clone();
        assert!(set_work(&mut m, "G60", "Z=1", &['X', 'Z']).is_err());
        assert!(set_work(&mut m, "G54", "Y=1", &['X', 'Z']).is_err());
        assert!(set_work(&mut m, "G54", "Z=1 X=oops", &['X', 'Z']).is_err());
        assert!(set_work(&mut m, "G54", "", &['X', 'Z']).is_err());
        assert_eq!(m, before);
    }
}
