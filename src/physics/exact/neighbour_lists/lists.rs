//! The neighbour lists themselves: the bulk's in one flat array at one
//! stride, a sphere's length in a byte, the lists that outgrew the stride
//! (and the large spheres') out of line. What is in them, and when, is the
//! owner's ([`NeighbourLists`](super::NeighbourLists)).
use crate::physics::exact::ids::Label;
use crate::physics::huge_pages;

/// Links in a cache line: a list of this many or fewer, at a stride of
/// this many, is one line.
const LINE_LINKS: usize = 16;
/// The stride of the lists in the flat array is a multiple of this many
/// links, chosen by a build from its lists' lengths ([`best_stride`]).
const STRIDE_STEP: usize = 8;
/// What a list out of line costs, in bytes, at a stride of 16: its `Vec`
/// (24), room for twice the stride (128) and the allocator's header (16).
/// A build weighs it against a wider stride for every sphere.
const OUT_BYTES: usize = 168;
/// At most one list in this many out of line after a build.
const OUT_AT_MOST: usize = 16;

/// One entry of a neighbour list: the neighbour. Where this sphere sits in
/// the neighbour's own list is found by a search of that list (about a
/// dozen entries, one or two cache lines), not stored: at a million dense
/// spheres the stored place was half the lists' memory (docs/perf-log.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Link {
    pub j: Label,
}

/// Where a sphere's list is kept, as its byte in `Lists::len` says: in
/// the flat array at its place, with this length, or the `Out(k)`th of the
/// lists kept out of line (one that outgrew the stride, or a large
/// sphere's), `k` kept in the first link of its place (unused while the
/// list is out). One byte a sphere, read by every look-up: at a million,
/// 1 MB where a word took 4.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Home {
    Flat(usize),
    Out(usize),
}

/// A `Lists::len` byte: the list is out of line.
const OUT: u8 = u8::MAX;
/// A `Lists::len` byte: the sphere is large (its list always out of line,
/// itself in no cell).
const LARGE: u8 = u8::MAX - 1;
/// The longest list a `Lists::len` byte holds in the flat array.
const MAX_FLAT: u8 = LARGE - 1;
/// The widest stride: lists of up to [`MAX_FLAT`] links, in whole steps.
const MAX_STRIDE: usize = MAX_FLAT as usize / STRIDE_STEP * STRIDE_STEP;

/// The stride, a multiple of [`STRIDE_STEP`] links, that holds lists of
/// the lengths `counts` (`counts[k]` lists of `k` links) in the fewest
/// bytes, the lists longer than it out of line at [`OUT_BYTES`] each, and
/// at most one list in [`OUT_AT_MOST`] out (a list out of line is slower
/// to read). At a million dense spheres (lattice start: 13.5 links on
/// average, 1.9 % past 16) that is 16, one cache line; on a start where
/// most lists hold 16 to 18, 24.
fn best_stride(counts: &[usize]) -> usize {
    let total: usize = counts.iter().sum();
    let longest = counts.iter().rposition(|&c| c > 0).unwrap_or(0);
    let out = |stride: usize| counts.iter().skip(stride + 1).sum::<usize>();
    (1..=longest
        .div_ceil(STRIDE_STEP)
        .clamp(1, MAX_STRIDE / STRIDE_STEP))
        .map(|k| k * STRIDE_STEP)
        .filter(|&s| out(s) * OUT_AT_MOST <= total)
        .min_by_key(|&s| total * s * size_of::<Link>() + out(s) * OUT_BYTES)
        .unwrap_or(MAX_STRIDE)
}

/// Neighbour lists: the bulk's in one flat array at one stride (no
/// pointer a list; the array starts on a cache line, so at a stride of 16
/// a list is one line), the rest (a list that outgrew the stride, until
/// its sphere relists, and the few large spheres', which may hold
/// thousands) in growable lists of their own.
#[derive(Clone, Debug, Default)]
pub(super) struct Lists {
    stride: usize,
    /// Where the first list starts in `flat`: its first link on a line.
    base: usize,
    flat: Vec<Link>,
    /// Each sphere's [`Home`] as a byte: its flat list's length, [`OUT`]
    /// or [`LARGE`].
    len: Vec<u8>,
    out: Vec<Vec<Link>>,
    /// Places in `out` whose list went back in the flat array, for the
    /// next one out.
    free: Vec<u32>,
}

