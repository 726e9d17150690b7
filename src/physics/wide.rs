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

/// Whether a pass over `items` items cut in blocks of `block` takes its
/// parallel form on `exec`: on many lanes, and with two blocks of items to
/// share (any two items for an executor that asks for every lane, so tests
/// reach the form on small scenes).
#[must_use]
pub fn wide_pass(exec: &dyn Exec, items: usize, block: usize) -> bool {
    let least = if exec.lane_cost() <= 1 { 1 } else { block };
    wide(exec) && items >= 2 * least.max(1)
}

/// Whether a step on `lanes` lanes (each on a core) takes the parallel forms.
#[must_use]
pub fn wide_for(lanes: usize) -> bool {
    lanes >= WIDE_LANES
}

#[cfg(test)]
mod tests {
    use super::{WIDE_LANES, wide, wide_for, wide_pass};
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

    #[test]
    fn a_pass_takes_its_parallel_form_from_two_blocks_on() {
        assert!(!wide_pass(&Lanes(64, 64), 2 * 4096 - 1, 4096));
        assert!(wide_pass(&Lanes(64, 64), 2 * 4096, 4096));
        assert!(!wide_pass(&Lanes(2, 2), 1 << 20, 4096));
    }
}
