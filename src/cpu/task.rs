//! Reading thread run times out of `/proc/self/task` (Linux only; other
//! systems get empty answers).
use super::ThreadRole;
use crate::procfs;

/// `(tid, name, cpu_seconds)` for every thread of the process, by tid. The
/// main thread (tid = pid) carries the program's name in the kernel; it is
/// listed as `main`, the name the article and the screen use for it.
pub fn read_threads() -> Vec<(i32, String, f64)> {
    let pid = std::process::id() as i32;
    let mut out: Vec<(i32, String, f64)> = procfs::task_ids()
        .into_iter()
        .filter_map(|tid| {
            // A thread may exit between listing and reading: skip it then.
            let secs = thread_cpu_seconds_of(tid)?;
            let name = procfs::task_comm(tid)?;
            let name = if tid == pid {
                ThreadRole::Main.name().into_owned()
            } else {
                name
            };
            Some((tid, name, secs))
        })
        .collect();
    out.sort_by_key(|t| t.0);
    out
}

/// CPU seconds (user + system) thread `tid` of this process has run.
pub fn thread_cpu_seconds_of(tid: i32) -> Option<f64> {
    // schedstat's first field: nanoseconds on a CPU, exact; else the ticks
    // of `stat`.
    if let Some(ns) = procfs::task_schedstat_ns(tid) {
        return Some(ns as f64 * 1e-9);
    }
    Some(tick_seconds(procfs::task_stat_ticks(tid)?))
}

/// Nanoseconds of CPU the calling thread has run (its own CPU clock,
/// `CLOCK_THREAD_CPUTIME_ID`): exact at any moment, unlike schedstat,
/// which a running thread's reader sees only up to the last tick.
pub fn thread_cpu_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    u64::try_from(t.tv_sec).unwrap_or(0) * 1_000_000_000 + u64::try_from(t.tv_nsec).unwrap_or(0)
}

/// Clock ticks of a `stat` time in seconds.
fn tick_seconds(ticks: u64) -> f64 {
    ticks as f64 / ticks_per_second()
}

/// The kernel's clock tick for `stat` times (`sysconf(_SC_CLK_TCK)`, from
/// the auxiliary vector).
fn ticks_per_second() -> f64 {
    rustix::param::clock_ticks_per_second().max(1) as f64
}

/// The calling thread's id (Linux): a system call that allocates nothing,
/// so a thread can say who it is at the edge of `ulimit -v`.
#[cfg(target_os = "linux")]
#[allow(clippy::unnecessary_wraps)] // `None` where there is no /proc
pub fn current_tid() -> Option<i32> {
    Some(rustix::thread::gettid().as_raw_nonzero().get())
}

/// No thread ids to read CPU by without /proc.
#[cfg(not(target_os = "linux"))]
pub fn current_tid() -> Option<i32> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clock_tick_is_the_kernels() {
        // USER_HZ is 100 on the Linux builds we know of; the test says so
        // if a kernel reports another (then the old constant was wrong).
        #[cfg(target_os = "linux")]
        assert_eq!(ticks_per_second(), 100.0);
    }
}
