//! The wide form of `Level::fill_lanes`: the staged keys dealt out to the
//! lanes' key ranges first, in parallel blocks, so that each lane then reads
//! its own keys alone and the sort's work does not grow with the lanes
//! (every lane scanning every key made it N × lanes). Each block keeps a
//! lane's keys in id order and a lane reads the blocks in order: the same
//! keys in the same order as its scan of them all, so the same layout.
use super::super::exec::{Exec, for_each_block_of, spans, work_ns};
use super::entry::{Entry, Source};
use super::place::{copy_in_order, layer_starts, order_room, sort_layers};

/// Staged keys per block of the deal; fixed, never the lane count.
const DEAL_BLOCK: usize = 4096;
/// Predicted nanoseconds of dealing one key (docs/threading.md).
const NS_PER_DEAL: usize = 3;

/// One block's keys, dealt.
#[derive(Default)]
struct Block {
    /// Where each lane's keys start in `picks`, then those in no lane's
    /// range (balls too wide for the level: rare, and dealt to keep the
    /// loops free of branches), then their end.
    starts: Vec<u32>,
    /// (cell key, sphere index) of the keys, grouped by lane, each group
    /// in id order.
    picks: Vec<(u32, u32)>,
    /// While dealing: each key's lane, and where each lane's next one goes.
    lane: Vec<u32>,
    next: Vec<u32>,
    /// Widest reach among `picks`.
    reach: f64,
}

/// The staged keys of the last deal, block by block; kept from step to
/// step, so the buffers keep their memory.
#[derive(Default)]
pub(super) struct Buckets {
    blocks: Vec<Block>,
    used: usize,
}

/// The lane whose range `l * cells / lanes .. (l + 1) * cells / lanes`
/// holds `key`, `lanes` for a key from `cells` on: `((key + 1) lanes - 1)
/// / cells`, computed as `((key + 1) lanes - 1/2) / cells` in floating
/// point, which is exact (the quotient lies at least `1 / (2 cells)` from
/// an integer, far above the rounding of numbers under 2^53) and much
/// cheaper than a division.
#[inline]
fn lane_of(key: u32, lanes: usize, inv_cells: f64) -> u32 {
    let l = ((f64::from(key) + 1.0) * lanes as f64 - 0.5) * inv_cells;
    (l as u32).min(lanes as u32)
}

impl Buckets {
    /// Deals the keys of `staged` to `lanes` ranges of the first `cells`
    /// keys, cut as `fill_lanes` cuts them; keys from `cells` on go to no
    /// lane. Returns the widest reach of the keys dealt.
    pub(super) fn deal<S: Source + ?Sized>(
        &mut self,
        staged: &S,
        lanes: usize,
        cells: usize,
        exec: &dyn Exec,
    ) -> f64 {
        let n = staged.keys().len();
        self.used = n.div_ceil(DEAL_BLOCK);
        if self.blocks.len() < self.used {
            self.blocks.resize_with(self.used, Block::default);
        }
        let inv_cells = 1.0 / cells as f64;
        let blocks = spans(&mut self.blocks[..self.used], (0..self.used).map(|_| 1));
        for_each_block_of(exec, blocks.len(), work_ns(n, NS_PER_DEAL), &|b| {
            let mut guard = blocks[b].lock();
            let Block {
                starts,
                picks,
                lane,
                next,
                reach,
            } = &mut guard[0];
            let ids = b * DEAL_BLOCK..((b + 1) * DEAL_BLOCK).min(n);
            starts.clear();
            starts.resize(lanes + 2, 0);
            lane.resize(ids.len(), 0);
            let mut reach_max: f64 = 0.0;
            for ((key, r), at) in staged.keys_of(ids.clone()).zip(lane.iter_mut()) {
                let l = lane_of(key, lanes, inv_cells);
                *at = l;
                starts[l as usize + 1] += 1;
                // Not `f64::max`: see `Level::fill_lanes`.
                if (l as usize) < lanes && r > reach_max {
                    reach_max = r;
                }
            }
            for l in 0..=lanes {
                starts[l + 1] += starts[l];
            }
            next.clear();
            next.extend_from_slice(&starts[..=lanes]);
            picks.resize(starts[lanes + 1] as usize, (0, 0));
            let dealt = staged.keys_of(ids.clone()).zip(lane.iter());
            for (((key, _), &l), i) in dealt.zip(ids.start as u32..) {
                let at = &mut next[l as usize];
                picks[*at as usize] = (key, i);
                *at += 1;
            }
            *reach = reach_max;
        });
        drop(blocks);
        let widest = self.blocks[..self.used].iter();
        widest.fold(0.0, |m, b| m.max(b.reach))
    }

