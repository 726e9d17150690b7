//! The CPU other processes take on the CPUs this process may run on: their
//! busy time from `/proc/stat` minus this process's own (`/proc/self/stat`),
//! both in clock ticks, so "pool is slower than off" has a visible reason.
//! Under `taskset -c 0` only CPU 0 counts, the same cores as the total.
use crate::procfs;

pub use crate::procfs::MachineTicks;

/// The CPUs this process may run on (its affinity), from procfs; None off
/// Linux or when unreadable.
pub fn allowed_cpus() -> Option<Vec<usize>> {
    procfs::parse_cpu_list(&procfs::status_field("Cpus_allowed_list")?)
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
        let machine = procfs::stat_cpu_ticks(self.allowed.as_deref())?;
        let own = procfs::self_stat_ticks()?;
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

    #[test]
    fn others_are_the_machine_minus_this_process() {
        let mut o = Others::default();
        // The aggregate line of procfs's `STAT_A`: two CPUs.
        let m0 = MachineTicks {
            busy: 1385,
            total: 9485,
            cpus: 2,
        };
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
}
