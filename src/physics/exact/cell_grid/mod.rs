//! The locality for dilute and moderate scenes: a cell grid with
//! cell-crossing events (Rapaport; `DynamO`). Cells are at least the largest
//! bulk diameter, so spheres can only touch from neighbouring cells; a
//! sphere's candidates are the spheres in the 27 cells around its own. A
//! sphere changes cell only at a crossing event, so the pair bookkeeping is
//! one move between cells (`CellBlocks`), and crossings are rarer than
//! neighbour-list rebuilds when the mean free path is long.
//!
//! Large spheres (the few far above the bulk radius) stay out of the grid:
//! every small sphere checks them at each prediction, and a large one scans
//! the cells over its own reach plus a skin, rescanning when it has moved
//! the skin (a small sphere entering that reach does so by a crossing, which
//! checks the large ones).
mod blocks;

use super::body::{Bodies, Body};
use super::ids::Label;
use super::large::{BIG_FACTOR, Split, split_big, time_to_leave};
use super::schedule::{Event, Kind};
use crate::physics::huge_pages;
use blocks::CellBlocks;
use glam::DVec3;

/// Most cells the grid may have per sphere, by default: in dilute scenes
/// cells a diameter wide would number far more than the spheres, and an
/// almost empty grid costs memory and cache without saving work (fewer,
/// larger cells also mean fewer crossings). 4 measured best over 10k to 1M
/// spheres at packing 0.005 and 0.1: 2 was as fast when dilute but slower at
/// 0.1, where cells a diameter wide are about 5 a sphere.
pub const CELLS_PER_SPHERE: u32 = 4;

/// Bits of one axis in a sphere's packed cell coordinates.
const AXIS_BITS: u32 = 10;
const AXIS_MASK: u32 = (1 << AXIS_BITS) - 1;
/// A large sphere's place: in no cell.
const BIG: u32 = 1 << 31;
const _: () = assert!(512 <= AXIS_MASK && 3 * AXIS_BITS < 31);

fn pack(c: [usize; 3]) -> u32 {
    (c[0] | c[1] << AXIS_BITS | c[2] << (2 * AXIS_BITS)) as u32
}

#[inline(always)]
fn unpack(p: u32) -> [u32; 3] {
    [
        p & AXIS_MASK,
        p >> AXIS_BITS & AXIS_MASK,
        p >> (2 * AXIS_BITS) & AXIS_MASK,
    ]
}

#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    per_side: usize,
    /// Cells per side with a layer of always-empty cells around the grid,
    /// so the stencils below need no bounds checks (an unpredictable branch
    /// per cell otherwise).
    padded: usize,
    /// Offsets from a cell's (-1, -1, -1) neighbour to its 27 neighbours
    /// (itself first),
    /// and to the 9 of the layer a crossing brings next to it (one set per
    /// direction, indexed by the crossing's mask).
    stencil: [usize; 27],
    /// Offsets from a cell to the 13 of its neighbours that come after it
    /// in memory, so a search over cells meets each pair of cells once.
    forward: [usize; 13],
    layers: [[usize; 9]; 8],
    /// Each sphere's cell coordinates (unpadded), [`AXIS_BITS`] an axis (a
    /// side has at most 512 cells), or [`BIG`] for a large one (in no cell):
    /// kept so that events need no integer division, and the cell's index
    /// is a multiply-add away.
    place: Vec<u32>,
    cell: f64,
    /// The small spheres of each cell; large ones are in no cell.
    list: CellBlocks,
    /// The large spheres, in increasing order (found by bisection).
    bigs: Vec<Label>,
    /// Where each large sphere last scanned from (indexed like `bigs`).
    scan_centre: Vec<DVec3>,
    small_rmax: f64,
    skin: f64,
}

