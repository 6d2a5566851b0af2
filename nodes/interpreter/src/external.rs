//! External program drives (the 802D's CF card and USB device for EXTCALL; decisions D110):
//! a folder per drive letter in the launch config, read when a program starts. Each part
//! program found (`.SPF`, `.MPF`, any case) is callable as `D:\FOLDER\NAME`: the drive, the
//! folders and the name in capitals with backslashes and without the extension, the way
//! EXTCALL writes it. The drives are read only, never written or cleaned.

use std::collections::BTreeMap;
use std::path::Path;

/// Deepest folder level read on a drive.
const MAX_DEPTH: usize = 4;
/// Largest program read, and largest sum of them per start: a drive is not program memory.
const MAX_FILE_BYTES: u64 = 16 << 20;
const MAX_TOTAL_BYTES: u64 = 256 << 20;

/// The name EXTCALL gives a program: `d:/Externe_UP/bohrung.spf ` → `D:\EXTERNE_UP\BOHRUNG`.
pub fn external_name(path: &str) -> String {
    let mut name = path.trim().replace('/', "\\").to_ascii_uppercase();
    for ext in [".SPF", ".MPF"] {
        if let Some(stem) = name.strip_suffix(ext) {
            name = stem.to_string();
        }
    }
    name
}

/// Every program on the drives (letter → folder) by its EXTCALL name, and what could not be
/// read (a missing drive is no problem: nothing is plugged in).
pub fn read_drives<P: AsRef<Path>>(
    drives: &BTreeMap<String, P>,
) -> (BTreeMap<String, String>, Vec<String>) {
    let mut found = BTreeMap::new();
    let mut problems = Vec::new();
    let mut total = 0;
    for (letter, root) in drives {
        let prefix = format!("{}:", letter.trim().to_ascii_uppercase());
        walk(
            root.as_ref(),
            &prefix,
            0,
            &mut total,
            &mut found,
            &mut problems,
        );
    }
    (found, problems)
}

fn walk(
    dir: &Path,
    prefix: &str,
    depth: usize,
    total: &mut u64,
    found: &mut BTreeMap<String, String>,
    problems: &mut Vec<String>,
) {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return,
        Err(e) => return problems.push(format!("{}: {e}", dir.display())),
    };
    let mut entries: Vec<_> = entries.flatten().collect();
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let file = entry.file_name().to_string_lossy().to_string();
        let path = entry.path();
        let name = format!("{prefix}\\{file}");
        match entry.metadata() {
            Ok(m) if m.is_dir() && depth < MAX_DEPTH => {
                walk(&path, &name, depth + 1, total, found, problems)
            }
            Ok(m) if m.is_file() => {
                let upper = file.to_ascii_uppercase();
                if !(upper.ends_with(".SPF") || upper.ends_with(".MPF")) {
                    continue;
                }
                if m.len() > MAX_FILE_BYTES || *total + m.len() > MAX_TOTAL_BYTES {
                    problems.push(format!("{}: too large to read", path.display()));
                    continue;
                }
                match std::fs::read(&path) {
                    Ok(bytes) => {
                        *total += m.len();
                        found.insert(
                            external_name(&name),
                            String::from_utf8_lossy(&bytes).into_owned(),
                        );
                    }
                    Err(e) => problems.push(format!("{}: {e}", path.display())),
                }
            }
            Ok(_) => {}
            Err(e) => problems.push(format!("{}: {e}", path.display())),
        }
    }
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
        let _ = std::fs::remove_dir_all(&root);
    }
}
