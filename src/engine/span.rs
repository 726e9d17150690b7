//! The span executor: work and span measured on any machine, as Cilk's
//! scalability analyser does. It says it has `P` lanes on `P` cores, so the
//! physics cuts and deals its sections as for a pool of `P` on a `P`-core
//! machine, but it runs every lane one after another on the calling thread
//! and times each block with that thread's own CPU clock. The blocks of a
//! section are then dealt, on paper, as the pool's shared counter deals
//! them to `P` truly parallel lanes (each lane takes the next block when it
//! finishes one: greedy list scheduling in block order), and the section
//! costs the makespan of that schedule. Results are per block, so the bits
//! are those of every other executor.
//!
//! Work: the CPU of the whole job. Span on `P` lanes: the serial part (the
//! work less the sections') plus every section's makespan on its lanes (a
//! `for_lanes` section: its longest lane). Span on infinite lanes: the
//! serial part plus every section's longest block, for the parallelism
//! work/span. Hand-offs and wake-ups cost nothing here, and the lanes share
//! no memory bandwidth: the figures are predictions.
//!
//! Reading the thread's CPU clock is a system call (docs/threading.md has
//! its cost); what the readings themselves cost, measured when the executor
//! is made, is taken off every block and off the work, so the figures are
//! the physics' and not the clock's.
use crate::cpu::thread_cpu_ns;
use crate::physics::Exec;
use parking_lot::Mutex;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Work and span of a job, CPU seconds of one thread.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorkSpan {
    /// All of the job's CPU.
    pub work: f64,
    /// The serial part plus each section's makespan on the lanes it got.
    pub span: f64,
    /// The serial part plus each section's longest block (or lane).
    pub span_inf: f64,
}

impl WorkSpan {
    /// Cilk's parallelism: work over the infinite-lane span (at least 1).
    #[must_use]
    pub fn parallelism(&self) -> f64 {
        if self.span_inf > 0.0 {
            self.work / self.span_inf
        } else {
            1.0
        }
    }

    /// The speed-up the `P`-lane schedule gives: work over the span on `P`
    /// lanes. Never above `min(P, parallelism)`.
    #[must_use]
    pub fn speedup(&self) -> f64 {
        if self.span > 0.0 {
            self.work / self.span
        } else {
            1.0
        }
    }
}

/// Jobs one after another: their work and spans add.
impl std::ops::AddAssign for WorkSpan {
    fn add_assign(&mut self, o: WorkSpan) {
        self.work += o.work;
        self.span += o.span;
        self.span_inf += o.span_inf;
    }
}

/// Nanoseconds the sections of a job took: their work, their makespans on
/// the lanes they got, and their longest blocks.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    work: u64,
    span: u64,
    span_inf: u64,
    /// Clock readings taken, whose cost is not the job's.
    reads: u64,
}

/// `P` lanes on paper, one thread in fact.
pub struct SpanExec {
    lanes: usize,
    /// Sections under way: one inside another runs plainly, its time part
    /// of the enclosing block.
    depth: AtomicUsize,
    tally: Mutex<Tally>,
    /// Nanoseconds one reading of the clock costs.
    read_ns: u64,
}

/// A reading of the thread's CPU clock costs what a run of them costs each.
fn read_cost() -> u64 {
    const READS: u64 = 2000;
    let t0 = thread_cpu_ns();
    for _ in 0..READS {
        std::hint::black_box(thread_cpu_ns());
    }
    thread_cpu_ns().saturating_sub(t0) / (READS + 1)
}

impl SpanExec {
    #[must_use]
    pub fn new(lanes: usize) -> SpanExec {
        SpanExec {
            lanes: lanes.max(1),
            depth: AtomicUsize::new(0),
            tally: Mutex::new(Tally::default()),
            read_ns: read_cost(),
        }
    }

    /// What one reading of the clock costs, in nanoseconds.
    #[must_use]
    pub fn read_ns(&self) -> u64 {
        self.read_ns
    }