    /// Lane `l`'s (cell key, sphere index) of the last deal, in id order,
    /// a group a block (nested loops over them cost less than a flattened
    /// iterator's checks).
    pub(super) fn lane(&self, l: usize) -> impl DoubleEndedIterator<Item = &[(u32, u32)]> + '_ {
        self.blocks[..self.used].iter().map(move |b| {
            let (from, to) = (b.starts[l] as usize, b.starts[l + 1] as usize);
            &b.picks[from..to]
        })
    }

    /// `place_indirect` of lane `l` from its dealt keys, `lo` its first key.
    pub(super) fn place_indirect<S: Source + ?Sized>(
        &self,
        l: usize,
        (staged, lo, base): (&S, u32, u32),
        table: &mut [u32],
        region: &mut [Entry],
        order: &mut Vec<u32>,
    ) {
        order_room(order, region.len());
        for group in self.lane(l).rev() {
            for &(key, i) in group.iter().rev() {
                let slot = &mut table[(key - lo) as usize];
                *slot -= 1;
                order[(*slot - base) as usize] = i;
            }
        }
        copy_in_order(staged, region, order);
    }

    /// `place_layered` of lane `l` from its dealt keys, `lo` its first key.
    #[allow(clippy::too_many_arguments)] // one lane's parts of the level
    pub(super) fn place_layered<S: Source + ?Sized>(
        &self,
        l: usize,
        (staged, lo, base): (&S, u32, u32),
        table: &mut [u32],
        region: &mut [Entry],
        layer: usize,
        heads: &mut [u32],
        scratch: &mut Vec<Entry>,
    ) {
        layer_starts(heads);
        for group in self.lane(l) {
            for &(key, i) in group {
                let head = &mut heads[(key - lo) as usize / layer];
                region[*head as usize] = staged.entry(i as usize);
                *head += 1;
            }
        }
        sort_layers(lo, base, table, region, layer, heads, scratch);
    }

    /// The direct placement of lane `l`'s records (their cells' ends in
    /// `table`), from its dealt keys.
    pub(super) fn place_records(
        &self,
        l: usize,
        (records, lo, base): (&[Entry], u32, u32),
        table: &mut [u32],
        region: &mut [Entry],
    ) {
        for group in self.lane(l).rev() {
            for &(key, i) in group.iter().rev() {
                let slot = &mut table[(key - lo) as usize];
                *slot -= 1;
                region[(*slot - base) as usize] = records[i as usize];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::entry::{Entry, Source};
    use super::super::level::tests::{KeysOnly, records};
    use super::super::level::{Level, WIDE};
    use super::lane_of;
    use crate::physics::exec::Exec;
    use crate::physics::wide::WIDE_LANES;

    /// `n` lanes on as many cores, every one given work, run one after
    /// another, last first.
    struct Many(usize);

    impl Exec for Many {
        fn lanes(&self) -> usize {
            self.0
        }
        fn cores(&self) -> usize {
            self.0
        }
        fn lane_cost(&self) -> usize {
            1
        }
        fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
            (0..self.0).rev().for_each(f);
        }
        fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
            b();
            a();
        }
    }

    #[test]
    fn a_key_goes_to_the_lane_whose_range_holds_it_and_a_wide_one_past_them() {
        for (cells, lanes) in [
            (10, 4),
            (42_875, 7),
            (42_875, 64),
            (1026 * 1026 * 1026, 256),
        ] {
            let bound = |l: usize| (l * cells / lanes) as u32;
            let inv = 1.0 / cells as f64;
            for l in 0..lanes {
                for key in [bound(l), bound(l + 1) - 1] {
                    assert_eq!(lane_of(key, lanes, inv), l as u32, "{cells} {lanes} {key}");
                }
            }
            for key in [cells as u32, WIDE] {
                assert_eq!(
                    lane_of(key, lanes, inv),
                    lanes as u32,
                    "{cells} {lanes} {key}"
                );
            }
        }
    }

    /// The level `fill_lanes` makes of `items` on `lanes` lanes: its
    /// entries (id, key, ball bits), cell table and widest reach.
    fn layout<S: Source + ?Sized>(
        n: usize,
        items: &S,
        lanes: usize,
    ) -> (Vec<[u64; 6]>, Vec<u32>, f64) {
        let mut level = Level::default();
        level.shape(1.0, 0.03, n, true);
        level.fill_lanes(items, &Many(lanes), None);
        let entries = level.entries.iter().map(|e| {
            let p = e.ball.pos;
            let bits = [p.x, p.y, p.z, e.ball.reach].map(f64::to_bits);
            [
                u64::from(e.id),
                u64::from(e.key),
                bits[0],
                bits[1],
                bits[2],
                bits[3],
            ]
        });
        (entries.collect(), level.cell_start.clone(), level.reach_max)
    }

    /// Records of several reaches, every 97th too wide for the level.
    fn staged(n: usize) -> Vec<Entry> {
        let mut level = Level::default();
        level.shape(1.0, 0.03, n, false);
        let mut items = records(&level, n);
        for (i, e) in items.iter_mut().enumerate() {
            e.ball.reach *= 1.0 + (i % 5) as f64;
            if i % 97 == 3 {
                e.key = WIDE;
            }
        }
        items
    }

    /// The dealt form (from `WIDE_LANES` lanes on) gives the layout of the
    /// serial counting sort of the keys in a cell, for records placed
    /// directly, by index (many records a lane) and by layers.
    #[test]
    fn dealt_keys_give_the_serial_layout_for_any_lane_count() {
        for n in [40_000, 140_000] {
            let items = staged(n);
            let mut serial = Level::default();
            serial.shape(1.0, 0.03, n, false);
            let fitting: Vec<Entry> = items.iter().copied().filter(|e| e.key != WIDE).collect();
            serial.fill(&fitting);
            let keys_only = KeysOnly(items.clone());
            let want = layout(n, &items[..], 1);
            assert_eq!(want.1, serial.cell_start, "{n}: one lane's cells");
            assert_eq!(want.0.len(), fitting.len() + 1, "{n}: entries and the pad");
            assert!(
                want.0
                    .iter()
                    .zip(&serial.entries)
                    .all(|(a, b)| a[0] == u64::from(b.id))
            );
            assert_eq!(want.2, serial.reach_max);
            for lanes in [1, 2, WIDE_LANES - 1, WIDE_LANES, 7, 64] {
                assert!(
                    layout(n, &items[..], lanes) == want,
                    "{n} records, {lanes} lanes"
                );
                assert!(
                    layout(n, &keys_only, lanes) == want,
                    "{n} layered, {lanes} lanes"
                );
            }
        }
    }
}
