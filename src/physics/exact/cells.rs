//! Broad phase for dilute and moderate scenes: a cell grid with
//! cell-crossing events (Rapaport; DynamO). Cells are at least the largest
//! bulk diameter, so spheres can only touch from neighbouring cells; a
//! sphere's candidates are the spheres in the 27 cells around its own. A
//! sphere changes cell only at a crossing event, so the pair bookkeeping is
//! one linked-list move, and crossings are rarer than neighbour-list
//! rebuilds when the mean free path is long.
//!
//! Large spheres (the few far above the bulk radius) stay out of the grid:
//! every small sphere checks them at each prediction, and a large one scans
//! the cells over its own reach plus a skin, rescanning when it has moved
//! the skin (a small sphere entering that reach does so by a crossing, which
//! checks the large ones).
use super::body::Body;
use super::cell_list::{CellList, NONE, split_big, time_to_leave};
use super::schedule::{Event, Kind};
use glam::DVec3;

const BIG_FACTOR: f64 = 3.0;

#[derive(Clone, Debug, Default)]
pub struct Cells {
    per_side: usize,
    cell: f64,
    /// The small spheres of each cell; large ones are in no cell.
    list: CellList,
    bigs: Vec<u32>,
    /// Where each large sphere last scanned from (indexed like `bigs`).
    scan_centre: Vec<DVec3>,
    big_slot: Vec<u32>,
    small_rmax: f64,
    skin: f64,
}

impl Cells {
    pub fn build(&mut self, bodies: &[Body], size: f64) {
        let n = bodies.len();
        self.list.reset(n, 0);
        self.big_slot.clear();
        self.big_slot.resize(n, NONE);
        self.bigs.clear();
        self.scan_centre.clear();
        if n == 0 {
            self.per_side = 1;
            return;
        }
        let big_above;
        (big_above, self.small_rmax) = split_big(bodies, BIG_FACTOR);
        // A little over a diameter, so rounding at a crossing can never
        // leave touching spheres two cells apart.
        let cell_min = 2.0 * self.small_rmax * (1.0 + 1e-9);
        let cap = ((16 * n) as f64).cbrt().ceil().clamp(1.0, 512.0);
        self.per_side = (size / cell_min).floor().clamp(1.0, cap) as usize;
        self.cell = size / self.per_side as f64;
        self.skin = self.cell;
        self.list.reset(n, self.per_side.pow(3));
        for (i, b) in bodies.iter().enumerate() {
            if b.radius > big_above {
                self.big_slot[i] = self.bigs.len() as u32;
                self.bigs.push(i as u32);
                self.scan_centre.push(b.pos);
            } else {
                let c = self.coords(b.pos);
                self.list.insert(i, self.index(c));
            }
        }
    }

    #[inline]
    pub fn is_big(&self, i: usize) -> bool {
        self.big_slot[i] != NONE
    }

    /// The broad-phase event of sphere `i` (at `b.t`): its next cell crossing,
    /// or for a large sphere the edge of its skin. Relative time.
    #[inline]
    pub fn next_event(&self, i: usize, b: &Body) -> (f64, Event) {
        if self.is_big(i) {
            let d = b.pos - self.scan_centre[self.big_slot[i] as usize];
            let t = time_to_leave(d, b.vel, self.skin * (1.0 - 1e-6));
            if t == f64::INFINITY {
                return (f64::INFINITY, Event::default());
            }
            let ev = Event {
                kind: Kind::Relist,
                ..Event::default()
            };
            return (t, ev);
        }
        let c = self.list.cell(i) as usize;
        let p = self.per_side;
        let coord = [c % p, (c / p) % p, c / (p * p)];
        let mut best = f64::INFINITY;
        let mut mask = 0u8;
        for (k, &ck) in coord.iter().enumerate() {
            let v = b.vel[k];
            let t = if v > 0.0 && ck + 1 < p {
                ((ck + 1) as f64 * self.cell - b.pos[k]) / v
            } else if v < 0.0 && ck > 0 {
                (ck as f64 * self.cell - b.pos[k]) / v
            } else {
                continue;
            };
            let t = t.max(0.0);
            if t < best {
                best = t;
                mask = k as u8 | if v > 0.0 { 4 } else { 0 };
            }
        }
        let ev = Event {
            kind: Kind::Cross,
            mask,
            ..Event::default()
        };
        (best, ev)
    }

