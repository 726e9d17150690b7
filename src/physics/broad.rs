//! Broad phase: which pairs can touch within a step. A uniform grid whose cell
//! is sized for the bulk of the spheres; the few that are much larger (or much
//! faster) than the bulk live on a second level and query the grid over their
//! own reach, so radii spread over orders of magnitude stay cheap. Tiny scenes
//! use all pairs.
use super::exec::{Exec, for_each_block};
use super::sphere::Sphere;
use glam::DVec3;
use parking_lot::Mutex;

/// Below this many spheres, all pairs beat building a grid.
const ALL_PAIRS_MAX: usize = 24;
/// Grid rows (cells along x at one y, z) per parallel block; fixed so results
/// never depend on the thread count.
const ROW_BLOCK: usize = 8;
const BIG_BLOCK: usize = 16;

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    pos: DVec3,
    reach: f64,
    id: u32,
    /// Cell column along x: rows are swept in x order.
    x: u32,
}

/// A pair that may touch: sphere indices, `i < j` not implied.
pub type Pair = (u32, u32);

#[derive(Default)]
pub struct Grid {
    dims: [usize; 3],
    inv_cell: f64,
    cell: f64,
    cell_start: Vec<u32>,
    entries: Vec<Entry>,
    keys: Vec<u32>,
    big: Vec<Entry>,
    small_reach_max: f64,
    all_pairs: bool,
    scratch: Vec<f64>,
    balls: Vec<(DVec3, f64)>,
    fill: Vec<u32>,
    cell_slots: Vec<Mutex<Vec<Pair>>>,
    big_slots: Vec<Mutex<Vec<Pair>>>,
}

