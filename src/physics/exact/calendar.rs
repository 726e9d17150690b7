//! A bucket ("calendar") event queue, after G. Paul, "A complexity O(1)
//! priority queue for event driven molecular dynamics simulations" (J.
//! Comput. Phys. 2007), as Smallenburg's EDMD uses it: an event in the near
//! future is pushed onto the list of its time bucket (no climb), only the
//! current bucket is kept ordered (a small binary heap), and events beyond
//! the calendar's window wait on an overflow list that is spread over the
//! buckets each time the window has moved on by its length.
//!
//! One pending event per sphere, as the tournament tree keeps, with lazy
//! deletion: an update pushes a new entry and leaves the old one where it
//! is; an entry is live while its key is its sphere's key, and dead ones are
//! dropped when their bucket comes up (or the overflow is spread), so they
//! can never be popped. Spheres with no event (time `+inf`) hold no entry.
use super::queue::{EventQueue, key, time};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// An entry's place in `entries`: what the buckets' and the overflow's
/// lists link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct EntryId(u32);

impl EntryId {
    /// The end of a list.
    const NONE: EntryId = EntryId(u32::MAX);

    fn index(self) -> usize {
        self.0 as usize
    }
}

/// The calendar's window, in medians of the pending events' times ahead
/// (taken at each rebuild): with one event per sphere, these are roughly
/// exponential with mean `median / ln 2`, so about 94 % of new events fall
/// inside four medians and the overflow stays short.
const WINDOW_MEDIANS: f64 = 4.0;

/// Pending times sampled for the median at a rebuild.
const SAMPLES: usize = 1024;

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    key: u64,
    sphere: u32,
    next: EntryId,
}

#[derive(Clone, Debug, Default)]
pub struct Calendar {
    /// Each sphere's pending event, as [`key`]s.
    keys: Vec<u64>,
    /// The entries of every list (buckets, overflow), and the free ones.
    entries: Vec<Entry>,
    free: EntryId,
    /// First entry of each bucket; bucket `a` (an absolute number) is slot
    /// `a & (heads.len() - 1)` while it is in the window.
    heads: Vec<EntryId>,
    /// Entries in buckets (live or dead): none means the window is empty.
    in_buckets: usize,
    overflow: EntryId,
    /// The current bucket and every earlier one, ordered by key then sphere.
    heap: BinaryHeap<Reverse<(u64, u32)>>,
    /// Time of bucket 0's start and buckets a unit of time.
    t0: f64,
    per_time: f64,
    /// Absolute number of the current bucket: entries of buckets up to it
    /// are in the heap, of the next `heads.len() - 1` in their slots.
    cur: i64,
    /// When `cur` reaches it the overflow is spread again (every entry on
    /// the overflow is of this bucket or later).
    spill_at: i64,
    /// The earliest of a queue with no finite event (found by a scan; kept
    /// until the next update).
    idle: Option<(u64, u32)>,
}

impl Calendar {
    /// The absolute bucket of `key`, or `None` for `+inf` and `NaN`s that
    /// sort after it (never popped before a finite event; no entry).
    /// Monotone in the key: subtraction, multiplication by a positive
    /// constant, floor and the saturating cast all keep order.
    #[inline(always)]
    fn bucket(&self, key: u64) -> Option<i64> {
        let t = time(key);
        if t.is_nan() {
            return if t.is_sign_negative() {
                Some(i64::MIN)
            } else {
                None
            };
        }
        if t == f64::INFINITY {
            return None;
        }
        Some(((t - self.t0) * self.per_time).floor() as i64)
    }

    fn slots(&self) -> i64 {
        self.heads.len() as i64
    }

    #[inline(always)]
    fn alloc(&mut self, key: u64, sphere: u32, next: EntryId) -> EntryId {
        let e = Entry { key, sphere, next };
        if self.free == EntryId::NONE {
            self.entries.push(e);
            EntryId((self.entries.len() - 1) as u32)
        } else {
            let k = self.free;
            self.free = self.entries[k.index()].next;
            self.entries[k.index()] = e;
            k
        }
    }

