//! How the physics spreads work over threads. The physics never starts a
//! thread: the engine hands it an `Exec`, and the physics cuts its work into
//! fixed-size blocks whose results are combined in block order, so the answer
//! is bit-identical whatever the executor and however many lanes it has.
use parking_lot::Mutex;
use std::ops::{Deref, DerefMut};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs work the physics hands it.
pub trait Exec: Sync {
    /// How many lanes `for_each_lane` runs at once.
    fn lanes(&self) -> usize;
    /// Run `f(lane)` for every lane in `0..lanes()`; return when all are done.
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync));
    /// Run two different jobs, at once where the executor can (functional
    /// decomposition: the `split` mode); return when both are done.
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync));
    /// Whether the models should cut their work by function (sphere–sphere
    /// beside sphere–wall, through `join`) rather than by data.
    fn functional(&self) -> bool {
        false
    }
    /// Run `job` on one of the executor's own threads, so that the parallel
    /// sections inside it start from a lane that is already awake instead
    /// of waking every lane from outside each time. Default: right here.
    fn host(&self, job: &mut (dyn FnMut() + Send)) {
        job();
    }
    /// Run `f(lane)` for every lane in `0..lanes` (at most `lanes()`), and
    /// wake no more threads than that. Default: every lane, the rest idle.
    fn for_lanes(&self, lanes: usize, f: &(dyn Fn(usize) + Sync)) {
        self.for_each_lane(&|lane| {
            if lane < lanes {
                f(lane);
            }
        });
    }
    /// Most cores the executor's lanes can run on at once (the machine's;
    /// by default each lane has one).
    fn cores(&self) -> usize {
        self.lanes()
    }
    /// Nanoseconds of predicted work a lane must have before another is
    /// woken; an executor that only checks the cut (tests) may say 1 to get
    /// every lane.
    fn lane_cost(&self) -> usize {
        LANE_COST_NS
    }
    /// Told the lanes each section gets and why (see `lanes_of`).
    fn note_lanes(&self, _lanes: usize, _bound: Bound) {}
    /// How many lanes the sections since the last call kept busy at most,
    /// and why not more; `None` for an executor that does not count.
    fn take_busy(&self) -> Option<Busy> {
        None
    }
    /// Run `f(lane, block)` for every block in `0..blocks` on `lanes` lanes
    /// (as `lanes_of` gave them), each lane taking the next block from a
    /// shared counter as it finishes one. An executor that times blocks
    /// (the span executor) deals them itself.
    fn for_blocks(&self, lanes: usize, blocks: usize, f: &(dyn Fn(usize, usize) + Sync)) {
        let next = AtomicUsize::new(0);
        self.for_lanes(lanes, &|lane| {
            next_blocks(&next, blocks).for_each(|b| f(lane, b));
        });
    }
}

/// The lane rule: a section gets one lane for every this many nanoseconds
/// of its predicted work, since waking a lane and handing it blocks costs
/// tens of microseconds of the caller's and the woken thread's time
/// (docs/threading.md, "How many lanes a pool section gets").
pub const LANE_COST_NS: usize = 40_000;

/// The predicted work of a section: `items` at `ns_each` nanoseconds each
/// (each site's cost per item is measured in docs/threading.md).
#[must_use]
pub const fn work_ns(items: usize, ns_each: usize) -> usize {
    items.saturating_mul(ns_each)
}

/// What held a parallel section to the lanes it got.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Bound {
    /// Every thread had work.
    #[default]
    Threads,
    /// More threads than the machine has cores: the rest would only queue.
    Cores,
    /// Fewer blocks than threads (blocks are cut by the work, never by the
    /// thread count, so the answer does not change with it).
    Blocks,
    /// Too little work to pay for waking another thread.
    Work,
}

/// The widest section of a step: `busy` of `threads` lanes, held by `bound`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Busy {
    pub busy: usize,
    pub threads: usize,
    pub bound: Bound,
}

/// The lanes a section of `blocks` blocks and `work` nanoseconds gets from
/// an executor of `threads` threads on `cores` cores, a lane costing
/// `lane_cost` nanoseconds: the least of the four limits, at least one, and which
/// limit it was (the first that binds, in the order threads, cores, work,
/// blocks).
#[must_use]
pub fn lanes_for(
    threads: usize,
    cores: usize,
    blocks: usize,
    work: usize,
    lane_cost: usize,
) -> (usize, Bound) {
    // When every thread (or core) has a lane, nothing else held it back,
    // even if the work would allow no more (8 789 spheres on 2 threads is
    // "2 of 2 busy", not "too few").
    let limits = [
        (threads, Bound::Threads),
        (cores, Bound::Cores),
        (work / lane_cost.max(1), Bound::Work),
        (blocks, Bound::Blocks),
    ];
    let least = limits.iter().map(|l| l.0).min().unwrap_or(1).max(1);
    let bound = limits
        .iter()
        .find(|l| l.0.max(1) == least)
        .map_or(Bound::Threads, |l| l.1);
    (least, bound)
}

