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

/// At most this many spheres are tested against everything.
const ALL_PAIRS_MAX: usize = 24;
/// Cell keys per parallel block; fixed so results never depend on the
/// thread count.
const KEY_BLOCK: usize = 2048;
/// Coarse-level spheres per parallel block of cross-level queries.
const CROSS_BLOCK: usize = 64;
/// Spheres per parallel block while binning.
const BUILD_BLOCK: usize = 4096;

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    pos: DVec3,
    reach: f64,
    id: u32,
    /// Padded cell key (see `Level::side`).
    key: u32,
}

/// A pair that may touch: sphere indices, `i < j` not implied.
pub type Pair = (u32, u32);

/// One uniform grid. It is padded with one empty layer of cells on every
/// side, so the neighbour cells of any real cell exist and need no bounds
/// checks: the 13 forward neighbours of cell `c` are 5 contiguous key ranges
/// at fixed offsets from `c`.
#[derive(Default)]
struct Level {
    /// Real cells per side.
    per_side: usize,
    /// Padded cells per side (`per_side + 2`).
    side: usize,
    inv_cell: f64,
    cell: f64,
    cell_start: Vec<u32>,
    /// Spheres of this level, sorted by cell key.
    entries: Vec<Entry>,
    /// Largest reach in this level.
    reach_max: f64,
}

#[derive(Default)]
pub struct Grid {
    levels: Vec<Level>,
    /// The last few, tested against everything.
    top: Vec<Entry>,
    balls: Vec<(DVec3, f64)>,
    keys: Vec<u32>,
    /// Spheres not yet placed in a level: (ball, id).
    rest: Vec<(DVec3, f64, u32)>,
    scratch: Vec<f64>,
    slots: Vec<Mutex<Vec<Pair>>>,
}

/// Real cell coordinates of `p`, clamped into `0..=last`. Truncation is
/// floor here (after max(0)), without a libm call.
#[inline]
fn cell_coords(p: DVec3, inv_cell: f64, last: usize) -> [usize; 3] {
    let c = |x: f64| ((x * inv_cell).max(0.0) as usize).min(last);
    [c(p.x), c(p.y), c(p.z)]
}

/// The 98th percentile of `reach` (estimated on every `stride`-th value: a
/// function of the state only, so the grid, and the order pairs come out
/// in, never depend on history) and the maximum.
fn cell_for(
    reaches: impl Iterator<Item = f64> + Clone,
    stride: usize,
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.clear();
    scratch.extend(reaches.clone().step_by(stride));
    let max = reaches.fold(0.0f64, f64::max);
    if scratch.is_empty() {
        return 2.0 * max;
    }
    let k = (scratch.len() * 98 / 100).min(scratch.len() - 1);
    let q = *scratch.select_nth_unstable_by(k, |a, b| a.total_cmp(b)).1;
    // When the fastest is close to the bulk, one level holds everyone.
    2.0 * if max <= 1.25 * q { max } else { q }
}

impl Level {
    fn shape(&mut self, size: f64, want: f64, n: usize) {
        // At most ~8 cells per sphere (empty cells cost nothing to skip)
        // and 1024 per side keep memory O(N).
        let cap = ((8 * n.max(1)) as f64).cbrt().ceil().clamp(1.0, 1024.0);
        self.per_side = (size / want.max(f64::MIN_POSITIVE)).floor().clamp(1.0, cap) as usize;
        self.side = self.per_side + 2;
        self.cell = size / self.per_side as f64;
        self.inv_cell = 1.0 / self.cell;
        self.reach_max = 0.0;
        self.cell_start.clear();
        self.cell_start
            .resize(self.side * self.side * self.side + 1, 0);
        self.entries.clear();
    }

    #[inline]
    fn fits(&self, reach: f64) -> bool {
        2.0 * reach <= self.cell
    }

    #[inline]
    fn key_of(&self, p: DVec3) -> u32 {
        let [x, y, z] = cell_coords(p, self.inv_cell, self.per_side - 1);
        ((x + 1) + self.side * ((y + 1) + self.side * (z + 1))) as u32
    }

