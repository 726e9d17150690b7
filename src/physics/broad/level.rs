//! One uniform grid level of the broad phase: spheres binned by the cell
//! of their ball's centre (a counting sort by cell key), the same-level
//! pairs, and the searches around a point or along the faces of the box.
use super::super::exec::{Exec, PerBlock, spans};
use super::entry::{Ball, Entry, Source};
use super::place::{place_indirect, place_layered, running_sums};
use glam::DVec3;
use parking_lot::Mutex;

/// Cell keys per parallel block; fixed so results never depend on the
/// thread count.
const KEY_BLOCK: usize = 2048;
/// From this many spheres per lane on, the sort into cells places indices,
/// then copies the records (measured: 3–6 % faster at 100 000 spheres, no
/// gain at 10 000, where everything stays in cache).
const INDIRECT_MIN: usize = 1 << 15;

/// The key of a ball too wide for the level's cells: in no cell.
pub(super) const WIDE: u32 = u32::MAX;

/// A ball within reach of nothing (NaN compares false), padding the pair
/// loops' candidate lists.
pub(super) const NOWHERE: Ball = Ball {
    pos: DVec3::NAN,
    reach: f64::NAN,
};
/// One uniform grid. It is padded with one empty layer of cells on every
/// side, so the neighbour cells of any real cell exist and need no bounds
/// checks: the 13 forward neighbours of cell `c` are 5 contiguous key ranges
/// at fixed offsets from `c`.
#[derive(Default)]
pub(super) struct Level {
    /// Real cells per side.
    pub(super) per_side: usize,
    /// Padded cells per side (`per_side + 2`).
    side: usize,
    /// The last real cell's coordinate, `per_side - 1`.
    last_cell: f64,
    inv_cell: f64,
    pub(super) cell: f64,
    pub(super) cell_start: Vec<u32>,
    /// The spheres of this level sorted by cell key, then a `NOWHERE` pad.
    pub(super) entries: Vec<Entry>,
    /// Per lane of `fill_lanes`: where each of its entries comes from.
    orders: PerBlock<Vec<u32>>,
    /// Per lane of `fill_lanes`, for a source without records: where each
    /// layer's records go next, and room for one layer's records.
    layers: PerBlock<(Vec<u32>, Vec<Entry>)>,
    /// Largest reach in this level.
    pub(super) reach_max: f64,
}

/// Real cell coordinates of `p`, clamped into `0..=last`. Truncation is
/// floor here (after max(0)), without a libm call; clamping in floating
/// point first (NaN goes to 0) lets the cast be a 32-bit one. `last` comes
/// as a float: converting it here cost as much as the rest.
#[inline]
fn cell_coords(p: DVec3, inv_cell: f64, last: f64) -> [usize; 3] {
    let c = |x: f64| (x * inv_cell).max(0.0).min(last) as u32 as usize;
    [c(p.x), c(p.y), c(p.z)]
}

/// Room for `n` entries and the `NOWHERE` pad; the old contents stay (the
/// scatter writes every slot), so no serial pass clears them. Takes the
/// entries, not the level, so it can run while the cell table is lent out.
/// The count is known, so the room is sized to it (a sixty-fourth over,
/// so a level that gains a few spheres is not moved every step): growing
/// by `resize` then `push` doubled it.
fn room(entries: &mut Vec<Entry>, n: usize) {
    entries.truncate(n);
    if entries.capacity() < n + 1 {
        entries.reserve_exact(n + 1 + n / 64 - entries.len());
    }
    entries.resize(n, Entry::default());
    entries.push(Entry {
        ball: NOWHERE,
        ..Entry::default()
    });
}
impl Level {
    /// Sizes the level for `n` spheres wanting cells of `want`. The cell
    /// table is zeroed here unless `lanes_zero` (the lanes of `fill_lanes`
    /// zero their own parts: at 100 000 spheres the table is megabytes).
    pub(super) fn shape(&mut self, size: f64, want: f64, n: usize, lanes_zero: bool) {
        // At most ~4 cells per sphere and 1024 per side keep memory O(N).
        // Empty cells are cheap to skip in the search, but every step counts,
        // sums and reads the whole table: with 8 per sphere, 100 000 dilute
        // spheres ran 3 % slower (the table left the cache), 10 000 1 %.
        let cap = ((4 * n.max(1)) as f64).cbrt().ceil().clamp(1.0, 1024.0);
        self.per_side = (size / want.max(f64::MIN_POSITIVE)).floor().clamp(1.0, cap) as usize;
        self.side = self.per_side + 2;
        self.cell = size / self.per_side as f64;
        self.inv_cell = 1.0 / self.cell;
        self.last_cell = (self.per_side - 1) as f64;
        self.reach_max = 0.0;
        let len = self.side * self.side * self.side + 1;
        if lanes_zero {
            self.cell_start.resize(len, 0);
        } else {
            self.cell_start.clear();
            self.cell_start.resize(len, 0);
        }
    }

