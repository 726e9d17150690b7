//! The first level's counting sort, past the caches: the running sums of
//! the cell table and the two ways one lane places its records into cells
//! (by index, then copied; or layer by layer). Split from `level.rs`, which
//! owns the level and calls them.
use super::entry::{Entry, Source};

/// Inclusive running sums of `counts`, from `start` on; returns the last.
/// The table has several cells per sphere, so this pass is long: each
/// block of eight is summed on its own and only the blocks' totals form a
/// chain, one add per eight cells instead of one per cell.
pub(super) fn running_sums(counts: &mut [u32], start: u32) -> u32 {
    let mut end = start;
    let (blocks, rest) = counts.as_chunks_mut::<8>();
    for block in blocks {
        let mut v = *block;
        // Sums within the block by doubling shifts: vector adds, no chain.
        for shift in [1, 2, 4] {
            let prev = v;
            for k in shift..8 {
                v[k] += prev[k - shift];
            }
        }
        for (c, l) in block.iter_mut().zip(v) {
            *c = end + l;
        }
        end += v[7];
    }
    for c in rest {
        end += *c;
        *c = end;
    }
    end
}

/// The placement of `Level::fill_lanes` for one lane of records past the
/// caches: `order` gets where each of them comes from, then the records are
/// copied over in order (reads of misses overlap; writes of them held the
/// sort up). `keys`, `table`, `region` and `base` as in [`place_layered`];
/// the table holds the cells' ends.
pub(super) fn place_indirect<S: Source + ?Sized>(
    staged: &S,
    keys: std::ops::Range<u32>,
    base: u32,
    table: &mut [u32],
    region: &mut [Entry],
    order: &mut Vec<u32>,
) {
    let (lo, hi) = (keys.start, keys.end);
    order_room(order, region.len());
    for (i, (key, _)) in staged.keys().enumerate().rev() {
        if key >= lo && key < hi {
            let slot = &mut table[(key - lo) as usize];
            *slot -= 1;
            order[(*slot - base) as usize] = i as u32;
        }
    }
    copy_in_order(staged, region, order);
}

/// Room for `n` places in `order`, exact and a sixty-fourth over:
/// `resize` would double it.
#[inline]
pub(super) fn order_room(order: &mut Vec<u32>, n: usize) {
    order.truncate(n);
    if order.capacity() < n {
        order.reserve_exact(n + n / 64 - order.len());
    }
    order.resize(n, 0);
}

/// The records `order` names, copied into `region` in its order.
#[inline]
pub(super) fn copy_in_order<S: Source + ?Sized>(staged: &S, region: &mut [Entry], order: &[u32]) {
    for (e, &i) in region.iter_mut().zip(order.iter()) {
        *e = staged.entry(i as usize);
    }
}

/// The placement of `Level::fill_lanes` for one lane of a source without
/// records. Past the caches, a record written (or read) anywhere in memory
/// costs a miss, and past the TLB's reach a page walk too; so does a count
/// in a cell table of megabytes. So the lane deals its records out in id
/// order to their layers of cells (a z layer's worth of keys each: some
/// tens of streams, each written in order), then counts and sorts each
/// layer, which fits in the second-level cache, into its cells. `keys` are
/// the lane's, `table` their cells, `region` where their records go,
/// starting at `base` in the entries; `heads` holds each layer's count,
/// `scratch` is room for one layer.
#[allow(clippy::too_many_arguments)] // one lane's parts of the level
pub(super) fn place_layered<S: Source + ?Sized>(
    staged: &S,
    keys: std::ops::Range<u32>,
    base: u32,
    table: &mut [u32],
    region: &mut [Entry],
    layer: usize,
    heads: &mut [u32],
    scratch: &mut Vec<Entry>,
) {
    let (lo, hi) = (keys.start, keys.end);
    layer_starts(heads);
    for (i, (key, _)) in staged.keys().enumerate() {
        if key >= lo && key < hi {
            let head = &mut heads[(key - lo) as usize / layer];
            region[*head as usize] = staged.entry(i);
            *head += 1;
        }
    }
    sort_layers(lo, base, table, region, layer, heads, scratch);
}

/// Each layer's count in `heads` to where it starts in the region.
#[inline]
pub(super) fn layer_starts(heads: &mut [u32]) {
    let mut start = 0;
    for h in heads.iter_mut() {
        (*h, start) = (start, start + *h);
    }
}

/// The second half of [`place_layered`]: each layer of `region` holds its
/// records in id order and ends where its head stopped; the counting sort
/// of each, from its copy, keeps that order within a cell.
pub(super) fn sort_layers(
    lo: u32,
    base: u32,
    table: &mut [u32],
    region: &mut [Entry],
    layer: usize,
    heads: &[u32],
    scratch: &mut Vec<Entry>,
) {
    let mut from = 0;
    for (k, (cells, &to)) in table.chunks_mut(layer).zip(heads.iter()).enumerate() {
        let first = lo + (k * layer) as u32;
        scratch.clear();
        scratch.extend_from_slice(&region[from..to as usize]);
        for e in scratch.iter() {
            cells[(e.key - first) as usize] += 1;
        }
        running_sums(cells, base + from as u32);
        for e in scratch.iter().rev() {
            let slot = &mut cells[(e.key - first) as usize];
            *slot -= 1;
            region[(*slot - base) as usize] = *e;
        }
        from = to as usize;
    }
}
