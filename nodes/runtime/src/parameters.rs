//! The machine's parameters as the cell reads and writes them: the launch config's machine,
//! servo, PLC and simulator settings under dotted names (`machine.axes.X.max_velocity`,
//! `servo.lookahead`). A write is checked against the table of who may write what within which
//! bounds ([`crate::parameter_rules`], D124) and against the whole config (type and the config's
//! own rules), stored in the parameter file and taken at the next start of the cell, as a
//! control asks for a power-off after a parameter change (decisions D44). Pure except for
//! [`load_file`] and [`save_file`].

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

use crate::parameter_rules;
use crate::LaunchConfig;

/// The sections that hold parameters. Network, HMI access and recording are the cell's and
/// the auditor's, not the machine's: nobody rewrites them over the network.
const SECTIONS: [&str; 4] = ["machine", "servo", "plc", "sim"];

/// Settings that are not parameters: identity, file paths, and the offset pages (written
/// through the offset services).
const NOT_PARAMETERS: [&str; 11] = [
    "machine.namespace",
    "machine.memory_file",
    "machine.program_directory",
    "machine.program_capacity_kib",
    "machine.parameter_file",
    "machine.tool_table",
    "machine.tools",
    "machine.work_offsets",
    "plc.program",
    "plc.memory_file",
    "machine.axes.*.name",
];

/// Written values by parameter name, as YAML scalars.
pub type Overlay = BTreeMap<String, String>;

fn excluded(name: &str) -> bool {
    NOT_PARAMETERS.iter().any(|p| {
        let prefix_of = |n: &str| name == n || name.starts_with(&format!("{n}."));
        match p.split_once(".*.") {
            Some((head, tail)) => {
                name.starts_with(&format!("{head}.")) && name.ends_with(&format!(".{tail}"))
            }
            None => prefix_of(p),
        }
    })
}

/// How a scalar value reads: `6000.0`, `true`, `rear`, `null`.
fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Every parameter with its value, in name order.
pub fn list(cfg: &LaunchConfig) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let Ok(root) = serde_json::to_value(cfg) else {
        return out;
    };
    for section in SECTIONS {
        if let Some(v) = root.get(section) {
            flatten(section.to_string(), v, &mut out);
        }
    }
    out.retain(|(name, _)| !excluded(name));
    out.sort();
    out
}

fn flatten(name: String, v: &Value, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(format!("{name}.{k}"), v, out);
            }
        }
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                // Axes are named by their letter, other lists by position.
                let key = item
                    .get("name")
                    .and_then(Value::as_str)
                    .map(str::to_string)
                    .unwrap_or_else(|| i.to_string());
                flatten(format!("{name}.{key}"), item, out);
            }
        }
        scalar => out.push((name, show(scalar))),
    }
}

/// The leaf `name` addresses in `root`, if there is one.
fn leaf<'a>(root: &'a mut Value, name: &str) -> Option<&'a mut Value> {
    let mut node = root;
    for part in name.split('.') {
        node = match node {
            Value::Object(map) => map.get_mut(part)?,
            Value::Array(items) => {
                let at = match part.parse::<usize>() {
                    Ok(i) => i,
                    Err(_) => items
                        .iter()
                        .position(|it| it.get("name").and_then(Value::as_str) == Some(part))?,
                };
                items.get_mut(at)?
            }
            _ => return None,
        };
    }
    Some(node)
}

/// `cfg` with parameter `name` set to `value` (a YAML scalar) as the cell writes it (the
/// bridge's `set_parameter`, the web panel, the parameter file at start): refused unless the
/// table lets the cell write it within its bounds ([`parameter_rules`]), then checked as the
/// launch config is at start; `cfg` itself is not touched. A refusal names the rule.
pub fn set(cfg: &LaunchConfig, name: &str, value: &str) -> Result<LaunchConfig, String> {
    if !list(cfg).iter().any(|(n, _)| n == name) {
        return Err(format!(
            "unknown parameter {name:?} (GetParameters lists them)"
        ));
    }
    if value.len() > 256 || value.chars().any(char::is_control) {
        return Err(format!("{name}: a value is one line of at most 256 bytes"));
    }
    let scalar: serde_yaml::Value =
        serde_yaml::from_str(value).map_err(|e| format!("{name}: not a value: {e}"))?;
    let number = scalar.as_f64();
    parameter_rules::check_cell_write(cfg, name, number, cfg.limits.monitors.get(name).copied())?;
    let new: Value =
        serde_json::to_value(&scalar).map_err(|e| format!("{name}: not a value: {e}"))?;
    if matches!(new, Value::Array(_) | Value::Object(_)) {
        return Err(format!("{name}: give one value, not a list or map"));
    }
    let mut root = serde_json::to_value(cfg).map_err(|e| e.to_string())?;
    let slot = leaf(&mut root, name).ok_or_else(|| format!("unknown parameter {name:?}"))?;
    *slot = new;
    let changed: LaunchConfig = serde_json::from_value(root).map_err(|e| format!("{name}: {e}"))?;
    changed
        .validate()
        .map_err(|e| format!("{name} refused: {e}"))?;
    Ok(changed)
}

