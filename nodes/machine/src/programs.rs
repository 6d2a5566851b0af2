//! Program memory's rules (decisions D60): what a program name may be, how large a program and
//! how many programs it holds, and where what is stored goes ([`ProgramStorage`]). Pure: the
//! task's core applies them, the runtime's program folder (`cnc_runtime::program_store`) keeps
//! the files.

use std::collections::BTreeMap;

/// Largest program text accepted into program memory, bytes.
pub const MAX_PROGRAM_BYTES: usize = 4 * 1024 * 1024;

/// The name an MDI entry runs under in program memory (decisions D43).
pub const MDI_PROGRAM: &str = "MDI";

/// Programs program memory holds at most (besides the byte capacity).
pub const MAX_PROGRAMS: usize = 1000;

/// Folder levels a program name may have (`a/b/c/NAME`).
pub const MAX_FOLDER_DEPTH: usize = 4;

/// A program name: folders and a file name separated by `/`, each of letters, digits, `.`,
/// `_` and `-`, not starting with `.`; at most 128 characters and four folders.
pub fn valid_program_name(name: &str) -> bool {
    let parts: Vec<&str> = name.split('/').collect();
    name.len() <= 128
        && parts.len() <= MAX_FOLDER_DEPTH + 1
        && parts.iter().all(|p| {
            !p.is_empty()
                && p.len() <= 64
                && !p.starts_with('.')
                && p.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c))
        })
}

/// Why `text` may not be stored as `name` in a memory holding `sizes` (bytes by name) of at
/// most `capacity` bytes, if it may not: name, size, count and capacity, each with its limit
/// (alarm 70, FANUC's "no program space in memory").
pub fn check_store(
    sizes: &BTreeMap<String, usize>,
    name: &str,
    len: usize,
    capacity: u64,
) -> Result<(), String> {
    if !valid_program_name(name) {
        return Err(format!(
            "invalid program name {name:?}: folders and a name separated by '/', each of \
             letters, digits, '.', '_', '-', not starting with '.'; at most 128 characters \
             and {MAX_FOLDER_DEPTH} folders"
        ));
    }
    if len > MAX_PROGRAM_BYTES {
        return Err(format!(
            "program too large: {len} bytes, limit {MAX_PROGRAM_BYTES}"
        ));
    }
    let replaced = sizes.get(name).copied();
    if replaced.is_none() && sizes.len() >= MAX_PROGRAMS {
        return Err(format!(
            "program memory full: {MAX_PROGRAMS} programs (alarm 70)"
        ));
    }
    let used: u64 = sizes.values().map(|&n| n as u64).sum();
    let after = used - replaced.unwrap_or(0) as u64 + len as u64;
    if after > capacity {
        return Err(format!(
            "program memory full: {name} needs {len} bytes, {} of {capacity} bytes free \
             (alarm 70: delete programs first)",
            capacity.saturating_sub(used - replaced.unwrap_or(0) as u64)
        ));
    }
    Ok(())
}

/// Where program memory keeps what is stored in it: the interpreter's core calls it inside
/// a load or a delete, so the answer says whether the program is kept.
pub trait ProgramStorage: Send {
    fn store(&mut self, name: &str, text: &str) -> Result<(), String>;
    fn remove(&mut self, name: &str) -> Result<(), String>;
}

/// Program memory for this run of the cell only (no `machine.program_directory`).
pub struct InRam;

impl ProgramStorage for InRam {
    fn store(&mut self, _: &str, _: &str) -> Result<(), String> {
        Ok(())
    }
    fn remove(&mut self, _: &str) -> Result<(), String> {
        Ok(())
    }
}

/// The size in bytes of each program.
pub fn sizes(programs: &BTreeMap<String, String>) -> BTreeMap<String, usize> {
    programs.iter().map(|(n, t)| (n.clone(), t.len())).collect()
}
