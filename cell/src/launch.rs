//! A launch file for a whole cell on one computer (issue 29's laptop demo): several machines,
//! each from its own launch config with a few settings changed, the cell supervisor's work
//! order and the robot, all in one process (`cnc run launch_configs/cell_two_lathes.yaml`).
//! On a shop network each machine runs `cnc run` on its own host instead.
//!
//! ```yaml
//! cell:
//!   machines:
//!     - config: sim_lathe.yaml          # relative to this file
//!       override: { hmi: { web_address: "127.0.0.1:8080" } }
//!   order: { name: demo, program: ../examples/lathe/robot_part.nc, parts: 5 }
//!   robot: { swap_seconds: 2.0 }
//!   supervisor: { lease_ms: 1000, records: records/cell }
//! ```

use std::path::{Path, PathBuf};
use std::time::Duration;

use cnc_runtime::config::CellPanel;
use cnc_runtime::LaunchConfig;
use serde::Deserialize;
use serde_yaml::Value;

use crate::supervisor::{Order, OrderLine};
use crate::supervisor_node::Options;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CellFile {
    cell: CellSection,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CellSection {
    machines: Vec<MachineEntry>,
    order: OrderEntry,
    #[serde(default)]
    robot: RobotEntry,
    #[serde(default)]
    supervisor: SupervisorEntry,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineEntry {
    /// The machine's launch config, relative to the cell file.
    config: PathBuf,
    /// Settings laid over it (mappings merged key by key).
    #[serde(default)]
    r#override: Value,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct OrderEntry {
    name: String,
    /// The part program, relative to the cell file; loaded into every machine.
    program: PathBuf,
    /// Parts per machine.
    parts: u32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotEntry {
    #[serde(default = "default_swap")]
    swap_seconds: f64,
}

impl Default for RobotEntry {
    fn default() -> Self {
        RobotEntry {
            swap_seconds: default_swap(),
        }
    }
}

fn default_swap() -> f64 {
    2.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SupervisorEntry {
    #[serde(default = "default_lease")]
    lease_ms: u64,
    /// Where the supervisor's audit bags go, relative to the cell file; absent: none.
    #[serde(default)]
    records: Option<PathBuf>,
}

impl Default for SupervisorEntry {
    fn default() -> Self {
        SupervisorEntry {
            lease_ms: default_lease(),
            records: None,
        }
    }
}

fn default_lease() -> u64 {
    1000
}

/// A cell read from its launch file.
#[derive(Debug)]
pub struct CellLaunch {
    pub machines: Vec<LaunchConfig>,
    pub order: Order,
    pub swap_seconds: f64,
    pub supervisor: Options,
}

/// Whether the YAML file at `path` is a cell launch file (its top key is `cell`).
pub fn is_cell_file(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| serde_yaml::from_str::<Value>(&t).ok())
        .is_some_and(|v| v.get("cell").is_some())
}

/// Lays `over` onto `base`: mappings key by key, anything else replaced.
fn merge(base: &mut Value, over: &Value) {
    match (base, over) {
        (Value::Mapping(b), Value::Mapping(o)) => {
            for (k, v) in o {
                match b.get_mut(k) {
                    Some(slot) => merge(slot, v),
                    None => {
                        b.insert(k.clone(), v.clone());
                    }
                }
            }
        }
        (b, o) => *b = o.clone(),
    }
}

fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Reads a cell launch file.
pub fn load(path: &Path) -> Result<CellLaunch, String> {
    let at = |e: String| format!("{}: {e}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| at(e.to_string()))?;
    let file: CellFile = serde_yaml::from_str(&text).map_err(|e| at(e.to_string()))?;
    let dir = folder(path);
    let c = file.cell;
    if c.machines.is_empty() {
        return Err(at("cell.machines names no machine".into()));
    }
    if c.order.parts == 0 {
        return Err(at("cell.order.parts must be at least 1".into()));
    }
    let mut machines = Vec::new();
    for m in &c.machines {
        let file = dir.join(&m.config);
        let text =
            std::fs::read_to_string(&file).map_err(|e| at(format!("{}: {e}", file.display())))?;
        let mut v: Value =
            serde_yaml::from_str(&text).map_err(|e| at(format!("{}: {e}", file.display())))?;
        merge(&mut v, &m.r#override);
        let yaml = serde_yaml::to_string(&v).map_err(|e| at(e.to_string()))?;
        let cfg = LaunchConfig::from_yaml_in(&yaml, folder(&file), None)
            .map_err(|e| at(format!("{}: {e}", file.display())))?;
        machines.push(cfg);
    }
    let mut names: Vec<&str> = machines
        .iter()
        .map(|m| m.machine.namespace.as_str())
        .collect();
    names.sort_unstable();
    if names.windows(2).any(|w| w[0] == w[1]) {
        return Err(at("two machines of the cell have the same namespace".into()));
    }
    // Each panel offers every machine's panel.
    let panels: Vec<CellPanel> = machines
        .iter()
        .filter(|m| !m.hmi.web_address.is_empty())
        .map(|m| CellPanel {
            name: m.machine.namespace.clone(),
            url: format!("http://{}/", m.hmi.web_address),
        })
        .collect();
    for m in &mut machines {
        m.hmi.cell_panels = panels.clone();
    }
    let program_file = dir.join(&c.order.program);
    let text = std::fs::read_to_string(&program_file)
        .map_err(|e| at(format!("{}: {e}", program_file.display())))?;
    let program = program_file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "part.nc".into());
    let order = Order {
        name: c.order.name,
        lines: machines
            .iter()
            .map(|m| OrderLine {
                machine: m.machine.namespace.clone(),
                program: program.clone(),
                text: text.clone(),
                parts: c.order.parts,
            })
            .collect(),
    };
    Ok(CellLaunch {
        machines,
        order,
        swap_seconds: c.robot.swap_seconds.max(0.0),
        supervisor: Options {
            lease: Duration::from_millis(c.supervisor.lease_ms.max(1)),
            records: c.supervisor.records.map(|r| dir.join(r)),
            ..Options::default()
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_repository_s_two_lathe_cell_reads_with_two_panels_and_its_order() {
        let path = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../launch_configs/cell_two_lathes.yaml"
        ));
        assert!(is_cell_file(path));
        let c = load(path).expect("cell file");
        let names: Vec<&str> = c
            .machines
            .iter()
            .map(|m| m.machine.namespace.as_str())
            .collect();
        assert_eq!(names, ["lathe1", "lathe2"]);
        assert_eq!(c.machines[1].hmi.cell_panels.len(), 2);
        assert_ne!(
            c.machines[0].machine.memory_file,
            c.machines[1].machine.memory_file
        );
        assert_ne!(c.machines[0].hmi.web_address, c.machines[1].hmi.web_address);
        assert_eq!(c.order.lines.len(), 2);
        assert!(c.order.lines[0].text.contains("M30"));
        // A machine's own config is not a cell file.
        let lathe = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../launch_configs/sim_lathe.yaml"
        ));
        assert!(lathe.is_file() && !is_cell_file(lathe));
    }

    #[test]
    fn overrides_merge_key_by_key() {
        let mut base: Value = serde_yaml::from_str("a: {b: 1, c: 2}\nd: [1]").expect("yaml");
        let over: Value = serde_yaml::from_str("a: {c: 3}\nd: [2, 3]").expect("yaml");
        merge(&mut base, &over);
        let want: Value = serde_yaml::from_str("a: {b: 1, c: 3}\nd: [2, 3]").expect("yaml");
        assert_eq!(base, want);
    }

    #[test]
    fn a_bad_cell_file_is_refused_with_its_reason() {
        let dir = std::env::temp_dir().join(format!("cnc_cell_launch_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let f = dir.join("c.yaml");
        for (text, why) in [
            ("cell: {machines: [], order: {name: a, program: p.nc, parts: 1}}", "no machine"),
            ("cell: {machines: [{config: x.yaml}], order: {name: a, program: p.nc, parts: 0}}", "at least 1"),
            ("cell: {machines: [{config: nope.yaml}], order: {name: a, program: p.nc, parts: 1}}", "nope.yaml"),
            ("cell: {machines: [], robot: {arms: 2}}", "unknown field"),
        ] {
            std::fs::write(&f, text).expect("write");
            let e = load(&f).expect_err(text);
            assert!(e.contains(why), "{text}: {e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
