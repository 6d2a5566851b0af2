//! Files the machine keeps across restarts (macro variables, offsets, PLC parameters).

use std::path::Path;

/// Writes `text` to a temporary file beside `path`, then renames it over `path`, so a power
/// cut leaves either the old or the new file, never half of one.
pub fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    let tmp = path.with_extension("tmp");
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}
