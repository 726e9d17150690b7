//! Broad phase of the event loop: neighbour lists with a skin, built from a
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

use super::body::{Bodies, Body};
use super::ids::{Cell, Label, SpeciesId};
use super::large::{BIG_FACTOR, split_big, time_to_leave};
#[cfg(feature = "experiments")]
use super::renumber::{apply, apply_chunks};
use crate::physics::huge_pages;
use chains::CellChains;
use glam::DVec3;

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
/// The flat lists' stride is a multiple of this many links, and grows by it
/// when a list fills. A build counts its lists first and leaves [`HEADROOM`]
/// links past the longest: at a million dense spheres (longest 18, mean
/// 13.5) the stride is 24 where a fixed 32 held a third more than that.
const STRIDE_STEP: usize = 8;
/// Links past the longest list a build leaves room for, as lists lengthen
/// with relists.
const HEADROOM: usize = 4;

/// A list centre with the sphere's species beside it (its radius from the
/// species table, a few lines every scan shares): 28 bytes, packed, where a
/// radius beside an aligned centre took 32.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, packed(4))]
struct Centre {
    pos: [f64; 3],
    species: SpeciesId,
}

impl Centre {
    #[inline(always)]
    fn pos(self) -> DVec3 {
        DVec3::from_array(self.pos)
    }
}

/// One entry of a neighbour list: the neighbour. Where this sphere sits in
/// the neighbour's own list is found by a search of that list (about a
/// dozen entries, one or two cache lines), not stored: at a million dense
/// spheres the stored place was half the lists' memory (docs/perf-log.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Link {
    pub j: Label,
}

/// Where a sphere's list is kept, as its word in `Lists::len` says: in the
/// flat array with this length (a bulk sphere), or the `Big(k)`th of the
/// large spheres' own lists (the word's top bit set). One word a sphere,
/// read by every look-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Home {
    Flat(usize),
    Big(usize),
}

/// The top bit of a `Lists::len` word: a large sphere's list.
const BIG: u32 = 1 << 31;

impl Home {
    #[inline(always)]
    fn of(word: u32) -> Home {
        if word & BIG == 0 {
            Home::Flat(word as usize)
        } else {
            Home::Big((word & !BIG) as usize)
        }
    }

    /// The length of a flat list (none for a large sphere's).
    #[inline(always)]
    fn flat_len(word: u32) -> Option<usize> {
        match Home::of(word) {
            Home::Flat(len) => Some(len),
            Home::Big(_) => None,
        }
    }
}

/// Neighbour lists of the bulk spheres in one flat array with one stride
/// (no pointer per list; the stride grows, in place, if a list fills),
/// and separate growable lists for the few large spheres, whose neighbours
/// may number thousands.
#[derive(Clone, Debug, Default)]
struct Lists {
    stride: usize,
    flat: Vec<Link>,
    /// Each sphere's [`Home`] as a word: its flat list's length, or
    /// [`BIG`] and its place in `big`.
    len: Vec<u32>,
    big: Vec<Vec<Link>>,
}

impl Lists {
    /// Empty lists for `n` spheres, all in the flat array at `stride`.
    fn reset(&mut self, n: usize, stride: usize) {
        huge_pages::refill(&mut self.len, n, 0);
        self.big.clear();
        self.set_stride(stride);
    }

    /// A new flat array at `stride`, every list emptied. The old one goes
    /// first, so the two are never held at once.
    fn set_stride(&mut self, stride: usize) {
        self.stride = stride;
        self.flat = Vec::new();
        self.flat = huge_pages::filled(self.len.len() * stride, Link::default());
        for w in self
            .len
            .iter_mut()
            .filter(|w| Home::flat_len(**w).is_some())
        {
            *w = 0;
        }
    }

    /// Count a pair found by a build's first pass (in the lengths).
    #[inline]
    fn count(&mut self, i: Label, j: Label) {
        for k in [i, j] {
            if !self.is_big(k) {
                self.len[k.index()] += 1;
            }
        }
    }

    /// After a build's counting pass: a stride with room for [`HEADROOM`]
    /// more links than the longest list, every list empty again.
    fn fit_counts(&mut self) {
        let longest = self.len.iter().filter_map(|&w| Home::flat_len(w)).max();
        let longest = longest.unwrap_or(0);
        self.set_stride((longest + HEADROOM).next_multiple_of(STRIDE_STEP));
    }

    /// Whether `i` is a large sphere (its list growable, itself in no cell).
    #[inline]
    fn is_big(&self, i: Label) -> bool {
        Home::flat_len(self.len[i.index()]).is_none()
    }

    fn make_big(&mut self, i: Label) {
        self.len[i.index()] = BIG | self.big.len() as u32;
        self.big.push(Vec::new());
    }

    #[inline(always)]
    fn home(&self, i: Label) -> Home {
        Home::of(self.len[i.index()])
    }

    #[inline]
    fn of(&self, i: Label) -> &[Link] {
        match self.home(i) {
            Home::Flat(len) => &self.flat[i.index() * self.stride..][..len],
            Home::Big(k) => &self.big[k],
        }
    }

