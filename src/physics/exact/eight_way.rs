//! An eight-way tournament ([`EightWay`]): the binary tournament it
//! replaced (deleted 2026-12-07, docs/perf-log.md) with eight children a node, so a node's children are
//! one cache line of keys. An update climbs log8 N levels instead of
//! log2 N: 7 lines at a million spheres where the binary tree touched 20
//! (the lower ones missed the cache at that size), and the inner nodes take
//! a seventh of the leaves' memory instead of as much again.
//!
//! Ties go to the lowest sphere index at every node (the leftmost of the
//! least keys), so the root is the least `(time, sphere)`: the order the
//! binary tree keeps, and so the same runs.

use super::queue::{EventQueue, key, time};
use crate::physics::huge_pages;

/// Children a node.
const WAYS: usize = 8;

/// A node's children's keys: one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Keys([u64; WAYS]);

/// A node's children's winning spheres (inner children only).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
struct Ids([u32; WAYS]);

/// Levels at most (a power of two, so an index is masked, not checked): a
/// `u32` index needs 12.
const MAX_LEVELS: usize = 16;

#[derive(Clone, Debug, Default)]
pub struct EightWay {
    /// Every level's nodes by groups of siblings, the leaves first and the
    /// root (alone in its group) last; `start[l]` is level `l`'s first group.
    keys: Vec<Keys>,
    /// The winning sphere of each node above the leaves, grouped as `keys`
    /// (a leaf's sphere is its place); level `l`'s first group is
    /// `start[l] - start[1]`.
    ids: Vec<Ids>,
    start: [usize; MAX_LEVELS],
    /// Levels, the leaves' and the root's included (at least 2).
    levels: usize,
}

/// Level `l`'s first group and the one above's.
#[inline(always)]
fn span(start: &[usize; MAX_LEVELS], l: usize) -> (usize, usize) {
    (start[(l - 1) % MAX_LEVELS], start[l % MAX_LEVELS])
}

/// The least key of a group and its place, the lowest place on ties: a
/// tree of pairs where the left wins ties, which LLVM unrolls into
/// conditional moves (the winner is random, so a branch would mispredict).
#[inline(always)]
fn least(g: &Keys) -> (u64, usize) {
    let mut v: [(u64, usize); WAYS] = std::array::from_fn(|k| (g.0[k], k));
    let mut n = WAYS;
    while n > 1 {
        n /= 2;
        for k in 0..n {
            let (a, b) = (v[2 * k], v[2 * k + 1]);
            v[k] = if b.0 < a.0 { b } else { a };
        }
    }
    v[0]
}

/// Node `p` of a level set from its children, group `p` of the level
/// below (whose groups start at `lo`; the node's level's at `up`; a level's
/// ids start `inner` groups before its keys). A leaf's sphere is its place.
#[inline(always)]
fn settle(keys: &mut [Keys], ids: &mut [Ids], inner: usize, (lo, up): (usize, usize), p: usize) {
    let (w, lane) = least(&keys[lo + p]);
    let id = if lo == 0 {
        (p * WAYS + lane) as u32
    } else {
        ids[lo - inner + p].0[lane]
    };
    let (g, at) = (up + p / WAYS, p % WAYS);
    keys[g].0[at] = w;
    ids[g - inner].0[at] = id;
}

impl EightWay {
    #[inline(always)]
    fn set_key(&mut self, i: usize, t: f64) {
        self.keys[i / WAYS].0[i % WAYS] = key(t);
    }
}

impl EventQueue for EightWay {
    fn reset(&mut self, n: usize) {
        // A level has a node for each group of the level below, down to
        // the root (a tree of one sphere still has a root above its leaf).
        let mut nodes = n.max(1);
        let mut total = 0;
        self.levels = 0;
        loop {
            let groups = nodes.div_ceil(WAYS);
            self.start[self.levels] = total;
            total += groups;
            self.levels += 1;
            if nodes == 1 && self.levels >= 2 {
                break;
            }
            nodes = groups;
        }
        // Padding leaves wait at infinity, after every sphere's own.
        let inf = Keys([key(f64::INFINITY); WAYS]);
        huge_pages::refill(&mut self.keys, total, inf);
        huge_pages::refill(&mut self.ids, total - self.start[1], Ids::default());
        self.rebuild();
    }

