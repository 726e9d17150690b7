//! A stable counting sort into buckets: the one way `swept` indexes pairs
//! and members by slot (a slot's meeting pairs, its partners, a cluster's
//! members). A stable sort has one answer, so its serial form and its
//! parallel one (for many lanes, `wide.rs`) give the same, however cut.
use crate::physics::exec::{Exec, PerBlock, for_each_block, spans};
use crate::physics::wide::wide;
use parking_lot::Mutex;
use std::ops::Range;

/// Keys per range of the parallel form, at least.
const RANGE_KEYS: usize = 1024;
/// Source items per block of the parallel form, at least.
const ITEM_BLOCK: usize = 2048;

/// The parallel form's buckets: by block of the source, by range of keys,
/// the (key, item) pairs in source order. Kept to reuse their memory.
pub(super) struct Buckets<T>(PerBlock<Vec<Vec<(u32, T)>>>);

impl<T> Default for Buckets<T> {
    fn default() -> Self {
        Buckets(PerBlock::default())
    }
}

/// Whether grouping `len` source items into `keys` keys on `exec` takes
/// the parallel form ([`group_wide`]).
pub(super) fn wide_group(exec: &dyn Exec, keys: usize, len: usize) -> bool {
    wide(exec) && keys > 0 && len >= 2 * ITEM_BLOCK.min(exec.min_work()).max(1)
}

/// Groups `items` by key in `0..keys`, keeping their order within a key:
/// `out[starts[k]..starts[k + 1]]` are the items of key `k`.
pub(super) fn group<T: Copy + Default>(
    starts: &mut Vec<u32>,
    out: &mut Vec<T>,
    keys: usize,
    items: impl Iterator<Item = (u32, T)> + Clone,
) {
    starts.clear();
    starts.resize(keys + 1, 0);
    // `for_each`, not `for`: chained pair lists are then walked list by
    // list, not item by item through the chain.
    items.clone().for_each(|(k, _)| starts[k as usize + 1] += 1);
    for k in 0..keys {
        starts[k + 1] += starts[k];
    }
    out.clear();
    out.resize(starts[keys] as usize, T::default());
    items.for_each(|(k, v)| {
        let at = &mut starts[k as usize];
        out[*at as usize] = v;
        *at += 1;
    });
    // Placing moved each start to the next key's; shift back.
    for k in (1..=keys).rev() {
        starts[k] = starts[k - 1];
    }
    starts[0] = 0;
}