impl Lists {
    /// Empty lists for `n` spheres, all in the flat array at `stride`.
    pub(super) fn reset(&mut self, n: usize, stride: usize) {
        huge_pages::refill(&mut self.len, n, 0);
        self.set_stride(stride);
    }

    /// A new flat array at `stride`, every flat list emptied and the
    /// large spheres' lists (out of line) emptied. The old array goes
    /// first, so the two are never held at once.
    fn set_stride(&mut self, stride: usize) {
        self.stride = stride;
        self.flat = Vec::new();
        self.out.clear();
        self.free.clear();
        // A line's worth more, to start on a line wherever the array is.
        let links = self.len.len() * stride + LINE_LINKS;
        self.flat = huge_pages::filled(links, Link::default());
        self.base = self.flat.as_ptr().align_offset(64).min(LINE_LINKS);
        for i in (0..self.len.len()).map(Label::at) {
            match self.len[i.index()] {
                LARGE => self.make_big(i),
                _ => self.len[i.index()] = 0,
            }
        }
    }

    /// Count a pair found by a build's first pass (in the lengths).
    #[inline]
    pub(super) fn count(&mut self, i: Label, j: Label) {
        for k in [i, j] {
            let w = &mut self.len[k.index()];
            if *w < MAX_FLAT {
                *w += 1;
            }
        }
    }

    /// After a build's counting pass: the stride [`best_stride`] picks for
    /// the lengths counted, every list empty again.
    pub(super) fn fit_counts(&mut self) {
        let mut counts = Vec::new();
        for &w in &self.len {
            if w <= MAX_FLAT {
                let len = usize::from(w);
                if counts.len() <= len {
                    counts.resize(len + 1, 0);
                }
                counts[len] += 1;
            }
        }
        self.set_stride(best_stride(&counts));
    }

    /// Whether `i` is a large sphere (its list growable, itself in no cell).
    #[inline]
    pub(super) fn is_big(&self, i: Label) -> bool {
        self.len[i.index()] == LARGE
    }

    /// `i` is large: its list is out of line for good (once there is a
    /// stride, so a place to say where).
    pub(super) fn make_big(&mut self, i: Label) {
        self.len[i.index()] = LARGE;
        if self.stride > 0 {
            let k = self.take_out();
            self.set_out_place(i, k);
        }
    }

    /// Where `i`'s list out of line is: in its unused place's first link.
    fn set_out_place(&mut self, i: Label, k: u32) {
        let at = self.at(i);
        self.flat[at].j = Label::from_raw(k);
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
        match self.len[i.index()] {
            w if w <= MAX_FLAT => Home::Flat(usize::from(w)),
            _ => self.out_home(i),
        }
    }

    /// The home of a list out of line: few are, so this stays off the
    /// look-up's path.
    #[cold]
    #[inline(never)]
    fn out_home(&self, i: Label) -> Home {
        Home::Out(self.flat[self.at(i)].j.index())
    }

    /// Where `i`'s place in the flat array starts.
    #[inline(always)]
    fn at(&self, i: Label) -> usize {
        self.base + i.index() * self.stride
    }

    #[inline]
    pub(super) fn of(&self, i: Label) -> &[Link] {
        match self.home(i) {
            Home::Flat(len) => &self.flat[self.at(i)..][..len],
            Home::Out(k) => &self.out[k],
        }
    }

    #[inline]
    fn of_mut(&mut self, i: Label) -> &mut [Link] {
        match self.home(i) {
            Home::Flat(len) => {
                let at = self.at(i);
                &mut self.flat[at..][..len]
            }
            Home::Out(k) => &mut self.out[k],
        }
    }

    #[inline]
    fn push(&mut self, i: Label, l: Link) {
        match self.home(i) {
            Home::Flat(len) if len < self.stride => {
                let at = self.at(i);
                self.flat[at + len] = l;
                self.len[i.index()] += 1;
            }
            Home::Flat(_) => self.move_out(i, l),
            Home::Out(k) => self.out[k].push(l),
        }
    }

