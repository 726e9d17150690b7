//! Everything ballpit reads out of Linux's `/proc`, in one place. Each
//! reader is a file read and a parser of its text, apart, so the parsers are
//! tested on strings. Off Linux (or with no /proc) the read fails and every
//! reader answers `None` (the thread list: empty).
use std::fs;

fn read(path: &str) -> Option<String> {
    fs::read_to_string(path).ok()
}

/// Clock ticks summed over CPUs, from the `cpu` lines of `/proc/stat`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MachineTicks {
    /// Ticks not idle: user, nice, system, irq, softirq, steal.
    pub busy: u64,
    /// All ticks: busy plus idle and iowait.
    pub total: u64,
    /// `cpuN` lines: the CPUs online (or those of the set asked for).
    pub cpus: usize,
}

/// The value of the `name:` line of `/proc/self/status`, trimmed.
pub(crate) fn status_field(name: &str) -> Option<String> {
    parse_field(&read("/proc/self/status")?, name).map(str::to_string)
}

/// The `name:  N kB` line of `/proc/self/status`, in KiB.
pub(crate) fn status_kib(name: &str) -> Option<u64> {
    parse_kib(&read("/proc/self/status")?, name)
}

/// The `name:  N kB` line of `/proc/meminfo`, in KiB.
pub(crate) fn meminfo_kib(name: &str) -> Option<u64> {
    parse_kib(&read("/proc/meminfo")?, name)
}

/// The 1-minute load average of the host, from `/proc/loadavg`.
pub(crate) fn loadavg_1min() -> Option<f64> {
    parse_loadavg_1min(&read("/proc/loadavg")?)
}

/// The ticks of `/proc/stat`: of every CPU, or (`Some`) of those listed.
pub(crate) fn stat_cpu_ticks(allowed: Option<&[usize]>) -> Option<MachineTicks> {
    let text = read("/proc/stat")?;
    match allowed {
        Some(cpus) => parse_stat_for(&text, cpus),
        None => parse_stat(&text),
    }
}

/// utime + stime of this process (`/proc/self/stat`), in ticks.
pub(crate) fn self_stat_ticks() -> Option<u64> {
    parse_stat_ticks(&read("/proc/self/stat")?)
}

/// The thread ids of this process (`/proc/self/task`), in directory order;
/// empty where it cannot be listed.
pub(crate) fn task_ids() -> Vec<i32> {
    let Ok(dir) = fs::read_dir("/proc/self/task") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
        .collect()
}

/// The name thread `tid` gave itself (`comm`), without the newline.
pub(crate) fn task_comm(tid: i32) -> Option<String> {
    let name = read(&format!("/proc/self/task/{tid}/comm"))?;
    Some(name.trim_end().to_string())
}

/// Nanoseconds thread `tid` ran on a CPU (`schedstat`'s first field).
pub(crate) fn task_schedstat_ns(tid: i32) -> Option<u64> {
    parse_schedstat_ns(&read(&format!("/proc/self/task/{tid}/schedstat"))?)
}

/// utime + stime of thread `tid` (its `stat`), in ticks.
pub(crate) fn task_stat_ticks(tid: i32) -> Option<u64> {
    parse_stat_ticks(&read(&format!("/proc/self/task/{tid}/stat"))?)
}

/// The rest of the line `name:…` of a `status`-like text, trimmed.
fn parse_field<'a>(text: &'a str, name: &str) -> Option<&'a str> {
    text.lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(':'))
        .map(str::trim)
}

/// The number of the first `name:  N kB` line of a /proc text.
fn parse_kib(text: &str, name: &str) -> Option<u64> {
    let line = text
        .lines()
        .find(|l| l.strip_prefix(name).is_some_and(|r| r.starts_with(':')))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The first field of `/proc/loadavg`.
fn parse_loadavg_1min(text: &str) -> Option<f64> {
    text.split_whitespace().next()?.parse().ok()
}

/// The first field of a `schedstat`.
fn parse_schedstat_ns(text: &str) -> Option<u64> {
    text.split_whitespace().next()?.parse().ok()
}

/// Parse `/proc/stat`. Guest time is already inside user and nice, so it is
/// not counted twice.
fn parse_stat(text: &str) -> Option<MachineTicks> {
    let mut lines = text.lines();
    let first = lines.next()?;
    let mut f = first.split_whitespace();
    if f.next()? != "cpu" {
        return None;
    }
    let v: Vec<u64> = f.map(|x| x.parse().ok()).collect::<Option<_>>()?;
    // user nice system idle iowait irq softirq steal (older kernels: fewer).
    let at = |i: usize| v.get(i).copied().unwrap_or(0);
    if v.len() < 4 {
        return None;
    }
    let busy = at(0) + at(1) + at(2) + at(5) + at(6) + at(7);
    let total = busy + at(3) + at(4);
    let cpus = text
        .lines()
        .filter(|l| {
            l.strip_prefix("cpu")
                .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
        })
        .count();
    Some(MachineTicks { busy, total, cpus })
}

/// Busy and total ticks of the `cpuN` lines whose N is in `allowed` (the
/// process's CPU set), `cpus` the number of them found.
fn parse_stat_for(text: &str, allowed: &[usize]) -> Option<MachineTicks> {
    let mut sum = MachineTicks {
        busy: 0,
        total: 0,
        cpus: 0,
    };
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("cpu") else {
            continue;
        };
        let Some((n, _)) = rest.split_once(' ') else {
            continue;
        };
        let Ok(n) = n.parse::<usize>() else { continue };
        if !allowed.contains(&n) {
            continue;
        }
        // The same sums as the aggregate line, on this CPU's line alone.
        let one = parse_stat(&format!("cpu {}", rest[n.to_string().len()..].trim()))?;
        sum.busy += one.busy;
        sum.total += one.total;
        sum.cpus += 1;
    }
    (sum.cpus > 0).then_some(sum)
}