impl CellGrid {
    /// A grid of cells at least a diameter wide and at most `per_sphere`
    /// cells per sphere.
    pub fn build(&mut self, bodies: &Bodies, size: f64, per_sphere: u32) {
        let n = bodies.len();
        self.list.reset(0, 0);
        huge_pages::refill(&mut self.place, n, BIG);
        self.bigs.clear();
        self.scan_centre.clear();
        if n == 0 {
            self.per_side = 1;
            return;
        }
        let Split {
            big_above,
            small_rmax,
            ..
        } = split_big(bodies, BIG_FACTOR);
        self.small_rmax = small_rmax;
        // A little over a diameter, so rounding at a crossing can never
        // leave touching spheres two cells apart.
        let cell_min = 2.0 * self.small_rmax * (1.0 + 1e-9);
        let cap = ((per_sphere as usize * n) as f64)
            .cbrt()
            .ceil()
            .clamp(1.0, 512.0);
        self.per_side = (size / cell_min).floor().clamp(1.0, cap) as usize;
        self.cell = size / self.per_side as f64;
        self.skin = self.cell;
        self.set_stencils();
        self.list.reset(n, self.padded.pow(3));
        for (i, b) in bodies.labels().zip(bodies.iter()) {
            if bodies.radius_of(b) > big_above {
                self.bigs.push(i);
                self.scan_centre.push(b.pos);
            } else {
                let c = self.coords(b.pos);
                self.place[i.index()] = pack(c);
                self.list.insert(i, self.index(c));
            }
        }
    }

    fn set_stencils(&mut self) {
        self.padded = self.per_side + 2;
        let q = self.padded;
        let at = |x: usize, y: usize, z: usize| x + q * (y + q * z);
        let cube = (0..27).map(|k| [k % 3, k / 3 % 3, k / 9]);
        // Own cell first, then faces, edges, corners: near partners come
        // first, so the running best is small early and fewer of the later
        // candidates pass the cheap test (each pass costs a root and, being
        // random, often a mispredicted branch).
        let mut near: Vec<[usize; 3]> = cube.clone().collect();
        near.sort_by_key(|c| c.iter().filter(|&&x| x != 1).count());
        for (slot, c) in self.stencil.iter_mut().zip(near) {
            *slot = at(c[0], c[1], c[2]);
        }
        let centre = at(1, 1, 1);
        for (slot, c) in self.forward.iter_mut().zip(cube.clone().skip(14)) {
            *slot = at(c[0], c[1], c[2]) - centre;
        }
        for mask in 0..8u8 {
            let axis = (mask & 3) as usize;
            if axis == 3 {
                continue;
            }
            let side = if mask & 4 != 0 { 2 } else { 0 };
            let layer = cube.clone().filter(|c| c[axis] == side);
            for (slot, c) in self.layers[mask as usize].iter_mut().zip(layer) {
                *slot = at(c[0], c[1], c[2]);
            }
        }
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.place.capacity() * 4
            + self.bigs.capacity() * size_of::<Label>()
            + self.list.heap_bytes()
            + self.scan_centre.capacity() * size_of::<DVec3>()
    }

    /// The large spheres (in no cell).
    pub fn bigs(&self) -> &[Label] {
        &self.bigs
    }

    /// Start loading sphere `i`'s place.
    #[inline(always)]
    pub fn prefetch_place(&self, i: usize) {
        if let Some(p) = self.place.get(i) {
            crate::physics::prefetch::line(p);
        }
    }

    #[inline]
    pub fn is_big(&self, i: Label) -> bool {
        self.place[i.index()] & BIG != 0
    }

    /// Large sphere `i`'s index in `bigs`.
    fn big_slot(&self, i: Label) -> usize {
        let (Ok(k) | Err(k)) = self.bigs.binary_search(&i);
        k
    }

    /// Index of small sphere `i`'s cell.
    #[inline]
    fn cell_of(&self, i: Label) -> usize {
        let [x, y, z] = unpack(self.place[i.index()]);
        let q = self.padded;
        (x as usize + 1) + q * ((y as usize + 1) + q * (z as usize + 1))
    }

