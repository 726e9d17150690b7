//! The pairs a grid finds: its work cut into units (key blocks of a
//! level, coarse spheres against the finer levels, the last few against
//! everything), run on the lanes and joined in a fixed order.
use super::entry::Ball;
use super::level::{Level, within};
use super::{Grid, Pair};
use crate::physics::exec::{Exec, for_each_block_of, work_ns};

/// Predicted nanoseconds a cell entry costs in `pairs` and in
/// `scan_within` (measured per block, docs/threading.md).
const NS_PER_ENTRY_PAIRS: usize = 50;
const NS_PER_ENTRY_SCAN: usize = 30;
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Coarse-level spheres per parallel block of cross-level queries.
const CROSS_BLOCK: usize = 64;
/// Pairs a unit of [`Grid::pairs_within`] (or [`Grid::count_within`]) finds before it adds them to the
/// shared total.
const LIMIT_FLUSH: usize = 256;

/// The work units of `pairs`, in the fixed order their results are joined.
#[derive(Clone, Copy)]
enum Unit {
    /// Same-level pairs of one key block of a level.
    Block { level: usize, block: usize },
    /// Spheres `from..to` of a coarse level against every finer level.
    Cross {
        level: usize,
        from: usize,
        to: usize,
    },
    /// The last few against everything.
    Top,
}

impl Grid {
    /// Entries over all levels: the work of a pass over the units.
    fn entries(&self) -> usize {
        self.levels.iter().map(|l| l.entries.len()).sum::<usize>() + self.top.len()
    }

    fn units(&self) -> Vec<Unit> {
        let mut units = Vec::new();
        for (l, level) in self.levels.iter().enumerate() {
            units.extend((0..level.key_blocks()).map(|block| Unit::Block { level: l, block }));
            if l > 0 {
                let n = level.entries.len() - 1;
                units.extend((0..n.div_ceil(CROSS_BLOCK)).map(|b| Unit::Cross {
                    level: l,
                    from: b * CROSS_BLOCK,
                    to: ((b + 1) * CROSS_BLOCK).min(n),
                }));
            }
        }
        if !self.top.is_empty() {
            units.push(Unit::Top);
        }
        units
    }

    /// The pairs of one unit within reach, as `f(id, id)`; `go` is asked
    /// before each sphere's pairs, and the unit stops when it says no.
    fn unit_pairs(&self, unit: Unit, go: &impl Fn() -> bool, f: &mut impl FnMut(u32, u32)) {
        match unit {
            Unit::Block { level, block } => self.levels[level].block_pairs(block, go, f),
            Unit::Cross { level, from, to } => {
                for e in &self.levels[level].entries[from..to] {
                    if !go() {
                        return;
                    }
                    for finer in &self.levels[..level] {
                        finer_pairs(finer, &e.ball, e.id, f);
                    }
                }
            }
            Unit::Top => {
                for (k, (a, ia)) in self.top.iter().enumerate() {
                    if !go() {
                        return;
                    }
                    for level in &self.levels {
                        finer_pairs(level, a, *ia, f);
                    }
                    let above = self.top[k + 1..].iter().filter(|(b, _)| within(a, b));
                    above.for_each(|(_, ib)| f(*ia, *ib));
                }
            }
        }
    }

    /// Every pair within reach, in a fixed order, found in parallel on
    /// `exec`; `keep` filters pairs.
    pub fn pairs<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
    ) {
        out.clear();
        let units = self.units();
        self.slots.ensure(units.len());
        let this = &*self;
        for_each_block_of(
            exec,
            units.len(),
            work_ns(this.entries(), NS_PER_ENTRY_PAIRS),
            &|u| {
                let mut v = this.slots[u].lock();
                v.clear();
                this.unit_pairs(units[u], &|| true, &mut |i, j| {
                    if keep(i, j) {
                        v.push((i, j));
                    }
                });
            },
        );
        for s in &self.slots[..units.len()] {
            out.extend_from_slice(&s.lock());
        }
    }

    /// As [`Grid::pairs`], but stops once more than `limit` pairs are
    /// found (a step's work budget; `None`: no limit); returns false then,
    /// with only some of them in `out`. Every unit runs to its end unless the running total
    /// is over `limit`, so the answer is "the pairs number more than
    /// `limit`", whatever the lanes and their timing.
    pub fn pairs_within<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        out: &mut Vec<Pair>,
        limit: Option<usize>,
    ) -> bool {
        let Some(limit) = limit else {
            self.pairs(exec, keep, out);
            return true;
        };
        out.clear();
        let (all, units) = self.scan_within::<true, K>(exec, keep, limit);
        if all {
            for s in &self.slots[..units] {
                out.extend_from_slice(&s.lock());
            }
        }
        all
    }

    /// Looks at the pairs within reach, keeping none, until more than
    /// `limit` of them were `counted`: true if every pair was looked at.
    /// For a readout that must not cost more than a step may.
    pub fn count_within<K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        counted: &K,
        limit: usize,
    ) -> bool {
        self.scan_within::<false, K>(exec, counted, limit).0
    }

    /// The pairs within reach, unit by unit, the ones `keep` accepts
    /// counted (and, if `STORE`, left in the unit's slot) until more than
    /// `limit` were; false then. Also returns the number of units.
    fn scan_within<const STORE: bool, K: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        exec: &dyn Exec,
        keep: &K,
        limit: usize,
    ) -> (bool, usize) {
        let units = self.units();
        if STORE {
            self.slots.ensure(units.len());
        }
        let this = &*self;
        let found = AtomicUsize::new(0);
        for_each_block_of(
            exec,
            units.len(),
            work_ns(this.entries(), NS_PER_ENTRY_SCAN),
            &|u| {
                let mut v = STORE.then(|| this.slots[u].lock());
                if let Some(v) = &mut v {
                    v.clear();
                }
                // Counted here, added to the total now and then: one shared
                // counter touched per pair would cost more than the pair.
                // The total is read then too: a unit that finds few pairs costs
                // little, whatever the others found.
                let (mine, told, over) = (Cell::new(0usize), Cell::new(0usize), Cell::new(false));
                let tell = || {
                    let new = mine.get() - told.get();
                    let before = found.fetch_add(new, Ordering::Relaxed);
                    told.set(mine.get());
                    over.set(before + new > limit);
                };
                let go = || {
                    if mine.get() - told.get() >= LIMIT_FLUSH {
                        tell();
                    }
                    !over.get()
                };
                let mut take = |i, j| {
                    if !keep(i, j) {
                        return;
                    }
                    if let Some(v) = &mut v {
                        v.push((i, j));
                    }
                    mine.set(mine.get() + 1);
                };
                over.set(found.load(Ordering::Relaxed) > limit);
                if go() {
                    this.unit_pairs(units[u], &go, &mut take);
                }
                tell();
            },
        );
        (found.into_inner() <= limit, units.len())
    }
}

/// The pairs of ball `a` (sphere `ia`) with the balls of a finer level.
#[inline]
fn finer_pairs(finer: &Level, a: &Ball, ia: u32, f: &mut impl FnMut(u32, u32)) {
    finer.near(a.pos, a.reach + finer.reach_max, &mut |j| {
        let b = &finer.entries[j];
        if within(a, &b.ball) {
            f(ia, b.id);
        }
    });
}