    /// Counting sort of `items` (ball, id, key), stable.
    /// Counting sort of `items`, stable, in place: counts go to
    /// `cell_start[key]`, inclusive prefix sums make that the end of each
    /// cell, and placing the items in reverse order walks each end down to
    /// the cell's start.
    fn fill(&mut self, items: impl DoubleEndedIterator<Item = Entry> + Clone) {
        for e in items.clone() {
            self.reach_max = self.reach_max.max(e.reach);
            self.cell_start[e.key as usize] += 1;
        }
        let cells = self.cell_start.len() - 1;
        let mut sum = 0;
        for c in &mut self.cell_start[..cells] {
            sum += *c;
            *c = sum;
        }
        self.cell_start[cells] = sum;
        self.entries.resize(sum as usize, Entry::default());
        for e in items.rev() {
            let slot = &mut self.cell_start[e.key as usize];
            *slot -= 1;
            self.entries[*slot as usize] = e;
        }
    }

    /// The same counting sort as [`Level::fill`] for the first level, cut
    /// by key range over the executor's lanes: each lane counts, sums and
    /// places only the keys of its range, into its own part of the cell
    /// table and of the entries, so the layout is the same for any number
    /// of lanes. `keys[i]` is sphere `i`'s cell, `u32::MAX` for none.
    fn fill_lanes(&mut self, keys: &[u32], balls: &[(DVec3, f64)], exec: &dyn Exec) {
        let cells = self.cell_start.len() - 1;
        let lanes = exec.lanes().clamp(1, 64).min(cells);
        let bounds: Vec<usize> = (0..=lanes).map(|l| l * cells / lanes).collect();
        let mut tables: Vec<Mutex<&mut [u32]>> = Vec::with_capacity(lanes);
        let mut rest = &mut self.cell_start[..cells];
        for l in 0..lanes {
            let (mine, more) = rest.split_at_mut(bounds[l + 1] - bounds[l]);
            tables.push(Mutex::new(mine));
            rest = more;
        }
        let totals: Vec<Mutex<(u32, f64)>> = (0..lanes).map(|_| Mutex::new((0, 0.0))).collect();
        exec.for_each_lane(&|l| {
            if l >= lanes {
                return;
            }
            let (lo, hi) = (bounds[l] as u32, bounds[l + 1] as u32);
            let mut table = tables[l].lock();
            let mut reach_max: f64 = 0.0;
            for (&k, b) in keys.iter().zip(balls) {
                if k >= lo && k < hi {
                    table[(k - lo) as usize] += 1;
                    reach_max = reach_max.max(b.1);
                }
            }
            *totals[l].lock() = (table.iter().sum(), reach_max);
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
        self.entries.resize(sum as usize, Entry::default());
        let mut regions: Vec<Mutex<&mut [Entry]>> = Vec::with_capacity(lanes);
        let mut rest = &mut self.entries[..];
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
            let mut end = offsets[l];
            for c in table.iter_mut() {
                end += *c;
                *c = end;
            }
            let mut out = regions[l].lock();
            for (i, (&key, &(pos, reach))) in keys.iter().zip(balls).enumerate().rev() {
                if key >= lo && key < hi {
                    let slot = &mut table[(key - lo) as usize];
                    *slot -= 1;
                    out[(*slot - offsets[l]) as usize] = Entry {
                        pos,
                        reach,
                        id: i as u32,
                        key,
                    };
                }
            }
        });
        drop(tables);
        self.cell_start[cells] = sum;
    }

    fn key_blocks(&self) -> usize {
        (self.cell_start.len() - 1).div_ceil(KEY_BLOCK)
    }

    /// Entries of the cells with keys `k0..k1`: contiguous, keys being sorted.
    #[inline]
    fn keys_range(&self, k0: usize, k1: usize) -> &[Entry] {
        &self.entries[self.cell_start[k0] as usize..self.cell_start[k1] as usize]
    }