    /// The locality event of sphere `i` (at `b.t`): its next cell crossing,
    /// or for a large sphere the edge of its skin. Relative time.
    #[inline]
    pub fn next_event(&self, i: Label, b: &Body) -> (f64, Event) {
        if self.is_big(i) {
            let d = b.pos - self.scan_centre[self.big_slot(i)];
            let t = time_to_leave(d, b.vel, self.skin * (1.0 - 1e-6));
            if t == f64::INFINITY {
                return (f64::INFINITY, Event::default());
            }
            return (t, Event::of(Kind::Relist, 0));
        }
        let coord = unpack(self.place[i.index()]);
        let last = self.per_side as u32 - 1;
        let mut best = f64::INFINITY;
        let mut mask = 0u8;
        // No branches on the signs of the velocity: they are random, so a
        // branch on them mispredicts half the time (and LLVM turns plain
        // selects back into such branches; indexing does not).
        for (k, &ck) in coord.iter().enumerate() {
            let v = b.vel[k];
            let up = v > 0.0;
            let face = ck + up as u32;
            let t = ((face as f64 * self.cell - b.pos[k]) / v).max(0.0);
            #[allow(clippy::needless_bitwise_bool)] // branchless on purpose, as above
            let open = (ck != [0, last][up as usize]) & (v != 0.0);
            let t = [f64::INFINITY, t][open as usize];
            let better = t < best;
            best = [best, t][better as usize];
            mask = [mask, k as u8 | (up as u8) << 2][better as usize];
        }
        (best, Event::of(Kind::Cross, mask))
    }

    /// The cell small sphere `i` crosses into as `mask` says (a crossing's
    /// mask: axis in bits 0..2, upwards if bit 2).
    #[inline(always)]
    fn next_cell(&self, i: Label, mask: u8) -> usize {
        let q = self.padded;
        let stride = [1, q, q * q][(mask & 3) as usize];
        let c = self.cell_of(i);
        if mask & 4 != 0 {
            c + stride
        } else {
            c - stride
        }
    }

    /// Start loading the cell words a crossing of sphere `i` as `mask` says
    /// will read: its cell, the next, and the layer the next brings.
    #[inline]
    pub fn prefetch_cross(&self, i: Label, mask: u8) {
        if mask & 3 == 3 || self.is_big(i) {
            return;
        }
        let to = self.next_cell(i, mask);
        self.list.prefetch(self.cell_of(i));
        self.list.prefetch(to);
        let corner = to - self.stencil[0];
        for &o in &self.layers[mask as usize] {
            self.list.prefetch(corner + o);
        }
    }

    /// Start loading the words of the 27 cells around small sphere `i`.
    #[inline]
    pub fn prefetch_around(&self, i: Label) {
        if self.is_big(i) {
            return;
        }
        let corner = self.cell_of(i) - self.stencil[0];
        for &o in &self.stencil {
            self.list.prefetch(corner + o);
        }
    }

    /// Sphere `i` crosses into the next cell as `mask` says.
    #[inline(always)]
    pub fn cross(&mut self, i: Label, mask: u8) {
        let c = self.cell_of(i);
        let to = self.next_cell(i, mask);
        let one = 1 << (AXIS_BITS * u32::from(mask & 3));
        let p = &mut self.place[i.index()];
        *p = if mask & 4 != 0 { *p + one } else { *p - one };
        self.list.move_to(i, c, to);
    }

    /// A large sphere rescans from where it is now.
    pub fn rescan(&mut self, i: Label, b: &Body) {
        let k = self.big_slot(i);
        self.scan_centre[k] = b.pos;
    }

    /// Every sphere that sphere `i` could touch before its next locality
    /// event, into `out[..n]` (returns `n`; sphere `i` itself may be among
    /// them), as `Label::raw`s: the 27 cells around a small one, the cells
    /// over a large one's reach (its `radius` plus the bulk's and a skin)
    /// from its scan centre; and every large sphere.
    #[inline]
    pub fn candidates(&self, i: Label, radius: f64, out: &mut Vec<u32>) -> usize {
        let n = if self.is_big(i) {
            let centre = self.scan_centre[self.big_slot(i)];
            let reach = DVec3::splat((radius + self.small_rmax + self.skin) * (1.0 + 1e-9));
            let (lo, hi) = (self.coords(centre - reach), self.coords(centre + reach));
            let cells: Vec<usize> = (lo[2]..=hi[2])
                .flat_map(|z| {
                    (lo[1]..=hi[1])
                        .flat_map(move |y| (lo[0]..=hi[0]).map(move |x| self.index([x, y, z])))
                })
                .collect();
            self.list.gather(0, &cells, out)
        } else {
            let corner = self.cell_of(i) - self.stencil[0];
            self.list.gather_stencil(corner, &self.stencil, out)
        };
        if self.bigs.is_empty() {
            return n;
        }
        out.truncate(n);
        out.extend(self.bigs.iter().map(|b| b.raw()));
        out.len()
    }