/// Every number of `cfg`'s parameters against its range in the table (any writer: the
/// launch config as read, and every write).
pub fn check_ranges(cfg: &LaunchConfig) -> Result<(), String> {
    for (name, value) in list(cfg) {
        if let Ok(v) = value.parse::<f64>() {
            parameter_rules::check_range(cfg, &name, v)?;
        }
    }
    Ok(())
}

/// The builder's value of every monitor of `cfg` (the launch config as read): its own value,
/// or what the machine takes where the file leaves it out.
pub fn builder_monitors(cfg: &LaunchConfig) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for (name, value) in list(cfg) {
        if !parameter_rules::rule(&name).monitor {
            continue;
        }
        let v = value.parse::<f64>().ok().or_else(|| derived(cfg, &name));
        if let Some(v) = v {
            out.insert(name, v);
        }
    }
    out
}

/// The value the machine takes for a monitor the file leaves out (`null`).
fn derived(cfg: &LaunchConfig, name: &str) -> Option<f64> {
    if name == "servo.late_warning_ms" {
        return Some(cfg.servo.late_warning());
    }
    let axis = name
        .strip_prefix("machine.axes.")?
        .strip_suffix(".following_error")?;
    let a = cfg.machine.axes.iter().find(|a| a.name == axis)?;
    Some(a.following_error_limit())
}

/// `cfg` with every written value of `overlay` applied in name order.
pub fn apply(cfg: LaunchConfig, overlay: &Overlay) -> Result<LaunchConfig, String> {
    overlay
        .iter()
        .try_fold(cfg, |cfg, (name, value)| set(&cfg, name, value))
}

