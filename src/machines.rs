//! Which launch config `cnc` uses: a file the user names, or a machine built into the binary.
//!
//! The repository's `launch_configs/sim_lathe.yaml`, `sim_mill.yaml` and `sim_mill_802d.yaml` and the demo part are
//! embedded at build time, so an installed `cnc` (`cargo install --path .`) runs the demo cell,
//! checks and simulates programs from any folder. A built-in machine has no file to take its
//! relative paths (kept memory, parameters, recordings) from; they are taken from its data
//! folder, `$XDG_DATA_HOME/cnc/<name>`, else `~/.local/share/cnc/<name>` (the XDG base
//! directory rule: a relative `XDG_DATA_HOME` is ignored).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use cnc_runtime::LaunchConfig;

/// The built-in machines by name: the launch configs of the repository, as they were built.
pub const BUILT_IN: [(&str, &str); 4] = [
    (
        "sim_lathe",
        include_str!("../launch_configs/sim_lathe.yaml"),
    ),
    ("sim_mill", include_str!("../launch_configs/sim_mill.yaml")),
    (
        "sim_mill_802d",
        include_str!("../launch_configs/sim_mill_802d.yaml"),
    ),
    (
        "sim_turnmill",
        include_str!("../launch_configs/sim_turnmill.yaml"),
    ),
];

/// The machine `cnc` uses when no config is named.
pub const DEFAULT_MACHINE: &str = "sim_lathe";

/// The demo part `cnc` runs with no arguments: file name and text.
pub const DEMO_PROGRAM: (&str, &str) = (
    "demo_shaft.nc",
    include_str!("../examples/lathe/demo_shaft.nc"),
);

/// Where a launch config comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    File(PathBuf),
    BuiltIn(&'static str),
}

/// The `--config` argument: a file when one is at that path, else a built-in machine's name;
/// none: the default machine.
pub fn source(arg: Option<&Path>) -> Result<Source, String> {
    let Some(arg) = arg else {
        return Ok(Source::BuiltIn(DEFAULT_MACHINE));
    };
    if arg.exists() {
        return Ok(Source::File(arg.to_path_buf()));
    }
    let name = arg.to_str().unwrap_or_default();
    match BUILT_IN.iter().find(|(n, _)| *n == name) {
        Some((n, _)) => Ok(Source::BuiltIn(n)),
        None => Err(format!(
            "{}: no such launch config file, nor a built-in machine ({})",
            arg.display(),
            built_in_names()
        )),
    }
}

fn built_in_names() -> String {
    BUILT_IN.map(|(n, _)| n).join(", ")
}

/// The data folder of the built-in machine `name`, from the values of `XDG_DATA_HOME` and
/// `HOME`.
pub fn data_dir(
    name: &str,
    xdg_data_home: Option<OsString>,
    home: Option<OsString>,
) -> Result<PathBuf, String> {
    let xdg = xdg_data_home.map(PathBuf::from).filter(|p| p.is_absolute());
    let base = match (xdg, home.map(PathBuf::from).filter(|p| p.is_absolute())) {
        (Some(x), _) => x,
        (None, Some(h)) => h.join(".local/share"),
        (None, None) => {
            return Err(format!(
                "the built-in machine {name} keeps its files under $XDG_DATA_HOME or $HOME, and \
                 neither is set to an absolute path; name a launch config file with --config"
            ))
        }
    };
    Ok(base.join("cnc").join(name))
}

/// The launch config `arg` names (see [`source`]), with `tool_table` read instead of the
/// config's when given; and how to name it to the user.
pub fn load(
    arg: Option<&Path>,
    tool_table: Option<&Path>,
) -> Result<(LaunchConfig, String), String> {
    match source(arg)? {
        Source::File(path) => {
            let cfg = LaunchConfig::load_with_tool_table(&path, tool_table)?;
            Ok((cfg, path.display().to_string()))
        }
        Source::BuiltIn(name) => {
            let text = BUILT_IN
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, t)| *t)
                .unwrap_or_default();
            let dir = data_dir(
                name,
                std::env::var_os("XDG_DATA_HOME"),
                std::env::var_os("HOME"),
            )?;
            let cfg = LaunchConfig::from_yaml_in(text, &dir, tool_table)
                .map_err(|e| format!("built-in machine {name}: {e}"))?;
            Ok((
                cfg,
                format!("built-in {name}, files under {}", dir.display()),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_folder_follows_the_xdg_rule() {
        let d = |x: Option<&str>, h: Option<&str>| {
            data_dir("sim_lathe", x.map(OsString::from), h.map(OsString::from))
        };
        assert_eq!(
            d(Some("/data"), Some("/home/op")),
            Ok(PathBuf::from("/data/cnc/sim_lathe"))
        );
        assert_eq!(
            d(None, Some("/home/op")),
            Ok(PathBuf::from("/home/op/.local/share/cnc/sim_lathe"))
        );
        // A relative XDG_DATA_HOME is ignored, as the XDG rule says.
        assert_eq!(
            d(Some("rel"), Some("/home/op")),
            Ok(PathBuf::from("/home/op/.local/share/cnc/sim_lathe"))
        );
        let e = d(None, None).unwrap_err();
        assert!(e.contains("--config"), "{e}");
    }

    #[test]
    fn a_config_argument_is_a_file_or_a_built_in_machine() {
        assert_eq!(source(None), Ok(Source::BuiltIn("sim_lathe")));
        assert_eq!(
            source(Some(Path::new("sim_mill"))),
            Ok(Source::BuiltIn("sim_mill"))
        );
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/launch_configs/sim_mill.yaml");
        assert_eq!(
            source(Some(Path::new(file))),
            Ok(Source::File(PathBuf::from(file)))
        );
        let e = source(Some(Path::new("no_such.yaml"))).unwrap_err();
        assert!(
            e.contains("no_such.yaml") && e.contains("sim_lathe, sim_mill, sim_mill_802d"),
            "{e}"
        );
    }

    #[test]
    fn every_built_in_machine_loads_with_its_paths_in_its_data_folder() {
        for (name, text) in BUILT_IN {
            let dir = Path::new("/nonexistent/cnc").join(name);
            let cfg = LaunchConfig::from_yaml_in(text, &dir, None).expect(name);
            let written = cfg.written_files();
            assert!(written.len() >= 3, "{name}: {written:?}");
            for (what, path) in written {
                assert!(
                    path.starts_with(&dir),
                    "{name}: {what} at {}",
                    path.display()
                );
            }
        }
    }
}
