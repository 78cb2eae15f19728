//! CPU time of the calling thread, shared by the benches that report simulated seconds per
//! CPU second.

/// The calling thread's CPU time (ns) from `/proc/thread-self/schedstat` (Linux); `None`
/// elsewhere.
pub fn thread_cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}