    #[inline]
    fn of_mut(&mut self, i: Label) -> &mut [Link] {
        match self.home(i) {
            Home::Flat(len) => &mut self.flat[i.index() * self.stride..][..len],
            Home::Big(k) => &mut self.big[k],
        }
    }

    #[inline]
    fn push(&mut self, i: Label, l: Link) {
        match self.home(i) {
            Home::Flat(len) => {
                if len == self.stride {
                    self.grow();
                }
                self.flat[i.index() * self.stride + len] = l;
                self.len[i.index()] += 1;
            }
            Home::Big(k) => self.big[k].push(l),
        }
    }

    #[inline]
    fn pop(&mut self, i: Label) {
        match self.home(i) {
            Home::Flat(_) => self.len[i.index()] -= 1,
            Home::Big(k) => {
                self.big[k].pop();
            }
        }
    }

    /// Make `i` and `j` neighbours.
    #[inline]
    fn link(&mut self, i: Label, j: Label) {
        self.push(i, Link { j });
        self.push(j, Link { j: i });
    }

    /// Remove `i` from all its neighbours' lists and empty its own.
    fn unlink_all(&mut self, i: Label) {
        for k in 0..self.of(i).len() {
            let j = self.of(i)[k].j;
            let list = self.of_mut(j);
            // A pair is linked once, so `i` is in `j`'s list exactly once.
            let at = list.iter().position(|l| l.j == i);
            debug_assert!(at.is_some(), "neighbours are linked both ways");
            if let Some(at) = at {
                // Move j's last entry into the hole.
                let last = list.len() - 1;
                list[at] = list[last];
                self.pop(j);
            }
        }
        match self.home(i) {
            Home::Flat(_) => self.len[i.index()] = 0,
            Home::Big(k) => self.big[k].clear(),
        }
    }

    /// The spheres are relabelled (`perm[new] = old`, `inv` its inverse);
    /// every list keeps its order.
    #[cfg(feature = "experiments")]
    fn relabel(&mut self, perm: &[Label], inv: &[Label]) {
        apply_chunks(&mut self.flat, self.stride, perm);
        apply(&mut self.len, perm);
        for i in 0..self.len.len() {
            if !self.is_big(Label::at(i)) {
                for l in self.of_mut(Label::at(i)) {
                    l.j = inv[l.j.index()];
                }
            }
        }
        for l in self.big.iter_mut().flatten() {
            l.j = inv[l.j.index()];
        }
    }

    fn grow(&mut self) {
        self.grow_to(self.stride + STRIDE_STEP);
    }

    /// A wider stride, in place: the buffer grows (a large one by remapping
    /// its pages, not by a copy, so the peak is the new size), then every
    /// list moves to its new place, the last first, so none is overwritten
    /// before it has moved. Each list keeps its order.
    fn grow_to(&mut self, stride: usize) {
        let (old, n) = (self.stride, self.len.len());
        huge_pages::reserve(&mut self.flat, n * stride);
        self.flat.resize(n * stride, Link::default());
        for (i, &w) in self.len.iter().enumerate().rev() {
            if let Some(len) = Home::flat_len(w) {
                self.flat.copy_within(i * old..i * old + len, i * stride);
            }
        }
        self.stride = stride;
    }
}