    /// `i`'s full flat list, then `l`, in a list out of line, in order.
    #[cold]
    fn move_out(&mut self, i: Label, l: Link) {
        let k = self.take_out();
        let (at, stride) = (self.at(i), self.stride);
        let list = &mut self.out[k as usize];
        list.reserve_exact(2 * stride.max(LINE_LINKS));
        list.extend_from_slice(&self.flat[at..at + stride]);
        list.push(l);
        self.len[i.index()] = OUT;
        self.set_out_place(i, k);
    }

    #[inline]
    fn pop(&mut self, i: Label) {
        match self.home(i) {
            Home::Flat(_) => self.len[i.index()] -= 1,
            Home::Out(k) => {
                self.out[k].pop();
            }
        }
    }

    /// Make `i` and `j` neighbours.
    #[inline]
    pub(super) fn link(&mut self, i: Label, j: Label) {
        self.push(i, Link { j });
        self.push(j, Link { j: i });
    }

    /// Remove `i` from all its neighbours' lists and empty its own (back in
    /// its line, unless it is large).
    #[inline]
    pub(super) fn unlink_all(&mut self, i: Label) {
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
            Home::Out(k) if self.is_big(i) => self.out[k].clear(),
            Home::Out(k) => {
                self.out[k] = Vec::new();
                self.free.push(k as u32);
                self.len[i.index()] = 0;
            }
        }
    }

    /// Bytes held on the heap.
    pub(super) fn heap_bytes(&self) -> usize {
        let out: usize = self
            .out
            .iter()
            .map(|b| b.capacity() * size_of::<Link>())
            .sum();
        self.flat.capacity() * size_of::<Link>()
            + self.len.capacity()
            + self.out.capacity() * size_of::<Vec<Link>>()
            + out
            + self.free.capacity() * 4
    }

    /// Start loading sphere `k`'s byte and the line(s) of its place.
    #[inline(always)]
    pub(super) fn prefetch(&self, k: usize) {
        use crate::physics::prefetch::line;
        let at = self.base + k * self.stride;
        if let (Some(w), Some(first)) = (self.len.get(k), self.flat.get(at)) {
            line(w);
            line(first);
            // A stride past a line: its last link may be on the next.
            if let Some(last) = self.flat.get(at + self.stride.saturating_sub(1)) {
                line(last);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Home, LINE_LINKS, Label, Link, Lists, STRIDE_STEP, best_stride};

    #[test]
    fn a_link_is_the_neighbour_alone() {
        // Most of the memory of `exact` at a million dense spheres.
        assert_eq!(size_of::<Link>(), 4);
    }

    fn ids(l: &Lists, i: usize) -> Vec<usize> {
        l.of(Label::at(i)).iter().map(|k| k.j.index()).collect()
    }

    #[test]
    fn unlinking_fills_each_hole_with_the_lists_last_entry() {
        let mut l = Lists::default();
        l.reset(5, STRIDE_STEP);
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

    /// A list past the stride moves out of line in order, keeps working
    /// there (holes filled by the last entry, as in the flat array), and
    /// goes back when its sphere relists; its place out of line is taken
    /// by the next. A large sphere's list stays out of line and the sphere
    /// large.
    #[test]
    fn a_list_past_the_stride_moves_out_and_back_in_order() {
        let n = 40;
        let mut l = Lists::default();
        l.reset(n, STRIDE_STEP);
        let at = Label::at;
        l.make_big(at(39));
        l.link(at(39), at(1));
        let extra = STRIDE_STEP + 4;
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
        assert_eq!(l.home(at(0)), Home::Flat(0));
        assert_eq!(l.free.len(), 1);
        for j in 1..=extra {
            assert!(!ids(&l, j).contains(&0), "0 still in {j}'s list");
        }
        // Sphere 2 outgrows the stride: it takes the freed place.
        for j in 3..=3 + STRIDE_STEP {
            l.link(at(2), at(j));
        }
        assert!(matches!(l.home(at(2)), Home::Out(_)) && l.free.is_empty());
        assert_eq!(ids(&l, 2), (3..=3 + STRIDE_STEP).collect::<Vec<_>>());
        assert!(l.is_big(at(39)) && matches!(l.home(at(39)), Home::Out(_)));
        assert_eq!(ids(&l, 39), [1]);
        l.unlink_all(at(39));
        assert!(l.is_big(at(39)) && ids(&l, 39).is_empty());
        assert_eq!(ids(&l, 1), Vec::<usize>::new());
    }

    /// A sphere's byte counts up to the longest list the flat array may
    /// hold, and no stride is wider: longer lists go out of line, even
    /// when most lists are that long.
    #[test]
    fn a_length_byte_bounds_the_stride() {
        let mut l = Lists::default();
        l.reset(400, 0);
        for j in 1..400 {
            l.count(Label::at(0), Label::at(j));
        }
        assert_eq!(l.len[0], super::MAX_FLAT);
        assert_eq!(l.len[1], 1);
        let mut long = vec![0; usize::from(super::MAX_FLAT) + 1];
        long[usize::from(super::MAX_FLAT)] = 1000;
        assert_eq!(best_stride(&long), super::MAX_STRIDE);
        assert!(super::MAX_STRIDE <= usize::from(super::MAX_FLAT));
        l.fit_counts();
        assert_eq!(l.stride, STRIDE_STEP, "one long list goes out");
        for j in 1..=super::MAX_STRIDE + 1 {
            l.link(Label::at(0), Label::at(j));
        }
        assert!(matches!(l.home(Label::at(0)), Home::Out(_)));
        assert_eq!(ids(&l, 0).len(), super::MAX_STRIDE + 1);
    }

    /// At a stride of a line, every list starts on one.
    #[test]
    fn at_a_stride_of_16_each_list_is_one_line() {
        let mut l = Lists::default();
        l.reset(50, LINE_LINKS);
        for i in 0..50 {
            let first = l.flat[l.at(Label::at(i))..].as_ptr();
            assert_eq!(first.addr() % 64, 0, "list {i}");
        }
    }

    /// The stride holds the lengths in the fewest bytes, counting a list
    /// out of line at its cost: one line for a million dense spheres'
    /// lattice start (lengths counted at 1M), a stride past the bulk when
    /// most lists are 16 to 18 long (a lattice at 100k).
    #[test]
    fn the_stride_follows_the_lengths_counted() {
        let million = [
            0, 0, 0, 0, 16, 100, 413, 1671, 5550, 12208, 23025, 53987, 133_080, 236_024, 263_266,
            179_056, 72362, 17338, 1904,
        ];
        assert_eq!(best_stride(&million), 16);
        let lattice = [
            0, 0, 0, 0, 0, 4, 4, 37, 185, 325, 266, 1706, 4906, 4838, 816, 5867, 21134, 34845,
            25067,
        ];
        assert_eq!(best_stride(&lattice), 24);
        assert_eq!(best_stride(&[]), STRIDE_STEP);
        assert_eq!(best_stride(&[5, 0, 0, 7]), STRIDE_STEP);
        // A few long lists go out of line rather than widen every one, but
        // not a tenth of them, even where that would take fewer bytes.
        let mut few = vec![0; 41];
        (few[12], few[40]) = (1000, 3);
        assert_eq!(best_stride(&few), 16);
        (few[12], few[20]) = (900, 100);
        assert_eq!(best_stride(&few), 24);
    }

    /// A build counts, then sizes the stride, every list empty again; the
    /// large sphere's many neighbours do not count.
    #[test]
    fn counting_sizes_the_stride_and_empties_the_lists() {
        let mut l = Lists::default();
        let n = 30;
        l.reset(n, 0);
        let at = Label::at;
        l.make_big(at(25));
        for j in 1..=20 {
            l.count(at(0), at(j));
            l.count(at(25), at(j));
        }
        l.fit_counts();
        // One list of 20 and twenty of 1 or 2: 8 and one list out.
        assert_eq!(l.stride, STRIDE_STEP);
        assert_eq!(ids(&l, 0), Vec::<usize>::new());
        assert!(l.is_big(at(25)));
        l.link(at(25), at(4));
        assert_eq!(ids(&l, 25), [4]);
        assert_eq!(ids(&l, 4), [25]);
    }
}