    /// Sphere `i` crosses into the next cell as `mask` says.
    #[inline]
    pub fn cross(&mut self, i: usize, mask: u8) {
        let p = self.per_side;
        let stride = [1, p, p * p][(mask & 3) as usize];
        let c = self.list.cell(i) as usize;
        let to = if mask & 4 != 0 {
            c + stride
        } else {
            c - stride
        };
        self.list.move_to(i, to);
    }

    /// A large sphere rescans from where it is now.
    pub fn rescan(&mut self, i: usize, b: &Body) {
        self.scan_centre[self.big_slot[i] as usize] = b.pos;
    }

    /// Every sphere that sphere `i` could touch before its next broad-phase
    /// event: the 27 cells around a small one, the cells over a large one's
    /// reach from its scan centre; and every large sphere.
    #[inline]
    pub fn for_each_candidate(&self, i: usize, b: &Body, mut f: impl FnMut(u32)) {
        let p = self.per_side;
        let (lo, hi) = if self.is_big(i) {
            let centre = self.scan_centre[self.big_slot[i] as usize];
            let reach = DVec3::splat((b.radius + self.small_rmax + self.skin) * (1.0 + 1e-9));
            (self.coords(centre - reach), self.coords(centre + reach))
        } else {
            let c = self.list.cell(i) as usize;
            let coord = [c % p, (c / p) % p, c / (p * p)];
            let m = p - 1;
            (
                coord.map(|x| x.saturating_sub(1)),
                coord.map(|x| (x + 1).min(m)),
            )
        };
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let row = p * (y + p * z);
                for x in lo[0]..=hi[0] {
                    self.list.for_each_in(row + x, |j| {
                        if j as usize != i {
                            f(j);
                        }
                    });
                }
            }
        }
        for &j in &self.bigs {
            if j as usize != i {
                f(j);
            }
        }
    }

    /// After a crossing (`mask` as in [`Kind::Cross`]): the spheres in the
    /// layer of cells that just came next to sphere `i`'s new cell. Together
    /// with its best event over the old neighbourhood, these are all it
    /// could touch (Rapaport's trick: a crossing scans 9 cells, not 27).
    #[inline]
    pub fn for_each_new_candidate(&self, i: usize, mask: u8, mut f: impl FnMut(u32)) {
        let p = self.per_side;
        let c = self.list.cell(i) as usize;
        let mut lo = [c % p, (c / p) % p, c / (p * p)];
        let axis = (mask & 3) as usize;
        let layer = if mask & 4 != 0 {
            lo[axis] + 1
        } else {
            match lo[axis].checked_sub(1) {
                Some(l) => l,
                None => return,
            }
        };
        if layer >= p {
            return;
        }
        let mut hi = lo.map(|x| (x + 1).min(p - 1));
        lo = lo.map(|x| x.saturating_sub(1));
        lo[axis] = layer;
        hi[axis] = layer;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let row = p * (y + p * z);
                for x in lo[0]..=hi[0] {
                    self.list.for_each_in(row + x, &mut f);
                }
            }
        }
    }

    fn coords(&self, p: DVec3) -> [usize; 3] {
        let m = self.per_side as f64 - 1.0;
        let c = |x: f64| (x / self.cell).floor().clamp(0.0, m) as usize;
        [c(p.x), c(p.y), c(p.z)]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.per_side * (c[1] + self.per_side * c[2])
    }
}