    /// Sphere `id`'s record on its way into this level: its cell's key,
    /// or [`WIDE`] and a place in `wide` when its ball is too wide.
    #[inline(always)]
    pub(super) fn stage(
        &self,
        (pos, reach): (DVec3, f64),
        id: u32,
        wide: &mut Vec<(Ball, u32)>,
    ) -> Entry {
        let ball = Ball { pos, reach };
        let key = if self.fits(reach) {
            self.key_of(pos)
        } else {
            wide.push((ball, id));
            WIDE
        };
        Entry { ball, id, key }
    }

    #[inline]
    pub(super) fn fits(&self, reach: f64) -> bool {
        2.0 * reach <= self.cell
    }

    #[inline]
    pub(super) fn key_of(&self, p: DVec3) -> u32 {
        let [x, y, z] = cell_coords(p, self.inv_cell, self.last_cell);
        ((x + 1) + self.side * ((y + 1) + self.side * (z + 1))) as u32
    }

    /// Counting sort of `items` (ball, id, key), stable, in place: counts go
    /// to `cell_start[key]`, inclusive prefix sums make that the end of each
    /// cell, and placing the items in reverse order walks each end down to
    /// the cell's start.
    pub(super) fn fill(&mut self, items: &[Entry]) {
        for e in items {
            self.reach_max = self.reach_max.max(e.ball.reach);
            self.cell_start[e.key as usize] += 1;
        }
        let cells = self.cell_start.len() - 1;
        let sum = running_sums(&mut self.cell_start[..cells], 0);
        self.cell_start[cells] = sum;
        room(&mut self.entries, sum as usize);
        for e in items.iter().rev() {
            let slot = &mut self.cell_start[e.key as usize];
            *slot -= 1;
            self.entries[*slot as usize] = *e;
        }
    }

