//! Which form the step's bookkeeping takes: the serial one, or a parallel
//! one that does more work in all but leaves less to one thread. Either
//! gives the same bits; the rule only picks the cheaper for the lanes the
//! step runs on.
use super::exec::Exec;

/// From this many lanes (on as many cores) on, the parallel forms pay: one
/// that adds work `W` to take `S` out of the serial part pays once
/// `S (lanes - 1) > W`, and the partition's add about 2.5 `S`
/// (docs/perf-log.md, 2026-12-06). One and two cores keep the serial forms.
pub const WIDE_LANES: usize = 4;

/// Whether a step on `exec` takes the parallel forms.
#[must_use]
pub fn wide(exec: &dyn Exec) -> bool {
    wide_for(exec.lanes().min(exec.cores()))
}

/// Whether a step on `lanes` lanes (each on a core) takes the parallel forms.
#[must_use]
pub fn wide_for(lanes: usize) -> bool {
    lanes >= WIDE_LANES
}

#[cfg(test)]
mod tests {
    use super::{WIDE_LANES, wide, wide_for};
    use crate::physics::exec::{Exec, Serial};

    struct Lanes(usize, usize);

    impl Exec for Lanes {
        fn lanes(&self) -> usize {
            self.0
        }
        fn cores(&self) -> usize {
            self.1
        }
        fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
            (0..self.0).for_each(f);
        }
        fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
            a();
            b();
        }
    }

    #[test]
    fn few_lanes_keep_the_serial_forms_and_many_take_the_parallel() {
        assert!(!wide_for(1));
        assert!(!wide_for(WIDE_LANES - 1));
        assert!(wide_for(WIDE_LANES));
        assert!(wide_for(256));
        assert!(!wide(&Serial));
        assert!(!wide(&Lanes(2, 64)));
        assert!(wide(&Lanes(64, 64)));
        // A pool of 64 on two cores runs two lanes at once: serial forms.
        assert!(!wide(&Lanes(64, 2)));
    }
}