    /// Cells of the grid, padding included (for cutting a search over them).
    pub fn cells(&self) -> usize {
        self.list.cells()
    }

    /// `f(i, j)` for every pair of small spheres in the same or neighbouring
    /// cells among `cells` (all of them once when the ranges cover the grid;
    /// the spheres that could touch, as for [`Self::candidates`]). `own` and
    /// `near` are scratch.
    pub fn for_each_near_pair(
        &self,
        cells: std::ops::Range<usize>,
        own: &mut Vec<u32>,
        near: &mut Vec<u32>,
        mut f: impl FnMut(Label, Label),
    ) {
        for c in cells {
            // Most cells are empty (up to 4 a sphere); padding always is.
            if self.list.is_empty(c) {
                continue;
            }
            let k = self.list.gather_stencil(c, &[0], own);
            let m = self.list.gather_stencil(c, &self.forward, near);
            for (x, &i) in own[..k].iter().enumerate() {
                for &j in own[x + 1..k].iter().chain(&near[..m]) {
                    f(Label::from_raw(i), Label::from_raw(j));
                }
            }
        }
    }

    /// Before a crossing (`mask` as in [`Kind::Cross`]): the spheres in the
    /// layer of cells the crossing brings next to small sphere `i`'s new
    /// cell (empty padding at the edge of the grid), into `out[..n]`;
    /// returns `n`. Together with its best event over the old
    /// neighbourhood, these are all it could touch (Rapaport's trick: a
    /// crossing scans 9 cells, not 27). The layer holds neither the old
    /// cell nor the new, so the move changes none of it: gathered first,
    /// its bodies can load while the move runs.
    #[inline(always)]
    pub fn next_layer(&self, i: Label, mask: u8, out: &mut Vec<u32>) -> usize {
        let corner = self.next_cell(i, mask) - self.stencil[0];
        self.list
            .gather_stencil(corner, &self.layers[mask as usize], out)
    }

    fn coords(&self, p: DVec3) -> [usize; 3] {
        let m = self.per_side as f64 - 1.0;
        let c = |x: f64| (x / self.cell).floor().clamp(0.0, m) as usize;
        [c(p.x), c(p.y), c(p.z)]
    }

    /// Index in the padded grid of the cell at unpadded coordinates `c`.
    fn index(&self, c: [usize; 3]) -> usize {
        let q = self.padded;
        (c[0] + 1) + q * ((c[1] + 1) + q * (c[2] + 1))
    }
}

#[cfg(test)]
mod tests {
    use super::{CELLS_PER_SPHERE, CellGrid};
    use crate::physics::exact::body::Bodies;
    use crate::physics::exact::schedule::Slot;
    use crate::scene::{SceneSpec, build_world};

    /// What exact holds a sphere besides its bodies and its queue (issue
    /// 20): the cell grid (4 cells a sphere at most, each one word; a block
    /// only for a cell of two spheres or more; each sphere's packed cell)
    /// and a 16-byte slot (with a byte apart for which event the queue
    /// holds). Before, the grid alone took 16 bytes a cell and 14 a sphere
    /// (about 85 a sphere), the event and pending records 36.
    #[test]
    fn the_cell_grid_and_the_event_slots_stay_small() {
        assert_eq!(size_of::<Slot>(), 16);
        for radius in [0.002_285_39, 0.006_19] {
            // 100k spheres at packing 0.005 and 0.1.
            let w = build_world(&SceneSpec {
                count: Some(100_000),
                radius: Some(radius),
                seed: Some(5),
                ..Default::default()
            })
            .expect("the scene builds");
            let bodies = Bodies::from_spheres(w.spheres.iter(), 0.0);
            let mut grid = CellGrid::default();
            grid.build(&bodies, w.size, CELLS_PER_SPHERE);
            let cells = grid.cells() as f64 / bodies.len() as f64;
            let per = grid.heap_bytes() as f64 / bodies.len() as f64;
            // The cells the spheres make: at least 3 a sphere (the cap is 4),
            // so a word a cell would be out of reach if cells were blocks.
            assert!(cells > 3.0 && cells < 4.5, "{cells} cells a sphere");
            assert!(
                per < 4.0 * cells + 8.0,
                "{per} bytes a sphere, {cells} cells"
            );
        }
    }
}
