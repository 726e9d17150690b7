//! A locality of the event loop: neighbour lists with a skin, built from a
//! cell grid (Smallenburg's EDMD does the same; it measured faster than
//! cell-crossing events because a sphere meets its neighbour list's edge far
//! less often than a cell wall, and checks fewer partners per collision).
//!
//! Each sphere has a list centre `c` (its position at the last rebuild) and
//! may wander `skin` from it before it must rebuild (a "relist" event). Two
//! spheres are neighbours when `|c_i - c_j| < r_i + r_j + 2 skin`; while both
//! are within `skin` of their centres, spheres that are not neighbours cannot
//! touch, so only neighbours need collision checks.
//!
//! The skin is one length for every sphere, so mixed radii stay cheap: the
//! grid cell is sized for the bulk (the 98th percentile of radius), and the
//! few much larger spheres live on a second level — every small sphere checks
//! them when it rebuilds, and a large one scans the grid cells over its own
//! reach.
mod chains;
mod lists;

use super::body::{Bodies, Body};
use super::ids::{Cell, Label, SpeciesId};
use super::large::{BIG_FACTOR, Split, split_big, time_to_leave};
use crate::physics::huge_pages;
use chains::CellChains;
use glam::DVec3;
pub use lists::Link;
use lists::Lists;

/// Skin as a fraction of the bulk radius, at least: a quarter diameter
/// (Smallenburg's 1.5 shell), best for dense scenes.
const SKIN_MIN_RADII: f64 = 0.5;
/// Dilute scenes get a wider skin, about this many neighbours per sphere:
/// a rebuild has a fixed cost, so rebuilding less often pays for the longer
/// lists (measured at N = 4000, packing 0.05 to 0.45).
const TARGET_NEIGHBOURS: f64 = 12.0;
/// Relist a little before the skin is used up, so rounding in the lazy
/// positions can never let a non-neighbour slip into contact.
const TRIGGER: f64 = 1.0 - 1e-6;

/// A list centre: 24 bytes. The sphere's radius, which a scan reads beside
/// it, is the one radius of the scene or, with several species, from
/// [`NeighbourLists::species`].
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
struct Centre {
    pos: [f64; 3],
}

impl Centre {
    #[inline(always)]
    fn pos(self) -> DVec3 {
        DVec3::from_array(self.pos)
    }
}

#[derive(Clone, Debug, Default)]
pub struct NeighbourLists {
    skin: f64,
    centre: Vec<Centre>,
    /// Each sphere's species, beside its centre for the scans; empty when
    /// the scene has one (every preset), which saves 4 bytes a sphere.
    species: Vec<SpeciesId>,
    lists: Lists,
    per_side: usize,
    inv_cell: f64,
    /// The spheres of each cell, by centre; second-level ones are in none.
    cells: CellChains,
    bigs: Vec<Label>,
    small_rmax: f64,
}