    #[inline]
    fn set_leaf(&mut self, i: usize, t: f64) {
        self.set_key(i, t);
    }

    fn rebuild(&mut self) {
        let inner = self.start[1];
        for l in 1..self.levels {
            let s = span(&self.start, l);
            for p in 0..s.1 - s.0 {
                settle(&mut self.keys, &mut self.ids, inner, s, p);
            }
        }
    }

    /// Climbs to the root always, as the binary tree does.
    #[inline(always)]
    fn update(&mut self, i: usize, t: f64) {
        self.set_key(i, t);
        let (mut p, inner) = (i / WAYS, self.start[1]);
        for l in 1..self.levels {
            settle(
                &mut self.keys,
                &mut self.ids,
                inner,
                span(&self.start, l),
                p,
            );
            p /= WAYS;
        }
    }

    /// Both leaves first, then both climbs a level at a time, so a node
    /// the two paths share is set from both new children, once; the two
    /// paths' reads are independent, so their misses overlap.
    #[inline(always)]
    fn update_two(&mut self, i: usize, ti: f64, j: usize, tj: f64) {
        self.set_key(i, ti);
        self.set_key(j, tj);
        let (mut a, mut b, inner) = (i / WAYS, j / WAYS, self.start[1]);
        for l in 1..self.levels {
            let s = span(&self.start, l);
            settle(&mut self.keys, &mut self.ids, inner, s, a);
            if b != a {
                settle(&mut self.keys, &mut self.ids, inner, s, b);
            }
            a /= WAYS;
            b /= WAYS;
        }
    }

    #[inline]
    fn peek(&mut self) -> (f64, usize) {
        let root = self.levels - 1;
        let w = self.keys[self.start[root]].0[0];
        (
            time(w),
            self.ids[self.start[root] - self.start[1]].0[0] as usize,
        )
    }

    /// The least of the root winner's siblings at every level of its path
    /// but the two lowest: the earliest event after the root's but for
    /// those among the winner's own 64 leaves (all of them in a tree of
    /// 64 or fewer). Any sphere, or a padding leaf, when no other event
    /// is finite. Always inlined: the loop asks for it once an event, and
    /// as a call it cost about 12 instructions each (callgrind, 100k
    /// spheres at packing 0.005, 2026-12-07).
    #[inline(always)]
    fn runner_up(&self) -> Option<usize> {
        let root = self.levels - 1;
        let inner = self.start[1];
        // The lowest levels are skipped: their groups are cold, and the next
        // event is among the winner's 63 nearest leaves only 63 times in N.
        let from = if root > 2 { 2 } else { 0 };
        let mut a = self.ids[self.start[root] - inner].0[0] as usize / WAYS.pow(from as u32);
        let (mut best, mut who) = (u64::MAX, None);
        for l in from..root {
            let (g, lane) = (a / WAYS, a % WAYS);
            let mut keys = self.keys[self.start[l % MAX_LEVELS] + g];
            keys.0[lane] = u64::MAX;
            let (k, at) = least(&keys);
            if k < best {
                best = k;
                who = Some(if l == 0 {
                    g * WAYS + at
                } else {
                    self.ids[self.start[l % MAX_LEVELS] - inner + g].0[at] as usize
                });
            }
            a = g;
        }
        who
    }

    /// The leaf group, and the keys and ids of the node above it: at a
    /// million spheres that level is 1.5 MB, so its lines are often out of
    /// a core's cache; the levels above are small and warm.
    #[inline]
    fn prefetch(&self, i: usize) {
        use crate::physics::prefetch::line;
        if let Some(g) = self.keys.get(i / WAYS) {
            line(g);
        }
        let p = i / (WAYS * WAYS);
        if let (Some(g), Some(d)) = (self.keys.get(self.start[1] + p), self.ids.get(p)) {
            line(g);
            line(d);
        }
    }

    #[inline]
    fn time_of(&self, i: usize) -> f64 {
        time(self.keys[i / WAYS].0[i % WAYS])
    }

