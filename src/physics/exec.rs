//! How the physics spreads work over threads. The physics never starts a
//! thread: the engine hands it an `Exec`, and the physics cuts its work into
//! fixed-size blocks whose results are combined in block order, so the answer
//! is bit-identical whatever the executor and however many lanes it has.
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
/// chunks spread over lanes.
pub fn for_each_chunk<T: Send>(
    exec: &dyn Exec,
    data: &mut [T],
    block: usize,
    f: &(dyn Fn(usize, &mut [T]) + Sync),
) {
    let chunks: Vec<parking_lot::Mutex<&mut [T]>> = data
        .chunks_mut(block)
        .map(parking_lot::Mutex::new)
        .collect();
    for_each_block(exec, chunks.len(), &|b| f(b, &mut chunks[b].lock()));
}

/// Run `f(block)` for every block in `0..blocks`, blocks spread over lanes.
/// Lanes take the next block as they finish one, so uneven blocks even out;
/// each block's result is its own, so who ran it never shows.
pub fn for_each_block(exec: &dyn Exec, blocks: usize, f: &(dyn Fn(usize) + Sync)) {
    let lanes = exec.lanes().min(blocks).max(1);
    if lanes == 1 {
        (0..blocks).for_each(f);
        return;
    }
    let next = AtomicUsize::new(0);
    exec.for_each_lane(&|lane| {
        if lane < lanes {
            next_blocks(&next, blocks).for_each(f);
        }
    });
}

/// The blocks one lane takes from a shared counter, until none are left.
pub fn next_blocks(next: &AtomicUsize, blocks: usize) -> impl Iterator<Item = usize> + '_ {
    std::iter::from_fn(move || {
        let b = next.fetch_add(1, Ordering::Relaxed);
        (b < blocks).then_some(b)
    })
}