    /// The same counting sort as [`Level::fill`] for the first level, cut
    /// by key range over the executor's lanes: each lane counts, sums and
    /// places only the keys of its range, into its own part of the cell
    /// table and of the entries, so the layout is the same for any number
    /// of lanes.
    /// `counted`: the cell table already holds the counts of one lane
    /// (made while staging), with (how many, widest reach). A source
    /// without `records` is placed through the index arrays, and its keys'
    /// reaches are not read (the caller keeps the widest).
    // The two passes of one sort, sharing their tables, each a loop over its
    // lane's keys in a closure per lane.
    #[allow(clippy::too_many_lines, clippy::excessive_nesting)]
    pub(super) fn fill_lanes<S: Source + ?Sized>(
        &mut self,
        staged: &S,
        exec: &dyn Exec,
        counted: Option<(u32, f64)>,
    ) {
        let cells = self.cell_start.len() - 1;
        let exec: &dyn Exec = if counted.is_some() {
            &super::super::exec::Serial
        } else {
            exec
        };
        let lanes = super::super::exec::lanes_of(exec, cells, staged.keys().len()).min(64);
        let bounds: Vec<usize> = (0..=lanes).map(|l| l * cells / lanes).collect();
        let tables = spans(
            &mut self.cell_start[..cells],
            bounds.windows(2).map(|w| w[1] - w[0]),
        );
        let totals: Vec<Mutex<(u32, f64)>> = (0..lanes)
            .map(|_| Mutex::new(counted.unwrap_or((0, 0.0))))
            .collect();
        // A source without records (a million spheres and more: the keyed
        // first level) is sorted by layers of cells (see `place_layered`),
        // which are counted here instead of the cells.
        let layered = staged.records().is_none();
        let layer = self.side * self.side;
        self.layers.ensure(lanes);
        let layers = &self.layers;
        exec.for_lanes(lanes, &|l| {
            if counted.is_some() {
                return;
            }
            let (lo, hi) = (bounds[l] as u32, bounds[l + 1] as u32);
            let mut table = tables[l].lock();
            table.fill(0);
            let mut reach_max: f64 = 0.0;
            let mut count = 0;
            let mut guard = layers[l].lock();
            let heads = &mut guard.0;
            heads.clear();
            let layers_here = if layered {
                table.len().div_ceil(layer)
            } else {
                0
            };
            heads.resize(layers_here, 0);
            for (key, reach) in staged.keys() {
                if key >= lo && key < hi {
                    if layered {
                        heads[(key - lo) as usize / layer] += 1;
                    } else {
                        table[(key - lo) as usize] += 1;
                    }
                    // Not `f64::max`: its NaN handling makes a slow chain
                    // through every sphere, and reaches are never NaN here.
                    if reach > reach_max {
                        reach_max = reach;
                    }
                    count += 1;
                }
            }
            *totals[l].lock() = (count, reach_max);
        });
        let mut offsets = Vec::with_capacity(lanes + 1);
        let mut sum = 0u32;
        for t in &totals {
            let (count, reach_max) = *t.lock();
            offsets.push(sum);
            sum += count;
            self.reach_max = self.reach_max.max(reach_max);
        }
        offsets.push(sum);
        room(&mut self.entries, sum as usize);
        // Past the caches, a record written anywhere in the entries costs a
        // miss: a lane then writes only where each record goes (a small
        // array that stays in cache) and copies the records over in order,
        // reading them where they lie (reads of misses overlap; writes of
        // them held the sort up).
        let records = staged.records().filter(|r| r.len() / lanes < INDIRECT_MIN);
        self.orders.ensure(lanes);
        let orders = &self.orders;
        let lens = offsets.windows(2).map(|w| (w[1] - w[0]) as usize);
        let regions = spans(&mut self.entries[..sum as usize], lens);
        exec.for_lanes(lanes, &|l| {
            let (lo, hi) = (bounds[l] as u32, bounds[l + 1] as u32);
            let mut table = tables[l].lock();
            let mut region = regions[l].lock();
            if layered {
                let mut guard = layers[l].lock();
                let (heads, scratch) = &mut *guard;
                let keys = lo..hi;
                place_layered(
                    staged,
                    keys,
                    offsets[l],
                    &mut table,
                    &mut region,
                    layer,
                    heads,
                    scratch,
                );
                return;
            }
            running_sums(&mut table, offsets[l]);
            if let Some(records) = records {
                for s in records.iter().rev() {
                    if s.key >= lo && s.key < hi {
                        let slot = &mut table[(s.key - lo) as usize];
                        *slot -= 1;
                        region[(*slot - offsets[l]) as usize] = *s;
                    }
                }
                return;
            }
            place_indirect(
                staged,
                lo..hi,
                offsets[l],
                &mut table,
                &mut region,
                &mut orders[l].lock(),
            );
        });
        drop(tables);
        self.cell_start[cells] = sum;
    }

    pub(super) fn key_blocks(&self) -> usize {
        (self.cell_start.len() - 1).div_ceil(KEY_BLOCK)
    }

