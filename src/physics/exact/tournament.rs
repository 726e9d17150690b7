//! The binary tournament tree (feature `experiments`): a complete binary
//! tree whose every inner node holds the earlier of its two children. It was
//! `exact`'s queue until 2026-12-05, when [`super::eight_way::EightWay`]
//! measured faster from 4k to 1M spheres (docs/perf-log.md); it stays as
//! the reference the other queues are held to.

use super::queue::{EventQueue, key, time};
use crate::physics::huge_pages;

#[derive(Clone, Debug, Default)]
pub struct Tournament {
    /// Node `k`: the key of its event's time and the sphere. Leaves are
    /// nodes `size..2*size`, the root is node 1; node 0 is unused. Keys and
    /// spheres apart, so a climb carries the winning key in a register and
    /// only the keys are on its chain of dependent steps.
    keys: Vec<u64>,
    /// The sphere of each inner node (`1..size`); a leaf's is its place.
    ids: Vec<u32>,
    size: usize,
}

/// The keys, the inner nodes' ids, and the two lengths less one.
type Nodes<'a> = (&'a mut [u64], &'a mut [u32], (usize, usize));

/// One step of a climb from inner node `k` (of a power-of-two tree, `mask`
/// the keys' length less one, `imask` the ids'), which holds `w`: set its
/// parent, and return the parent's key. Ties go left (lower indices), so a
/// left sibling wins a tie too: hence the `+ (k & 1)`. Every index is below
/// its array's length, so the masks change none and let the compiler drop
/// the bounds checks.
#[inline(always)]
fn step(keys: &mut [u64], ids: &mut [u32], (mask, imask): (usize, usize), k: usize, w: u64) -> u64 {
    let s = keys[(k ^ 1) & mask];
    let sib = s < w.wrapping_add((k & 1) as u64);
    let w = w ^ ((w ^ s) & 0u64.wrapping_sub(sib as u64));
    let id = ids[(k ^ sib as usize) & imask];
    keys[(k >> 1) & mask] = w;
    ids[(k >> 1) & imask] = id;
    w
}

/// The first step of a climb, from leaf `k` of a tree of `size` leaves: as
/// [`step`], but a leaf's sphere is its place, `k - size`, so leaves keep
/// no id (4 bytes a sphere less, and one store less an update).
#[inline(always)]
fn leaf_step(
    keys: &mut [u64],
    ids: &mut [u32],
    (mask, imask): (usize, usize),
    k: usize,
    w: u64,
    size: usize,
) -> u64 {
    let s = keys[(k ^ 1) & mask];
    let sib = s < w.wrapping_add((k & 1) as u64);
    let w = w ^ ((w ^ s) & 0u64.wrapping_sub(sib as u64));
    keys[(k >> 1) & mask] = w;
    ids[(k >> 1) & imask] = ((k ^ sib as usize) - size) as u32;
    w
}

impl EventQueue for Tournament {
    /// Time of sphere `i`'s pending event.
    #[inline]
    fn time_of(&self, i: usize) -> f64 {
        time(self.keys[self.size + i])
    }

    /// Bytes held on the heap.
    fn heap_bytes(&self) -> usize {
        self.keys.capacity() * 8 + self.ids.capacity() * 4
    }

    /// A queue for spheres `0..n`, every event at infinity (each leaf is
    /// its sphere, so ties at infinity go to the lowest index too).
    fn reset(&mut self, n: usize) {
        self.size = n.next_power_of_two().max(1);
        huge_pages::refill(&mut self.keys, 2 * self.size, key(f64::INFINITY));
        huge_pages::refill(&mut self.ids, self.size.max(2), 0);
        self.rebuild();
    }

    /// Set the leaves without rebuilding the tree; call [`Self::rebuild`] after.
    #[inline]
    fn set_leaf(&mut self, i: usize, t: f64) {
        self.keys[self.size + i] = key(t);
    }

    fn rebuild(&mut self) {
        for k in (1..self.size).rev() {
            let right = (self.keys[2 * k + 1] < self.keys[2 * k]) as usize;
            let child = 2 * k + right;
            self.keys[k] = self.keys[child];
            self.ids[k] = if child >= self.size {
                (child - self.size) as u32
            } else {
                self.ids[child]
            };
        }
    }

    /// Sphere `i`'s pending event is now at `t`. Climbs to the root always:
    /// stopping early where the winner stays saves little, and a branch on
    /// either the stop or the comparison is taken at random.
    #[inline]
    fn update(&mut self, i: usize, t: f64) {
        let size = self.size;
        let mut k = size + i;
        let Some((keys, ids, masks)) = self.nodes() else {
            return;
        };
        let mut w = key(t);
        keys[k & masks.0] = w;
        if k > 1 {
            w = leaf_step(keys, ids, masks, k, w, size);
            k >>= 1;
        }
        while k > 1 {
            w = step(keys, ids, masks, k, w);
            k >>= 1;
        }
    }

