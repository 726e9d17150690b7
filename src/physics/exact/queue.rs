//! The event queue: one pending event per sphere, kept in a tournament tree
//! (a complete binary tree whose every inner node holds the earlier of its two
//! children). DynamO and Smallenburg's EDMD also keep one event per particle;
//! the tree makes "replace sphere i's event" and "peek the earliest" O(log N)
//! and O(1) with no allocation and no stale entries, which a binary heap of
//! all predictions would accumulate.
//!
//! Simultaneous events pop in sphere-index order (lower index first): the
//! fixed order that makes runs reproducible.

#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    t: f64,
    id: u32,
}

impl Node {
    const EMPTY: Node = Node {
        t: f64::INFINITY,
        id: u32::MAX,
    };
}

/// Whether the right child of a pair beats the left. Ties go left, and the
/// left subtree holds the lower indices, so every inner node holds the
/// earliest event of its subtree, the lowest index among equal times,
/// without comparing indices.
#[inline(always)]
fn right_wins(l: Node, r: Node) -> bool {
    r.t < l.t
}

#[derive(Clone, Debug, Default)]
pub struct EventQueue {
    /// Node `k` is `pairs[k / 2][k % 2]`, which is also index `k` of the
    /// flattened slice (the climb's view): siblings side by side. Leaves are
    /// nodes `size..2*size`, the root is node 1; node 0 is unused.
    pairs: Vec<[Node; 2]>,
    size: usize,
}

impl EventQueue {
    /// A queue for spheres `0..n`, every event at infinity.
    pub fn reset(&mut self, n: usize) {
        self.size = n.next_power_of_two().max(1);
        self.pairs.clear();
        self.pairs.resize(self.size, [Node::EMPTY; 2]);
    }

    #[inline(always)]
    fn node(&mut self, k: usize) -> &mut Node {
        &mut self.pairs[k >> 1][k & 1]
    }

    /// Set the leaves without rebuilding the tree; call [`Self::rebuild`] after.
    #[inline]
    pub fn set_leaf(&mut self, i: usize, t: f64) {
        *self.node(self.size + i) = Node { t, id: i as u32 };
    }

    pub fn rebuild(&mut self) {
        for k in (1..self.size).rev() {
            let [l, r] = self.pairs[k];
            *self.node(k) = if right_wins(l, r) { r } else { l };
        }
    }

    /// Sphere `i`'s pending event is now at `t`. Climbs to the root always,
    /// and picks each winner by indexing: stopping early where the winner
    /// stays saves little, and a branch on either the stop or the
    /// comparison is taken at random (LLVM turns a plain select back into
    /// such a branch).
    #[inline]
    pub fn update(&mut self, i: usize, t: f64) {
        // Nodes in one flat slice (node `k` at index `k`): every index below
        // is less than its power-of-two length, so masking with `len - 1`
        // changes none of them and lets the compiler drop the bounds checks
        // (a quarter of a climb's work), and the sibling and parent indices
        // are one bit operation each.
        let nodes = self.pairs.as_flattened_mut();
        if nodes.is_empty() {
            return;
        }
        let mask = nodes.len() - 1;
        let mut k = self.size + i;
        nodes[k & mask] = Node { t, id: i as u32 };
        while k > 1 {
            let pair = [nodes[(k & !1) & mask], nodes[(k | 1) & mask]];
            k >>= 1;
            nodes[k & mask] = pair[right_wins(pair[0], pair[1]) as usize];
        }
    }

    /// [`Self::update`] for two spheres at once (the two of a contact): each
    /// climbs to where their paths meet, and the rest is climbed once.
    #[inline]
    pub fn update_two(&mut self, i: usize, ti: f64, j: usize, tj: f64) {
        let nodes = self.pairs.as_flattened_mut();
        if nodes.is_empty() || i == j {
            self.update(i, ti);
            return self.update(j, tj);
        }
        let mask = nodes.len() - 1;
        let (mut a, mut b) = (self.size + i, self.size + j);
        nodes[a & mask] = Node { t: ti, id: i as u32 };
        nodes[b & mask] = Node { t: tj, id: j as u32 };
        // Both leaves are set before any parent is taken, so a parent the
        // two share sees both.
        while a != b {
            for k in [a, b] {
                let pair = [nodes[(k & !1) & mask], nodes[(k | 1) & mask]];
                nodes[(k >> 1) & mask] = pair[right_wins(pair[0], pair[1]) as usize];
            }
            a >>= 1;
            b >>= 1;
        }
        while a > 1 {
            let pair = [nodes[(a & !1) & mask], nodes[(a | 1) & mask]];
            a >>= 1;
            nodes[a & mask] = pair[right_wins(pair[0], pair[1]) as usize];
        }
    }

    /// The earliest pending event: time and sphere (time infinite if none).
    #[inline]
    pub fn peek(&self) -> (f64, usize) {
        let n = self.pairs[0][1];
        (n.t, n.id as usize)
    }

    /// Time of sphere `i`'s pending event.
    #[inline]
    pub fn time_of(&self, i: usize) -> f64 {
        let k = self.size + i;
        self.pairs[k >> 1][k & 1].t
    }

    /// Subtract `shift` from every time (a new time origin); order is kept
    /// because subtraction of a constant is monotone under rounding.
    pub fn shift(&mut self, shift: f64) {
        for pair in &mut self.pairs[self.size / 2..] {
            for node in pair {
                node.t -= shift;
            }
        }
        self.rebuild();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_time_then_index_order() {
        let mut q = EventQueue::default();
        q.reset(5);
        for (i, t) in [3.0, 1.0, 2.0, 1.0, 5.0].into_iter().enumerate() {
            q.set_leaf(i, t);
        }
        q.rebuild();
        let mut order = Vec::new();
        for _ in 0..5 {
            let (t, i) = q.peek();
            order.push((t, i));
            q.update(i, f64::INFINITY);
        }
        assert_eq!(order, [(1.0, 1), (1.0, 3), (2.0, 2), (3.0, 0), (5.0, 4)]);
        assert_eq!(q.peek().0, f64::INFINITY);
    }

    #[test]
    fn update_moves_an_event_both_ways() {
        let mut q = EventQueue::default();
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
            let (mut one, mut two) = (EventQueue::default(), EventQueue::default());
            one.reset(n);
            two.reset(n);
            for _ in 0..3000 {
                let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
                let ti = rng.random_range(0..6) as f64;
                let tj = rng.random_range(0..6) as f64;
                one.update(i, ti);
                one.update(j, tj);
                two.update_two(i, ti, j, tj);
                assert_eq!(one.pairs, two.pairs);
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
            let mut q = EventQueue::default();
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
