//! A folder of programs as a subprogram library (`cnc check --library`, the run's library):
//! the shell reads it, the interpreter's `library::add_program` files each.

use std::path::Path;

use cnc_interpreter::library::add_program;
use cnc_interpreter::Library;

/// Reads every program of a folder (the shell's job; the core never touches files).
/// Unreadable or nameless files are skipped and listed in the second value.
pub fn load_dir(dir: &Path) -> std::io::Result<(Library, Vec<String>)> {
    let mut lib = Library::new();
    let mut skipped = Vec::new();
    let mut entries: Vec<_> = std::fs::read_dir(dir)?.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.path());
    for entry in entries {
        let path = entry.path();
        if !path.is_file() {
            continue;
        }
        let Ok(bytes) = std::fs::read(&path) else {
            skipped.push(format!("{}: unreadable", path.display()));
            continue;
        };
        let Ok(text) = String::from_utf8(bytes) else {
            skipped.push(format!("{}: not UTF-8 text", path.display()));
            continue;
        };
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("?")
            .to_string();
        if let Err(taken) = add_program(&mut lib, &name, &text) {
            skipped.push(taken);
        }
    }
    Ok((lib, skipped))
}