impl Grid {
    /// Bin the spheres. `ball(s)` is a centre and a reach: during the step
    /// the sphere stays inside that ball, so a pair matters only when the
    /// distance of the centres is at most the sum of the reaches.
    pub fn build(&mut self, spheres: &[Sphere], size: f64, ball: impl Fn(&Sphere) -> (DVec3, f64)) {
        let n = spheres.len();
        self.entries.clear();
        self.big.clear();
        self.balls.clear();
        self.balls.extend(spheres.iter().map(ball));
        self.all_pairs = n <= ALL_PAIRS_MAX;
        if self.all_pairs {
            self.big.extend(
                self.balls
                    .iter()
                    .enumerate()
                    .map(|(i, &(pos, reach))| Entry {
                        pos,
                        reach,
                        id: i as u32,
                        x: 0,
                    }),
            );
            return;
        }
        // Cell from the 98th percentile of reach (estimated on every 8th
        // sphere: a function of the state only, so the grid, and the order
        // pairs come out in, never depend on history): the bulk share few
        // cells, the outliers go to the second level.
        self.scratch.clear();
        self.scratch
            .extend(self.balls.iter().step_by(8).map(|b| b.1));
        let max_reach = self.balls.iter().fold(0.0f64, |m, b| m.max(b.1));
        let k = (self.scratch.len() * 98 / 100).min(self.scratch.len() - 1);
        let q = *self
            .scratch
            .select_nth_unstable_by(k, |a, b| a.total_cmp(b))
            .1;
        let small_max = if max_reach <= 3.0 * q { max_reach } else { q };
        let want = (2.0 * small_max).max(f64::MIN_POSITIVE);
        // At most ~2 cells per sphere and 1024 per side keeps memory O(N).
        let cap = ((2 * n) as f64).cbrt().ceil().clamp(1.0, 1024.0);
        let per_side = (size / want).floor().clamp(1.0, cap) as usize;
        self.dims = [per_side; 3];
        self.cell = size / per_side as f64;
        self.inv_cell = 1.0 / self.cell;
        self.small_reach_max = 0.0;
        let cells = per_side * per_side * per_side;
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        self.keys.clear();
        for (i, &(pos, r)) in self.balls.iter().enumerate() {
            if 2.0 * r <= self.cell {
                let key = self.cell_of(pos);
                self.small_reach_max = self.small_reach_max.max(r);
                self.cell_start[key + 1] += 1;
                self.keys.push(key as u32);
            } else {
                self.keys.push(u32::MAX);
                self.big.push(Entry {
                    pos,
                    reach: r,
                    id: i as u32,
                    x: 0,
                });
            }
        }
        for c in 0..cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let small = self.cell_start[cells] as usize;
        self.entries.resize(small, Entry::default());
        // Counting sort, stable: spheres of a cell keep index order.
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start[..cells]);
        let nx = self.dims[0] as u32;
        for (i, (&key, &(pos, reach))) in self.keys.iter().zip(&self.balls).enumerate() {
            if key != u32::MAX {
                let slot = &mut self.fill[key as usize];
                self.entries[*slot as usize] = Entry {
                    pos,
                    reach,
                    id: i as u32,
                    x: key % nx,
                };
                *slot += 1;
            }
        }
    }

    fn cell_of(&self, p: DVec3) -> usize {
        let [nx, ny, nz] = self.dims;
        let c = |x: f64, n: usize| ((x * self.inv_cell) as isize).clamp(0, n as isize - 1) as usize;
        c(p.x, nx) + nx * (c(p.y, ny) + ny * c(p.z, nz))
    }

    /// Every pair within reach, in a fixed order (cell blocks, then the
    /// second level), found in parallel on `exec`; `keep` filters pairs.
    pub fn pairs<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
    ) {
        out.clear();
        let rows = self.dims[1] * self.dims[2];
        let cell_blocks = if self.all_pairs {
            0
        } else {
            rows.div_ceil(ROW_BLOCK)
        };
        let big_blocks = self.big.len().div_ceil(BIG_BLOCK);
        ensure_slots(&mut self.cell_slots, cell_blocks);
        ensure_slots(&mut self.big_slots, big_blocks);
        let this = &*self;
        let total = cell_blocks + big_blocks;
        for_each_block(exec, total, &|b| {
            if b < cell_blocks {
                let mut v = this.cell_slots[b].lock();
                v.clear();
                let end = ((b + 1) * ROW_BLOCK).min(rows);
                for r in b * ROW_BLOCK..end {
                    this.row_pairs(r, &mut |i, j| {
                        if keep(i, j) {
                            v.push((i, j))
                        }
                    });
                }
            } else {
                let b = b - cell_blocks;
                let mut v = this.big_slots[b].lock();
                v.clear();
                let end = ((b + 1) * BIG_BLOCK).min(this.big.len());
                for k in b * BIG_BLOCK..end {
                    this.big_pairs(k, &mut |i, j| {
                        if keep(i, j) {
                            v.push((i, j))
                        }
                    });
                }
            }
        });
        for s in &self.cell_slots[..cell_blocks] {
            out.extend_from_slice(&s.lock());
        }
        for s in &self.big_slots[..big_blocks] {
            out.extend_from_slice(&s.lock());
        }
    }

    /// Entries of the cells `x0..=x1` of row `(y, z)`: contiguous, since
    /// keys run along x.
    #[inline]
    fn row(&self, x0: usize, x1: usize, y: usize, z: usize) -> &[Entry] {
        let [nx, ny, _] = self.dims;
        let base = nx * (y + ny * z);
        &self.entries[self.cell_start[base + x0] as usize..self.cell_start[base + x1 + 1] as usize]
    }

    /// Entries of row `r` (= y + ny z), in x order.
    #[inline]
    fn row_entries(&self, r: usize) -> &[Entry] {
        let nx = self.dims[0];
        &self.entries[self.cell_start[r * nx] as usize..self.cell_start[(r + 1) * nx] as usize]
    }

    /// Pairs with at least one sphere in row `r`, each found once: each
    /// sphere against the rest of its cell and the next cell along x, and
    /// the cells x-1..=x+1 of the four forward rows (13 cells in all).
    /// Each neighbour window is a pair of cursors that only move forward as
    /// the sweep moves along x, so empty cells cost nothing.
    fn row_pairs(&self, r: usize, f: &mut impl FnMut(u32, u32)) {
        let here = self.row_entries(r);
        if here.is_empty() {
            return;
        }
        let [_, ny, nz] = self.dims;
        let (y, z) = (r % ny, r / ny);
        let mut others: [&[Entry]; 4] = [&[]; 4];
        let mut count = 0;
        if y + 1 < ny {
            others[count] = self.row_entries(r + 1);
            count += 1;
        }
        if z + 1 < nz {
            for yy in y.saturating_sub(1)..=(y + 1).min(ny - 1) {
                others[count] = self.row_entries(yy + ny * (z + 1));
                count += 1;
            }
        }
        let others = &others[..count];
        let mut lo = [0usize; 4];
        let mut hi = [0usize; 4];
        let mut same_hi = 0;
        let mut k = 0;
        // One cell at a time: its windows are found once for all its spheres.
        while k < here.len() {
            let x = here[k].x;
            let mut end = k + 1;
            while end < here.len() && here[end].x == x {
                end += 1;
            }
            while same_hi < here.len() && here[same_hi].x <= x + 1 {
                same_hi += 1;
            }
            let mut windows: [&[Entry]; 4] = [&[]; 4];
            for (o, row) in others.iter().enumerate() {
                while lo[o] < row.len() && row[lo[o]].x + 1 < x {
                    lo[o] += 1;
                }
                hi[o] = hi[o].max(lo[o]);
                while hi[o] < row.len() && row[hi[o]].x <= x + 1 {
                    hi[o] += 1;
                }
                windows[o] = &row[lo[o]..hi[o]];
            }
            for (j, a) in here[k..end].iter().enumerate() {
                for b in &here[k + j + 1..same_hi] {
                    test(a, b, f);
                }
                for w in &windows[..others.len()] {
                    for b in *w {
                        test(a, b, f);
                    }
                }
            }
            k = end;
        }
    }

    /// Every sphere (either level) that may lie within `span` of `p`, as
    /// `f(id, centre, reach)`: all of the second level, and the grid cells
    /// that cover `p ± span`. The caller applies its own test.
    pub fn near(&self, p: DVec3, span: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        if !self.all_pairs && !self.entries.is_empty() {
            let lo = self.cell_coords(p - DVec3::splat(span));
            let hi = self.cell_coords(p + DVec3::splat(span));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for b in self.row(lo[0], hi[0], y, z) {
                        f(b.id, b.pos, b.reach);
                    }
                }
            }
        }
        for b in &self.big {
            f(b.id, b.pos, b.reach);
        }
    }

    /// Largest reach among first-level (grid) spheres.
    pub fn small_reach(&self) -> f64 {
        self.small_reach_max
    }

    fn grid_near(&self, a: &Entry, f: &mut impl FnMut(u32, u32)) {
        let span = a.reach + self.small_reach_max;
        let lo = self.cell_coords(a.pos - DVec3::splat(span));
        let hi = self.cell_coords(a.pos + DVec3::splat(span));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for b in self.row(lo[0], hi[0], y, z) {
                    test(a, b, f);
                }
            }
        }
    }

    /// Pairs of second-level sphere `k` with every grid sphere in its reach
    /// and with the second-level spheres after it.
    fn big_pairs(&self, k: usize, f: &mut impl FnMut(u32, u32)) {
        let a = &self.big[k];
        if !self.all_pairs && !self.entries.is_empty() {
            self.grid_near(a, f);
        }
        for b in &self.big[k + 1..] {
            test(a, b, f);
        }
    }

    fn cell_coords(&self, p: DVec3) -> [usize; 3] {
        let c = |x: f64, n: usize| ((x * self.inv_cell).floor().max(0.0) as usize).min(n - 1);
        [
            c(p.x, self.dims[0]),
            c(p.y, self.dims[1]),
            c(p.z, self.dims[2]),
        ]
    }
}

#[inline(always)]
fn test(a: &Entry, b: &Entry, f: &mut impl FnMut(u32, u32)) {
    let s = a.reach + b.reach;
    if (a.pos - b.pos).length_squared() <= s * s {
        f(a.id, b.id);
    }
}

fn ensure_slots<T>(slots: &mut Vec<Mutex<Vec<T>>>, n: usize) {
    while slots.len() < n {
        slots.push(Mutex::new(Vec::new()));
    }
}

/// Calls `f(i, j)` once for every pair whose spheres touch or overlap
/// (centres within the sum of radii). Serial; for checks and placement.
pub fn for_each_near_pair(spheres: &[Sphere], size: f64, mut f: impl FnMut(usize, usize)) {
    let mut grid = Grid::default();
    grid.build(spheres, size, |s| (s.pos, s.radius));
    let mut out = Vec::new();
    grid.pairs(&super::exec::Serial, &|_: u32, _: u32| true, &mut out);
    for (i, j) in out {
        f(i as usize, j as usize);
    }
}
