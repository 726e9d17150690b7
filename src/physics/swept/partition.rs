//! Which spheres with events run together. Each such sphere gets a slot;
//! slots are joined into clusters by union-find (each cluster's slots also
//! form a cycle, so a merged cluster's members are found without scanning
//! everyone), and each round's clusters to run are laid out with their
//! members and meeting pairs. On many lanes (`wide.rs`) the slots are
//! numbered and the first round laid out in parallel, to the same bits.
use super::group::{Buckets, group, group_wide, wide_group};
use crate::physics::exec::{Exec, PerBlock, for_each_block, spans};
use crate::physics::wide::wide;
use parking_lot::Mutex;

/// Spheres per block when numbering the slots in parallel.
const NUMBER_BLOCK: usize = 8192;
/// Slots per block when finding their roots in parallel.
const ROOT_BLOCK: usize = 4096;

/// A sphere's place among the spheres with events of a step part: what
/// everything kept by slot is indexed with, never a sphere id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Slot(u32);

impl Slot {
    /// No slot: the sphere has no events (yet).
    pub const NONE: Slot = Slot(u32::MAX);

    pub fn at(index: usize) -> Slot {
        Slot(index as u32)
    }

    pub fn index(self) -> usize {
        self.0 as usize
    }

    pub fn is_none(self) -> bool {
        self == Slot::NONE
    }
}

/// A cluster to run: members `order[m0..m1]`, meeting pairs
/// `pairs[p0..p1]`.
#[derive(Clone, Copy)]
pub(super) struct Todo {
    pub m0: u32,
    pub m1: u32,
    pub p0: u32,
    pub p1: u32,
}

/// The clusters one round runs; rebuilt every round.
#[derive(Default)]
pub(super) struct Batch {
    /// The members of every cluster, each cluster's in sphere order.
    pub order: Vec<u32>,
    pub pairs: Vec<(u32, u32)>,
    pub todo: Vec<Todo>,
    /// Scratch for one cluster's members and pairs.
    found: Vec<u32>,
    ps: Vec<u32>,
}

/// The spheres with events of one step part, and their clusters.
#[derive(Default)]
pub(super) struct Partition {
    /// Sphere id → slot among the involved, `Slot::NONE` for the rest.
    pub slot: Vec<Slot>,
    /// Slot → sphere id.
    pub ids: Vec<u32>,
    /// Slots from here on were added after the first round.
    pub first_late: usize,
    parent: Vec<Slot>,
    /// Each cluster's slots as a cycle (`next` of the last is the first).
    next: Vec<Slot>,
    /// By root slot: the cluster must run (again).
    dirty: Vec<bool>,
    /// Roots marked dirty since the last partition (some merged since).
    dirty_roots: Vec<Slot>,
    /// Set by `merge_all`: the next partition is one cluster of everyone.
    whole: bool,
    /// By slot: where its meeting pairs (as the pair's first sphere) start
    /// in `meets_of`, indices into the step's `meets`.
    meet_start: Vec<u32>,
    meets_of: Vec<u32>,
    /// By meeting pair: the slot of its first sphere.
    meet_slot: Vec<Slot>,
    /// By slot of the first round: where its partners among the step's
    /// pairs (meeting or near) start in `partners`.
    pub partner_start: Vec<u32>,
    pub partners: Vec<u32>,
    /// Whether `meet_start` and `meets_of` are this part's (only rounds
    /// after the first read them).
    meets_indexed: bool,
    /// By slot, its cluster's root, when the first round is laid out.
    roots: Vec<Slot>,
    /// By root slot, where its members and pairs start in the batch.
    member_start: Vec<u32>,
    pair_start: Vec<u32>,
    /// Scratch of the parallel forms.
    ids_buckets: Buckets<u32>,
    pair_buckets: Buckets<(u32, u32)>,
    marked: PerBlock<u32>,
}

impl Partition {
    /// Slots for the spheres of the pairs that meet and those that reach a
    /// wall, in sphere order, each its own cluster; returns how many.
    pub fn start(
        &mut self,
        exec: &dyn Exec,
        n: usize,
        meets: &[(u32, u32)],
        hits: &[u32],
    ) -> usize {
        for &i in &self.ids {
            self.slot[i as usize] = Slot::NONE;
        }
        self.slot.resize(n, Slot::NONE);
        self.ids.clear();
        // Marked, then read off in order: one pass over the spheres costs
        // less than sorting the tens of thousands of ends of the pairs.
        for &(i, j) in meets {
            self.slot[i as usize] = Slot(0);
            self.slot[j as usize] = Slot(0);
        }
        for &i in hits {
            self.slot[i as usize] = Slot(0);
        }
        if wide(exec) && n >= 2 * NUMBER_BLOCK.min(exec.min_work()) {
            self.number_wide(exec);
        } else {
            for (i, slot) in self.slot.iter_mut().enumerate() {
                if !slot.is_none() {
                    *slot = Slot::at(self.ids.len());
                    self.ids.push(i as u32);
                }
            }
        }
        self.meets_indexed = false;
        self.meet_slot.clear();
        self.meet_slot
            .extend(meets.iter().map(|&(i, _)| self.slot[i as usize]));
        let m = self.ids.len();
        self.first_late = m;
        self.parent.clear();
        self.parent.extend((0..m).map(Slot::at));
        self.next.clear();
        self.next.extend((0..m).map(Slot::at));
        self.dirty_roots.clear();
        self.dirty.clear();
        self.dirty.resize(m, true);
        m
    }

