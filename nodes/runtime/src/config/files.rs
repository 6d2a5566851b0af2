//! Reading a launch config: the file, the file paths it names (taken from its folder), the
//! parameter file and the tool table applied over it.

use std::path::Path;

use super::LaunchConfig;

impl LaunchConfig {
    pub fn from_yaml(text: &str) -> Result<Self, String> {
        let mut cfg: LaunchConfig =
            serde_yaml::from_str(text).map_err(|e| format!("launch config: {e}"))?;
        // The machine's own file rates the axes it does not rate explicitly at its values, and
        // sets the monitors the cell may tighten but not loosen (D124).
        cfg.limits.complete(&cfg.machine.axes);
        for (name, v) in crate::parameters::builder_monitors(&cfg) {
            cfg.limits.monitors.entry(name).or_insert(v);
        }
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads the launch config and applies the parameter file over it. A parameter file that
    /// does not apply stops the start with its entry named: the machine never runs on
    /// parameters nobody checked. Relative paths in the file are taken from its folder.
    pub fn load(path: &Path) -> Result<Self, String> {
        Self::load_with_tool_table(path, None)
    }

    /// [`LaunchConfig::load`], with `tool_table` (if given) read instead of the config's
    /// `machine.tool_table` (`cnc check --tools`).
    pub fn load_with_tool_table(path: &Path, tool_table: Option<&Path>) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Self::from_yaml_in(&text, dir, tool_table).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// A launch config read from `text` as if it were a file in `dir` (the built-in machines
    /// of the `cnc` binary have a data folder instead of a file): relative file paths in it
    /// are taken from `dir`; then the parameter file and the tool table (`tool_table` if
    /// given, as the command line names it, else the config's) are applied.
    pub fn from_yaml_in(text: &str, dir: &Path, tool_table: Option<&Path>) -> Result<Self, String> {
        let mut cfg = Self::from_yaml(text)?;
        cfg.resolve_paths(dir);
        if let Some(table) = tool_table {
            cfg.machine.tool_table = Some(table.to_path_buf());
        }
        let cfg = cfg.with_parameter_file()?;
        match cfg.machine.tool_table.clone() {
            Some(table) => cfg.with_tool_table(&table),
            None => Ok(cfg),
        }
    }

    /// Takes every relative file path of the config from `dir`: a config names its files
    /// from where it lies, so `cnc` finds them from any working directory.
    fn resolve_paths(&mut self, dir: &Path) {
        let m = &mut self.machine;
        let files = [
            &mut m.tool_table,
            &mut m.memory_file,
            &mut m.position_file,
            &mut m.msg_file,
            &mut m.program_directory,
            &mut m.parameter_file,
            &mut self.plc.program,
            &mut self.plc.memory_file,
            &mut self.hmi.operators_file,
            &mut self.servo.drive_trace,
        ];
        for file in files.into_iter().flatten() {
            if file.is_relative() {
                *file = dir.join(&*file);
            }
        }
        for folder in self.machine.external_drives.values_mut() {
            if folder.is_relative() {
                *folder = dir.join(&*folder);
            }
        }
        if self.recorder.directory.is_relative() {
            self.recorder.directory = dir.join(&self.recorder.directory);
        }
        if let Some(sec) = &mut self.network.security {
            if sec.keystore.is_relative() {
                sec.keystore = dir.join(&sec.keystore);
            }
        }
    }

    /// The files this config writes, as `(what, path)`, for the user to know where they are.
    pub fn written_files(&self) -> Vec<(&'static str, &Path)> {
        let mut out = Vec::new();
        let m = &self.machine;
        if let Some(f) = &m.memory_file {
            out.push(("kept variables and offsets", f.as_path()));
        }
        if let Some(f) = &m.position_file {
            out.push(("program position", f.as_path()));
        }
        if let Some(f) = &m.program_directory {
            out.push(("program memory", f.as_path()));
        }
        if let Some(f) = &m.msg_file {
            out.push(("MSG service file", f.as_path()));
        }
        if let Some(f) = &m.parameter_file {
            out.push(("parameters", f.as_path()));
        }
        if let Some(f) = &self.plc.memory_file {
            out.push(("PLC memory", f.as_path()));
        }
        if let Some(f) = &self.servo.drive_trace {
            out.push(("drive trace", f.as_path()));
        }
        if self.recorder.enabled {
            out.push(("recordings", self.recorder.directory.as_path()));
        }
        out
    }

    /// This config with the tools of a tool table file added to the offset page; a number
    /// both name is refused.
    pub fn with_tool_table(mut self, path: &std::path::Path) -> Result<Self, String> {
        for (n, entry) in crate::tool_table::load(path)? {
            if self.machine.tools.insert(n, entry).is_some() {
                return Err(format!(
                    "{}: tool {n} is also in machine.tools",
                    path.display()
                ));
            }
        }
        Ok(self)
    }

    /// This config with the written parameters of `machine.parameter_file` applied.
    pub fn with_parameter_file(self) -> Result<Self, String> {
        let Some(file) = self.machine.parameter_file.clone() else {
            return Ok(self);
        };
        let overlay = crate::parameters::load_file(&file)?;
        crate::parameters::apply(self, &overlay).map_err(|e| {
            format!(
                "parameter file {}: {e} (correct or remove the entry)",
                file.display()
            )
        })
    }
}
