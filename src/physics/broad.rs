//! Broad phase: which pairs can touch within a step. A hierarchy of uniform
//! grids: the first level's cell is sized for the bulk of the spheres (the
//! 98th percentile of their reach); the ones that do not fit go up to a
//! coarser level sized the same way among themselves, and so on, and the last
//! handful are tested against everything. A sphere of a coarse level meets
//! the finer levels by querying their cells over its own reach, so radii or
//! speeds spread over orders of magnitude stay about linear in cost. Tiny
//! scenes use all pairs.
use super::exec::{Exec, for_each_block, for_each_chunk};
use super::sphere::Sphere;
use glam::DVec3;
use parking_lot::Mutex;
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// At most this many spheres are tested against everything.
const ALL_PAIRS_MAX: usize = 24;
/// Cell keys per parallel block; fixed so results never depend on the
/// thread count.
const KEY_BLOCK: usize = 2048;
/// Coarse-level spheres per parallel block of cross-level queries.
const CROSS_BLOCK: usize = 64;
/// Fewer spheres than this are sorted into the first level on one lane.
const LANES_MIN_SPHERES: usize = 4096;
/// Spheres per parallel block while binning.
const BUILD_BLOCK: usize = 4096;
/// From this many spheres per lane on, the sort into cells places indices,
/// then copies the records (measured: 3–6 % faster at 100 000 spheres, no
/// gain at 10 000, where everything stays in cache).
const INDIRECT_MIN: usize = 1 << 15;
/// How far past its level's widest ball a sphere's ball may grow in a run
/// and still be found through the grid ([`Grid::near`] searches that much
/// wider). Wider searches cost more each; a narrower cap sends more balls to
/// the run's own list of grown ones, which every search walks. With whole
/// steps 1.5 made a cluster of 100 000 at packing 0.1 four times slower than
/// 2; since such steps are cut into parts (`swept/parts.rs`) clusters stay
/// small, and 1.25 against 2 (`examples/parts`, `examples/step`, in turn)
/// made dense 30k–100k 13–20 % faster and left gas at 0.005–0.1, 1k–100k,
/// projectiles and `mixed` within ±3 %.
const GROWTH_CAP: f64 = 1.25;
/// Pairs a unit of [`Grid::pairs_within`] finds before it adds them to the
/// shared total.
const LIMIT_FLUSH: usize = 256;
/// The first level's cell comes from every this-many-th reach.
const SAMPLE_STRIDE: usize = 32;

/// A sphere's ball for the step: it stays within `reach` of `pos`.
#[derive(Clone, Copy, Debug, Default)]
struct Ball {
    pos: DVec3,
    reach: f64,
}

/// A sphere in a level: its ball, id and padded cell key (on its way into
/// the first level, `u32::MAX` when too wide for it). One record, so that
/// sorting it into place writes one place in memory, not three.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    ball: Ball,
    id: u32,
    key: u32,
}

/// A pair that may touch: sphere indices, `i < j` not implied.
pub type Pair = (u32, u32);

/// One uniform grid. It is padded with one empty layer of cells on every
/// side, so the neighbour cells of any real cell exist and need no bounds
/// checks: the 13 forward neighbours of cell `c` are 5 contiguous key ranges
/// at fixed offsets from `c`.
/// A ball within reach of nothing (NaN compares false), padding the pair
/// loops' candidate lists.
const NOWHERE: Ball = Ball {
    pos: DVec3::NAN,
    reach: f64::NAN,
};

#[derive(Default)]
struct Level {
    /// Real cells per side.
    per_side: usize,
    /// Padded cells per side (`per_side + 2`).
    side: usize,
    /// The last real cell's coordinate, `per_side - 1`.
    last_cell: f64,
    inv_cell: f64,
    cell: f64,
    cell_start: Vec<u32>,
    /// The spheres of this level sorted by cell key, then a `NOWHERE` pad.
    entries: Vec<Entry>,
    /// Per lane of `fill_lanes`: where each of its entries comes from.
    orders: Vec<Mutex<Vec<u32>>>,
    /// Largest reach in this level.
    reach_max: f64,
}

