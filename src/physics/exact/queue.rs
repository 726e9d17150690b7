//! The event queue: one pending event per sphere ([`EventQueue`]), and the
//! keys its trees compare. The queue the model runs on is
//! [`super::eight_way::EightWay`], a tournament tree of eight children a
//! node, held to the order below by `tests/physics/exact_queue.rs` (the
//! binary tournament and the bucket queue it was measured against are
//! deleted: docs/perf-log.md, 2026-12-07).
//! `DynamO` and Smallenburg's EDMD also keep one event per particle; a tree
//! makes "replace sphere i's event" and "peek the earliest" O(log N) and
//! O(1) with no allocation and no stale entries, which a binary heap of all
//! predictions would accumulate.

/// The earliest of one pending event time per sphere. Simultaneous events
/// pop in sphere-index order (lower index first): the fixed order that makes
/// runs reproducible, so another queue must keep it to give the same runs:
/// [`Self::peek`] is the least `(time, sphere)` over every sphere, ties of
/// `+inf` included (and `(+inf, u32::MAX)` with no spheres). Times are not
/// `NaN`s without the sign bit (those sort after `+inf`).
pub trait EventQueue: Default {
    /// Spheres `0..n`, every event at infinity.
    fn reset(&mut self, n: usize);
    /// Set sphere `i`'s time without restoring the order; call
    /// [`Self::rebuild`] after setting them all.
    fn set_leaf(&mut self, i: usize, t: f64);
    /// Restore the order after [`Self::set_leaf`]s.
    fn rebuild(&mut self);
    /// Sphere `i`'s pending event is now at `t`.
    fn update(&mut self, i: usize, t: f64);
    /// Spheres `i` and `j` (the two of a contact) are now at `ti` and `tj`.
    fn update_two(&mut self, i: usize, ti: f64, j: usize, tj: f64) {
        self.update(i, ti);
        self.update(j, tj);
    }
    /// The earliest pending event: time and sphere (time infinite if none).
    /// Mutable, so a queue may sort lazily.
    fn peek(&mut self) -> (f64, usize);
    /// The sphere whose event is likely next after [`Self::peek`]'s (or
    /// any sphere): a hint for loading its records early; `None` when the
    /// queue gives no hint.
    fn runner_up(&self) -> Option<usize> {
        None
    }
    /// Start loading what [`Self::update`] of sphere `i` will read first.
    fn prefetch(&self, _i: usize) {}
    /// Time of sphere `i`'s pending event.
    fn time_of(&self, i: usize) -> f64;
    /// Subtract `shift` from every time (a new time origin).
    fn shift(&mut self, shift: f64);
    /// Bytes held on the heap.
    fn heap_bytes(&self) -> usize;
}

/// A time as a `u64` whose unsigned order is the time's order (`-0` is
/// taken as `+0`, so the two tie as before): the climb compares integers,
/// which LLVM keeps as a conditional move where a select on two `f64`s
/// became a random branch.
#[inline(always)]
pub(super) fn key(t: f64) -> u64 {
    let bits = (t + 0.0).to_bits();
    bits ^ ((((bits as i64) >> 63) as u64) | (1 << 63))
}

#[inline(always)]
pub(super) fn time(key: u64) -> f64 {
    f64::from_bits(key ^ (!(((key as i64) >> 63) as u64) | (1 << 63)))
}

/// Five leaves with ties pop by time, then lower index, and an emptied
/// queue answers infinity at sphere 0: the order every queue must keep.
#[cfg(test)]
pub(super) fn check_pop_order<Q: EventQueue>() {
    let mut q = Q::default();
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
    assert_eq!(q.peek(), (f64::INFINITY, 0));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key keeps every time and its order (minus zero ties plus zero).
    #[test]
    fn keys_order_like_times() {
        let times = [
            f64::NEG_INFINITY,
            -3.5,
            -f64::MIN_POSITIVE,
            0.0,
            5e-324,
            1e-300,
            0.25,
            1.0,
            f64::MAX,
            f64::INFINITY,
        ];
        for (a, &ta) in times.iter().enumerate() {
            assert_eq!(time(key(ta)), ta);
            for &tb in &times[a + 1..] {
                assert!(key(ta) < key(tb), "{ta} vs {tb}");
            }
        }
        assert_eq!(key(-0.0), key(0.0));
    }
}
