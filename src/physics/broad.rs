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
/// Cell keys per parallel block; fixed so results never depend on the
/// thread count.
const KEY_BLOCK: usize = 2048;
const BIG_BLOCK: usize = 16;
/// Spheres per parallel block while binning.
const BUILD_BLOCK: usize = 4096;

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    pos: DVec3,
    reach: f64,
    id: u32,
    /// Padded cell key (see `Grid::side`).
    key: u32,
}

/// A pair that may touch: sphere indices, `i < j` not implied.
pub type Pair = (u32, u32);

/// The grid is padded with one empty layer of cells on every side, so the
/// neighbour cells of any real cell exist and need no bounds checks: the
/// 13 forward neighbours of cell `c` are 5 contiguous key ranges at fixed
/// offsets from `c`.
#[derive(Default)]
pub struct Grid {
    /// Real cells per side.
    per_side: usize,
    /// Padded cells per side (`per_side + 2`).
    side: usize,
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
    /// The per-sphere arithmetic runs in parallel on `exec`; the counting
    /// sort is serial integer work.
    pub fn build(
        &mut self,
        spheres: &[Sphere],
        size: f64,
        ball: impl Fn(&Sphere) -> (DVec3, f64) + Sync,
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        self.entries.clear();
        self.big.clear();
        self.balls.resize(n, (DVec3::ZERO, 0.0));
        {
            let chunks: Vec<Mutex<&mut [(DVec3, f64)]>> =
                self.balls.chunks_mut(BUILD_BLOCK).map(Mutex::new).collect();
            for_each_block(exec, chunks.len(), &|b| {
                let mut chunk = chunks[b].lock();
                for (slot, s) in chunk.iter_mut().zip(&spheres[b * BUILD_BLOCK..]) {
                    *slot = ball(s);
                }
            });
        }
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
                        key: 0,
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
        // At most ~8 cells per sphere (cheap: empty cells cost nothing to skip)
        // and 1024 per side keep memory O(N).
        let cap = ((8 * n) as f64).cbrt().ceil().clamp(1.0, 1024.0);
        self.per_side = (size / want).floor().clamp(1.0, cap) as usize;
        self.side = self.per_side + 2;
        self.cell = size / self.per_side as f64;
        self.inv_cell = 1.0 / self.cell;
        self.small_reach_max = 0.0;
        let cells = self.side * self.side * self.side;
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        self.keys.resize(n, 0);
        {
            let (last, side, inv_cell, cell) =
                (self.per_side - 1, self.side, self.inv_cell, self.cell);
            let balls = &self.balls;
            let chunks: Vec<Mutex<&mut [u32]>> =
                self.keys.chunks_mut(BUILD_BLOCK).map(Mutex::new).collect();
            for_each_block(exec, chunks.len(), &|b| {
                let mut chunk = chunks[b].lock();
                for (slot, &(pos, r)) in chunk.iter_mut().zip(&balls[b * BUILD_BLOCK..]) {
                    *slot = if 2.0 * r <= cell {
                        let [x, y, z] = cell_coords(pos, inv_cell, last);
                        ((x + 1) + side * ((y + 1) + side * (z + 1))) as u32
                    } else {
                        u32::MAX
                    };
                }
            });
        }
        for (i, (&key, &(pos, r))) in self.keys.iter().zip(&self.balls).enumerate() {
            if key != u32::MAX {
                self.small_reach_max = self.small_reach_max.max(r);
                self.cell_start[key as usize + 1] += 1;
            } else {
                self.big.push(Entry {
                    pos,
                    reach: r,
                    id: i as u32,
                    key: 0,
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
        for (i, (&key, &(pos, reach))) in self.keys.iter().zip(&self.balls).enumerate() {
            if key != u32::MAX {
                let slot = &mut self.fill[key as usize];
                self.entries[*slot as usize] = Entry {
                    pos,
                    reach,
                    id: i as u32,
                    key,
                };
                *slot += 1;
            }
        }
    }

    #[inline]
    fn key(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.side * (y + self.side * z)
    }

    fn cell_coords(&self, p: DVec3) -> [usize; 3] {
        cell_coords(p, self.inv_cell, self.per_side - 1)
    }

    /// Every pair within reach, in a fixed order (key blocks, then the
    /// second level), found in parallel on `exec`; `keep` filters pairs.
    pub fn pairs<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
    ) {
        out.clear();
        let keys = self.cell_start.len().saturating_sub(1);
        let key_blocks = if self.all_pairs {
            0
        } else {
            keys.div_ceil(KEY_BLOCK)
        };
        let big_blocks = self.big.len().div_ceil(BIG_BLOCK);
        ensure_slots(&mut self.cell_slots, key_blocks);
        ensure_slots(&mut self.big_slots, big_blocks);
        let this = &*self;
        for_each_block(exec, key_blocks + big_blocks, &|b| {
            if b < key_blocks {
                let mut v = this.cell_slots[b].lock();
                v.clear();
                let lo = this.cell_start[b * KEY_BLOCK] as usize;
                let hi = this.cell_start[((b + 1) * KEY_BLOCK).min(keys)] as usize;
                this.entry_pairs(lo, hi, &mut |i, j| {
                    if keep(i, j) {
                        v.push((i, j))
                    }
                });
            } else {
                let b = b - key_blocks;
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
        for s in &self.cell_slots[..key_blocks] {
            out.extend_from_slice(&s.lock());
        }
        for s in &self.big_slots[..big_blocks] {
            out.extend_from_slice(&s.lock());
        }
    }

    /// Entries of the cells with keys `k0..k1`: contiguous, keys being sorted.
    #[inline]
    fn keys_range(&self, k0: usize, k1: usize) -> &[Entry] {
        &self.entries[self.cell_start[k0] as usize..self.cell_start[k1] as usize]
    }

    /// Pairs with at least one sphere among entries `lo..hi` (whole cells),
    /// each found once: a sphere against the rest of its cell and the next
    /// cell along x, and the cells x-1..=x+1 of the four forward rows.
    fn entry_pairs(&self, lo: usize, hi: usize, f: &mut impl FnMut(u32, u32)) {
        let s = self.side;
        let cs = &self.cell_start[..];
        let e = &self.entries[..];
        let mut k = lo;
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
                    test(a, b, f);
                }
                for w in windows {
                    for b in w {
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
            self.near_entries(p, span, &mut |b| f(b.id, b.pos, b.reach));
        }
        for b in &self.big {
            f(b.id, b.pos, b.reach);
        }
    }

    fn near_entries(&self, p: DVec3, span: f64, f: &mut impl FnMut(&Entry)) {
        let lo = self.cell_coords(p - DVec3::splat(span));
        let hi = self.cell_coords(p + DVec3::splat(span));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let k = self.key(lo[0] + 1, y + 1, z + 1);
                for b in self.keys_range(k, k + hi[0] - lo[0] + 1) {
                    f(b);
                }
            }
        }
    }

    /// Largest reach among first-level (grid) spheres.
    pub fn small_reach(&self) -> f64 {
        self.small_reach_max
    }

    /// Pairs of second-level sphere `k` with every grid sphere in its reach
    /// and with the second-level spheres after it.
    fn big_pairs(&self, k: usize, f: &mut impl FnMut(u32, u32)) {
        let a = &self.big[k];
        if !self.all_pairs && !self.entries.is_empty() {
            self.near_entries(a.pos, a.reach + self.small_reach_max, &mut |b| {
                test(a, b, f)
            });
        }
        for b in &self.big[k + 1..] {
            test(a, b, f);
        }
    }
}

/// Real cell coordinates of `p`, clamped into `0..=last`. Truncation is
/// floor here (after max(0)), without a libm call.
#[inline]
fn cell_coords(p: DVec3, inv_cell: f64, last: usize) -> [usize; 3] {
    let c = |x: f64| ((x * inv_cell).max(0.0) as usize).min(last);
    [c(p.x), c(p.y), c(p.z)]
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
    grid.build(spheres, size, |s| (s.pos, s.radius), &super::exec::Serial);
    let mut out = Vec::new();
    grid.pairs(&super::exec::Serial, &|_: u32, _: u32| true, &mut out);
    for (i, j) in out {
        f(i as usize, j as usize);
    }
}
