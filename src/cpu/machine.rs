//! The CPU other processes take on the CPUs this process may run on: their
//! busy time from `/proc/stat` minus this process's own (`/proc/self/stat`),
//! both in clock ticks, so "pool is slower than off" has a visible reason.
//! Under `taskset -c 0` only CPU 0 counts, the same cores as the total.
use std::fs;

/// Clock ticks summed over every CPU, from the `cpu` line of `/proc/stat`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MachineTicks {
    /// Ticks not idle: user, nice, system, irq, softirq, steal.
    pub busy: u64,
    /// All ticks: busy plus idle and iowait.
    pub total: u64,
    /// `cpuN` lines: the CPUs online.
    pub cpus: usize,
}

/// Parse `/proc/stat`. Guest time is already inside user and nice, so it is
/// not counted twice.
pub fn parse_proc_stat(text: &str) -> Option<MachineTicks> {
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
pub fn parse_proc_stat_for(text: &str, allowed: &[usize]) -> Option<MachineTicks> {
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
        let one = parse_proc_stat(&format!("cpu {}", rest[n.to_string().len()..].trim()))?;
        sum.busy += one.busy;
        sum.total += one.total;
        sum.cpus += 1;
    }
    (sum.cpus > 0).then_some(sum)
}

/// A CPU list as `/proc/self/status` writes `Cpus_allowed_list`: `0-3,6`.
pub fn parse_cpu_list(list: &str) -> Option<Vec<usize>> {
    let mut out = Vec::new();
    for part in list.trim().split(',').filter(|p| !p.is_empty()) {
        match part.split_once('-') {
            Some((a, b)) => out.extend(a.trim().parse::<usize>().ok()?..=b.trim().parse().ok()?),
            None => out.push(part.trim().parse().ok()?),
        }
    }
    (!out.is_empty()).then_some(out)
}

/// The CPUs this process may run on (its affinity), from procfs; None off
/// Linux or when unreadable.
pub fn allowed_cpus() -> Option<Vec<usize>> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    let line = status
        .lines()
        .find_map(|l| l.strip_prefix("Cpus_allowed_list:"))?;
    parse_cpu_list(line)
}

/// utime + stime of a `/proc/PID/stat` line, in ticks.
pub fn stat_ticks(stat: &str) -> Option<u64> {
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace();
    // After ')': state is field 3; utime and stime are fields 14 and 15.
    let utime: u64 = fields.nth(11)?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some(utime + stime)
}

/// Tracks the two counters between samples.
#[derive(Default)]
pub struct Others {
    last: Option<(MachineTicks, u64)>,
    /// The CPU set measured: None for every CPU.
    allowed: Option<Vec<usize>>,
}

impl Others {
    /// Others measured over `allowed` CPUs only (None: every CPU).
    pub fn on(allowed: Option<Vec<usize>>) -> Others {
        Others {
            last: None,
            allowed,
        }
    }

    /// Read both files now; the load of other processes since the last
    /// call, in percent of one core. None on the first call or off Linux.
    pub fn sample(&mut self) -> Option<f64> {
        let text = fs::read_to_string("/proc/stat").ok()?;
        let machine = match &self.allowed {
            Some(cpus) => parse_proc_stat_for(&text, cpus)?,
            None => parse_proc_stat(&text)?,
        };
        let own = stat_ticks(&fs::read_to_string("/proc/self/stat").ok()?)?;
        self.update(machine, own)
    }

    /// The step of `sample` after the reading, apart for tests.
    pub fn update(&mut self, machine: MachineTicks, own: u64) -> Option<f64> {
        let prev = self.last.replace((machine, own));
        let (m0, o0) = prev?;
        let total = machine.total.checked_sub(m0.total)?;
        if total == 0 {
            return None;
        }
        let busy = machine.busy.saturating_sub(m0.busy);
        let own = own.saturating_sub(o0);
        // Ticks of all CPUs over the interval: `total` is `cpus` cores' worth.
        let others = busy.saturating_sub(own) as f64 / total as f64;
        Some(others * machine.cpus.max(1) as f64 * 100.0)
    }
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
    fn proc_stat_busy_total_and_cpus() {
        let m = parse_proc_stat(STAT_A).unwrap();
        // busy = user + nice + system + irq + softirq + steal; guest is in user.
        assert_eq!(m.busy, 1000 + 50 + 300 + 10 + 20 + 5);
        assert_eq!(m.total, m.busy + 8000 + 100);
        assert_eq!(m.cpus, 2);
        assert_eq!(parse_proc_stat("intr 1 2\n"), None);
        assert_eq!(parse_proc_stat("cpu 1 2\n"), None);
    }

    #[test]
    fn others_are_the_machine_minus_this_process() {
        let mut o = Others::default();
        let m0 = parse_proc_stat(STAT_A).unwrap();
        assert_eq!(o.update(m0, 100), None);
        // One second on 2 CPUs at 100 Hz: 200 ticks, 150 of them busy, 60
        // of those ours: others took 90 ticks = 0.9 of one core.
        let m1 = MachineTicks {
            busy: m0.busy + 150,
            total: m0.total + 200,
            cpus: 2,
        };
        let got = o.update(m1, 160).unwrap();
        assert!((got - 90.0).abs() < 1e-9, "{got}");
        // Our ticks can run ahead of the machine's by a tick: never negative.
        let m2 = MachineTicks {
            busy: m1.busy + 10,
            total: m1.total + 200,
            cpus: 2,
        };
        assert_eq!(o.update(m2, 175), Some(0.0));
    }

    #[test]
    fn only_the_allowed_cpus_count() {
        let all = parse_proc_stat(STAT_A).unwrap();
        let cpu0 = parse_proc_stat_for(STAT_A, &[0]).unwrap();
        assert_eq!(cpu0.cpus, 1);
        assert_eq!(cpu0.busy, 500 + 25 + 150 + 5 + 10 + 3);
        assert_eq!(cpu0.total, cpu0.busy + 4000 + 50);
        let both = parse_proc_stat_for(STAT_A, &[0, 1]).unwrap();
        assert_eq!((both.busy, both.total, both.cpus), (all.busy, all.total, 2));
        assert_eq!(parse_proc_stat_for(STAT_A, &[7]), None);
        assert_eq!(parse_cpu_list("0-3,6\n"), Some(vec![0, 1, 2, 3, 6]));
        assert_eq!(parse_cpu_list("1"), Some(vec![1]));
        assert_eq!(parse_cpu_list("x"), None);
    }

    #[test]
    fn own_ticks_after_odd_names() {
        let line = "42 (a) b (c)) R 1 1 1 0 -1 4194304 132 0 0 0 250 130 0 0 20 0 1 0";
        assert_eq!(stat_ticks(line), Some(380));
    }
}
