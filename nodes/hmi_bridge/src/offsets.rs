//! The offset pages between the interpreter's text form (`T n x z wear_x wear_z radius tip`,
//! `W G54 X=.. Z=..` lines; `offset_page.rs` there checks every value) and the services'
//! `ToolOffset` / `WorkOffset` messages.

use cnc_msgs::msg::{ToolOffset, WorkOffset};

/// The page text as messages; lines that do not read are skipped (the interpreter wrote them).
pub fn parse_page(text: &str) -> (Vec<ToolOffset>, Vec<WorkOffset>) {
    let mut tools = Vec::new();
    let mut work = Vec::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["T", n, x, z, wx, wz, r, tip] => {
                let f = |w: &str| w.parse::<f64>().ok();
                if let (
                    Ok(number),
                    Some(x),
                    Some(z),
                    Some(wear_x),
                    Some(wear_z),
                    Some(radius),
                    Ok(tip),
                ) = (n.parse(), f(x), f(z), f(wx), f(wz), f(r), tip.parse())
                {
                    tools.push(ToolOffset {
                        number,
                        x,
                        z,
                        wear_x,
                        wear_z,
                        radius,
                        tip,
                    });
                }
            }
            ["W", code, values @ ..] => {
                let mut w = WorkOffset {
                    code: code.to_string(),
                    ..WorkOffset::default()
                };
                for v in values {
                    if let Some((axis, value)) = v.split_once('=') {
                        if let Ok(value) = value.parse() {
                            w.axes.push(axis.into());
                            w.values.push(value);
                        }
                    }
                }
                work.push(w);
            }
            _ => {}
        }
    }
    (tools, work)
}

/// A tool row as the interpreter's command takes it: offset number, and the six values.
pub fn tool_command(t: &ToolOffset) -> (String, String) {
    (
        t.number.to_string(),
        format!(
            "{} {} {} {} {} {}",
            t.x, t.z, t.wear_x, t.wear_z, t.radius, t.tip
        ),
    )
}

/// A work offset as the interpreter's command takes it: the code, and `X=.. Z=..`.
pub fn work_command(w: &WorkOffset) -> Result<(String, String), String> {
    if w.axes.len() != w.values.len() {
        return Err(format!(
            "work offset {}: {} axes but {} values",
            w.code,
            w.axes.len(),
            w.values.len()
        ));
    }
    if w.axes
        .iter()
        .any(|a| a.contains(['=', ' ']) || a.is_empty())
    {
        return Err(format!("work offset {}: bad axis name", w.code));
    }
    let values: Vec<String> = w
        .axes
        .iter()
        .zip(&w.values)
        .map(|(a, v)| format!("{a}={v}"))
        .collect();
    Ok((w.code.clone(), values.join(" ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_reads_into_messages_and_a_row_goes_back_unchanged() {
        let page = "T 1 0.000 0.000 0.010 -0.020 0.400 3\nT 2 1.5 2.5 0 0 0.8 2\nW G54 X=0.000 Z=-120.500\nW G55 X=0.000 Z=0.000\n";
        let (tools, work) = parse_page(page);
        assert_eq!(tools.len(), 2);
        assert_eq!(tools[0].wear_z, -0.02);
        assert_eq!(tools[1].tip, 2);
        assert_eq!(work[0].code, "G54");
        assert_eq!(work[0].axes, ["X", "Z"]);
        assert_eq!(work[0].values, [0.0, -120.5]);
        assert_eq!(
            tool_command(&tools[1]),
            ("2".to_string(), "1.5 2.5 0 0 0.8 2".to_string())
        );
        assert_eq!(
            work_command(&work[0]).unwrap(),
            ("G54".to_string(), "X=0 Z=-120.5".to_string())
        );
        let bad = WorkOffset {
            code: "G54".into(),
            axes: vec!["X".into()],
            values: vec![],
        };
        assert!(work_command(&bad)
            .unwrap_err()
            .contains("1 axes but 0 values"));
        // A value that is not finite reaches the interpreter as text it refuses.
        let nan = ToolOffset {
            x: f64::NAN,
            ..ToolOffset::default()
        };
        assert!(tool_command(&nan).1.starts_with("NaN"));
    }
}