/// [`group`] of the items `items(0..len)` yields, in parallel (`items(r)`
/// yields those of source positions `r`, in order): each block of the source drops its
/// items into buckets by range of keys (in parallel); then each range
/// sorts its buckets, taken in block order, as [`group`] does (in
/// parallel). About one pass more than the serial form.
pub(super) fn group_wide<T, I, F>(
    exec: &dyn Exec,
    buckets: &mut Buckets<T>,
    starts: &mut Vec<u32>,
    out: &mut Vec<T>,
    keys: usize,
    len: usize,
    items: &F,
) where
    T: Copy + Default + Send + Sync,
    I: Iterator<Item = (u32, T)>,
    F: Fn(Range<usize>) -> I + Sync,
{
    // The cut changes nothing but the work: a few blocks and ranges a lane.
    let cut = 2 * exec.lanes().min(exec.cores());
    let blocks = len.div_ceil(ITEM_BLOCK).clamp(1, cut);
    let per_block = len.div_ceil(blocks);
    let ranges = keys.div_ceil(RANGE_KEYS).clamp(1, cut);
    let per_range = keys.div_ceil(ranges).max(1);
    let ranges = keys.div_ceil(per_range).max(1);
    buckets.0.ensure(blocks);
    let bs = &buckets.0;
    for_each_block(exec, blocks, &|b| {
        let mut mine = bs[b].lock();
        mine.resize_with(ranges, Vec::new);
        mine.iter_mut().for_each(Vec::clear);
        let from = (b * per_block).min(len);
        for (k, v) in items(from..((b + 1) * per_block).min(len)) {
            mine[k as usize / per_range].push((k, v));
        }
    });
    let lists: Vec<&Vec<Vec<(u32, T)>>> = buckets.0[..blocks]
        .iter_mut()
        .map(|m| &*m.get_mut())
        .collect();
    let sizes: Vec<usize> = (0..ranges)
        .map(|r| lists.iter().map(|l| l[r].len()).sum())
        .collect();
    let total: usize = sizes.iter().sum();
    starts.clear();
    starts.resize(keys + 1, 0);
    starts[keys] = total as u32;
    out.clear();
    out.resize(total, T::default());
    let outs = spans(out, sizes.iter().copied());
    let heads: Vec<Mutex<&mut [u32]>> = starts[..keys]
        .chunks_mut(per_range)
        .map(Mutex::new)
        .collect();
    let bases: Vec<u32> = sizes
        .iter()
        .scan(0u32, |at, &s| {
            let b = *at;
            *at += s as u32;
            Some(b)
        })
        .collect();
    for_each_block(exec, ranges, &|r| {
        let (mut head, mut dst) = (heads[r].lock(), outs[r].lock());
        let first = r * per_range;
        let mine = || lists.iter().flat_map(|l| l[r].iter());
        mine().for_each(|&(k, _)| head[k as usize - first] += 1);
        // Counts to each key's end in `dst`; placing from the back keeps
        // the order within a key.
        let mut at = 0u32;
        for h in head.iter_mut() {
            at += *h;
            *h = at;
        }
        for &(k, v) in mine().rev() {
            let h = &mut head[k as usize - first];
            *h -= 1;
            dst[*h as usize] = v;
        }
        for h in head.iter_mut() {
            *h += bases[r];
        }
    });
}

#[cfg(test)]
mod tests {
    use super::{Buckets, group, group_wide, wide_group};
    use crate::physics::exec::{Exec, Serial};

    /// Many lanes on as many cores, run one after another.
    struct Many;

    impl Exec for Many {
        fn lanes(&self) -> usize {
            64
        }
        fn cores(&self) -> usize {
            64
        }
        fn min_work(&self) -> usize {
            1
        }
        fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
            (0..64).rev().for_each(f);
        }
        fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
            a();
            b();
        }
    }

    #[test]
    fn items_land_in_their_key_in_their_order() {
        let items = [(2, 'a'), (0, 'b'), (2, 'c'), (3, 'd'), (0, 'e')];
        let (mut starts, mut out) = (Vec::new(), Vec::new());
        group(&mut starts, &mut out, 4, items.iter().copied());
        assert_eq!(starts, [0, 2, 2, 4, 5]);
        assert_eq!(out, ['b', 'e', 'a', 'c', 'd']);
    }

    #[test]
    fn the_parallel_form_sorts_as_the_serial_one() {
        // Keys spread unevenly, many repeated, some never used.
        for (keys, len) in [(1, 10), (7, 3), (5000, 40_000), (70_000, 9_000)] {
            let key = |i: usize| ((i * 2_654_435_761) % 1_000_003 % keys) as u32;
            let items = |r: std::ops::Range<usize>| r.map(move |i| (key(i), i as u32));
            let (mut s0, mut o0) = (Vec::new(), Vec::new());
            let mut b = Buckets::default();
            group(&mut s0, &mut o0, keys, items(0..len));
            assert!(wide_group(&Many, keys, len) && !wide_group(&Serial, keys, len));
            let (mut s1, mut o1) = (vec![9; 3], vec![1; 5]);
            group_wide(&Many, &mut b, &mut s1, &mut o1, keys, len, &items);
            assert_eq!(s0.len(), keys + 1);
            assert_eq!(o0.len(), len);
            assert_eq!(
                (s1, o1),
                (s0.clone(), o0.clone()),
                "{keys} keys, {len} items"
            );
            // Every item in its key, in its order.
            for k in 0..keys {
                let got = &o0[s0[k] as usize..s0[k + 1] as usize];
                assert!(got.windows(2).all(|w| w[0] < w[1]));
                assert!(got.iter().all(|&i| key(i as usize) == k as u32));
            }
        }
    }
}
