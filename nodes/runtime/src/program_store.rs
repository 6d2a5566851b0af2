//! Program memory on disk, as a control's program memory is: one folder per machine
//! (`machine.program_directory`), a plain file per program (folders in a name such as
//! `shafts/O0010.nc` are folders on disk), written durably, its total bounded by
//! `machine.program_capacity_kib` (decisions D60). The rules are `cnc_machine::programs`'s,
//! so the task's core and `cnc program import` apply the same ones.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use cnc_machine::programs::*;

impl ProgramStorage for ProgramDir {
    fn store(&mut self, name: &str, text: &str) -> Result<(), String> {
        ProgramDir::store(self, name, text)
    }
    fn remove(&mut self, name: &str) -> Result<(), String> {
        ProgramDir::remove(self, name)
    }
}

/// The folder of one machine's programs.
#[derive(Debug, Clone)]
pub struct ProgramDir {
    pub root: PathBuf,
}

impl ProgramDir {
    pub fn new(root: &Path) -> ProgramDir {
        ProgramDir {
            root: root.to_path_buf(),
        }
    }

    fn path(&self, name: &str) -> Result<PathBuf, String> {
        if valid_program_name(name) {
            Ok(self.root.join(name))
        } else {
            Err(format!("invalid program name {name:?}"))
        }
    }

    /// Every program in the folder, and what was left out and why (a file too large or
    /// badly named, a folder too deep). A missing folder is an empty memory.
    pub fn read_all(&self) -> (BTreeMap<String, String>, Vec<String>) {
        self.read(true, usize::MAX)
    }

    /// The same, from a folder this controller does not own (an external drive): nothing is
    /// removed, and reading stops once `budget` bytes are read (the rest is reported).
    pub fn read_untouched(&self, budget: usize) -> (BTreeMap<String, String>, Vec<String>) {
        self.read(false, budget)
    }

    fn read(&self, tidy: bool, budget: usize) -> (BTreeMap<String, String>, Vec<String>) {
        let mut walk = Walk {
            tidy,
            budget,
            programs: BTreeMap::new(),
            problems: Vec::new(),
        };
        walk.folder(&self.root, "", 0);
        (walk.programs, walk.problems)
    }
}

/// One reading of a program folder.
struct Walk {
    /// Remove what a cut-short write left (only in the controller's own folder).
    tidy: bool,
    /// Bytes still to read.
    budget: usize,
    programs: BTreeMap<String, String>,
    problems: Vec<String>,
}

impl Walk {
    fn folder(&mut self, dir: &Path, prefix: &str, depth: usize) {
        let entries = match std::fs::read_dir(dir) {
            Ok(e) => e,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return,
            Err(e) => return self.problems.push(format!("{}: {e}", dir.display())),
        };
        let mut entries: Vec<_> = entries.flatten().collect();
        entries.sort_by_key(|e| e.file_name());
        for entry in entries {
            let file = entry.file_name().to_string_lossy().to_string();
            let name = format!("{prefix}{file}");
            let path = entry.path();
            // Left over by a write a crash cut short: the old file is still there.
            if crate::persist::is_leftover(&file) {
                if self.tidy {
                    let _ = std::fs::remove_file(&path);
                }
                continue;
            }
            let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
            if is_dir && depth < MAX_FOLDER_DEPTH && valid_program_name(&name) {
                self.folder(&path, &format!("{name}/"), depth + 1);
                continue;
            }
            if is_dir || !valid_program_name(&name) {
                self.problems
                    .push(format!("{}: not a program name, left out", path.display()));
                continue;
            }
            match std::fs::metadata(&path) {
                Ok(m) if m.len() > MAX_PROGRAM_BYTES as u64 => self.problems.push(format!(
                    "{}: {} bytes, limit {MAX_PROGRAM_BYTES}, left out",
                    path.display(),
                    m.len()
                )),
                Ok(m) if m.len() > self.budget as u64 => self.problems.push(format!(
                    "{}: over the bytes to read, left out",
                    path.display()
                )),
                _ => match std::fs::read_to_string(&path) {
                    Ok(text) => {
                        self.budget = self.budget.saturating_sub(text.len());
                        self.programs.insert(name, text);
                    }
                    Err(e) => self
                        .problems
                        .push(format!("{}: {e}, left out", path.display())),
                },
            }
        }
    }
}