#[derive(Clone, Debug, Default)]
pub struct NeighbourLists {
    skin: f64,
    centre: Vec<Centre>,
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
        let l = &self.lists;
        let big: usize = l.big.iter().map(|b| b.capacity() * size_of::<Link>()).sum();
        self.centre.capacity() * size_of::<Centre>()
            + l.flat.capacity() * size_of::<Link>()
            + l.len.capacity() * 4
            + self.bigs.capacity() * size_of::<Label>()
            + l.big.capacity() * size_of::<Vec<Link>>()
            + big
            + self.cells.heap_bytes()
    }

    /// Lists for every sphere, all centred where the spheres are now.
    pub fn build(&mut self, bodies: &Bodies, size: f64) {
        let n = bodies.len();
        self.centre.clear();
        huge_pages::reserve(&mut self.centre, n);
        self.centre.extend(bodies.iter().map(|b| Centre {
            pos: b.pos.to_array(),
            species: b.species,
        }));
        self.lists.reset(n, 0);
        self.bigs.clear();
        self.cells.reset(n, 0);
        if n == 0 {
            return;
        }
        let mut radii: Vec<f64> = bodies.iter().map(|b| bodies.radius_of(b)).collect();
        let k = (n * 98 / 100).min(n - 1);
        let bulk = *radii.select_nth_unstable_by(k, f64::total_cmp).1;
        let big_above;
        (big_above, self.small_rmax) = split_big(bodies, BIG_FACTOR);
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
        // Count, size the flat array once, then link: growing it while
        // linking would hold the old array beside the new.
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

    /// The spheres are relabelled (`perm[new] = old`, `inv` its inverse);
    /// every list and cell keeps its order.
    #[cfg(feature = "experiments")]
    pub fn relabel(&mut self, perm: &[Label], inv: &[Label]) {
        apply(&mut self.centre, perm);
        self.lists.relabel(perm, inv);
        self.cells.relabel(perm, inv);
        for b in &mut self.bigs {
            *b = inv[b.index()];
        }
    }

    #[inline]
    pub fn of(&self, i: Label) -> &[Link] {
        self.lists.of(i)
    }

    /// Start loading what predicting sphere `k` reads first: its list's
    /// word and links, and its list's centre.
    #[inline(always)]
    pub fn prefetch(&self, k: usize) {
        use crate::physics::prefetch::{line, record};
        if let (Some(w), Some(c)) = (self.lists.len.get(k), self.centre.get(k)) {
            line(w);
            record(c);
            let at = k * self.lists.stride;
            if let Some(l) = self.lists.flat.get(at) {
                line(l);
            }
            if let Some(l) = self.lists.flat.get(at + self.lists.stride - 1) {
                line(l);
            }
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
        let test = |j: Label, centre: &[Centre], lists: &mut Lists| {
            if !want(j) {
                return;
            }
            let c = centre[j.index()];
            let s = ri + bodies.radius_of_species(c.species);
            if (ci - c.pos()).length_squared() < s * s {
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
                        test(j, &self.centre, &mut self.lists);
                    });
                }
            }
        }
        for k in 0..self.bigs.len() {
            test(self.bigs[k], &self.centre, &mut self.lists);
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
    use super::{HEADROOM, Label, Link, Lists, STRIDE_STEP};

    #[test]
    fn a_link_is_the_neighbour_alone() {
        // Most of the memory of `exact` at a million dense spheres.
        assert_eq!(size_of::<Link>(), 4);
    }

    #[test]
    fn a_centre_is_28_bytes() {
        assert_eq!(size_of::<super::Centre>(), 28);
    }

    #[test]
    fn unlinking_fills_each_hole_with_the_lists_last_entry() {
        let mut l = Lists::default();
        l.reset(5, STRIDE_STEP);
        let at = Label::at;
        for (i, j) in [(0, 1), (2, 1), (1, 3), (4, 1), (0, 3)] {
            l.link(at(i), at(j));
        }
        let ids = |l: &Lists, i| l.of(at(i)).iter().map(|k| k.j.index()).collect::<Vec<_>>();
        assert_eq!(ids(&l, 1), [0, 2, 3, 4]);
        l.unlink_all(at(0));
        // 0 left 1's list (4, its last, took the hole) and 3's.
        assert_eq!(ids(&l, 0), Vec::<usize>::new());
        assert_eq!(ids(&l, 1), [4, 2, 3]);
        assert_eq!(ids(&l, 3), [1]);
        l.unlink_all(at(1));
        for i in 0..5 {
            assert_eq!(ids(&l, i), Vec::<usize>::new(), "list of {i}");
        }
    }

    /// A list past the stride widens it in place: every list keeps its
    /// entries in order. A count sizes the stride past the longest list.
    #[test]
    fn a_full_list_widens_the_stride_and_keeps_every_list() {
        let mut l = Lists::default();
        let n = 30;
        l.reset(n, STRIDE_STEP);
        let at = Label::at;
        // Sphere 25 is large: its list is its own, whatever the stride.
        l.make_big(at(25));
        l.link(at(25), at(1));
        // Sphere 0 neighbours 1..=20 (past two strides); 1..=3 also
        // neighbour 29, and 29 is last in memory, so its list moves first.
        for j in 1..=20 {
            l.link(at(0), at(j));
        }
        for j in 1..=3 {
            l.link(at(29), at(j));
        }
        assert_eq!(l.stride, 3 * STRIDE_STEP);
        let ids = |l: &Lists, i| l.of(at(i)).iter().map(|k| k.j.index()).collect::<Vec<_>>();
        assert_eq!(ids(&l, 0), (1..=20).collect::<Vec<_>>());
        assert_eq!(ids(&l, 29), [1, 2, 3]);
        assert_eq!(ids(&l, 1), [25, 0, 29]);
        for j in 2..=3 {
            assert_eq!(ids(&l, j), [0, 29], "list of {j}");
        }
        assert!(l.is_big(at(25)) && !l.is_big(at(0)));
        assert_eq!(ids(&l, 25), [1]);
        let mut c = Lists::default();
        c.reset(n, 0);
        c.make_big(at(25));
        for j in 1..=20 {
            c.count(at(0), at(j));
            // A large sphere's many neighbours do not size the stride.
            c.count(at(25), at(j));
        }
        c.fit_counts();
        assert_eq!(c.stride, (20 + HEADROOM).next_multiple_of(STRIDE_STEP));
        assert_eq!(ids(&c, 0), Vec::<usize>::new());
        assert!(c.is_big(at(25)));
        c.link(at(25), at(4));
        assert_eq!(ids(&c, 25), [4]);
    }
}