    /// The marked slots numbered in sphere order, in parallel blocks: each
    /// block counts its marks, then numbers them from the count before it.
    fn number_wide(&mut self, exec: &dyn Exec) {
        let blocks = self.slot.len().div_ceil(NUMBER_BLOCK);
        self.marked.ensure(blocks);
        let (slot, marked) = (&self.slot, &self.marked);
        for_each_block(exec, blocks, &|b| {
            let mine = &slot[b * NUMBER_BLOCK..((b + 1) * NUMBER_BLOCK).min(slot.len())];
            *marked[b].lock() = mine.iter().filter(|s| !s.is_none()).count() as u32;
        });
        let counts: Vec<usize> = self.marked[..blocks]
            .iter_mut()
            .map(|c| *c.get_mut() as usize)
            .collect();
        self.ids.resize(counts.iter().sum(), 0);
        let firsts: Vec<usize> = counts
            .iter()
            .scan(0, |at, &c| {
                let first = *at;
                *at += c;
                Some(first)
            })
            .collect();
        let ids = spans(&mut self.ids, counts.iter().copied());
        let slots: Vec<Mutex<&mut [Slot]>> =
            self.slot.chunks_mut(NUMBER_BLOCK).map(Mutex::new).collect();
        for_each_block(exec, blocks, &|b| {
            let (mut slot, mut ids) = (slots[b].lock(), ids[b].lock());
            let mut k = 0;
            for (i, s) in slot.iter_mut().enumerate() {
                if !s.is_none() {
                    *s = Slot::at(firsts[b] + k);
                    ids[k] = (b * NUMBER_BLOCK + i) as u32;
                    k += 1;
                }
            }
        });
    }

    /// The first clusters: the spheres of each pair that meets, or whose
    /// balls overlap with both having events, run together.
    pub fn join_pairs(&mut self, exec: &dyn Exec, meets: &[(u32, u32)], near: &[(u32, u32)]) {
        for &(i, j) in meets {
            self.union(self.slot[i as usize], self.slot[j as usize]);
        }
        for &(i, j) in near {
            let (a, b) = (self.slot[i as usize], self.slot[j as usize]);
            if !a.is_none() && !b.is_none() {
                self.union(a, b);
            }
        }
        self.index_partners(exec, meets, near);
    }

    /// Each first-round slot's partners among the pairs the grid found
    /// (counting sort by slot): a rescan whose ball lies inside the
    /// sphere's binned one finds everyone it can meet among them.
    fn index_partners(&mut self, exec: &dyn Exec, meets: &[(u32, u32)], near: &[(u32, u32)]) {
        let (slot, m) = (&self.slot, self.ids.len());
        let ends = |i: u32, j: u32| {
            [(i, j), (j, i)].into_iter().filter_map(|(k, other)| {
                let a = slot[k as usize];
                (!a.is_none()).then_some((a.0, other))
            })
        };
        let len = meets.len() + near.len();
        if wide_group(exec, m, len) {
            // Source positions `r` of the meeting pairs followed by the near.
            let by_slot = |r: std::ops::Range<usize>| {
                let (k, e) = (meets.len(), r.end);
                let pairs = meets[r.start.min(k)..e.min(k)]
                    .iter()
                    .chain(&near[r.start.max(k) - k..e.max(k) - k]);
                pairs.flat_map(|&(i, j)| ends(i, j))
            };
            let (starts, out) = (&mut self.partner_start, &mut self.partners);
            group_wide(exec, &mut self.ids_buckets, starts, out, m, len, &by_slot);
            return;
        }
        let ends = meets
            .iter()
            .chain(near)
            .flat_map(|&(i, j)| [(i, j), (j, i)]);
        let by_slot = ends.filter_map(|(k, other)| {
            let a = slot[k as usize];
            (!a.is_none()).then_some((a.0, other))
        });
        group(&mut self.partner_start, &mut self.partners, m, by_slot);
    }

    pub fn find(&mut self, mut x: Slot) -> Slot {
        while self.parent[x.index()] != x {
            let p = self.parent[x.index()];
            self.parent[x.index()] = self.parent[p.index()];
            x = p;
        }
        x
    }