    /// Same-level pairs with a sphere in key block `b`, each found once: a
    /// sphere against the rest of its cell and the next cell along x, and the
    /// cells x-1..=x+1 of the four forward rows.
    #[allow(clippy::excessive_nesting)] // the hot kernel's loops, fused by hand (perf-log.md)
    pub(super) fn block_pairs(
        &self,
        b: usize,
        go: &impl Fn() -> bool,
        f: &mut impl FnMut(u32, u32),
    ) {
        let keys = self.cell_start.len() - 1;
        let cs = &self.cell_start[..];
        let entries = &self.entries[..];
        let nowhere = (entries.len() - 1) as u32;
        let lo = cs[b * KEY_BLOCK] as usize;
        let hi = cs[((b + 1) * KEY_BLOCK).min(keys)] as usize;
        // Nearly every window holds at most a few spheres, so four indices
        // are copied from each unconditionally and only the real ones
        // counted, then the candidates are tested four at a time, padded
        // with `NOWHERE`: a loop that nearly always runs once, where five
        // short loops had exits the branch predictor could not guess. The
        // buffer lives across spheres: only what a sphere wrote is read.
        let mut buf = [nowhere; 4 * 6];
        // One sphere at a time, its windows looked up afresh: cells hold a
        // sphere or so, and state kept per cell spilled out of registers.
        for (i, e) in (lo..).zip(&entries[lo..hi]) {
            if !go() {
                return;
            }
            let (a, ia) = (&e.ball, e.id);
            let (mut len, mut all) = (0, 0);
            for (lo, hi) in self.windows(i, e.key as usize) {
                let l = lo as u32;
                buf[len..len + 4].copy_from_slice(&[l, l + 1, l + 2, l + 3]);
                len += (hi - lo).min(4);
                all += hi - lo;
            }
            buf[len..len + 4].copy_from_slice(&[nowhere; 4]);
            if all != len {
                self.wide_pairs(i, f);
                continue;
            }
            for four in buf[..len.next_multiple_of(4)].chunks_exact(4) {
                let near = |j: u32| within(a, &entries[j as usize].ball);
                // `|`, not `||`: all four tested without branches.
                if near(four[0]) | near(four[1]) | near(four[2]) | near(four[3]) {
                    for &j in four {
                        if near(j) {
                            f(ia, entries[j as usize].id);
                        }
                    }
                }
            }
        }
    }

    /// The entry ranges the pairs of entry `i` (in cell `c`) come from: the
    /// rest of its row from the next entry on up to the next cell, then the
    /// forward rows (y+1, z) and (y-1..=y+1, z+1), cells x-1..=x+1 each.
    #[inline(always)]
    fn windows(&self, i: usize, c: usize) -> [(usize, usize); 5] {
        let (cs, s) = (&self.cell_start[..], self.side);
        let (r1, r2) = (c + s - 1, c + s * s - s - 1);
        let w1 = &cs[r1..r1 + 4];
        let w2 = &cs[r2..r2 + 2 * s + 4];
        [
            (i + 1, cs[c + 2] as usize),
            (w1[0] as usize, w1[3] as usize),
            (w2[0] as usize, w2[3] as usize),
            (w2[s] as usize, w2[s + 3] as usize),
            (w2[2 * s] as usize, w2[2 * s + 3] as usize),
        ]
    }

    /// The pairs of entry `i` when a window holds more than four: rare, so
    /// kept out of the loop's registers.
    #[cold]
    #[inline(never)]
    fn wide_pairs(&self, i: usize, f: &mut impl FnMut(u32, u32)) {
        let e = &self.entries[i];
        for (lo, hi) in self.windows(i, e.key as usize) {
            scan(&e.ball, e.id, &self.entries[lo..hi], f);
        }
    }

    /// Indices of the spheres in the cells on the faces of the box.
    pub(super) fn on_faces(&self, f: &mut impl FnMut(usize)) {
        self.on_faces_of(0..self.per_side, f);
    }

    /// [`Level::on_faces`] of the cells in the planes `zs` alone.
    pub(super) fn on_faces_of(&self, zs: std::ops::Range<usize>, f: &mut impl FnMut(usize)) {
        if self.entries.len() <= 1 {
            return;
        }
        let (last, s, cs) = (self.per_side - 1, self.side, &self.cell_start);
        let key = |x: usize, y: usize, z: usize| (x + 1) + s * ((y + 1) + s * (z + 1));
        for z in zs {
            for y in 0..=last {
                let (a, b) = (key(0, y, z), key(last, y, z));
                if z == 0 || z == last || y == 0 || y == last {
                    (cs[a] as usize..cs[b + 1] as usize).for_each(&mut *f);
                } else {
                    (cs[a] as usize..cs[a + 1] as usize).for_each(&mut *f);
                    (cs[b] as usize..cs[b + 1] as usize).for_each(&mut *f);
                }
            }
        }
    }