/// The lanes `exec` gives a section of `blocks` blocks and `work`
/// nanoseconds of predicted work.
#[must_use]
pub fn lanes_of(exec: &dyn Exec, blocks: usize, work: usize) -> usize {
    let (lanes, bound) = lanes_for(exec.lanes(), exec.cores(), blocks, work, exec.lane_cost());
    exec.note_lanes(lanes, bound);
    lanes
}

/// `exec`, or the calling thread where the lane rule would give a section
/// of `blocks` blocks and `work` nanoseconds one lane anyway: for a pass
/// whose parallel form costs more than its serial one.
#[must_use]
pub fn or_serial(exec: &dyn Exec, blocks: usize, work: usize) -> &dyn Exec {
    let (lanes, _) = lanes_for(exec.lanes(), exec.cores(), blocks, work, exec.lane_cost());
    if lanes > 1 { exec } else { &Serial }
}

/// Everything on the calling thread.
#[derive(Clone, Copy, Debug, Default)]
pub struct Serial;

impl Exec for Serial {
    fn lanes(&self) -> usize {
        1
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        f(0);
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        a();
        b();
    }
}

/// Run `f(block, chunk)` for `data` cut into chunks of `block` items, the
/// chunks spread over lanes (an item costing `ns_each` nanoseconds).
pub fn for_each_chunk<T: Send>(
    exec: &dyn Exec,
    data: &mut [T],
    block: usize,
    ns_each: usize,
    f: &(dyn Fn(usize, &mut [T]) + Sync),
) {
    let work = work_ns(data.len(), ns_each);
    let chunks: Vec<Mutex<&mut [T]>> = data.chunks_mut(block).map(Mutex::new).collect();
    for_each_block_of(exec, chunks.len(), work, &|b| f(b, &mut chunks[b].lock()));
}

/// Run `f(block)` for every block in `0..blocks`, each block counted as
/// enough work for a lane (see `for_each_block_of`).
pub fn for_each_block(exec: &dyn Exec, blocks: usize, f: &(dyn Fn(usize) + Sync)) {
    for_each_block_of(exec, blocks, blocks.saturating_mul(exec.lane_cost()), f);
}

/// Run `f(block)` for every block in `0..blocks` (`work` nanoseconds in all),
/// blocks spread over the lanes `lanes_for` gives. Lanes take the next block
/// as they finish one, so uneven blocks even out; each block's result is its
/// own, so who ran it never shows.
pub fn for_each_block_of(exec: &dyn Exec, blocks: usize, work: usize, f: &(dyn Fn(usize) + Sync)) {
    let lanes = lanes_of(exec, blocks, work);
    exec.for_blocks(lanes, blocks, &|_, b| f(b));
}

/// The blocks one lane takes from a shared counter, until none are left.
pub fn next_blocks(next: &AtomicUsize, blocks: usize) -> impl Iterator<Item = usize> + '_ {
    std::iter::from_fn(move || {
        let b = next.fetch_add(1, Ordering::Relaxed);
        (b < blocks).then_some(b)
    })
}

/// One `T` per block (or lane) of a parallel section, each behind its own
/// lock so a lane holds its block's alone. Kept from step to step and only
/// grown, so the buffers inside keep their memory.
pub struct PerBlock<T>(Vec<Mutex<T>>);

impl<T> Default for PerBlock<T> {
    fn default() -> Self {
        PerBlock(Vec::new())
    }
}

impl<T: Default> PerBlock<T> {
    /// At least `n` blocks.
    pub fn ensure(&mut self, n: usize) {
        if self.0.len() < n {
            self.0.resize_with(n, Default::default);
        }
    }
}

impl<T> PerBlock<T> {
    pub fn truncate(&mut self, n: usize) {
        self.0.truncate(n);
    }
}

impl<T> Deref for PerBlock<T> {
    type Target = [Mutex<T>];
    fn deref(&self) -> &[Mutex<T>] {
        &self.0
    }
}

impl<T> DerefMut for PerBlock<T> {
    fn deref_mut(&mut self) -> &mut [Mutex<T>] {
        &mut self.0
    }
}