    /// Joins two slots' clusters; the joined cluster must run again.
    pub fn union(&mut self, a: Slot, b: Slot) {
        let lo = self.link(a, b);
        self.dirty[lo.index()] = true;
        self.dirty_roots.push(lo);
    }

    /// Joins two slots' clusters under the lower root, which it returns.
    pub fn link(&mut self, a: Slot, b: Slot) -> Slot {
        let (ra, rb) = (self.find(a), self.find(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        if lo != hi {
            self.parent[hi.index()] = lo;
            // Splicing two cycles is swapping one successor of each.
            self.next.swap(lo.index(), hi.index());
        }
        lo
    }

    /// Cluster `root` ran and needs no rerun unless it merges.
    pub fn ran(&mut self, root: Slot) {
        self.dirty[root.index()] = false;
    }

    /// A slot for sphere `id`, a bystander met after the first round, on
    /// its own.
    pub fn add(&mut self, id: u32) -> Slot {
        let k = Slot::at(self.ids.len());
        self.slot[id as usize] = k;
        self.ids.push(id);
        self.parent.push(k);
        self.next.push(k);
        self.dirty.push(true);
        self.dirty_roots.push(k);
        k
    }

    /// Every cluster, finished or not, as one: the plain serial loop over
    /// all the spheres with events, which no sphere outside it with
    /// events can touch, so it finishes in one run. No rescan of it looks up partners
    /// (the one run searches the grid).
    pub fn merge_all(&mut self) {
        let m = self.ids.len();
        for s in 0..m {
            self.parent[s] = Slot(0);
            self.next[s] = Slot::at((s + 1) % m);
        }
        if m > 0 {
            self.dirty[0] = true;
            self.dirty_roots.push(Slot(0));
        }
        self.whole = true;
    }

    /// Drops the partner index: the step runs as one cluster.
    pub fn no_partners(&mut self) {
        self.partner_start.clear();
    }

    /// This round's clusters (named by root slot) and the ones that must
    /// run, with their members and meeting pairs, into `batch`: every
    /// cluster in the `first` round, only those marked dirty later, each
    /// found by walking its cycle.
    pub fn partition(
        &mut self,
        exec: &dyn Exec,
        meets: &[(u32, u32)],
        first: bool,
        batch: &mut Batch,
    ) {
        batch.todo.clear();
        batch.order.clear();
        batch.pairs.clear();
        if self.whole {
            self.partition_whole(meets, batch);
        } else if first {
            self.partition_all(exec, meets, batch);
        } else {
            self.partition_dirty(exec, meets, batch);
        }
    }

    /// Everyone in one cluster (after `merge_all`): the members are the
    /// slots in sphere order and the pairs all of them, as detected.
    fn partition_whole(&mut self, meets: &[(u32, u32)], batch: &mut Batch) {
        self.whole = false;
        self.dirty_roots.clear();
        let m = self.ids.len();
        batch.order.extend_from_slice(&self.ids);
        if m > self.first_late {
            // Slots added after the first round are not in sphere order.
            batch.order.sort_unstable();
        }
        batch.pairs.extend_from_slice(meets);
        if m > 0 {
            batch.todo.push(Todo {
                m0: 0,
                m1: m as u32,
                p0: 0,
                p1: meets.len() as u32,
            });
        }
    }

    fn partition_all(&mut self, exec: &dyn Exec, meets: &[(u32, u32)], batch: &mut Batch) {
        self.dirty_roots.clear();
        if wide_group(exec, self.ids.len(), self.ids.len()) {
            self.partition_wide(exec, meets, batch);
            return;
        }
        self.index_meets(exec, meets);
        // Every cluster, by root (a root is its own parent), walked round
        // its cycle.
        for root in (0..self.ids.len()).map(Slot::at) {
            if self.parent[root.index()] == root {
                self.push_cluster(root, meets, batch);
            }
        }
    }

    /// [`Partition::partition_all`] in parallel: every cluster, in order of
    /// its root (its lowest slot), with its members in slot order (the
    /// sphere order, in the first round) and its meeting pairs in detection
    /// order, as the slots and the pairs grouped by their root.
    fn partition_wide(&mut self, exec: &dyn Exec, meets: &[(u32, u32)], batch: &mut Batch) {
        let mut roots = std::mem::take(&mut self.roots);
        self.roots_into(exec, &mut roots);
        self.roots = roots;
        let m = self.ids.len();
        let (roots, ids, meet_slot) = (&self.roots, &self.ids, &self.meet_slot);
        let members = |r: std::ops::Range<usize>| r.map(|s| (roots[s].0, ids[s]));
        let (starts, order) = (&mut self.member_start, &mut batch.order);
        group_wide(exec, &mut self.ids_buckets, starts, order, m, m, &members);
        let pairs = |r: std::ops::Range<usize>| {
            let first = meet_slot[r.clone()].iter();
            first.zip(&meets[r]).map(|(s, &p)| (roots[s.index()].0, p))
        };
        let (starts, out) = (&mut self.pair_start, &mut batch.pairs);
        group_wide(
            exec,
            &mut self.pair_buckets,
            starts,
            out,
            m,
            meets.len(),
            &pairs,
        );
        let (ms, ps) = (&self.member_start, &self.pair_start);
        for (r, root) in roots.iter().enumerate() {
            if root.index() == r {
                batch.todo.push(Todo {
                    m0: ms[r],
                    m1: ms[r + 1],
                    p0: ps[r],
                    p1: ps[r + 1],
                });
            }
        }
    }

    /// Every slot's root into `out`: on many lanes in parallel blocks, each
    /// slot climbing on its own; else by `find`.
    pub fn roots_into(&mut self, exec: &dyn Exec, out: &mut Vec<Slot>) {
        let m = self.ids.len();
        out.clear();
        if !(wide(exec) && m >= 2 * ROOT_BLOCK.min(exec.min_work())) {
            out.extend((0..m).map(|s| self.find(Slot::at(s))));
            return;
        }
        out.resize(m, Slot::NONE);
        let parent = &self.parent;
        let chunks: Vec<Mutex<&mut [Slot]>> = out.chunks_mut(ROOT_BLOCK).map(Mutex::new).collect();
        for_each_block(exec, chunks.len(), &|b| {
            for (k, r) in chunks[b].lock().iter_mut().enumerate() {
                let mut x = Slot::at(b * ROOT_BLOCK + k);
                while parent[x.index()] != x {
                    x = parent[x.index()];
                }
                *r = x;
            }
        });
    }

    /// Each first-round slot's meeting pairs (as the pair's first sphere),
    /// once a round after the first needs them.
    fn index_meets(&mut self, exec: &dyn Exec, meets: &[(u32, u32)]) {
        debug_assert_eq!(self.meet_slot.len(), meets.len());
        if self.meets_indexed {
            return;
        }
        self.meets_indexed = true;
        let (starts, out) = (&mut self.meet_start, &mut self.meets_of);
        if wide_group(exec, self.first_late, meets.len()) {
            let slots = &self.meet_slot;
            let by_slot = |r: std::ops::Range<usize>| {
                let from = r.start as u32;
                slots[r].iter().map(|s| s.0).zip(from..)
            };
            let buckets = &mut self.ids_buckets;
            group_wide(
                exec,
                buckets,
                starts,
                out,
                self.first_late,
                meets.len(),
                &by_slot,
            );
            return;
        }
        let by_slot = self.meet_slot.iter().map(|s| s.0).zip(0..);
        group(starts, out, self.first_late, by_slot);
    }

    /// Cluster `root` as a run to make: its members in sphere order and its
    /// meeting pairs in detection order (the order the first round has).
    fn push_cluster(&self, root: Slot, meets: &[(u32, u32)], batch: &mut Batch) {
        let (found, ps) = (&mut batch.found, &mut batch.ps);
        found.clear();
        ps.clear();
        let mut s = root;
        loop {
            // Slots of the first round are in sphere order; later ones are
            // not: the ids are sorted below.
            found.push(self.ids[s.index()]);
            // Slots added after the first round own no meeting pairs.
            if s.index() < self.first_late {
                let (a, b) = (self.meet_start[s.index()], self.meet_start[s.index() + 1]);
                ps.extend_from_slice(&self.meets_of[a as usize..b as usize]);
            }
            s = self.next[s.index()];
            if s == root {
                break;
            }
        }
        found.sort_unstable();
        ps.sort_unstable();
        let (m0, p0) = (batch.order.len() as u32, batch.pairs.len() as u32);
        batch.order.extend_from_slice(found);
        batch.pairs.extend(ps.iter().map(|&p| meets[p as usize]));
        batch.todo.push(Todo {
            m0,
            m1: batch.order.len() as u32,
            p0,
            p1: batch.pairs.len() as u32,
        });
    }

    /// The clusters marked dirty since the last partition, each with its
    /// members in sphere order and its meeting pairs in detection order
    /// (as the first round has them), in order of their roots.
    fn partition_dirty(&mut self, exec: &dyn Exec, meets: &[(u32, u32)], batch: &mut Batch) {
        self.index_meets(exec, meets);
        let mut roots = std::mem::take(&mut self.dirty_roots);
        for r in &mut roots {
            *r = self.find(*r);
        }
        roots.sort_unstable();
        roots.dedup();
        roots.retain(|&r| self.dirty[r.index()]);
        for &root in &roots {
            self.push_cluster(root, meets, batch);
        }
        roots.clear();
        self.dirty_roots = roots;
    }
}