    /// Same-level pairs with a sphere in key block `b`, each found once: a
    /// sphere against the rest of its cell and the next cell along x, and the
    /// cells x-1..=x+1 of the four forward rows.
    fn block_pairs(&self, b: usize, f: &mut impl FnMut(&Entry, &Entry)) {
        let keys = self.cell_start.len() - 1;
        let cs = &self.cell_start[..];
        let e = &self.entries[..];
        let s = self.side;
        let mut k = cs[b * KEY_BLOCK] as usize;
        let hi = cs[((b + 1) * KEY_BLOCK).min(keys)] as usize;
        while k < hi {
            let c = e[k].key as usize;
            let end = cs[c + 1] as usize;
            let row_end = cs[c + 2] as usize;
            // Forward rows: (y+1, z), then (y-1..=y+1, z+1); x-1..=x+1 each.
            let (r1, r2) = (c + s - 1, c + s * s - s - 1);
            let (r3, r4) = (r2 + s, r2 + 2 * s);
            let windows = [
                &e[cs[r1] as usize..cs[r1 + 3] as usize],
                &e[cs[r2] as usize..cs[r2 + 3] as usize],
                &e[cs[r3] as usize..cs[r3 + 3] as usize],
                &e[cs[r4] as usize..cs[r4 + 3] as usize],
            ];
            for i in k..end {
                let a = &e[i];
                for b in &e[i + 1..row_end] {
                    f(a, b);
                }
                for w in windows {
                    for b in w {
                        f(a, b);
                    }
                }
            }
            k = end;
        }
    }

    /// Entries in the cells covering `p ± span`.
    fn near(&self, p: DVec3, span: f64, f: &mut impl FnMut(&Entry)) {
        if self.entries.is_empty() {
            return;
        }
        let last = self.per_side - 1;
        let lo = cell_coords(p - DVec3::splat(span), self.inv_cell, last);
        let hi = cell_coords(p + DVec3::splat(span), self.inv_cell, last);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let k = (lo[0] + 1) + self.side * ((y + 1) + self.side * (z + 1));
                for b in self.keys_range(k, k + hi[0] - lo[0] + 1) {
                    f(b);
                }
            }
        }
    }
}