    /// Nanoseconds from `t` to now, less the reading's own cost.
    fn since(&self, t: u64, now: u64) -> u64 {
        now.saturating_sub(t).saturating_sub(self.read_ns)
    }

    /// Run `job` on this thread and measure its work and span.
    pub fn measure(&self, job: &mut dyn FnMut()) -> WorkSpan {
        *self.tally.lock() = Tally::default();
        let t0 = thread_cpu_ns();
        job();
        let t = *self.tally.lock();
        // At least its sections' work: the readings' cost, taken off as
        // measured at start, may take off more than they cost on a tiny job.
        let work = thread_cpu_ns()
            .saturating_sub(t0)
            .saturating_sub((t.reads + 1) * self.read_ns)
            .max(t.work);
        let serial = work.saturating_sub(t.work);
        let s = |ns: u64| ns as f64 * 1e-9;
        WorkSpan {
            work: s(work),
            span: s(serial + t.span),
            span_inf: s(serial + t.span_inf),
        }
    }

    /// Whether this section is the outermost (and is to be timed).
    fn enter(&self) -> bool {
        self.depth.fetch_add(1, Ordering::Relaxed) == 0
    }

    fn leave(&self, timed: Option<Tally>) {
        self.depth.fetch_sub(1, Ordering::Relaxed);
        if let Some(t) = timed {
            let mut tally = self.tally.lock();
            tally.work += t.work;
            tally.span += t.span;
            tally.span_inf += t.span_inf;
            tally.reads += t.reads;
        }
    }
}

/// `lanes` lanes taking blocks in order, each the next as it finishes one.
struct Schedule {
    free: BinaryHeap<Reverse<(u64, usize)>>,
}

impl Schedule {
    fn new(lanes: usize) -> Schedule {
        Schedule {
            free: (0..lanes.max(1)).map(|l| Reverse((0, l))).collect(),
        }
    }

    /// The lane that takes the next block: the first free (the lowest
    /// numbered of those free at once).
    fn next_lane(&self) -> usize {
        self.free.peek().map_or(0, |r| r.0.1)
    }

    /// The next block took `ns` on the lane `next_lane` named.
    fn took(&mut self, ns: u64) {
        if let Some(Reverse((at, lane))) = self.free.pop() {
            self.free.push(Reverse((at + ns, lane)));
        }
    }

    /// When the last lane finishes.
    fn makespan(&self) -> u64 {
        self.free.iter().map(|r| r.0.0).max().unwrap_or(0)
    }
}

/// The makespan of blocks taking `times` (in block order) on `lanes` lanes
/// that each take the next block as they finish one.
#[must_use]
pub fn makespan(lanes: usize, times: &[u64]) -> u64 {
    let mut s = Schedule::new(lanes);
    for &t in times {
        s.took(t);
    }
    s.makespan()
}

impl Exec for SpanExec {
    fn lanes(&self) -> usize {
        self.lanes
    }