impl ProgramDir {
    /// Stores a program durably (its folders created).
    pub fn store(&self, name: &str, text: &str) -> Result<(), String> {
        crate::persist::write_atomic(&self.path(name)?, text)
    }

    /// Removes a program durably, and the folders it leaves empty.
    pub fn remove(&self, name: &str) -> Result<(), String> {
        let path = self.path(name)?;
        crate::persist::remove_durable(&path)?;
        let mut dir = path.parent().map(Path::to_path_buf);
        while let Some(d) = dir.filter(|d| *d != self.root && d.starts_with(&self.root)) {
            if std::fs::remove_dir(&d).is_err() {
                break;
            }
            dir = d.parent().map(Path::to_path_buf);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_may_have_folders_but_never_leave_the_program_folder() {
        for ok in ["O0010", "part.nc", "shafts/O0010.nc", "a/b/c/d/e.nc"] {
            assert!(valid_program_name(ok), "{ok}");
        }
        for bad in [
            "",
            "../etc/passwd",
            "/abs",
            "a//b",
            "a/./b",
            ".hidden",
            "a/b/c/d/e/f",
            "sp ace",
        ] {
            assert!(!valid_program_name(bad), "{bad}");
        }
    }

    #[test]
    fn the_capacity_counts_a_replaced_program_once() {
        let sizes: BTreeMap<String, usize> = [("a".to_string(), 600)].into_iter().collect();
        assert!(check_store(&sizes, "a", 1000, 1000).is_ok());
        let e = check_store(&sizes, "b", 500, 1000).unwrap_err();
        assert!(
            e.contains("400 of 1000 bytes free") && e.contains("alarm 70"),
            "{e}"
        );
        assert!(check_store(&sizes, "b", 400, 1000).is_ok());
    }

    /// Issue 45 item 6: a name ending in `.tmp` is a program like any other: storing `PART.nc`
    /// after `PART.nc.tmp` does not use the latter as its temporary file, neither is removed
    /// at the next start, and a store that fails leaves nothing behind.
    #[test]
    fn a_program_named_like_a_temporary_file_is_kept() {
        let root = std::env::temp_dir().join(format!("cnc_programs_tmp_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let dir = ProgramDir::new(&root);
        dir.store("PART.nc.tmp", "G0 X1\nM30\n").unwrap();
        dir.store("PART.nc", "G0 X2\nM30\n").unwrap();
        dir.store("half.tmp", "M30\n").unwrap();
        let (programs, problems) = dir.read_all();
        assert_eq!(
            programs.keys().collect::<Vec<_>>(),
            ["PART.nc", "PART.nc.tmp", "half.tmp"],
            "{problems:?}"
        );
        assert_eq!(programs["PART.nc.tmp"], "G0 X1\nM30\n");
        // A store that cannot be made (a folder stands where the file would go) leaves no
        // stray file.
        std::fs::create_dir_all(root.join("BUSY.nc/inside")).unwrap();
        assert!(dir.store("BUSY.nc", "M30\n").is_err());
        let stray: Vec<_> = std::fs::read_dir(&root)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(stray.is_empty(), "{stray:?}");
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn programs_and_their_folders_come_back_from_the_disk() {
        let root = std::env::temp_dir().join(format!("cnc_programs_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let dir = ProgramDir::new(&root);
        dir.store("O0001", "G0 X1\nM30\n").unwrap();
        dir.store("shafts/O0010.nc", "M99\n").unwrap();
        std::fs::write(root.join(".O0001.tmp"), "cut").unwrap();
        std::fs::write(root.join(".hidden"), "x").unwrap();
        let (programs, problems) = dir.read_all();
        assert_eq!(
            programs.keys().collect::<Vec<_>>(),
            ["O0001", "shafts/O0010.nc"]
        );
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert!(
            !root.join(".O0001.tmp").exists(),
            "a cut-short write's leftover"
        );
        dir.remove("shafts/O0010.nc").unwrap();
        assert!(!root.join("shafts").exists());
        let _ = std::fs::remove_dir_all(&root);
    }
}
