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
use super::renumber::apply;
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
/// Links a list keeps in its sphere's own line: one cache line (64
/// bytes) a sphere, read whole by every prediction. A list that grows past
/// it moves out of line until the sphere relists. At a million dense
/// spheres lists hold 12 to 13.5 links on average and at most 18 (the
/// lattice start: 1.9 % past 16, 0.01 % once the fluid has melted), where
/// a stride sized by the longest list took 24 links (docs/benchmarks.md).
const LINE_LINKS: usize = 16;

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

/// A sphere's list when it fits its line: the links, the first
/// `len` of them in use; aligned, so a list is one cache line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
struct Line([Link; LINE_LINKS]);

/// Where a sphere's list is kept, as its word in `Lists::len` says: in its
/// own [`Line`] with this length, or the `Out(k)`th of the lists kept out
/// of line (one past [`LINE_LINKS`] links, or a large sphere's). One word a
/// sphere, read by every look-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Home {
    Line(usize),
    Out(usize),
}

/// The top bit of a `Lists::len` word: the list is out of line.
const OUT: u32 = 1 << 31;
/// The next bit: the sphere is large (its list always out of line, itself
/// in no cell).
const LARGE: u32 = 1 << 30;

impl Home {
    #[inline(always)]
    fn of(word: u32) -> Home {
        if word & OUT == 0 {
            Home::Line(word as usize)
        } else {
            Home::Out((word & !(OUT | LARGE)) as usize)
        }
    }
}

/// Neighbour lists: each sphere's in its own cache line while it fits
/// (nearly all), the rest (a list that outgrew its line, and the few
/// large spheres', which may hold thousands) in growable lists of their
/// own.
#[derive(Clone, Debug, Default)]
struct Lists {
    lines: Vec<Line>,
    /// Each sphere's [`Home`] as a word: its line's length, or [`OUT`]
    /// (and [`LARGE`]) and its place in `out`.
    len: Vec<u32>,
    out: Vec<Vec<Link>>,
    /// Places in `out` whose list went back in line, for the next one out.
    free: Vec<u32>,
}

impl Lists {
    /// Empty lists for `n` spheres, all in line. The old lines go first, so
    /// two arrays are never held at once.
    fn reset(&mut self, n: usize) {
        huge_pages::refill(&mut self.len, n, 0);
        self.lines = Vec::new();
        self.lines = huge_pages::filled(n, Line::default());
        self.out.clear();
        self.free.clear();
    }

    /// Whether `i` is a large sphere (its list growable, itself in no cell).
    #[inline]
    fn is_big(&self, i: Label) -> bool {
        self.len[i.index()] & LARGE != 0
    }

    fn make_big(&mut self, i: Label) {
        self.len[i.index()] = OUT | LARGE | self.take_out();
    }

    /// A free place in `out`, its list empty.
    fn take_out(&mut self) -> u32 {
        self.free.pop().unwrap_or_else(|| {
            self.out.push(Vec::new());
            (self.out.len() - 1) as u32
        })
    }

    #[inline(always)]
    fn home(&self, i: Label) -> Home {
        Home::of(self.len[i.index()])
    }

    #[inline]
    fn of(&self, i: Label) -> &[Link] {
        match self.home(i) {
            Home::Line(len) => &self.lines[i.index()].0[..len],
            Home::Out(k) => &self.out[k],
        }
    }

    #[inline]
    fn of_mut(&mut self, i: Label) -> &mut [Link] {
        match self.home(i) {
            Home::Line(len) => &mut self.lines[i.index()].0[..len],
            Home::Out(k) => &mut self.out[k],
        }
    }

    #[inline]
    fn push(&mut self, i: Label, l: Link) {
        match self.home(i) {
            Home::Line(len) if len < LINE_LINKS => {
                self.lines[i.index()].0[len] = l;
                self.len[i.index()] += 1;
            }
            Home::Line(_) => self.move_out(i, l),
            Home::Out(k) => self.out[k].push(l),
        }
    }

    /// `i`'s full line, then `l`, in a list out of line, in order.
    #[cold]
    fn move_out(&mut self, i: Label, l: Link) {
        let k = self.take_out();
        let list = &mut self.out[k as usize];
        list.reserve_exact(2 * LINE_LINKS);
        list.extend_from_slice(&self.lines[i.index()].0);
        list.push(l);
        self.len[i.index()] = OUT | k;
    }

    #[inline]
    fn pop(&mut self, i: Label) {
        match self.home(i) {
            Home::Line(_) => self.len[i.index()] -= 1,
            Home::Out(k) => {
                self.out[k].pop();
            }
        }
    }

    /// Make `i` and `j` neighbours.
    #[inline]
    fn link(&mut self, i: Label, j: Label) {
        self.push(i, Link { j });
        self.push(j, Link { j: i });
    }