#[derive(Default)]
pub struct Grid {
    levels: Vec<Level>,
    /// The last few, tested against everything.
    top: Vec<(Ball, u32)>,
    staged: Vec<Entry>,
    /// The box's side, as of the last build.
    size: f64,
    /// Spheres not yet placed in a level: (ball, id).
    rest: Vec<(Ball, u32)>,
    scratch: Vec<f64>,
    /// Per block of spheres, the balls too wide for the first level (found
    /// in parallel, joined in block order).
    wide: Vec<Mutex<Vec<(Ball, u32)>>>,
    slots: Vec<Mutex<Vec<Pair>>>,
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

/// Inclusive running sums of `counts`, from `start` on; returns the last.
/// The table has several cells per sphere, so this pass is long: each
/// block of eight is summed on its own and only the blocks' totals form a
/// chain, one add per eight cells instead of one per cell.
fn running_sums(counts: &mut [u32], start: u32) -> u32 {
    let mut end = start;
    let mut blocks = counts.chunks_exact_mut(8);
    for block in &mut blocks {
        let mut v: [u32; 8] = block.try_into().expect("eight");
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
    for c in blocks.into_remainder() {
        end += *c;
        *c = end;
    }
    end
}

/// Twice the 98th percentile of `reach` (estimated on every `stride`-th
/// value: a function of the state only, so the grid, and the order pairs
/// come out in, never depend on history), or twice `max` when the fastest is
/// close to the bulk.
fn cell_for(
    reaches: impl Iterator<Item = f64>,
    max: f64,
    stride: usize,
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.clear();
    scratch.extend(reaches.step_by(stride));
    cell_of_sample(scratch, max)
}

/// [`cell_for`] of reaches already sampled into `scratch` (reordered);
/// `max` is the widest reach known (for the first level, the sample's: a
/// sphere wider than the cell then goes up a level, as any would).
fn cell_of_sample(scratch: &mut [f64], max: f64) -> f64 {
    if scratch.is_empty() {
        return 2.0 * max;
    }
    let k = (scratch.len() * 98 / 100).min(scratch.len() - 1);
    let q = *scratch.select_nth_unstable_by(k, |a, b| a.total_cmp(b)).1;
    // When the fastest is close to the bulk, one level holds everyone.
    2.0 * if max <= 1.25 * q { max } else { q }
}

/// Room for `n` entries and the `NOWHERE` pad; the old contents stay (the
/// scatter writes every slot), so no serial pass clears them. Takes the
/// entries, not the level, so it can run while the cell table is lent out.
fn room(entries: &mut Vec<Entry>, n: usize) {
    entries.truncate(n);
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
    fn shape(&mut self, size: f64, want: f64, n: usize, lanes_zero: bool) {
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
    /// or `u32::MAX` and a place in `wide` when its ball is too wide.
    #[inline(always)]
    fn stage(&self, (pos, reach): (DVec3, f64), id: u32, wide: &mut Vec<(Ball, u32)>) -> Entry {
        let ball = Ball { pos, reach };
        let key = if self.fits(reach) {
            self.key_of(pos)
        } else {
            wide.push((ball, id));
            u32::MAX
        };
        Entry { ball, id, key }
    }

    #[inline]
    fn fits(&self, reach: f64) -> bool {
        2.0 * reach <= self.cell
    }

    #[inline]
    fn key_of(&self, p: DVec3) -> u32 {
        let [x, y, z] = cell_coords(p, self.inv_cell, self.last_cell);
        ((x + 1) + self.side * ((y + 1) + self.side * (z + 1))) as u32
    }

    /// Counting sort of `items` (ball, id, key), stable, in place: counts go
    /// to `cell_start[key]`, inclusive prefix sums make that the end of each
    /// cell, and placing the items in reverse order walks each end down to
    /// the cell's start.
    fn fill(&mut self, items: &[Entry]) {
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
    /// (made while staging), with (how many, widest reach).
    fn fill_lanes(&mut self, staged: &[Entry], exec: &dyn Exec, counted: Option<(u32, f64)>) {
        let cells = self.cell_start.len() - 1;
        let exec: &dyn Exec = if counted.is_some() {
            &super::exec::Serial
        } else {
            exec
        };
        let lanes = exec.lanes().clamp(1, 64).min(cells);
        let bounds: Vec<usize> = (0..=lanes).map(|l| l * cells / lanes).collect();
        let mut tables: Vec<Mutex<&mut [u32]>> = Vec::with_capacity(lanes);
        let mut rest = &mut self.cell_start[..cells];
        for l in 0..lanes {
            let (mine, more) = rest.split_at_mut(bounds[l + 1] - bounds[l]);
            tables.push(Mutex::new(mine));
            rest = more;
        }
        let totals: Vec<Mutex<(u32, f64)>> = (0..lanes)
            .map(|_| Mutex::new(counted.unwrap_or((0, 0.0))))
            .collect();
        exec.for_each_lane(&|l| {
            if l >= lanes || counted.is_some() {
                return;
            }
            let (lo, hi) = (bounds[l] as u32, bounds[l + 1] as u32);
            let mut table = tables[l].lock();
            table.fill(0);
            let mut reach_max: f64 = 0.0;
            let mut count = 0;
            for s in staged {
                if s.key >= lo && s.key < hi {
                    table[(s.key - lo) as usize] += 1;
                    // Not `f64::max`: its NaN handling makes a slow chain
                    // through every sphere, and reaches are never NaN here.
                    if s.ball.reach > reach_max {
                        reach_max = s.ball.reach;
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
        let indirect = staged.len() / lanes >= INDIRECT_MIN;
        self.orders.resize_with(lanes, Default::default);
        let orders = &self.orders;
        let mut regions: Vec<Mutex<&mut [Entry]>> = Vec::with_capacity(lanes);
        let mut rest = &mut self.entries[..sum as usize];
        for l in 0..lanes {
            let (mine, more) = rest.split_at_mut((offsets[l + 1] - offsets[l]) as usize);
            regions.push(Mutex::new(mine));
            rest = more;
        }
        exec.for_each_lane(&|l| {
            if l >= lanes {
                return;
            }
            let (lo, hi) = (bounds[l] as u32, bounds[l + 1] as u32);
            let mut table = tables[l].lock();
            running_sums(&mut table, offsets[l]);
            let mut region = regions[l].lock();
            if !indirect {
                for s in staged.iter().rev() {
                    if s.key >= lo && s.key < hi {
                        let slot = &mut table[(s.key - lo) as usize];
                        *slot -= 1;
                        region[(*slot - offsets[l]) as usize] = *s;
                    }
                }
                return;
            }
            let mut order = orders[l].lock();
            order.resize(region.len(), 0);
            for (i, s) in staged.iter().enumerate().rev() {
                if s.key >= lo && s.key < hi {
                    let slot = &mut table[(s.key - lo) as usize];
                    *slot -= 1;
                    order[(*slot - offsets[l]) as usize] = i as u32;
                }
            }
            for (e, &i) in region.iter_mut().zip(order.iter()) {
                *e = staged[i as usize];
            }
        });
        drop(tables);
        self.cell_start[cells] = sum;
    }

    fn key_blocks(&self) -> usize {
        (self.cell_start.len() - 1).div_ceil(KEY_BLOCK)
    }

    /// Same-level pairs with a sphere in key block `b`, each found once: a
    /// sphere against the rest of its cell and the next cell along x, and the
    /// cells x-1..=x+1 of the four forward rows.
    fn block_pairs(&self, b: usize, go: &impl Fn() -> bool, f: &mut impl FnMut(u32, u32)) {
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
    fn on_faces(&self, f: &mut impl FnMut(usize)) {
        if self.entries.len() <= 1 {
            return;
        }
        let (last, s, cs) = (self.per_side - 1, self.side, &self.cell_start);
        let key = |x: usize, y: usize, z: usize| (x + 1) + s * ((y + 1) + s * (z + 1));
        for z in 0..=last {
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
    fn near(&self, p: DVec3, span: f64, f: &mut impl FnMut(usize)) {
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
fn within(a: &Ball, b: &Ball) -> bool {
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

/// The work units of `pairs`, in the fixed order their results are joined.
#[derive(Clone, Copy)]
enum Unit {
    /// Same-level pairs of one key block of a level.
    Block { level: usize, block: usize },
    /// Spheres `from..to` of a coarse level against every finer level.
    Cross {
        level: usize,
        from: usize,
        to: usize,
    },
    /// The last few against everything.
    Top,
}

impl Grid {
    /// Bin the spheres. `ball(s)` is a centre and a reach: during the step
    /// the sphere stays inside that ball, so a pair matters only when the
    /// distance of the centres is at most the sum of the reaches. The
    /// per-sphere arithmetic of the first level runs on `exec`.
    pub fn build(
        &mut self,
        spheres: &[Sphere],
        size: f64,
        ball: impl Fn(&Sphere) -> (DVec3, f64) + Sync,
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        self.size = size;
        self.top.clear();
        let mut depth = 0;
        if n > ALL_PAIRS_MAX {
            if self.levels.is_empty() {
                self.levels.push(Level::default());
            }
            // The first level's cell comes from a sample of the reaches (a
            // function of the state only, so the grid, and the order pairs
            // come out in, never depend on history); then each sphere's
            // ball and key are made in one pass over the spheres.
            self.scratch.clear();
            self.scratch
                .extend(spheres.iter().step_by(SAMPLE_STRIDE).map(|s| ball(s).1));
            let max = self.scratch.iter().fold(0.0f64, |m, &r| m.max(r));
            let want = cell_of_sample(&mut self.scratch, max);
            let level = &mut self.levels[0];
            level.shape(size, want, n, true);
            self.staged.resize(n, Entry::default());
            self.rest.clear();
            // Under this many spheres, waking other threads costs more than
            // the sort; the layout is the same for any number of lanes.
            if n < LANES_MIN_SPHERES || exec.lanes() <= 1 {
                // One lane: the cells are counted while staging, so the
                // table's increments overlap the arithmetic of the balls
                // and the staged records are read once less.
                level.cell_start.fill(0);
                let (mut count, mut reach_max) = (0, 0.0f64);
                for ((slot, s), id) in self.staged.iter_mut().zip(spheres).zip(0..) {
                    *slot = level.stage(ball(s), id, &mut self.rest);
                    if slot.key != u32::MAX {
                        level.cell_start[slot.key as usize] += 1;
                        count += 1;
                        // Not `f64::max`: see `fill_lanes`.
                        if slot.ball.reach > reach_max {
                            reach_max = slot.ball.reach;
                        }
                    }
                }
                level.fill_lanes(&self.staged, exec, Some((count, reach_max)));
            } else {
                let blocks = n.div_ceil(BUILD_BLOCK);
                self.wide.resize_with(blocks, Default::default);
                let level = &*level;
                let wide = &self.wide;
                for_each_chunk(exec, &mut self.staged, BUILD_BLOCK, &|b, chunk| {
                    let mut wide = wide[b].lock();
                    wide.clear();
                    let first = (b * BUILD_BLOCK) as u32;
                    let mine = chunk.iter_mut().zip(&spheres[b * BUILD_BLOCK..]);
                    for ((slot, s), id) in mine.zip(first..) {
                        *slot = level.stage(ball(s), id, &mut wide);
                    }
                });
                self.levels[0].fill_lanes(&self.staged, exec, None);
                for w in &self.wide[..blocks] {
                    self.rest.extend_from_slice(&w.lock());
                }
            }
            depth = 1;
            // Coarser levels for what did not fit, serially: they are few.
            while self.rest.len() > ALL_PAIRS_MAX {
                if self.levels.len() == depth {
                    self.levels.push(Level::default());
                }
                let max = self.rest.iter().fold(0.0f64, |m, b| m.max(b.0.reach));
                let want = cell_for(
                    self.rest.iter().map(|b| b.0.reach),
                    max,
                    1,
                    &mut self.scratch,
                );
                let level = &mut self.levels[depth];
                level.shape(size, want, self.rest.len(), false);
                let placed: Vec<Entry> = self
                    .rest
                    .iter()
                    .filter(|b| level.fits(b.0.reach))
                    .map(|&(ball, id)| Entry {
                        ball,
                        id,
                        key: level.key_of(ball.pos),
                    })
                    .collect();
                if placed.is_empty() {
                    // Balls wider than a one-cell level (the whole box) fit
                    // no coarser level either: they join the top, tested
                    // against everything. Without this the loop never ends.
                    break;
                }
                level.fill(&placed);
                let cell = level.cell;
                self.rest.retain(|b| 2.0 * b.0.reach > cell);
                depth += 1;
            }
            self.top.extend_from_slice(&self.rest);
        } else {
            self.top.extend(spheres.iter().zip(0..).map(|(s, i)| {
                let (pos, reach) = ball(s);
                (Ball { pos, reach }, i)
            }));
        }
        self.levels.truncate(depth);
    }

    fn units(&self) -> Vec<Unit> {
        let mut units = Vec::new();
        for (l, level) in self.levels.iter().enumerate() {
            units.extend((0..level.key_blocks()).map(|block| Unit::Block { level: l, block }));
            if l > 0 {
                let n = level.entries.len() - 1;
                units.extend((0..n.div_ceil(CROSS_BLOCK)).map(|b| Unit::Cross {
                    level: l,
                    from: b * CROSS_BLOCK,
                    to: ((b + 1) * CROSS_BLOCK).min(n),
                }));
            }
        }
        if !self.top.is_empty() {
            units.push(Unit::Top);
        }
        units
    }

    /// The pairs of one unit within reach, as `f(id, id)`; `go` is asked
    /// before each sphere's pairs, and the unit stops when it says no.
    fn unit_pairs(&self, unit: Unit, go: &impl Fn() -> bool, f: &mut impl FnMut(u32, u32)) {
        match unit {
            Unit::Block { level, block } => self.levels[level].block_pairs(block, go, f),
            Unit::Cross { level, from, to } => {
                let coarse = &self.levels[level];
                for e in &coarse.entries[from..to] {
                    if !go() {
                        return;
                    }
                    let (a, ia) = (&e.ball, e.id);
                    for finer in &self.levels[..level] {
                        finer.near(a.pos, a.reach + finer.reach_max, &mut |j| {
                            let b = &finer.entries[j];
                            if within(a, &b.ball) {
                                f(ia, b.id);
                            }
                        });
                    }
                }
            }
            Unit::Top => {
                for (k, (a, ia)) in self.top.iter().enumerate() {
                    if !go() {
                        return;
                    }
                    for level in &self.levels {
                        level.near(a.pos, a.reach + level.reach_max, &mut |j| {
                            let b = &level.entries[j];
                            if within(a, &b.ball) {
                                f(*ia, b.id);
                            }
                        });
                    }
                    for (b, ib) in &self.top[k + 1..] {
                        if within(a, b) {
                            f(*ia, *ib);
                        }
                    }
                }
            }
        }
    }

    /// Every pair within reach, in a fixed order, found in parallel on
    /// `exec`; `keep` filters pairs.
    pub fn pairs<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
    ) {
        out.clear();
        let units = self.units();
        while self.slots.len() < units.len() {
            self.slots.push(Mutex::new(Vec::new()));
        }
        let this = &*self;
        for_each_block(exec, units.len(), &|u| {
            let mut v = this.slots[u].lock();
            v.clear();
            this.unit_pairs(units[u], &|| true, &mut |i, j| {
                if keep(i, j) {
                    v.push((i, j));
                }
            });
        });
        for s in &self.slots[..units.len()] {
            out.extend_from_slice(&s.lock());
        }
    }

    /// As [`Grid::pairs`], but stops once more than `limit` pairs are
    /// found (a step's work budget); returns false then, with only some of
    /// them in `out`. Every unit runs to its end unless the running total
    /// is over `limit`, so the answer is "the pairs number more than
    /// `limit`", whatever the lanes and their timing.
    pub fn pairs_within<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
        limit: usize,
    ) -> bool {
        if limit == usize::MAX {
            self.pairs(exec, keep, out);
            return true;
        }
        out.clear();
        let units = self.units();
        while self.slots.len() < units.len() {
            self.slots.push(Mutex::new(Vec::new()));
        }
        let this = &*self;
        let found = AtomicUsize::new(0);
        for_each_block(exec, units.len(), &|u| {
            let mut v = this.slots[u].lock();
            v.clear();
            // Counted here, added to the total now and then: one shared
            // counter touched per pair would cost more than the pair.
            // The total is read then too: a unit that finds few pairs costs
            // little, whatever the others found.
            let (mine, told, over) = (Cell::new(0usize), Cell::new(0usize), Cell::new(false));
            let tell = || {
                let new = mine.get() - told.get();
                let before = found.fetch_add(new, Ordering::Relaxed);
                told.set(mine.get());
                over.set(before + new > limit);
            };
            let go = || {
                if mine.get() - told.get() >= LIMIT_FLUSH {
                    tell();
                }
                !over.get()
            };
            over.set(found.load(Ordering::Relaxed) > limit);
            if go() {
                this.unit_pairs(units[u], &go, &mut |i, j| {
                    if keep(i, j) {
                        v.push((i, j));
                        mine.set(mine.get() + 1);
                    }
                });
            }
            tell();
        });
        if found.into_inner() > limit {
            return false;
        }
        for s in &self.slots[..units.len()] {
            out.extend_from_slice(&s.lock());
        }
        true
    }

    /// Every sphere whose ball may meet a ball of radius `reach` around `p`,
    /// as `f(id, centre, reach)`, including spheres whose reach has since
    /// grown up to [`Grid::growth_cap`]; the caller applies its own test.
    pub fn near(&self, p: DVec3, reach: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        for level in &self.levels {
            level.near(p, reach + GROWTH_CAP * level.reach_max, &mut |j| {
                let e = &level.entries[j];
                f(e.id, e.ball.pos, e.ball.reach)
            });
        }
        for (b, id) in &self.top {
            f(*id, b.pos, b.reach);
        }
    }

    /// Every sphere whose ball, as binned, may meet a ball of radius `reach`
    /// around `p`, as `f(id, centre, reach)`: like [`Grid::near`] for
    /// callers that track grown balls themselves, so a narrower search.
    pub fn near_binned(&self, p: DVec3, reach: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        for level in &self.levels {
            level.near(p, reach + level.reach_max, &mut |j| {
                let e = &level.entries[j];
                f(e.id, e.ball.pos, e.ball.reach)
            });
        }
        for (b, id) in &self.top {
            f(*id, b.pos, b.reach);
        }
    }

    /// Every sphere whose ball reaches a face of the box the grid was built
    /// for, as `f(id)`, in no particular order. Only the cells on the faces
    /// and the last few are looked at: a ball is at most half a cell wide,
    /// so from any other cell it stays over half a cell inside.
    pub fn near_faces(&self, f: &mut impl FnMut(u32)) {
        let size = self.size;
        let out = |b: &Ball| {
            (b.pos.min_element() - b.reach <= 0.0) | (b.pos.max_element() + b.reach >= size)
        };
        for level in &self.levels {
            level.on_faces(&mut |j| {
                // The balls lie in cell order, so this test reads memory in
                // order; the caller's test, for the few that pass, does not.
                let e = &level.entries[j];
                if out(&e.ball) {
                    f(e.id)
                }
            });
        }
        for (b, id) in &self.top {
            if out(b) {
                f(*id);
            }
        }
    }

    /// How far a sphere that started with reach `reach` may grow and still
    /// be found by [`Grid::near`]; beyond it the caller must track it itself.
    pub fn growth_cap(&self, reach: f64) -> f64 {
        self.levels
            .iter()
            .find(|l| l.fits(reach))
            .map_or(f64::INFINITY, |l| GROWTH_CAP * l.reach_max)
    }

    /// Cells per side of each level, and how many spheres each holds (the
    /// last number: tested against everything). For diagnostics.
    pub fn shape(&self) -> (Vec<(usize, usize)>, usize) {
        (
            self.levels
                .iter()
                .map(|l| (l.per_side, l.entries.len().saturating_sub(1)))
                .collect(),
            self.top.len(),
        )
    }
}

/// Calls `f(i, j)` once for every pair whose spheres touch or overlap
/// (centres within the sum of radii). Serial; for checks and placement.
pub fn for_each_near_pair(spheres: &[Sphere], size: f64, mut f: impl FnMut(usize, usize)) {
    let mut grid = Grid::default();
    grid.build(spheres, size, |s| (s.pos, s.radius), &super::exec::Serial);
    let mut out = Vec::new();
    grid.pairs(&super::exec::Serial, &|_: u32, _: u32| true, &mut out);
    for (i, j) in out {
        f(i as usize, j as usize);
    }
}
