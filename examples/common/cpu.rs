//! CPU time of the calling thread for the profiling examples.

use std::sync::OnceLock;
use std::time::Instant;

/// Seconds this thread has run on a CPU (`/proc/thread-self/schedstat`, so waiting for a core
/// does not count); the wall time since the first call where that file is missing.
pub fn cpu() -> f64 {
    static START: OnceLock<Instant> = OnceLock::new();
    let on_cpu = std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok());
    on_cpu.map_or_else(
        || START.get_or_init(Instant::now).elapsed().as_secs_f64(),
        |ns| ns * 1e-9,
    )
}

/// Runs `f` and keeps in `best` the least CPU time (as [`cpu`]) a run of it has taken.
#[allow(dead_code)] // not every profiling example keeps a best time
pub fn best_time<T>(best: &mut f64, f: impl FnOnce() -> T) -> T {
    let t = cpu();
    let out = f();
    *best = best.min(cpu() - t);
    out
}