/// The parameter file; a missing file is an empty one.
pub fn load_file(path: &Path) -> Result<Overlay, String> {
    match std::fs::read_to_string(path) {
        Ok(text) => serde_yaml::from_str::<Option<Overlay>>(&text)
            .map(Option::unwrap_or_default)
            .map_err(|e| format!("parameter file {}: {e}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Overlay::new()),
        Err(e) => Err(format!("parameter file {}: {e}", path.display())),
    }
}

pub fn save_file(path: &Path, overlay: &Overlay) -> Result<(), String> {
    let text = serde_yaml::to_string(overlay).map_err(|e| e.to_string())?;
    let header = "# Parameters written from the cell (SetParameter); applied over the launch config at start.\n";
    crate::persist::write_atomic(path, &format!("{header}{text}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lathe() -> LaunchConfig {
        let text = include_str!("../../../launch_configs/sim_lathe.yaml");
        LaunchConfig::from_yaml(text).expect("sim_lathe.yaml")
    }

    fn value(cfg: &LaunchConfig, name: &str) -> Option<String> {
        list(cfg)
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }

    #[test]
    fn parameters_are_named_by_section_axis_letter_and_field() {
        let cfg = lathe();
        assert_eq!(
            value(&cfg, "machine.axes.X.max_velocity").as_deref(),
            Some("6000.0")
        );
        assert_eq!(value(&cfg, "machine.arc_plane.0").as_deref(), Some("Z"));
        assert_eq!(value(&cfg, "servo.period_ms").as_deref(), Some("4.0"));
        assert_eq!(
            value(&cfg, "machine.dialect").as_deref(),
            Some("huaxing-lathe")
        );
        for hidden in [
            "machine.namespace",
            "machine.axes.X.name",
            "machine.memory_file",
            "machine.tool_table",
            "plc.program",
            "hmi.allowed_clients.0",
            "network.interfaces.0",
            "recorder.enabled",
        ] {
            assert_eq!(value(&cfg, hidden), None, "{hidden}");
        }
        assert!(list(&cfg)
            .iter()
            .all(|(n, _)| !n.starts_with("machine.tools")));
        // A file path is not a parameter: a client could point the next start at any file.
        assert!(set(&cfg, "machine.tool_table", "/etc/passwd").is_err());
    }

    #[test]
    fn a_write_is_checked_by_type_and_by_the_configs_rules() {
        let cfg = lathe();
        let changed = set(&cfg, "machine.axes.X.max_velocity", "5000").expect("a number");
        assert_eq!(changed.machine.axes[0].max_velocity, 5000.0);
        assert_eq!(
            cfg.machine.axes[0].max_velocity, 6000.0,
            "the original is kept"
        );
        let e = set(&cfg, "machine.axes.X.max_velocity", "fast").unwrap_err();
        assert!(e.contains("invalid type"), "{e}");
        let e = set(&cfg, "machine.axes.X.max_velocity", "-5").unwrap_err();
        assert!(e.contains("positive velocity"), "{e}");
        let e = set(&cfg, "servo.lookahead", "[1, 2]").unwrap_err();
        assert!(e.contains("not a list"), "{e}");
        let e = set(&cfg, "machine.namespace", "other").unwrap_err();
        assert!(e.contains("unknown parameter"), "{e}");
        let e = set(&cfg, "hmi.allowed_clients.0", "*").unwrap_err();
        assert!(e.contains("unknown parameter"), "{e}");
        // The dialect and the geometry are the builder's (D124), whatever the value.
        for (name, value) in [
            ("machine.dialect", "klingon-lathe"),
            ("machine.dialect", "fanuc-mill"),
            ("machine.tool_post", "front"),
            ("machine.tool_post", "sideways"),
        ] {
            let e = set(&cfg, name, value).unwrap_err();
            assert!(e.contains("the machine builder's"), "{e}");
        }
    }

    #[test]
    fn the_parameter_file_applies_over_the_config_and_a_bad_entry_is_named() {
        let mut overlay = Overlay::new();
        overlay.insert("servo.lookahead".into(), "12".into());
        overlay.insert("machine.axes.Z.max_acceleration".into(), "1200".into());
        let cfg = apply(lathe(), &overlay).expect("applies");
        assert_eq!(cfg.servo.lookahead, 12);
        assert_eq!(cfg.machine.axes[1].max_acceleration, 1200.0);
        overlay.insert("servo.lookahead".into(), "99999".into());
        let e = apply(lathe(), &overlay).unwrap_err();
        assert!(e.contains("servo.lookahead = 99999 outside 2..256"), "{e}");
        overlay.insert("servo.lookahead".into(), "12".into());
        overlay.insert("servo.period_ms".into(), "8".into());
        let e = apply(lathe(), &overlay).unwrap_err();
        assert!(
            e.contains("servo.period_ms is the machine builder's"),
            "{e}"
        );

        let dir = std::env::temp_dir().join(format!("cnc_params_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.yaml");
        assert!(
            load_file(&path).unwrap().is_empty(),
            "no file: nothing written"
        );
        save_file(&path, &overlay).unwrap();
        assert_eq!(load_file(&path).unwrap(), overlay);
        std::fs::write(&path, "servo.lookahead: [").unwrap();
        assert!(load_file(&path).unwrap_err().contains("parameter file"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Issue 26's findings: a written value may not widen what the machine is rated for, nor
    /// be non-finite, nor make a move that never ends.
    #[test]
    fn a_parameter_may_not_widen_the_machines_ratings() {
        let cfg = lathe();
        for (name, value, says) in [
            ("machine.axes.X.max", "1e308", "rated travel -2..300"),
            ("machine.axes.X.min", "-1e308", "rated travel -2..300"),
            ("machine.axes.X.max_velocity", "1e308", "rated 60..6000"),
            (
                "machine.axes.X.max_acceleration",
                "1e-300",
                "rated 15..1500",
            ),
            ("machine.axes.Z.max_jerk", "1e300", "max_jerk"),
            ("machine.axes.X.max_velocity", ".inf", "not a finite number"),
            ("machine.axes.X.max_velocity", ".nan", "not a finite number"),
            (
                "sim.spindle_acceleration",
                "1e-300",
                "sim.spindle_acceleration",
            ),
            ("servo.dry_run_feed", "-.inf", "not a finite number"),
        ] {
            let e = set(&cfg, name, value).expect_err(name);
            assert!(
                e.contains(name) && e.contains(says),
                "{name} = {value}: {e}"
            );
        }
        // Lowering a rating is a parameter change like any other.
        let slower = set(&cfg, "machine.axes.X.max_velocity", "3000").expect("lower");
        assert_eq!(slower.machine.axes[0].max_velocity, 3000.0);
        let shorter = set(&cfg, "machine.axes.X.max", "250").expect("shorter travel");
        // … and the ratings themselves are no parameter.
        assert!(list(&shorter).iter().all(|(n, _)| !n.starts_with("limits")));
        assert!(set(&cfg, "limits.spindle_max_rpm", "99999").is_err());
    }

    /// Every parameter with random, extreme and non-finite values: each write is refused with
    /// the parameter's name, or gives a config within the machine's ratings.
    #[test]
    fn every_parameter_under_extreme_values_is_refused_by_name_or_stays_rated() {
        let cfg = lathe();
        let values = [
            "0",
            "-1",
            "1e308",
            "-1e308",
            "1e-300",
            ".inf",
            "-.inf",
            ".nan",
            "18446744073709551615",
            "-9223372036854775809",
            "4294967296",
            "255",
            "true",
            "''",
            "~",
            "x",
            "1.5",
        ];
        let mut refused = 0;
        for (name, _) in list(&cfg) {
            for v in values {
                match set(&cfg, &name, v) {
                    Err(e) => {
                        refused += 1;
                        assert!(e.contains(&name), "{name} = {v}: {e}");
                    }
                    Ok(changed) => {
                        changed.validate().expect("a taken write is valid");
                        for (a, l) in changed.machine.axes.iter().zip(cfg.machine.axes.iter()) {
                            assert!(a.min >= l.min && a.max <= l.max, "{name} = {v}");
                            assert!(a.max_velocity <= l.max_velocity, "{name} = {v}");
                            assert!(a.max_acceleration >= 0.01 * l.max_acceleration);
                        }
                    }
                }
            }
        }
        assert!(refused > list(&cfg).len() * 5, "{refused}");
    }
}
