//! Real-time treatment for the loops that keep the machine's time: the servo loop, the io
//! node's drive loop and the PLC scan ask for `SCHED_FIFO` at the launch config's priorities,
//! with the process's memory locked and the stack touched before the first tick, and
//! optionally a CPU of their own. Only these threads: the DDS threads, the interpreter and the
//! bridge stay at normal priority, and nothing the real-time loops do waits on them (they talk
//! through iceoryx2 and non-blocking channels).
//!
//! When the system does not allow it (no `CAP_SYS_NICE`, `RLIMIT_RTPRIO` 0, no real-time
//! budget in the cgroup), the thread says why once and runs as an ordinary thread.

use std::sync::OnceLock;

/// What a thread got.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Granted {
    /// `SCHED_FIFO` at this priority.
    Fifo(i32),
    /// An ordinary thread, and why.
    Normal(String),
}

impl Granted {
    pub fn is_realtime(&self) -> bool {
        matches!(self, Granted::Fifo(_))
    }
}

fn os_error() -> String {
    std::io::Error::last_os_error().to_string()
}

/// Locks the process's memory once (`mlockall`), so a page fault cannot stall a tick. Returns
/// why not, if it failed (the first caller's answer is remembered).
///
/// What is mapped now is locked at once; what is mapped later is locked page by page as it is
/// touched (`MCL_ONFAULT`), not filled in whole by `mmap`: with `MCL_FUTURE` alone, an
/// ordinary thread mapping a large segment (iceoryx2 growing a port for a 4 MiB program)
/// fills it while it holds the process's memory-map lock, and a real-time loop that grows its
/// heap meanwhile waits for it — measured 160–210 ms for 256 MiB, against 0.2 ms with
/// `MCL_ONFAULT`, on this machine; under load that can be long enough for motion to take the
/// PLC for silent (alarm 1092, decisions D41).
pub fn lock_memory() -> Result<(), String> {
    static RESULT: OnceLock<Result<(), String>> = OnceLock::new();
    RESULT
        .get_or_init(|| {
            // SAFETY: plain syscalls with flag arguments. MCL_FUTURE without MCL_CURRENT
            // leaves the mappings the first call locked as they are. Without the first (a
            // small RLIMIT_MEMLOCK), nothing is asked for later mappings either: they would
            // fail to map once past the limit.
            if unsafe { libc::mlockall(libc::MCL_CURRENT) } != 0 {
                return Err(format!("memory not locked: mlockall: {}", os_error()));
            }
            match unsafe { libc::mlockall(libc::MCL_FUTURE | libc::MCL_ONFAULT) } {
                0 => Ok(()),
                _ => Err(format!(
                    "memory locked, but not what is mapped later: mlockall: {}",
                    os_error()
                )),
            }
        })
        .clone()
}

/// Touches `bytes` of this thread's stack so its pages are there before the first tick.
#[inline(never)]
fn touch_stack(bytes: usize) {
    let mut block = [0u8; 64 * 1024];
    std::hint::black_box(&mut block);
    if bytes > block.len() {
        touch_stack(bytes - block.len());
    }
}

/// Puts the calling thread on `cpu`.
fn pin(cpu: usize) -> Result<(), String> {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; CPU_SET writes inside it.
    let r = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    match r {
        0 => Ok(()),
        _ => Err(format!("not pinned to CPU {cpu}: {}", os_error())),
    }
}

/// Asks for real-time treatment of the calling thread (`name` for the messages). `priority`
/// 0 means: stay an ordinary thread. Logs once what it got.
pub fn enter(name: &str, priority: i32, cpu: Option<usize>, lock: bool) -> Granted {
    let mut notes = Vec::new();
    if let Some(cpu) = cpu {
        if let Err(e) = pin(cpu) {
            notes.push(e);
        }
    }
    if lock {
        if let Err(e) = lock_memory() {
            notes.push(e);
        }
    }
    touch_stack(256 * 1024);
    let granted = if priority <= 0 {
        Granted::Normal("real-time off in the launch config (realtime.*_priority 0)".into())
    } else {
        let param = libc::sched_param {
            sched_priority: priority,
        };
        // SAFETY: sets this thread's policy with a valid parameter.
        let r =
            unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
        match r {
            0 => Granted::Fifo(priority),
            e => Granted::Normal(format!(
                "SCHED_FIFO {priority} refused: {} (needs root or CAP_SYS_NICE, RLIMIT_RTPRIO \
                 {priority} or more, and a real-time budget; see README, real time)",
                std::io::Error::from_raw_os_error(e)
            )),
        }
    };
    match &granted {
        Granted::Fifo(p) if notes.is_empty() => {
            log::info!("{name}: real-time, SCHED_FIFO {p}, memory locked")
        }
        Granted::Fifo(p) => log::warn!("{name}: SCHED_FIFO {p}; {}", notes.join("; ")),
        Granted::Normal(why) => {
            notes.insert(0, why.clone());
            log::warn!("{name}: runs as an ordinary thread: {}", notes.join("; "))
        }
    }
    granted
}

/// The calling thread's scheduling policy and priority, read back from the kernel.
pub fn current() -> (i32, i32) {
    let mut policy = 0;
    let mut param = libc::sched_param { sched_priority: 0 };
    // SAFETY: reads this thread's policy into valid out-parameters.
    unsafe { libc::pthread_getschedparam(libc::pthread_self(), &mut policy, &mut param) };
    (policy, param.sched_priority)
}

/// Locked memory of this process in kB (`VmLck` of `/proc/self/status`).
pub fn locked_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmLck:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        })
        .unwrap_or(0)
}