    fn cores(&self) -> usize {
        self.lanes
    }

    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        self.for_lanes(self.lanes, f);
    }

    fn for_lanes(&self, lanes: usize, f: &(dyn Fn(usize) + Sync)) {
        let lanes = lanes.max(1);
        if !self.enter() {
            (0..lanes).for_each(f);
            return self.leave(None);
        }
        let (mut t, mut work, mut longest) = (thread_cpu_ns(), 0, 0);
        for lane in 0..lanes {
            f(lane);
            let now = thread_cpu_ns();
            let took = self.since(t, now);
            (work, longest) = (work + took, longest.max(took));
            t = now;
        }
        self.leave(Some(Tally {
            work,
            span: longest,
            span_inf: longest,
            reads: 1 + lanes as u64,
        }));
    }

    fn for_blocks(&self, lanes: usize, blocks: usize, f: &(dyn Fn(usize, usize) + Sync)) {
        if !self.enter() {
            (0..blocks).for_each(|b| f(0, b));
            return self.leave(None);
        }
        let mut schedule = Schedule::new(lanes);
        let (mut t, mut work, mut longest) = (thread_cpu_ns(), 0, 0);
        for b in 0..blocks {
            f(schedule.next_lane(), b);
            let now = thread_cpu_ns();
            let took = self.since(t, now);
            schedule.took(took);
            (work, longest) = (work + took, longest.max(took));
            t = now;
        }
        self.leave(Some(Tally {
            work,
            span: schedule.makespan(),
            span_inf: longest,
            reads: 1 + blocks as u64,
        }));
    }

    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        if !self.enter() {
            a();
            b();
            return self.leave(None);
        }
        let t0 = thread_cpu_ns();
        a();
        let t1 = thread_cpu_ns();
        b();
        let t2 = thread_cpu_ns();
        let (ta, tb) = (self.since(t0, t1), self.since(t1, t2));
        let longest = ta.max(tb);
        self.leave(Some(Tally {
            work: ta + tb,
            span: if self.lanes > 1 { longest } else { ta + tb },
            span_inf: longest,
            reads: 3,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_makespan_deals_each_block_to_the_first_free_lane() {
        // Two lanes: 5 → lane 0, 3 → lane 1 (free at 3), 4 → lane 1 (7),
        // 2 → lane 0 (7), 6 → lane 0 or 1 at 7: ends at 13.
        assert_eq!(makespan(2, &[5, 3, 4, 2, 6]), 13);
        // One lane is the sum; as many lanes as blocks the longest.
        assert_eq!(makespan(1, &[5, 3, 4, 2, 6]), 20);
        assert_eq!(makespan(5, &[5, 3, 4, 2, 6]), 6);
        assert_eq!(makespan(64, &[5, 3, 4, 2, 6]), 6);
        // In order, not sorted: a long block last is not balanced away.
        assert_eq!(makespan(2, &[1, 1, 1, 1, 10]), 12);
        assert_eq!(makespan(3, &[]), 0);
        assert_eq!(makespan(0, &[2, 2]), 4, "no lanes is one");
    }

    #[test]
    fn the_lane_taking_a_block_is_the_first_free_one() {
        let mut s = Schedule::new(3);
        let mut lanes = Vec::new();
        for t in [4, 1, 2, 1, 5] {
            lanes.push(s.next_lane());
            s.took(t);
        }
        // 4 on 0, 1 on 1, 2 on 2, then lane 1 (free at 1), then lane 1
        // again (free at 2, with lane 2 at 2: the lower lane).
        assert_eq!(lanes, [0, 1, 2, 1, 1]);
        assert_eq!(s.makespan(), 7);
    }

    /// Spins `ns` nanoseconds of this thread's CPU.
    fn spin(ns: u64) {
        let t0 = thread_cpu_ns();
        while thread_cpu_ns() - t0 < ns {
            std::hint::spin_loop();
        }
    }

    #[test]
    fn a_job_of_even_blocks_has_span_of_its_lanes_and_its_serial_part() {
        let exec = SpanExec::new(4);
        let ms = 1_000_000;
        let ws = exec.measure(&mut || {
            spin(4 * ms);
            exec.for_blocks(4, 8, &|lane, _| {
                assert!(lane < 4);
                spin(ms);
            });
        });
        // Work 12 ms; span 4 + 2 (8 blocks on 4 lanes); span∞ 4 + 1.
        assert!((ws.work - 12e-3).abs() < 1.5e-3, "{ws:?}");
        assert!((ws.span - 6e-3).abs() < 1.0e-3, "{ws:?}");
        assert!((ws.span_inf - 5e-3).abs() < 1.0e-3, "{ws:?}");
        assert!(ws.span_inf <= ws.span && ws.span <= ws.work);
        assert!(ws.speedup() <= 4.0 && ws.speedup() <= ws.parallelism() + 1e-12);
    }
}