#[inline(always)]
fn within(a: &Entry, b: &Entry) -> bool {
    let s = a.reach + b.reach;
    (a.pos - b.pos).length_squared() <= s * s
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
        self.top.clear();
        self.balls.resize(n, (DVec3::ZERO, 0.0));
        for_each_chunk(exec, &mut self.balls, BUILD_BLOCK, &|b, chunk| {
            for (slot, s) in chunk.iter_mut().zip(&spheres[b * BUILD_BLOCK..]) {
                *slot = ball(s);
            }
        });
        let mut depth = 0;
        if n > ALL_PAIRS_MAX {
            // First level: keys in parallel, the sort serial.
            if self.levels.is_empty() {
                self.levels.push(Level::default());
            }
            let want = cell_for(self.balls.iter().map(|b| b.1), 8, &mut self.scratch);
            let level = &mut self.levels[0];
            level.shape(size, want, n);
            self.keys.resize(n, 0);
            {
                let level = &*level;
                let balls = &self.balls;
                for_each_chunk(exec, &mut self.keys, BUILD_BLOCK, &|b, chunk| {
                    for (slot, &(pos, r)) in chunk.iter_mut().zip(&balls[b * BUILD_BLOCK..]) {
                        *slot = if level.fits(r) {
                            level.key_of(pos)
                        } else {
                            u32::MAX
                        };
                    }
                });
            }
            let (keys, balls) = (&self.keys, &self.balls);
            level.fill_lanes(keys, balls, exec);
            self.rest.clear();
            self.rest.extend(
                keys.iter()
                    .zip(balls)
                    .enumerate()
                    .filter(|(_, (k, _))| **k == u32::MAX)
                    .map(|(i, (_, &(p, r)))| (p, r, i as u32)),
            );
            depth = 1;
            // Coarser levels for what did not fit, serially: they are few.
            while self.rest.len() > ALL_PAIRS_MAX {
                if self.levels.len() == depth {
                    self.levels.push(Level::default());
                }
                let want = cell_for(self.rest.iter().map(|b| b.1), 1, &mut self.scratch);
                let level = &mut self.levels[depth];
                level.shape(size, want, self.rest.len());
                let placed: Vec<Entry> = self
                    .rest
                    .iter()
                    .filter(|b| level.fits(b.1))
                    .map(|&(pos, reach, id)| Entry {
                        pos,
                        reach,
                        id,
                        key: level.key_of(pos),
                    })
                    .collect();
                if placed.is_empty() {
                    // Balls wider than a one-cell level (the whole box) fit
                    // no coarser level either: they join the top, tested
                    // against everything. Without this the loop never ends.
                    break;
                }
                level.fill(placed.iter().copied());
                let cell = level.cell;
                self.rest.retain(|b| 2.0 * b.1 > cell);
                depth += 1;
            }
            self.top
                .extend(self.rest.iter().map(|&(pos, reach, id)| Entry {
                    pos,
                    reach,
                    id,
                    key: 0,
                }));
        } else {
            self.top.extend(
                self.balls
                    .iter()
                    .enumerate()
                    .map(|(i, &(pos, reach))| Entry {
                        pos,
                        reach,
                        id: i as u32,
                        key: 0,
                    }),
            );
        }
        self.levels.truncate(depth);
    }

    fn units(&self) -> Vec<Unit> {
        let mut units = Vec::new();
        for (l, level) in self.levels.iter().enumerate() {
            units.extend((0..level.key_blocks()).map(|block| Unit::Block { level: l, block }));
            if l > 0 {
                let n = level.entries.len();
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

    fn unit_pairs(&self, unit: Unit, f: &mut impl FnMut(&Entry, &Entry)) {
        match unit {
            Unit::Block { level, block } => self.levels[level].block_pairs(block, f),
            Unit::Cross { level, from, to } => {
                for a in &self.levels[level].entries[from..to] {
                    for finer in &self.levels[..level] {
                        finer.near(a.pos, a.reach + finer.reach_max, &mut |b| f(a, b));
                    }
                }
            }
            Unit::Top => {
                for (k, a) in self.top.iter().enumerate() {
                    for level in &self.levels {
                        level.near(a.pos, a.reach + level.reach_max, &mut |b| f(a, b));
                    }
                    for b in &self.top[k + 1..] {
                        f(a, b);
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
            this.unit_pairs(units[u], &mut |a, b| {
                if within(a, b) && keep(a.id, b.id) {
                    v.push((a.id, b.id));
                }
            });
        });
        for s in &self.slots[..units.len()] {
            out.extend_from_slice(&s.lock());
        }
    }

    /// Every sphere whose ball may meet a ball of radius `reach` around `p`,
    /// as `f(id, centre, reach)`, including spheres whose reach has since
    /// grown up to [`Grid::growth_cap`]; the caller applies its own test.
    pub fn near(&self, p: DVec3, reach: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        for level in &self.levels {
            level.near(p, reach + 2.0 * level.reach_max, &mut |b| {
                f(b.id, b.pos, b.reach)
            });
        }
        for b in &self.top {
            f(b.id, b.pos, b.reach);
        }
    }

    /// Every sphere whose ball, as binned, may meet a ball of radius `reach`
    /// around `p`, as `f(id, centre, reach)`: like [`Grid::near`] for
    /// callers that track grown balls themselves, so a narrower search.
    pub fn near_binned(&self, p: DVec3, reach: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        for level in &self.levels {
            level.near(p, reach + level.reach_max, &mut |b| f(b.id, b.pos, b.reach));
        }
        for b in &self.top {
            f(b.id, b.pos, b.reach);
        }
    }

    /// How far a sphere that started with reach `reach` may grow and still
    /// be found by [`Grid::near`]; beyond it the caller must track it itself.
    pub fn growth_cap(&self, reach: f64) -> f64 {
        self.levels
            .iter()
            .find(|l| l.fits(reach))
            .map_or(f64::INFINITY, |l| 2.0 * l.reach_max)
    }

    /// Cells per side of each level, and how many spheres each holds (the
    /// last number: tested against everything). For diagnostics.
    pub fn shape(&self) -> (Vec<(usize, usize)>, usize) {
        (
            self.levels
                .iter()
                .map(|l| (l.per_side, l.entries.len()))
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
