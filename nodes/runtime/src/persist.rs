//! Files the machine keeps across restarts (macro variables, offsets, PLC memory, programs):
//! written whole to a temporary file, flushed to the disk, renamed over the old one and the
//! folder flushed, so a kill or a power cut at any moment leaves the old or the new file,
//! never half of one, and a write reported done is on the disk (decisions D59).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc};

/// The temporary file a durable write of `path` goes through: `.<name>.tmp` beside it. The
/// leading dot puts it where no program name reaches (a name never starts with `.`,
/// `program_store::valid_program_name`), so `PART.nc.tmp` is a program like any other and
/// the leftover of a cut-short write is told apart from it (issue 45).
pub fn temporary_of(path: &Path) -> PathBuf {
    let mut name = std::ffi::OsString::from(".");
    name.push(path.file_name().unwrap_or_default());
    name.push(".tmp");
    path.with_file_name(name)
}

/// Whether a file name is the leftover of a durable write a crash cut short.
pub fn is_leftover(file_name: &str) -> bool {
    file_name.starts_with('.') && file_name.ends_with(".tmp")
}

/// Writes `bytes` to `path` durably: temporary file, `fsync`, rename, `fsync` of the folder.
/// A write that fails leaves no temporary file behind.
pub fn write_durable(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let tmp = temporary_of(path);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        })
        .and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("{}: {e}", path.display()));
    }
    sync_dir(&dir)
}

/// Flushes a folder's entries (a rename or a removal in it) to the disk.
pub fn sync_dir(dir: &Path) -> Result<(), String> {
    std::fs::File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|e| format!("{}: {e}", dir.display()))
}

/// [`write_durable`] of a text.
pub fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    write_durable(path, text.as_bytes())
}

/// Removes `path` durably (the folder flushed after it).
pub fn remove_durable(path: &Path) -> Result<(), String> {
    std::fs::remove_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => sync_dir(dir),
        None => Ok(()),
    }
}

/// Writes one file durably on a thread of its own, so a loop that must keep its period (the
/// PLC scan) hands over a snapshot and goes on. Snapshots given faster than the disk takes
/// them are coalesced: the newest wins. [`Keeper::durable`] tells which version is on the
/// disk, so a loop can hold back what it reports (a counted part) until it is kept.
pub struct Keeper {
    to_writer: Option<mpsc::Sender<(u64, Vec<u8>)>>,
    written: Arc<AtomicU64>,
    /// The last write failed (logged): what waits for the disk should not wait forever.
    failing: Arc<std::sync::atomic::AtomicBool>,
    given: u64,
    writer: Option<std::thread::JoinHandle<()>>,
}

impl Keeper {
    /// A keeper of `path`; `what` names it in the log when a write fails.
    pub fn new(path: PathBuf, what: &'static str) -> Keeper {
        let (tx, rx) = mpsc::channel::<(u64, Vec<u8>)>();
        let written = Arc::new(AtomicU64::new(0));
        let done = written.clone();
        let failing = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let failed = failing.clone();
        let writer = std::thread::Builder::new()
            .name(format!("keep {what}"))
            .spawn(move || {
                while let Ok(mut next) = rx.recv() {
                    while let Ok(newer) = rx.try_recv() {
                        next = newer;
                    }
                    match write_durable(&path, &next.1) {
                        Ok(()) => {
                            done.store(next.0, Ordering::Release);
                            failed.store(false, Ordering::Release);
                        }
                        Err(e) => {
                            log::error!("{what} not kept: {e}");
                            failed.store(true, Ordering::Release);
                        }
                    }
                }
            })
            .ok();
        Keeper {
            to_writer: Some(tx),
            written,
            failing,
            given: 0,
            writer,
        }
    }

    /// Hands over the file's new contents; returns its version.
    pub fn keep(&mut self, bytes: Vec<u8>) -> u64 {
        self.given += 1;
        if let Some(tx) = &self.to_writer {
            let _ = tx.send((self.given, bytes));
        }
        self.given
    }

    /// The newest version on the disk (0: none yet).
    pub fn durable(&self) -> u64 {
        self.written.load(Ordering::Acquire)
    }

    /// Whether the last write failed (it was logged).
    pub fn failing(&self) -> bool {
        self.failing.load(Ordering::Acquire)
    }

    /// The newest version handed over.
    pub fn given(&self) -> u64 {
        self.given
    }
}

impl Drop for Keeper {
    /// Writes what is still pending before the node stops.
    fn drop(&mut self) {
        self.to_writer = None;
        if let Some(w) = self.writer.take() {
            let _ = w.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_durable_write_replaces_the_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("cnc_persist_{}", std::process::id()));
        let file = dir.join("a.yaml");
        write_atomic(&file, "one").unwrap();
        write_atomic(&file, "two").unwrap();
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "two");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "{names:?}");
        remove_durable(&file).unwrap();
        assert!(!file.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_keeper_writes_the_newest_snapshot_and_reports_its_version() {
        let dir = std::env::temp_dir().join(format!("cnc_keeper_{}", std::process::id()));
        let file = dir.join("k.yaml");
        let mut keeper = Keeper::new(file.clone(), "test file");
        let mut last = 0;
        for i in 0..50 {
            last = keeper.keep(format!("v{i}").into_bytes());
        }
        drop(keeper);
        assert_eq!(last, 50);
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "v49");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
