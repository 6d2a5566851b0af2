//! One controller per machine on a host (issue 29, decisions D65). A machine's nodes find each
//! other by their instance name (namespace and DDS domain, [`crate::shm::instance`]) in
//! host-wide shared memory, so a second controller started by mistake with the same namespace
//! would take over the first one's channels: its motion blocks would reach the first machine's
//! drives. Each node therefore holds an exclusive lock on a file named after its instance and
//! itself while it runs; a second holder is refused with a message that names the first. The
//! locks live in `/tmp` like iceoryx2's own files, so their scope is the shared memory's: the
//! whole host, whatever network namespace a process is in. The kernel drops a lock when its
//! process ends, however it ends, so a crash leaves nothing to clean up.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};

/// Where the lock files are: one folder for every user of the host, as `/tmp` itself.
pub const LOCK_DIR: &str = "/tmp/cnc_locks";

/// A node's hold on its instance; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct InstanceLock {
    _file: File,
    pub path: PathBuf,
}

/// Takes `node`'s lock of `instance` in [`LOCK_DIR`].
pub fn acquire(instance: &str, node: &str) -> Result<InstanceLock, String> {
    acquire_in(Path::new(LOCK_DIR), instance, node)
}

/// Takes `node`'s lock of `instance` in `dir`, or says who holds it.
pub fn acquire_in(dir: &Path, instance: &str, node: &str) -> Result<InstanceLock, String> {
    if !dir.exists() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        // Shared by every user, like /tmp: anyone may add a lock, none remove another's.
        let _ = std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o1777));
    }
    let path = dir.join(format!("{instance}.{node}.lock"));
    let open = |write: bool| {
        OpenOptions::new()
            .read(true)
            .write(write)
            .create(write)
            .truncate(false)
            .mode(0o644)
            .open(&path)
    };
    // Another user's lock file can still be locked through a read-only descriptor.
    let mut file = open(true)
        .or_else(|_| open(false))
        .map_err(|e| format!("{}: {e}", path.display()))?;
    // SAFETY: flock on a descriptor this function owns; no memory is passed.
    let taken = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } == 0;
    if !taken {
        let mut holder = String::new();
        let _ = file.read_to_string(&mut holder);
        let holder = holder.trim();
        let (namespace, domain) = instance.rsplit_once("_d").unwrap_or((instance, "?"));
        return Err(format!(
            "machine {namespace} (DDS domain {domain}) already runs on this host: its {node} \
             node runs in {}; a second controller with the same namespace and domain would take \
             over its channels. Stop that one, or give this one another namespace or domain ({})",
            if holder.is_empty() {
                "another process"
            } else {
                holder
            },
            path.display()
        ));
    }
    // Who holds it, for the message a second controller gets (best effort).
    let _ = file.set_len(0);
    let _ = file.rewind();
    let _ = write!(file, "process {}", std::process::id());
    Ok(InstanceLock { _file: file, path })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_holder_is_refused_naming_the_first_and_a_released_lock_is_free_again() {
        let dir = std::env::temp_dir().join(format!("cnc_lock_test_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let first = acquire_in(&dir, "lathe1_d7", "motion").expect("the first takes it");
        let e = acquire_in(&dir, "lathe1_d7", "motion").expect_err("the second is refused");
        assert!(
            e.contains("machine lathe1 (DDS domain 7) already runs"),
            "{e}"
        );
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        // Another node, namespace or domain is another lock.
        let other_node = acquire_in(&dir, "lathe1_d7", "plc").expect("another node");
        let other_domain = acquire_in(&dir, "lathe1_d8", "motion").expect("another domain");
        let other_ns = acquire_in(&dir, "lathe2_d7", "motion").expect("another namespace");
        drop(first);
        let again = acquire_in(&dir, "lathe1_d7", "motion").expect("free once released");
        drop((again, other_node, other_domain, other_ns));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