    /// Remove `i` from all its neighbours' lists and empty its own (back in
    /// its line, unless it is large).
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
            Home::Line(_) => self.len[i.index()] = 0,
            Home::Out(k) if self.is_big(i) => self.out[k].clear(),
            Home::Out(k) => {
                self.out[k] = Vec::new();
                self.free.push(k as u32);
                self.len[i.index()] = 0;
            }
        }
    }

    /// The spheres are relabelled (`perm[new] = old`, `inv` its inverse);
    /// every list keeps its order.
    #[cfg(feature = "experiments")]
    fn relabel(&mut self, perm: &[Label], inv: &[Label]) {
        apply(&mut self.lines, perm);
        apply(&mut self.len, perm);
        for (line, &w) in self.lines.iter_mut().zip(&self.len) {
            if let Home::Line(len) = Home::of(w) {
                for l in &mut line.0[..len] {
                    l.j = inv[l.j.index()];
                }
            }
        }
        for l in self.out.iter_mut().flatten() {
            l.j = inv[l.j.index()];
        }
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
        let out: usize = l.out.iter().map(|b| b.capacity() * size_of::<Link>()).sum();
        self.centre.capacity() * size_of::<Centre>()
            + l.lines.capacity() * size_of::<Line>()
            + l.len.capacity() * 4
            + self.bigs.capacity() * size_of::<Label>()
            + l.out.capacity() * size_of::<Vec<Link>>()
            + out
            + l.free.capacity() * 4
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
        self.lists.reset(n);
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
        for i in bodies.labels() {
            self.scan(i, bodies, |j| j > i);
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
        self.scan(i, bodies, |j| j != i);
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
    /// word and line, and its list's centre.
    #[inline(always)]
    pub fn prefetch(&self, k: usize) {
        use crate::physics::prefetch::{line, record};
        if let (Some(w), Some(c), Some(l)) = (
            self.lists.len.get(k),
            self.centre.get(k),
            self.lists.lines.get(k),
        ) {
            line(w);
            record(c);
            line(l);
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

    /// Find the neighbours `j` of `i` (with `want(j)`) and link each pair.
    #[allow(clippy::excessive_nesting)] // a box of cells, z, y, x, each cell's spheres in a closure
    fn scan(&mut self, i: Label, bodies: &Bodies, want: impl Fn(Label) -> bool) {
        let ci = self.centre[i.index()].pos();
        let ri = bodies.radius(i) + 2.0 * self.skin;
        let test = |j: Label, centre: &[Centre], lists: &mut Lists| {
            if !want(j) {
                return;
            }
            let c = centre[j.index()];
            let s = ri + bodies.radius_of_species(c.species);
            if (ci - c.pos()).length_squared() < s * s {
                lists.link(i, j);
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
    use super::{Home, LINE_LINKS, Label, Line, Link, Lists};

    #[test]
    fn a_link_is_the_neighbour_alone_and_a_line_one_cache_line() {
        // Most of the memory of `exact` at a million dense spheres.
        assert_eq!(size_of::<Link>(), 4);
        assert_eq!((size_of::<Line>(), align_of::<Line>()), (64, 64));
    }

    #[test]
    fn a_centre_is_28_bytes() {
        assert_eq!(size_of::<super::Centre>(), 28);
    }

    fn ids(l: &Lists, i: usize) -> Vec<usize> {
        l.of(Label::at(i)).iter().map(|k| k.j.index()).collect()
    }

    #[test]
    fn unlinking_fills_each_hole_with_the_lists_last_entry() {
        let mut l = Lists::default();
        l.reset(5);
        let at = Label::at;
        for (i, j) in [(0, 1), (2, 1), (1, 3), (4, 1), (0, 3)] {
            l.link(at(i), at(j));
        }
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

    /// A list past its line moves out of line in order, keeps working there
    /// (holes filled by the last entry, as in line), and goes back in line
    /// when its sphere relists; its place out of line is taken by the next.
    /// A large sphere's list stays out of line and the sphere large.
    #[test]
    fn a_list_past_its_line_moves_out_and_back_in_order() {
        let n = 40;
        let mut l = Lists::default();
        l.reset(n);
        let at = Label::at;
        l.make_big(at(39));
        l.link(at(39), at(1));
        let extra = LINE_LINKS + 4;
        for j in 1..=extra {
            l.link(at(0), at(j));
        }
        assert_eq!(ids(&l, 0), (1..=extra).collect::<Vec<_>>());
        assert!(matches!(l.home(at(0)), Home::Out(_)) && !l.is_big(at(0)));
        assert_eq!(ids(&l, 1), [39, 0]);
        // Sphere 5 leaves 0's list: 0's last entry takes its hole.
        l.unlink_all(at(5));
        let mut want: Vec<usize> = (1..=extra).collect();
        want[4] = extra;
        want.pop();
        assert_eq!(ids(&l, 0), want);
        l.unlink_all(at(0));
        assert_eq!(l.home(at(0)), Home::Line(0));
        assert_eq!(l.free.len(), 1);
        for j in 1..=extra {
            assert!(!ids(&l, j).contains(&0), "0 still in {j}'s list");
        }
        // Sphere 2 outgrows its line: it takes the freed place.
        for j in 3..=3 + LINE_LINKS {
            l.link(at(2), at(j));
        }
        assert!(matches!(l.home(at(2)), Home::Out(_)) && l.free.is_empty());
        assert_eq!(ids(&l, 2), (3..=3 + LINE_LINKS).collect::<Vec<_>>());
        assert!(l.is_big(at(39)) && matches!(l.home(at(39)), Home::Out(_)));
        assert_eq!(ids(&l, 39), [1]);
        l.unlink_all(at(39));
        assert!(l.is_big(at(39)) && ids(&l, 39).is_empty());
        assert_eq!(ids(&l, 1), Vec::<usize>::new());
    }
}