/// `data` cut into consecutive spans of the lengths `lens` (which must sum
/// to at most its length), each behind a lock for the lane that takes it.
pub fn spans<T>(data: &mut [T], lens: impl Iterator<Item = usize>) -> Vec<Mutex<&mut [T]>> {
    let mut rest = data;
    lens.map(|len| {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        Mutex::new(head)
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::{Bound, LANE_COST_NS, PerBlock, Serial, lanes_for, or_serial, spans, work_ns};

    #[test]
    fn lanes_follow_the_tightest_limit() {
        let w = LANE_COST_NS;
        // An executor that wants every lane (tests of the cut) gets them.
        assert_eq!(lanes_for(8, 8, 100, 10, 1), (8, Bound::Threads));
        // Under a lane's cost, one lane however many threads and items.
        assert_eq!(lanes_for(64, 2, 1, w - 1, w), (1, Bound::Work));
        assert_eq!(lanes_for(256, 2, 40, w - 1, w), (1, Bound::Work));
        // Enough work, few blocks.
        assert_eq!(lanes_for(64, 64, 3, 100 * w, w), (3, Bound::Blocks));
        // Enough of both: the cores, then the threads.
        assert_eq!(lanes_for(64, 2, 100, 100 * w, w), (2, Bound::Cores));
        assert_eq!(lanes_for(8, 64, 100, 100 * w, w), (8, Bound::Threads));
        // Work for exactly three lanes.
        assert_eq!(lanes_for(8, 8, 100, 3 * w + 1, w), (3, Bound::Work));
        // Work for exactly the threads: every one busy, nothing held back.
        assert_eq!(lanes_for(2, 2, 100, 2 * w + 5, w), (2, Bound::Threads));
        assert_eq!(lanes_for(64, 2, 100, 2 * w + 5, w), (2, Bound::Cores));
        // Never none, whatever the limits.
        assert_eq!(lanes_for(0, 0, 0, 0, w).0, 1);
        assert_eq!(lanes_for(1, 2, 100, 100 * w, w), (1, Bound::Threads));
    }

    /// The rule is by work, not items: the same count of items gets one
    /// lane where each is cheap and many where each is dear.
    #[test]
    fn lanes_follow_the_work_not_the_items() {
        let w = LANE_COST_NS;
        // 8000 free flights (3 ns each): 24 µs, one lane.
        assert_eq!(
            lanes_for(64, 64, 100, work_ns(8000, 3), w),
            (1, Bound::Work)
        );
        // 8000 cluster members (800 ns each): 6.4 ms, every lane.
        assert_eq!(
            lanes_for(64, 64, 400, work_ns(8000, 800), w),
            (64, Bound::Threads)
        );
        // Just under and just over two lanes' cost.
        assert_eq!(lanes_for(8, 8, 100, 2 * w - 1, w).0, 1);
        assert_eq!(lanes_for(8, 8, 100, 2 * w, w).0, 2);
        // The product saturates rather than wrapping to a small figure.
        assert_eq!(work_ns(usize::MAX, 2), usize::MAX);
    }

    /// A pass's parallel form runs only where the rule gives it two lanes.
    #[test]
    fn a_pass_stays_serial_under_two_lanes_of_work() {
        struct Four;
        impl super::Exec for Four {
            fn lanes(&self) -> usize {
                4
            }
            fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
                (0..4).for_each(f);
            }
            fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
                a();
                b();
            }
        }
        let w = LANE_COST_NS;
        assert_eq!(or_serial(&Four, 100, 2 * w - 1).lanes(), 1);
        assert_eq!(or_serial(&Four, 100, 2 * w).lanes(), 4);
        assert_eq!(
            or_serial(&Four, 1, 100 * w).lanes(),
            1,
            "one block is one lane"
        );
        assert_eq!(or_serial(&Serial, 100, 100 * w).lanes(), 1);
    }

    #[test]
    fn spans_cut_in_order_and_leave_the_rest() {
        let mut data: Vec<u32> = (0..10).collect();
        let cut = spans(&mut data, [3, 0, 4].into_iter());
        let got: Vec<Vec<u32>> = cut.iter().map(|s| s.lock().to_vec()).collect();
        assert_eq!(got, vec![vec![0, 1, 2], vec![], vec![3, 4, 5, 6]]);
    }

    #[test]
    fn per_block_grows_and_keeps_what_it_holds() {
        let mut blocks: PerBlock<Vec<u32>> = PerBlock::default();
        blocks.ensure(2);
        blocks[1].lock().push(7);
        blocks.ensure(1);
        assert_eq!(blocks.len(), 2);
        blocks.ensure(3);
        assert_eq!(blocks.len(), 3);
        assert_eq!(*blocks[1].lock(), vec![7]);
        blocks.truncate(1);
        assert_eq!(blocks.len(), 1);
    }
}
