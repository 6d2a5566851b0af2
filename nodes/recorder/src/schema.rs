//! `ros2msg` schemas as rosbag2 writes them: the type's `.msg` text, then the text of every
//! type it uses, each after a line of 80 `=` and `MSG: package/Type`.

use cnc_msgs::MSG_FILES;

const TIME: &str = "int32 sec\nuint32 nanosec\n";

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64", "string", "wstring",
];

/// `.msg` text of `package/Type` (also `package/msg/Type`).
fn text_of(package: &str, ty: &str) -> Option<&'static str> {
    match package {
        "builtin_interfaces" if ty == "Time" => Some(TIME),
        cnc_msgs::PACKAGE => MSG_FILES.iter().find(|(n, _)| *n == ty).map(|(_, t)| *t),
        _ => None,
    }
}

/// `package/msg/Type` or `package/Type` → (package, Type).
fn split(full: &str) -> Option<(&str, &str)> {
    let mut parts = full.split('/');
    let package = parts.next()?;
    let ty = parts.next_back()?;
    Some((package, ty))
}

/// The types a `.msg` text uses, as `package/Type`, in order of first use.
fn used_types(package: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        let Some(ty) = line.split_whitespace().next() else {
            continue;
        };
        // Constants (`uint8 X=1`) have primitive types; arrays end in `[]` or `[N]`.
        let base = ty.split('[').next().unwrap_or(ty);
        if PRIMITIVES.contains(&base) {
            continue;
        }
        let qualified = if base.contains('/') {
            base.to_string()
        } else {
            format!("{package}/{base}")
        };
        if !out.contains(&qualified) {
            out.push(qualified);
        }
    }
    out
}

/// The schema of `type_name` (`cnc_msgs/msg/AxisState`).
pub fn ros2msg(type_name: &str) -> Result<String, String> {
    let (package, ty) = split(type_name).ok_or_else(|| format!("bad type name {type_name}"))?;
    let main = text_of(package, ty).ok_or_else(|| format!("no definition of {type_name}"))?;
    let mut text = main.trim_end().to_string();
    let mut done: Vec<String> = vec![format!("{package}/{ty}")];
    let mut todo = used_types(package, main);
    while let Some(dep) = (!todo.is_empty()).then(|| todo.remove(0)) {
        if done.contains(&dep) {
            continue;
        }
        let (p, t) = split(&dep).ok_or_else(|| format!("bad type name {dep}"))?;
        let body = text_of(p, t).ok_or_else(|| format!("no definition of {dep}"))?;
        text.push_str(&format!(
            "\n{}\nMSG: {dep}\n{}",
            "=".repeat(80),
            body.trim_end()
        ));
        todo.extend(used_types(p, body));
        done.push(dep);
    }
    text.push('\n');
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_types_follow_the_main_text_once_each() {
        let s = ros2msg("cnc_msgs/msg/ActiveAlarms").unwrap();
        assert!(s.starts_with("# Every alarm that is active now"));
        assert_eq!(s.matches("MSG: builtin_interfaces/Time").count(), 1);
        assert_eq!(s.matches("MSG: cnc_msgs/Alarm").count(), 1);
        let s = ros2msg("cnc_msgs/msg/SimInput").unwrap();
        assert!(!s.contains("MSG:"));
        assert!(ros2msg("cnc_msgs/msg/Nope").is_err());
    }
}