impl NeighbourLists {
    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.centre.capacity() * size_of::<Centre>()
            + self.species.capacity() * size_of::<SpeciesId>()
            + self.lists.heap_bytes()
            + self.bigs.capacity() * size_of::<Label>()
            + self.cells.heap_bytes()
    }

    /// Lists for every sphere, all centred where the spheres are now.
    pub fn build(&mut self, bodies: &Bodies, size: f64) {
        let n = bodies.len();
        self.centre.clear();
        huge_pages::reserve(&mut self.centre, n);
        self.centre.extend(bodies.iter().map(|b| Centre {
            pos: b.pos.to_array(),
        }));
        self.species.clear();
        if bodies.species_count() > 1 {
            huge_pages::reserve(&mut self.species, n);
            self.species.extend(bodies.iter().map(|b| b.species));
        }
        self.lists.reset(n, 0);
        self.bigs.clear();
        self.cells.reset(n, 0);
        if n == 0 {
            return;
        }
        let Split {
            bulk,
            big_above,
            small_rmax,
        } = split_big(bodies, BIG_FACTOR);
        self.small_rmax = small_rmax;
        // Ideal-gas estimate of the distance that holds TARGET_NEIGHBOURS.
        let density = n as f64 / (size * size * size);
        let reach = (TARGET_NEIGHBOURS / (density * 4.0 / 3.0 * std::f64::consts::PI)).cbrt();
        let skin = (SKIN_MIN_RADII * bulk)
            .max(0.5 * (reach - 2.0 * bulk))
            .clamp(1e-12 * size, 0.25 * size);
        let cell_min = 2.0 * (self.small_rmax + skin);
        // At most ~4 cells per sphere keeps memory O(N).
        let cap = ((4 * n) as f64).cbrt().ceil().clamp(1.0, 256.0);
        self.per_side = (size / cell_min).floor().clamp(1.0, cap) as usize;
        self.inv_cell = self.per_side as f64 / size;
        // Cells larger than needed (few or tiny spheres): widen the skin to
        // fill them, which costs no more per rebuild and rebuilds less often.
        self.skin = (0.5 * size / self.per_side as f64 - self.small_rmax).max(skin);
        self.cells.reset(n, self.per_side.pow(3));
        for (i, b) in bodies.labels().zip(bodies.iter()) {
            if bodies.radius_of(b) > big_above {
                self.bigs.push(i);
                self.lists.make_big(i);
            } else {
                self.cells.insert(i, self.cell_of(b.pos));
            }
        }
        // Count, size the flat array once, then link.
        for i in bodies.labels() {
            self.scan(i, bodies, |j| j > i, Lists::count);
        }
        self.lists.fit_counts();
        for i in bodies.labels() {
            self.scan(i, bodies, |j| j > i, Lists::link);
        }
    }

    /// Sphere `i` (moved to the current time) gets a new centre and list.
    pub fn rebuild(&mut self, i: Label, bodies: &Bodies) {
        self.lists.unlink_all(i);
        if !self.lists.is_big(i) {
            // The cell it was put in: its old centre's.
            let from = self.cell_of(self.centre[i.index()].pos());
            self.cells.move_to(i, from, self.cell_of(bodies[i].pos));
        }
        self.centre[i.index()].pos = bodies[i].pos.to_array();
        self.scan(i, bodies, |j| j != i, Lists::link);
    }

    #[inline]
    pub fn of(&self, i: Label) -> &[Link] {
        self.lists.of(i)
    }

    /// Start loading what predicting sphere `k` reads first: its list's
    /// word and links, and its list's centre.
    #[inline(always)]
    pub fn prefetch(&self, k: usize) {
        if let Some(c) = self.centre.get(k) {
            crate::physics::prefetch::record(c);
            self.lists.prefetch(k);
        }
    }

    /// Time from `b.t` until sphere `i` has wandered to the edge of its skin.
    #[inline]
    pub fn relist_time(&self, i: Label, b: &Body) -> f64 {
        time_to_leave(
            b.pos - self.centre[i.index()].pos(),
            b.vel,
            self.skin * TRIGGER,
        )
    }

    /// Find the neighbours `j` of `i` (with `want(j)`) and `found(i, j)`
    /// each pair: link it, or count it.
    #[allow(clippy::excessive_nesting)] // a box of cells, z, y, x, each cell's spheres in a closure
    fn scan(
        &mut self,
        i: Label,
        bodies: &Bodies,
        want: impl Fn(Label) -> bool,
        found: impl Fn(&mut Lists, Label, Label),
    ) {
        let ci = self.centre[i.index()].pos();
        let ri = bodies.radius(i) + 2.0 * self.skin;
        // One species: every sphere's radius is i's.
        let one_radius = self.species.is_empty().then(|| bodies.radius(i));
        let test = |j: Label, centre: &[Centre], species: &[SpeciesId], lists: &mut Lists| {
            if !want(j) {
                return;
            }
            let rj = one_radius.unwrap_or_else(|| bodies.radius_of_species(species[j.index()]));
            let s = ri + rj;
            if (ci - centre[j.index()].pos()).length_squared() < s * s {
                found(lists, i, j);
            }
        };
        let big = self.lists.is_big(i);
        let reach = if big {
            bodies.radius(i) + self.small_rmax + 2.0 * self.skin
        } else {
            0.0
        };
        let (lo, hi) = if big {
            (
                self.coords(ci - DVec3::splat(reach)),
                self.coords(ci + DVec3::splat(reach)),
            )
        } else {
            let c = self.coords(ci);
            let m = self.per_side - 1;
            (c.map(|x| x.saturating_sub(1)), c.map(|x| (x + 1).min(m)))
        };
        let p = self.per_side;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    self.cells.for_each_in(x + p * (y + p * z), |j| {
                        test(j, &self.centre, &self.species, &mut self.lists);
                    });
                }
            }
        }
        for k in 0..self.bigs.len() {
            test(self.bigs[k], &self.centre, &self.species, &mut self.lists);
        }
    }

    fn coords(&self, p: DVec3) -> [usize; 3] {
        let m = self.per_side as f64 - 1.0;
        let c = |x: f64| (x * self.inv_cell).floor().clamp(0.0, m) as usize;
        [c(p.x), c(p.y), c(p.z)]
    }

    fn cell_of(&self, p: DVec3) -> Cell {
        let [x, y, z] = self.coords(p);
        Cell::at(x + self.per_side * (y + self.per_side * z))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_centre_is_24_bytes() {
        assert_eq!(size_of::<super::Centre>(), 24);
    }
}
