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
/// Cells per parallel block; fixed so results never depend on thread count.
const CELL_BLOCK: usize = 256;
const BIG_BLOCK: usize = 16;

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    pos: DVec3,
    reach: f64,
    id: u32,
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
    cell_slots: Vec<Mutex<Vec<Pair>>>,
    big_slots: Vec<Mutex<Vec<Pair>>>,
}

impl Grid {
    /// Bin the spheres; sphere `i` reaches `reach(i)` from its centre during
    /// the step, so a pair matters when their centres are within the sum.
    pub fn build(&mut self, spheres: &[Sphere], size: f64, reach: impl Fn(&Sphere) -> f64) {
        let n = spheres.len();
        self.entries.clear();
        self.big.clear();
        self.all_pairs = n <= ALL_PAIRS_MAX;
        if self.all_pairs {
            self.big
                .extend(spheres.iter().enumerate().map(|(i, s)| Entry {
                    pos: s.pos,
                    reach: reach(s),
                    id: i as u32,
                }));
            return;
        }
        // Cell from the 98th percentile of reach: the bulk share few cells,
        // the outliers go to the second level.
        self.scratch.clear();
        self.scratch.extend(spheres.iter().map(&reach));
        let max_reach = self.scratch.iter().copied().fold(0.0, f64::max);
        let k = (n * 98 / 100).min(n - 1);
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
        for (i, s) in spheres.iter().enumerate() {
            let r = reach(s);
            if 2.0 * r <= self.cell {
                let key = self.cell_of(s.pos);
                self.small_reach_max = self.small_reach_max.max(r);
                self.cell_start[key + 1] += 1;
                self.keys.push(key as u32);
            } else {
                self.keys.push(u32::MAX);
                self.big.push(Entry {
                    pos: s.pos,
                    reach: r,
                    id: i as u32,
                });
            }
        }
        for c in 0..cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let small = self.cell_start[cells] as usize;
        self.entries.resize(small, Entry::default());
        // Counting sort, stable: spheres of a cell keep index order.
        let mut fill: Vec<u32> = self.cell_start[..cells].to_vec();
        for (i, s) in spheres.iter().enumerate() {
            let key = self.keys[i];
            if key != u32::MAX {
                let slot = &mut fill[key as usize];
                self.entries[*slot as usize] = Entry {
                    pos: s.pos,
                    reach: reach(s),
                    id: i as u32,
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

    fn cell_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
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
        let cell_blocks = if self.all_pairs {
            0
        } else {
            self.cell_count().div_ceil(CELL_BLOCK)
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
                let end = ((b + 1) * CELL_BLOCK).min(this.cell_count());
                for c in b * CELL_BLOCK..end {
                    this.cell_pairs(c, &mut |i, j| {
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

    /// Pairs with at least one sphere in cell `c`, each found once: the cell
    /// with itself and its 13 forward neighbours, read as 5 row ranges.
    fn cell_pairs(&self, c: usize, f: &mut impl FnMut(u32, u32)) {
        let (lo, hi) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
        if lo == hi {
            return;
        }
        let [nx, ny, nz] = self.dims;
        let (x, y, z) = (c % nx, (c / nx) % ny, c / (nx * ny));
        let here = &self.entries[lo..hi];
        // Same row: the rest of this cell and the next one along x.
        let row_end = if x + 1 < nx {
            self.cell_start[c + 2] as usize
        } else {
            hi
        };
        for (k, a) in here.iter().enumerate() {
            for b in &self.entries[lo + k + 1..row_end] {
                test(a, b, f);
            }
        }
        let (x0, x1) = (x.saturating_sub(1), (x + 1).min(nx - 1));
        let mut rows = [(0usize, 0usize); 4];
        let mut count = 0;
        if y + 1 < ny {
            rows[count] = (y + 1, z);
            count += 1;
        }
        if z + 1 < nz {
            for yy in y.saturating_sub(1)..=(y + 1).min(ny - 1) {
                rows[count] = (yy, z + 1);
                count += 1;
            }
        }
        for &(yy, zz) in &rows[..count] {
            let other = self.row(x0, x1, yy, zz);
            if other.is_empty() {
                continue;
            }
            for a in here {
                for b in other {
                    test(a, b, f);
                }
            }
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
    grid.build(spheres, size, |s| s.radius);
    let mut out = Vec::new();
    grid.pairs(&super::exec::Serial, &|_: u32, _: u32| true, &mut out);
    for (i, j) in out {
        f(i as usize, j as usize);
    }
}
