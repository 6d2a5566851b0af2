//! The offset pages, read and written from outside (the cell's services, the web HMI): tool
//! offsets (`000` §5.2, `002` §4.4: geometry, wear, nose radius, tip direction) and the work
//! offsets G54–G59, as the typed rows of `cnc_msgs`. Every value is checked before anything
//! changes, so a bad entry leaves the page as it was.

use cnc_interpreter::fanuc::lathe::MAX_OFFSET;
use cnc_interpreter::setup::{Memory, ToolOffset};
use cnc_interpreter::Dialect;
use cnc_msgs::msg;

/// Largest offset value accepted, mm (the address table's 4+3 digits).
pub const LIMIT_MM: f64 = 9999.999;

/// A value as the page shows it: to the 0.001 mm the address table writes.
fn shown(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// The whole page: every tool row, and the work offsets G54–G59 with every configured axis.
pub fn page(memory: &Memory, axes: &[char]) -> (Vec<msg::ToolOffset>, Vec<msg::WorkOffset>) {
    let tools = memory
        .tools
        .iter()
        .map(|(&number, t)| msg::ToolOffset {
            number,
            x: shown(t.x),
            z: shown(t.z),
            wear_x: shown(t.wear_x),
            wear_z: shown(t.wear_z),
            radius: shown(t.radius),
            tip: t.tip,
        })
        .collect();
    let work = (0..6u8)
        .map(|index| {
            let row = memory.work.get(&index);
            msg::WorkOffset {
                code: format!("G5{}", 4 + index),
                axes: axes.iter().map(char::to_string).collect(),
                values: axes
                    .iter()
                    .map(|a| shown(row.and_then(|r| r.get(a)).copied().unwrap_or(0.0)))
                    .collect(),
            }
        })
        .collect();
    (tools, work)
}

fn value(v: f64, what: &str) -> Result<f64, String> {
    if !v.is_finite() || v.abs() > LIMIT_MM {
        return Err(format!("{what}: {v} is out of range (±{LIMIT_MM} mm)"));
    }
    Ok(v)
}

/// Sets the tool offset row `row.number`. The page is `dialect`'s: 1–99 on the lathes
/// (alarm 62 beyond), 1–200 on FANUC 0-M, T×10+D on the 802D.
pub fn set_tool(
    memory: &mut Memory,
    dialect: Dialect,
    row: &msg::ToolOffset,
) -> Result<String, String> {
    let n = row.number;
    if dialect.is_lathe() && !(1..=MAX_OFFSET).contains(&n) {
        return Err(format!(
            "offset number {n} out of range 1-{MAX_OFFSET} (alarm 62)"
        ));
    }
    cnc_machine::tools::check_entry(dialect.name(), n)?;
    let radius = value(row.radius, "nose radius")?;
    if radius < 0.0 {
        return Err(format!("nose radius {radius} is negative"));
    }
    if row.tip > 9 {
        return Err(format!("tip direction {} out of range 0-9", row.tip));
    }
    let checked = ToolOffset {
        x: value(row.x, "X")?,
        z: value(row.z, "Z")?,
        wear_x: value(row.wear_x, "X wear")?,
        wear_z: value(row.wear_z, "Z wear")?,
        radius,
        tip: row.tip,
    };
    memory.tools.insert(n, checked);
    Ok(format!("tool offset {n} set"))
}

/// Sets the axes `row` names of its work offset (G54–G59); the others keep their values.
pub fn set_work(
    memory: &mut Memory,
    row: &msg::WorkOffset,
    axes: &[char],
) -> Result<String, String> {
    let code = row.code.trim().to_ascii_uppercase();
    let index = cnc_machine::work_offset_index(&code)
        .ok_or_else(|| format!("work offset {:?} is not G54-G59 (alarm 62)", row.code))?;
    if row.axes.len() != row.values.len() {
        return Err(format!(
            "work offset {code}: {} axes but {} values",
            row.axes.len(),
            row.values.len()
        ));
    }
    let mut changes = Vec::new();
    for (axis, &v) in row.axes.iter().zip(&row.values) {
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
    let entry = memory.work.entry(index).or_default();
    for (letter, v) in changes {
        entry.insert(letter, v);
    }
    Ok(format!("work offset {code} set"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tool(number: u32, [x, z, wear_x, wear_z, radius]: [f64; 5], tip: u8) -> msg::ToolOffset {
        msg::ToolOffset {
            number,
            x,
            z,
            wear_x,
            wear_z,
            radius,
            tip,
        }
    }

    fn work(code: &str, values: &[(&str, f64)]) -> msg::WorkOffset {
        msg::WorkOffset {
            code: code.into(),
            axes: values.iter().map(|(a, _)| a.to_string()).collect(),
            values: values.iter().map(|(_, v)| *v).collect(),
        }
    }

    #[test]
    fn a_tool_row_is_set_read_back_and_a_bad_row_changes_nothing() {
        let mut m = Memory::default();
        let row = tool(3, [-120.5, 40.0, 0.02, -0.01, 0.4], 3);
        assert_eq!(
            set_tool(&mut m, Dialect::HuaxingLathe, &row).unwrap(),
            "tool offset 3 set"
        );
        let (tools, _) = page(&m, &['X', 'Z']);
        assert_eq!(tools, [row]);
        let before = m.clone();
        for bad in [
            tool(0, [0.0; 5], 0),
            tool(100, [0.0; 5], 0),
            tool(3, [f64::NAN, 0.0, 0.0, 0.0, 0.0], 0),
            tool(3, [10000.0, 0.0, 0.0, 0.0, 0.0], 0),
            tool(3, [0.0, 0.0, 0.0, 0.0, -0.4], 3),
            tool(3, [0.0, 0.0, 0.0, 0.0, 0.4], 10),
        ] {
            assert!(
                set_tool(&mut m, Dialect::HuaxingLathe, &bad).is_err(),
                "{bad:?}"
            );
        }
        assert_eq!(m, before);
    }

    #[test]
    fn each_dialect_has_its_own_entries() {
        let mut m = Memory::default();
        let row = |n| tool(n, [0.0, 60.0, 0.0, 0.0, 6.0], 0);
        // The 802D: T20 D1 is entry 201, T32000 D9 the last; D0 is no edge.
        for n in [201, 320009] {
            assert!(
                set_tool(&mut m, Dialect::Sinumerik802d, &row(n)).is_ok(),
                "{n}"
            );
        }
        for n in [200, 5, 320010] {
            assert!(
                set_tool(&mut m, Dialect::Sinumerik802d, &row(n)).is_err(),
                "{n}"
            );
        }
        // FANUC 0-M: H and D 1–200; the lathes 1–99.
        assert!(set_tool(&mut m, Dialect::FanucMill, &row(150)).is_ok());
        assert!(set_tool(&mut m, Dialect::FanucMill, &row(201)).is_err());
        assert!(set_tool(&mut m, Dialect::Gtc2eLathe, &row(150)).is_err());
        assert_eq!(
            m.tools.keys().copied().collect::<Vec<_>>(),
            [150, 201, 320009]
        );
    }

    #[test]
    fn work_offsets_change_only_the_axes_given() {
        let mut m = Memory::default();
        let xz = ['X', 'Z'];
        set_work(&mut m, &work("g55", &[("X", 10.0), ("Z", -200.25)]), &xz).unwrap();
        set_work(&mut m, &work("G55", &[("Z", -100.0)]), &xz).unwrap();
        let (_, rows) = page(&m, &xz);
        assert_eq!(rows[1], work("G55", &[("X", 10.0), ("Z", -100.0)]));
        let before = m.clone();
        assert!(set_work(&mut m, &work("G60", &[("Z", 1.0)]), &xz).is_err());
        assert!(set_work(&mut m, &work("G54", &[("Y", 1.0)]), &xz).is_err());
        assert!(set_work(&mut m, &work("G54", &[("Z", 1.0), ("X", f64::NAN)]), &xz).is_err());
        assert!(set_work(&mut m, &work("G54", &[]), &xz).is_err());
        let mut unpaired = work("G54", &[("X", 1.0)]);
        unpaired.values.clear();
        assert!(set_work(&mut m, &unpaired, &xz)
            .unwrap_err()
            .contains("1 axes but 0 values"));
        assert_eq!(m, before);
    }
}
