//! External program drives (the 802D's CF card and USB device for EXTCALL; decisions D110):
//! a folder per drive letter in the launch config, read when a program starts. Each part
//! program found (`.SPF`, `.MPF`, any case) is callable as `D:\FOLDER\NAME`: the drive, the
//! folders and the name in capitals with backslashes and without the extension, the way
//! EXTCALL writes it. The drives are read only, never written or cleaned.

use std::collections::BTreeMap;
use std::path::Path;

use cnc_runtime::program_store::ProgramDir;

/// The most read from all drives at one start: a drive is not program memory (each program
/// keeps program memory's limit, 4 MiB, and its rules for names and folders).
const MAX_TOTAL_BYTES: usize = 256 << 20;

pub use cnc_interpreter::library::external_name;

/// Every part program (`.SPF`, `.MPF`) on the drives (letter → folder) by its EXTCALL name,
/// and what could not be read (a missing drive is no problem: nothing is plugged in). The
/// folders are read as program memory is, but never tidied.
pub fn read_drives<P: AsRef<Path>>(
    drives: &BTreeMap<String, P>,
) -> (BTreeMap<String, String>, Vec<String>) {
    let mut found = BTreeMap::new();
    let mut problems = Vec::new();
    let mut budget = MAX_TOTAL_BYTES;
    for (letter, root) in drives {
        let (programs, mut p) = ProgramDir::new(root.as_ref()).read_untouched(budget);
        problems.append(&mut p);
        for (name, text) in programs {
            budget = budget.saturating_sub(text.len());
            let upper = name.to_ascii_uppercase();
            if upper.ends_with(".SPF") || upper.ends_with(".MPF") {
                let path = format!("{}:\\{name}", letter.trim());
                found.insert(external_name(&path), text);
            }
        }
    }
    (found, problems)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_folder_is_read_as_extcall_names_and_a_missing_one_is_empty() {
        let root = std::env::temp_dir().join(format!("cnc_extdrive_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("Externe_UP")).unwrap();
        std::fs::write(root.join("Externe_UP/bohrung.spf"), "G1 X1\nM17\n").unwrap();
        std::fs::write(root.join("notes.txt"), "not a program").unwrap();
        // What a cut-short write leaves in program memory is removed there; here it stays.
        std::fs::write(root.join("old.tmp"), "someone else's").unwrap();
        let drives: BTreeMap<String, std::path::PathBuf> = [
            ("d".to_string(), root.clone()),
            ("G".to_string(), root.join("absent")),
        ]
        .into_iter()
        .collect();
        let (found, problems) = read_drives(&drives);
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(found.keys().collect::<Vec<_>>(), [r"D:\EXTERNE_UP\BOHRUNG"]);
        assert_eq!(
            external_name(r" D:\EXTERNE_UP\BOHRUNG "),
            r"D:\EXTERNE_UP\BOHRUNG"
        );
        assert_eq!(external_name("g:/x/Main.mpf"), r"G:\X\MAIN");
        // Read, never written: the folder is as it was.
        assert!(root.join("notes.txt").exists());
        assert!(root.join("old.tmp").exists());
        let _ = std::fs::remove_dir_all(&root);
    }
}