    /// [`Self::update`] for two spheres at once (the two of a contact): each
    /// climbs to where their paths meet, and the rest is climbed once.
    #[inline]
    fn update_two(&mut self, i: usize, ti: f64, j: usize, tj: f64) {
        if i == j {
            self.update(i, ti);
            return self.update(j, tj);
        }
        let size = self.size;
        let (mut a, mut b) = (size + i, size + j);
        let Some((keys, ids, masks)) = self.nodes() else {
            return;
        };
        let (mut wa, mut wb) = (key(ti), key(tj));
        keys[a & masks.0] = wa;
        keys[b & masks.0] = wb;
        // Both nodes of a level are set before either parent is taken, so
        // a parent the two share sees both. Two distinct leaves mean at
        // least two leaves, so both climb from the leaf level.
        let pa = leaf_step(keys, ids, masks, a, wa, size);
        wb = leaf_step(keys, ids, masks, b, wb, size);
        wa = pa;
        a >>= 1;
        b >>= 1;
        while a != b {
            let pa = step(keys, ids, masks, a, wa);
            wb = step(keys, ids, masks, b, wb);
            wa = pa;
            a >>= 1;
            b >>= 1;
        }
        while a > 1 {
            wa = step(keys, ids, masks, a, wa);
            a >>= 1;
        }
    }

    /// The earliest pending event: time and sphere (time infinite if none).
    #[inline]
    fn peek(&mut self) -> (f64, usize) {
        // A tree of one leaf: the root is that leaf, sphere 0.
        let id = if self.size > 1 { self.ids[1] } else { 0 };
        (time(self.keys[1]), id as usize)
    }

    /// Subtract `shift` from every time (a new time origin); order is kept
    /// because subtraction of a constant is monotone under rounding.
    fn shift(&mut self, shift: f64) {
        for k in &mut self.keys[self.size..] {
            *k = key(time(*k) - shift);
        }
        self.rebuild();
    }
}

impl Tournament {
    /// The two arrays as slices of power-of-two lengths, and those lengths
    /// less one (`None` before any reset).
    #[inline(always)]
    fn nodes(&mut self) -> Option<Nodes<'_>> {
        let (len, ilen) = (self.keys.len(), self.ids.len());
        if len == 0 {
            return None;
        }
        Some((
            &mut self.keys[..len],
            &mut self.ids[..ilen],
            (len - 1, ilen - 1),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::exact::queue::check_pop_order;

    #[test]
    fn pops_in_time_then_index_order() {
        check_pop_order::<Tournament>();
    }

    #[test]
    fn update_moves_an_event_both_ways() {
        let mut q = Tournament::default();
        q.reset(3);
        for i in 0..3 {
            q.set_leaf(i, i as f64);
        }
        q.rebuild();
        q.update(0, 10.0);
        assert_eq!(q.peek(), (1.0, 1));
        q.update(2, 0.5);
        assert_eq!(q.peek(), (0.5, 2));
        assert_eq!(q.time_of(0), 10.0);
        q.shift(0.5);
        assert_eq!(q.peek(), (0.0, 2));
    }

    /// Pairs of updates at once give the tree single updates give.
    #[test]
    fn update_two_matches_two_updates() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        for n in [2, 3, 64, 100] {
            let (mut one, mut two) = (Tournament::default(), Tournament::default());
            one.reset(n);
            two.reset(n);
            for _ in 0..3000 {
                let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
                let ti = rng.random_range(0..6) as f64;
                let tj = rng.random_range(0..6) as f64;
                one.update(i, ti);
                one.update(j, tj);
                two.update_two(i, ti, j, tj);
                assert_eq!((&one.keys, &one.ids), (&two.keys, &two.ids));
            }
        }
    }

    /// Random updates with many equal times (and infinities), against a
    /// scan of all leaves: earliest time, then lowest index.
    #[test]
    fn peek_matches_a_scan_with_ties() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        for n in [1, 2, 3, 5, 64, 100] {
            let mut q = Tournament::default();
            q.reset(n);
            let mut times = vec![f64::INFINITY; n];
            q.rebuild();
            for _ in 0..5000 {
                let i = rng.random_range(0..n);
                let t = match rng.random_range(0..10) {
                    0 => f64::INFINITY,
                    k => (k % 4) as f64,
                };
                times[i] = t;
                q.update(i, t);
                let best = times.iter().copied().fold(f64::INFINITY, f64::min);
                let (t, id) = q.peek();
                assert_eq!(t, best);
                if best.is_finite() {
                    assert_eq!(id, times.iter().position(|&x| x == best).unwrap());
                }
            }
        }
    }
}