    #[inline(always)]
    fn release(&mut self, k: EntryId) {
        self.entries[k.index()].next = self.free;
        self.free = k;
    }

    /// Put sphere `i`'s entry at `key` where its bucket says.
    #[inline(always)]
    fn insert(&mut self, i: usize, key: u64) {
        let Some(a) = self.bucket(key) else {
            return;
        };
        if a <= self.cur {
            self.heap.push(Reverse((key, i as u32)));
        } else if a < self.cur.saturating_add(self.slots()) {
            let slot = (a as usize) & (self.heads.len() - 1);
            let head = self.heads[slot];
            self.heads[slot] = self.alloc(key, i as u32, head);
            self.in_buckets += 1;
        } else {
            self.overflow = self.alloc(key, i as u32, self.overflow);
        }
    }

    fn live(&self, key: u64, sphere: u32) -> bool {
        self.keys[sphere as usize] == key
    }

    /// Spread the overflow over the window from `cur`: drop dead entries,
    /// move the ones now inside to their bucket (or the heap).
    fn spill(&mut self) {
        let mut k = std::mem::replace(&mut self.overflow, EntryId::NONE);
        let end = self.cur.saturating_add(self.slots());
        while k != EntryId::NONE {
            let Entry { key, sphere, next } = self.entries[k.index()];
            match self.bucket(key) {
                Some(a) if self.live(key, sphere) => {
                    if a <= self.cur {
                        self.heap.push(Reverse((key, sphere)));
                        self.release(k);
                    } else if a < end {
                        let slot = (a as usize) & (self.heads.len() - 1);
                        self.entries[k.index()].next = self.heads[slot];
                        self.heads[slot] = k;
                        self.in_buckets += 1;
                    } else {
                        self.entries[k.index()].next = self.overflow;
                        self.overflow = k;
                    }
                }
                _ => self.release(k),
            }
            k = next;
        }
        self.spill_at = end;
    }

    /// The window is empty: move it to the earliest live overflow entry.
    /// False if there is none (no finite event left).
    fn jump(&mut self) -> bool {
        let mut earliest = None::<i64>;
        let mut k = self.overflow;
        while k != EntryId::NONE {
            let e = self.entries[k.index()];
            if self.live(e.key, e.sphere)
                && let Some(a) = self.bucket(e.key)
            {
                earliest = Some(earliest.map_or(a, |b| b.min(a)));
            }
            k = e.next;
        }
        if let Some(a) = earliest {
            self.cur = self.cur.max(a);
            self.spill();
            return true;
        }
        // Only dead entries: free them all.
        let mut k = std::mem::replace(&mut self.overflow, EntryId::NONE);
        while k != EntryId::NONE {
            let next = self.entries[k.index()].next;
            self.release(k);
            k = next;
        }
        false
    }

    /// Move the next bucket into the heap.
    fn next_bucket(&mut self) {
        self.cur += 1;
        if self.cur >= self.spill_at {
            self.spill();
        }
        let slot = (self.cur as usize) & (self.heads.len() - 1);
        let mut k = std::mem::replace(&mut self.heads[slot], EntryId::NONE);
        while k != EntryId::NONE {
            let Entry { key, sphere, next } = self.entries[k.index()];
            self.heap.push(Reverse((key, sphere)));
            self.release(k);
            self.in_buckets -= 1;
            k = next;
        }
    }

    /// The earliest of a queue with no finite event: a scan, kept.
    fn idle_min(&mut self) -> (f64, usize) {
        let best = *self.idle.get_or_insert_with(|| {
            (self.keys.iter().enumerate())
                .map(|(i, &k)| (k, i as u32))
                .min()
                .unwrap_or((key(f64::INFINITY), u32::MAX))
        });
        (time(best.0), best.1 as usize)
    }

