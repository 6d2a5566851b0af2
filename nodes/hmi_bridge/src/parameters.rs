//! Parameter reads and writes from the cell (decisions D44): the values the cell runs with,
//! the values written since (stored in `machine.parameter_file`, taken at the next start), and
//! the write interlock (MDI mode, no program running), as a control's parameter write enable.

use std::path::PathBuf;

use cnc_msgs::msg::MachineState;
use cnc_runtime::parameters::{self, Overlay};
use cnc_runtime::LaunchConfig;

pub struct Parameters {
    /// What the nodes were started with.
    running: LaunchConfig,
    /// With every write since applied: what the next start runs with.
    stored: LaunchConfig,
    overlay: Overlay,
    file: Option<PathBuf>,
}

/// One parameter: name, running value, and the written value if it differs (else empty).
pub type Row = (String, String, String);

impl Parameters {
    /// `running` is the config the cell started with, the parameter file already applied.
    pub fn new(running: &LaunchConfig) -> Self {
        let file = running.machine.parameter_file.clone();
        let overlay = match file.as_deref().map(parameters::load_file) {
            Some(Ok(o)) => o,
            Some(Err(e)) => {
                log::error!("hmi_bridge: {e}");
                Overlay::new()
            }
            None => Overlay::new(),
        };
        Parameters {
            running: running.clone(),
            stored: running.clone(),
            overlay,
            file,
        }
    }

    /// The parameters whose names start with `prefix`.
    pub fn read(&self, prefix: &str) -> Vec<Row> {
        let stored = parameters::list(&self.stored);
        parameters::list(&self.running)
            .into_iter()
            .zip(stored)
            .filter(|((name, _), _)| name.starts_with(prefix))
            .map(|((name, now), (_, next))| {
                let pending = if next == now { String::new() } else { next };
                (name, now, pending)
            })
            .collect()
    }

    /// How many parameters take a new value at the next start.
    pub fn pending(&self) -> usize {
        self.read("").iter().filter(|r| !r.2.is_empty()).count()
    }

    /// Writes one parameter if the machine allows it now; stored before it is reported done.
    pub fn write(
        &mut self,
        name: &str,
        value: &str,
        machine: Option<&MachineState>,
    ) -> Result<String, String> {
        let Some(file) = self.file.clone() else {
            return Err(
                "parameter write refused: no machine.parameter_file in the launch config".into(),
            );
        };
        let Some(m) = machine else {
            return Err("parameter write refused: machine state not known yet".into());
        };
        if m.mode != MachineState::MODE_MDI {
            return Err(format!(
                "parameter write refused: mode {}, not MDI (parameter write needs MDI mode)",
                MachineState::mode_name_of(m.mode)
            ));
        }
        if matches!(
            m.execution,
            MachineState::ACTIVE | MachineState::FEED_HOLD | MachineState::INTERRUPTED
        ) {
            return Err("parameter write refused: a program is running (stop it first)".into());
        }
        let value = value.trim();
        let changed = parameters::set(&self.stored, name, value)?;
        let mut overlay = self.overlay.clone();
        overlay.insert(name.to_string(), value.to_string());
        parameters::save_file(&file, &overlay)
            .map_err(|e| format!("parameter write failed, nothing changed: {e}"))?;
        self.overlay = overlay;
        self.stored = changed;
        Ok(format!(
            "{name} = {value} stored; the cell takes it at its next start"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lathe(file: Option<PathBuf>) -> LaunchConfig {
        let text = include_str!("../../../launch_configs/sim_lathe.yaml");
        let mut cfg = LaunchConfig::from_yaml(text).expect("sim_lathe.yaml");
        cfg.machine.parameter_file = file;
        cfg
    }

    fn state(mode: u8, execution: u8) -> MachineState {
        MachineState {
            mode,
            execution,
            ..MachineState::default()
        }
    }

    #[test]
    fn a_write_needs_mdi_mode_and_no_run_and_is_pending_until_the_next_start() {
        let dir = std::env::temp_dir().join(format!("cnc_bridge_params_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("parameters.yaml");
        let _ = std::fs::remove_file(&file);
        let cfg = lathe(Some(file.clone()));
        let mut p = Parameters::new(&cfg);
        let name = "machine.axes.X.max_velocity";
        let auto = state(MachineState::MODE_AUTO, MachineState::READY);
        let e = p.write(name, "5000", Some(&auto)).unwrap_err();
        assert!(e.contains("mode AUTO, not MDI"), "{e}");
        let running = state(MachineState::MODE_MDI, MachineState::ACTIVE);
        assert!(p
            .write(name, "5000", Some(&running))
            .unwrap_err()
            .contains("running"));
        assert!(p.write(name, "5000", None).is_err());
        let mdi = state(MachineState::MODE_MDI, MachineState::READY);
        assert!(p.write(name, "-1", Some(&mdi)).is_err());
        assert!(!file.exists(), "refused writes store nothing");
        assert_eq!(p.pending(), 0);

        p.write(name, " 5000 ", Some(&mdi)).expect("written");
        assert_eq!(
            p.read(name),
            [(name.to_string(), "6000.0".to_string(), "5000.0".to_string())]
        );
        assert_eq!(p.pending(), 1);
        // The next start runs with it.
        let next = cfg.clone().with_parameter_file().expect("applies");
        assert_eq!(next.machine.axes[0].max_velocity, 5000.0);
        assert_eq!(Parameters::new(&next).pending(), 0);

        let none = Parameters::new(&lathe(None)).write(name, "5000", Some(&mdi));
        assert!(none.unwrap_err().contains("no machine.parameter_file"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