    /// Indices of the spheres in the cells covering `p ± span`.
    #[allow(clippy::excessive_nesting)] // rows of a box of cells, batched by hand for the hot path
    pub(super) fn near(&self, p: DVec3, span: f64, f: &mut impl FnMut(usize)) {
        if self.entries.len() <= 1 {
            return;
        }
        let lo = cell_coords(p - DVec3::splat(span), self.inv_cell, self.last_cell);
        let hi = cell_coords(p + DVec3::splat(span), self.inv_cell, self.last_cell);
        let cs = &self.cell_start;
        // As in `block_pairs`: rows hold a sphere or two, so four indices
        // are copied from each unconditionally and the real ones counted,
        // and `f` runs in one loop instead of one short loop per row.
        let mut buf = [0u32; 64];
        let mut len = 0;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let k = (lo[0] + 1) + self.side * ((y + 1) + self.side * (z + 1));
                let (from, to) = (cs[k], cs[k + hi[0] - lo[0] + 1]);
                if len + 4 > buf.len() || to - from > 4 {
                    buf[..len].iter().for_each(|&j| f(j as usize));
                    len = 0;
                    if to - from > 4 {
                        (from as usize..to as usize).for_each(&mut *f);
                        continue;
                    }
                }
                buf[len..len + 4].copy_from_slice(&[from, from + 1, from + 2, from + 3]);
                len += (to - from) as usize;
            }
        }
        buf[..len].iter().for_each(|&j| f(j as usize));
    }
}
#[inline(always)]
pub(super) fn within(a: &Ball, b: &Ball) -> bool {
    let s = a.reach + b.reach;
    (a.pos - b.pos).length_squared() <= s * s
}

/// `f(ia, id)` for each of `entries` within reach of `a`.
#[inline(always)]
fn scan(a: &Ball, ia: u32, entries: &[Entry], f: &mut impl FnMut(u32, u32)) {
    for e in entries {
        if within(a, &e.ball) {
            f(ia, e.id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::exec::Serial;

    /// `n` records with keys of real cells of `level`, from a fixed LCG.
    fn records(level: &Level, n: usize) -> Vec<Entry> {
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        let mut unit = || {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n as u32)
            .map(|id| {
                let pos = DVec3::new(unit(), unit(), unit());
                Entry {
                    ball: Ball { pos, reach: 0.001 },
                    id,
                    key: level.key_of(pos),
                }
            })
            .collect()
    }

    /// Lanes run one after the other on the calling thread.
    struct OneByOne(usize);

    impl Exec for OneByOne {
        fn lanes(&self) -> usize {
            self.0
        }
        fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
            (0..self.0).for_each(f);
        }
        fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
            a();
            b();
        }
    }

    /// A source without records, as the keyed first level is.
    struct KeysOnly(Vec<Entry>);

    impl Source for KeysOnly {
        fn keys(&self) -> impl DoubleEndedIterator<Item = (u32, f64)> + ExactSizeIterator {
            self.0.iter().map(|e| (e.key, e.ball.reach))
        }
        fn entry(&self, i: usize) -> Entry {
            self.0[i]
        }
        fn records(&self) -> Option<&[Entry]> {
            None
        }
    }

    /// A source without records is sorted by layers of cells: the layout
    /// is that of a stable sort by cell key, on one lane and on two, and
    /// each cell's start is the number of records before it.
    #[test]
    fn layered_fill_is_a_stable_sort_by_key() {
        let n = 40_000;
        for lanes in [1, 2] {
            let two = OneByOne(2);
            let exec: &dyn Exec = if lanes > 1 { &two } else { &Serial };
            let mut level = Level::default();
            level.shape(1.0, 0.03, n, true);
            let items = KeysOnly(records(&level, n));
            level.fill_lanes(&items, exec, None);
            let mut want = items.0.clone();
            want.sort_by_key(|e| e.key);
            let got = &level.entries[..n];
            assert!(
                got.iter()
                    .zip(&want)
                    .all(|(a, b)| a.id == b.id && a.key == b.key),
                "{lanes} lanes: not the stable sort by key"
            );
            assert!(
                got.iter()
                    .all(|e| e.ball.pos == items.0[e.id as usize].ball.pos)
            );
            let mut per_cell = vec![0u32; level.cell_start.len() - 1];
            for e in &items.0 {
                per_cell[e.key as usize] += 1;
            }
            let mut before = 0;
            for (k, (&start, &count)) in level.cell_start.iter().zip(&per_cell).enumerate() {
                assert_eq!(start, before, "{lanes} lanes: cell {k}");
                before += count;
            }
            assert_eq!(level.cell_start[level.cell_start.len() - 1], n as u32);
            assert_eq!(level.reach_max, 0.001);
        }
    }
}
