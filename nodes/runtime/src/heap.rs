//! How the process's allocator treats large blocks (issue 26, decisions D63).
//!
//! A program text is up to 4 MiB and passes through several nodes' buffers. glibc's allocator
//! maps a block that large on its own, but after the first such block is freed it raises its
//! threshold to that size (a heuristic for programs that allocate and free the same size
//! again and again), and later blocks come from its per-thread heaps, which it seldom gives
//! back: after 120 loads of 4 MiB and their deletion the cell's heap was 770 MiB larger, about
//! 580 MiB of it in those heaps (the rest in DDS's sample cache, also D63). A fixed
//! threshold turns the heuristic off, so a block of 1 MiB or more is always its own mapping
//! and goes back to the system when freed.

/// Blocks of this size or more are mapped on their own and returned when freed.
pub const OWN_MAPPING_BYTES: i32 = 1024 * 1024;

/// Sets the allocator's fixed threshold; call once at the start of the process, before its
/// threads. Elsewhere than glibc it does nothing (other allocators have no such heuristic).
pub fn return_large_blocks() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes the allocator's parameters; it takes no pointers.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, OWN_MAPPING_BYTES);
    }
}