    /// Empty every list and set the bucket width from the pending times.
    fn clear(&mut self) {
        let n = self.keys.len();
        self.entries.clear();
        self.free = EntryId::NONE;
        self.heads.clear();
        self.heads
            .resize(n.next_power_of_two().max(1), EntryId::NONE);
        self.in_buckets = 0;
        self.overflow = EntryId::NONE;
        self.heap.clear();
        self.idle = None;
        let finite = |k: &u64| time(*k).is_finite();
        let t0 = self
            .keys
            .iter()
            .filter(|k| finite(k))
            .map(|&k| time(k))
            .fold(f64::INFINITY, f64::min);
        self.t0 = if t0.is_finite() { t0 } else { 0.0 };
        // The median time ahead of a strided sample.
        let stride = (n / SAMPLES).max(1);
        let mut ahead: Vec<f64> = (self.keys.iter().step_by(stride))
            .filter(|k| finite(k))
            .map(|&k| time(k) - self.t0)
            .collect();
        let median = if ahead.is_empty() {
            0.0
        } else {
            let mid = ahead.len() / 2;
            *ahead.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        // Any width keeps the order; a median of zero (all at once) or an
        // overflowing one falls back to a unit window.
        let window = if median > 0.0 && median.is_finite() {
            WINDOW_MEDIANS * median
        } else {
            1.0
        };
        self.per_time = self.heads.len() as f64 / window;
        if !self.per_time.is_finite() || self.per_time <= 0.0 {
            self.per_time = 1.0;
        }
        self.cur = 0;
        self.spill_at = self.slots();
    }
}

impl EventQueue for Calendar {
    fn reset(&mut self, n: usize) {
        self.keys.clear();
        self.keys.resize(n, key(f64::INFINITY));
        self.clear();
    }

    #[inline]
    fn set_leaf(&mut self, i: usize, t: f64) {
        self.keys[i] = key(t);
    }

    fn rebuild(&mut self) {
        self.clear();
        for i in 0..self.keys.len() {
            self.insert(i, self.keys[i]);
        }
    }

    #[inline]
    fn update(&mut self, i: usize, t: f64) {
        let k = key(t);
        self.keys[i] = k;
        self.idle = None;
        self.insert(i, k);
    }

    #[inline]
    fn peek(&mut self) -> (f64, usize) {
        loop {
            while let Some(&Reverse((k, i))) = self.heap.peek() {
                if self.live(k, i) {
                    return (time(k), i as usize);
                }
                self.heap.pop();
            }
            if self.in_buckets > 0 {
                self.next_bucket();
            } else if !self.jump() {
                return self.idle_min();
            }
        }
    }

    #[inline]
    fn time_of(&self, i: usize) -> f64 {
        time(self.keys[i])
    }

    /// As the tournament: each key moved by the same rounding, then a
    /// rebuild (which also sets the buckets to the new schedule).
    fn shift(&mut self, shift: f64) {
        for k in &mut self.keys {
            *k = key(time(*k) - shift);
        }
        self.rebuild();
    }

    fn heap_bytes(&self) -> usize {
        self.keys.capacity() * 8
            + self.entries.capacity() * size_of::<Entry>()
            + self.heads.capacity() * 4
            + self.heap.capacity() * size_of::<Reverse<(u64, u32)>>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_time_then_index_order() {
        super::super::queue::check_pop_order::<Calendar>();
    }

    /// Events far past the window wait on the overflow and come back in
    /// order; dead entries never pop.
    #[test]
    fn far_events_and_dead_entries() {
        let mut q = Calendar::default();
        q.reset(4);
        for i in 0..4 {
            q.set_leaf(i, 1.0 + i as f64 * 0.001);
        }
        q.rebuild();
        q.update(0, 1e6);
        q.update(1, 1e6);
        q.update(2, 5.0);
        q.update(2, 1e9);
        assert_eq!(q.peek(), (1.003, 3));
        q.update(3, 2e9);
        assert_eq!(q.peek(), (1e6, 0));
        q.update(0, f64::INFINITY);
        assert_eq!(q.peek(), (1e6, 1));
        q.update(1, f64::INFINITY);
        assert_eq!(q.peek(), (1e9, 2));
        q.update(2, f64::INFINITY);
        assert_eq!(q.peek(), (2e9, 3));
        q.update(3, f64::INFINITY);
        assert_eq!(q.peek(), (f64::INFINITY, 0));
        assert!(q.entries.len() <= 8, "{} entries", q.entries.len());
    }
}