/// A CPU list as `/proc/self/status` writes `Cpus_allowed_list`: `0-3,6`.
pub(crate) fn parse_cpu_list(list: &str) -> Option<Vec<usize>> {
    let mut out = Vec::new();
    for part in list.trim().split(',').filter(|p| !p.is_empty()) {
        match part.split_once('-') {
            Some((a, b)) => out.extend(a.trim().parse::<usize>().ok()?..=b.trim().parse().ok()?),
            None => out.push(part.trim().parse().ok()?),
        }
    }
    (!out.is_empty()).then_some(out)
}

/// utime + stime of a `/proc/PID/stat` line, in ticks.
fn parse_stat_ticks(stat: &str) -> Option<u64> {
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace();
    // After ')': state is field 3; utime and stime are fields 14 and 15.
    let utime: u64 = fields.nth(11)?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some(utime + stime)
}

#[cfg(test)]
mod tests {
    use super::*;

    const STAT_A: &str = "cpu  1000 50 300 8000 100 10 20 5 40 0
cpu0 500 25 150 4000 50 5 10 3 20 0
cpu1 500 25 150 4000 50 5 10 2 20 0
intr 12345 0 0
ctxt 999
btime 1700000000
processes 4242
procs_running 3
";

    #[test]
    fn reads_mem_available() {
        let text =
            "MemTotal:       24576000 kB\nMemFree:         1000 kB\nMemAvailable:   23000000 kB\n";
        assert_eq!(parse_kib(text, "MemAvailable"), Some(23_000_000));
        assert_eq!(parse_kib("MemTotal: 5 kB\n", "MemAvailable"), None);
        // The name is the whole key: `MemAvailableX:` is another line.
        assert_eq!(parse_kib("MemAvailableX: 5 kB\n", "MemAvailable"), None);
    }

    #[test]
    fn status_fields_and_sizes() {
        let text = "Name:\tballpit\nVmSize:\t  123456 kB\nVmHWM:\t    2048 kB\nCpus_allowed_list:\t0-3,6\n";
        assert_eq!(parse_kib(text, "VmSize"), Some(123_456));
        assert_eq!(parse_kib(text, "VmHWM"), Some(2048));
        assert_eq!(parse_kib(text, "VmRSS"), None);
        assert_eq!(parse_field(text, "Cpus_allowed_list"), Some("0-3,6"));
        assert_eq!(parse_field(text, "Name"), Some("ballpit"));
        assert_eq!(parse_field(text, "Cpus"), None);
    }

    #[test]
    fn load_and_schedstat_first_fields() {
        assert_eq!(parse_loadavg_1min("2.16 1.50 0.90 1/85 7953\n"), Some(2.16));
        assert_eq!(parse_loadavg_1min(""), None);
        assert_eq!(parse_schedstat_ns("123456789 2000 17\n"), Some(123_456_789));
        assert_eq!(parse_schedstat_ns("x 1"), None);
    }

    #[test]
    fn proc_stat_busy_total_and_cpus() {
        let m = parse_stat(STAT_A).unwrap();
        // busy = user + nice + system + irq + softirq + steal; guest is in user.
        assert_eq!(m.busy, 1000 + 50 + 300 + 10 + 20 + 5);
        assert_eq!(m.total, m.busy + 8000 + 100);
        assert_eq!(m.cpus, 2);
        assert_eq!(parse_stat("intr 1 2\n"), None);
        assert_eq!(parse_stat("cpu 1 2\n"), None);
    }

    #[test]
    fn only_the_allowed_cpus_count() {
        let all = parse_stat(STAT_A).unwrap();
        let cpu0 = parse_stat_for(STAT_A, &[0]).unwrap();
        assert_eq!(cpu0.cpus, 1);
        assert_eq!(cpu0.busy, 500 + 25 + 150 + 5 + 10 + 3);
        assert_eq!(cpu0.total, cpu0.busy + 4000 + 50);
        let both = parse_stat_for(STAT_A, &[0, 1]).unwrap();
        assert_eq!((both.busy, both.total, both.cpus), (all.busy, all.total, 2));
        assert_eq!(parse_stat_for(STAT_A, &[7]), None);
        assert_eq!(parse_cpu_list("0-3,6\n"), Some(vec![0, 1, 2, 3, 6]));
        assert_eq!(parse_cpu_list("1"), Some(vec![1]));
        assert_eq!(parse_cpu_list("x"), None);
    }

    #[test]
    fn own_ticks_after_odd_names() {
        let line = "42 (a) b (c)) R 1 1 1 0 -1 4194304 132 0 0 0 250 130 0 0 20 0 1 0";
        assert_eq!(parse_stat_ticks(line), Some(380));
    }

    #[test]
    fn this_process_reads_on_linux() {
        // The readers against the real files, where there are some.
        #[cfg(target_os = "linux")]
        {
            assert!(status_kib("VmHWM").is_some_and(|k| k > 0));
            assert!(meminfo_kib("MemAvailable").is_some());
            assert!(
                status_field("Cpus_allowed_list").is_some_and(|l| parse_cpu_list(&l).is_some())
            );
            assert!(stat_cpu_ticks(None).is_some_and(|m| m.cpus > 0));
            assert!(self_stat_ticks().is_some());
            let ids = task_ids();
            assert!(!ids.is_empty());
            assert!(task_comm(ids[0]).is_some());
            assert!(task_stat_ticks(ids[0]).is_some());
        }
    }
}