    /// Subtract `shift` from every time; the order is kept, as in the
    /// binary tree. Padding leaves stay at infinity.
    fn shift(&mut self, shift: f64) {
        for g in &mut self.keys[..self.start[1]] {
            for k in &mut g.0 {
                *k = key(time(*k) - shift);
            }
        }
        self.rebuild();
    }

    fn heap_bytes(&self) -> usize {
        self.keys.capacity() * size_of::<Keys>() + self.ids.capacity() * size_of::<Ids>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::exact::queue::check_pop_order;

    #[test]
    fn pops_in_time_then_index_order() {
        check_pop_order::<EightWay>();
    }

    #[test]
    fn least_takes_the_lowest_place_on_ties() {
        let g = |f: fn(usize) -> u64| Keys(std::array::from_fn(f));
        // Two least keys: the lower place wins, wherever the two sit.
        assert_eq!(
            least(&g(|k| [5, 3, 9, 3, 7, 3, 1, 1][k % 8])),
            (1, 6 % WAYS)
        );
        assert_eq!(
            least(&g(|k| [5, 3, 9, 3, 7, 3, 1, 1][(k + 3) % 8])),
            (1, 3 % WAYS)
        );
        assert_eq!(least(&g(|_| 2)), (2, 0));
        assert_eq!(least(&g(|k| u64::from(k + 1 != WAYS) * 4)), (0, WAYS - 1));
    }

    /// The runner-up's time is the least outside the winner's 64 leaves
    /// (outside the winner alone when there are 64 or fewer), under random
    /// updates with ties.
    #[test]
    fn runner_up_is_the_next_event_outside_the_winners_leaves() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(4);
        for n in [2, 9, 64, 65, 100, 600, 5000] {
            let mut q = EightWay::default();
            q.reset(n);
            let mut times = vec![f64::INFINITY; n];
            for _ in 0..3000 {
                let i = rng.random_range(0..n);
                times[i] = f64::from(rng.random_range(0..50_u32));
                q.update(i, times[i]);
                let w = q.peek().1;
                let apart = |k: usize| if n > 64 { k / 64 != w / 64 } else { k != w };
                let next = (0..n)
                    .filter(|&k| apart(k))
                    .map(|k| times[k])
                    .fold(f64::INFINITY, f64::min);
                if next.is_finite() {
                    let r = q.runner_up().expect("another finite event has a runner-up");
                    assert!(r < n, "{n} spheres: {r}");
                    assert_eq!(q.time_of(r), next, "{n} spheres");
                }
            }
        }
    }

    #[test]
    fn levels_fit_every_size() {
        for (n, levels) in [
            (0, 2),
            (1, 2),
            (8, 2),
            (9, 3),
            (64, 3),
            (65, 4),
            (1 << 20, 8),
        ] {
            let mut q = EightWay::default();
            q.reset(n);
            assert_eq!(q.levels, levels, "{n} spheres");
            assert_eq!(q.peek().0, f64::INFINITY);
        }
    }

    /// Random updates with many equal times (and infinities), single and
    /// in pairs, against a scan of all leaves: earliest time, then lowest
    /// index; sizes across one to four levels of groups.
    #[test]
    fn peek_matches_a_scan_with_ties() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        for n in [1, 2, 7, 8, 9, 63, 64, 65, 100, 600] {
            let mut q = EightWay::default();
            q.reset(n);
            let mut times = vec![f64::INFINITY; n];
            let at = |rng: &mut rand_xoshiro::Xoshiro256PlusPlus| match rng.random_range(0..10) {
                0 => f64::INFINITY,
                k => f64::from(k % 4),
            };
            for _ in 0..5000 {
                let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
                let (ti, tj) = (at(&mut rng), at(&mut rng));
                if rng.random_range(0..2) == 0 || i == j {
                    times[i] = ti;
                    q.update(i, ti);
                } else {
                    times[i] = ti;
                    times[j] = tj;
                    q.update_two(i, ti, j, tj);
                }
                let best = times.iter().copied().fold(f64::INFINITY, f64::min);
                let (t, id) = q.peek();
                assert_eq!(t, best, "{n} spheres");
                let first = times.iter().position(|&x| x == best).unwrap_or(0);
                assert_eq!(id, first, "{n} spheres");
                assert_eq!(q.time_of(i), times[i]);
            }
        }
    }
}
