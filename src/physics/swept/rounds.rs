//! The contact events of a step, cut into clusters that run side by side.
//!
//! The spheres with an event (a pair that meets, or a wall) are grouped:
//! pairs that meet, and pairs of such spheres whose balls for the step
//! overlap, end up in one cluster. Each cluster runs the serial event loop
//! on its own (`cluster::Run`), on any lane; a sphere with no events that a
//! run meets joins that run. Spheres of two clusters whose balls met after
//! all (a member's ball grew into the other's as its path turned) are only
//! noted. Once every run of a round is done, the paths decide, turn by turn,
//! whether such pairs really come within touching distance (with a margin
//! far above rounding), and so do all balls that meet where one sphere's
//! path turned or was taken in by a run (the others took it to fly
//! straight). Those that do conflict, as do two runs that took in the same
//! sphere: conflicting clusters are merged and run again, until a round
//! ends with no conflict. When rounds go on too long, or merging leaves
//! most spheres to run again, or over 30 % of the spheres have events from
//! the start (clusters percolate), everything runs as one cluster: the
//! plain serial event loop. One lane runs clusters too: small event queues
//! and rescans that check a few members directly cost less than one queue
//! for the whole step.
//!
//! The result is the serial loop's, bit for bit, however the clusters fall
//! and whatever runs them: clusters that cannot touch each other have no
//! events in common, events within one are taken in the same order (ties by
//! sphere id), and totals are summed in a fixed order.
use super::cluster::{Coarse, Kink, Member, Run, Shared};
use super::{NONE, path_ball};
use crate::physics::broad::Grid;
use crate::physics::exec::{Exec, Serial, next_blocks};
use crate::physics::sphere::Sphere;
use glam::DVec3;
use parking_lot::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Fewer grown balls than this are compared on one lane.
const LANES_MIN_BALLS: usize = 2048;
/// Fewer spheres with events than this run their clusters on one lane.
const LANES_MIN_MEMBERS: usize = 512;
/// Clusters per parallel block.
const CLUSTER_BLOCK: usize = 16;
/// Rounds run in parallel before the rest run as one absorbing cluster.
const PARALLEL_ROUNDS: usize = 8;

/// What one block of clusters left.
#[derive(Default)]
struct BlockOut {
    /// Finished clusters: (why capped, how many of `members` are theirs,
    /// the work the run did).
    done: Vec<(Option<Coarse>, u32, u64)>,
    members: Vec<Member>,
    /// The members' turns (`Member::kink0` indexes here).
    kinks: Vec<Kink>,
    /// Finished runs' (member, member of another cluster) to compare.
    cross: Vec<(u32, u32)>,
}

/// How a step's events were cut, for benches and tests (for a step cut
/// into parts, summed over them; `rounds` the most any part took).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RoundStats {
    /// Clusters of the first round.
    pub clusters: usize,
    pub rounds: usize,
    /// Cluster runs after the first round.
    pub reruns: usize,
    /// Spheres with events.
    pub involved: usize,
    /// Pairs in different clusters whose paths were compared, and how many
    /// of those were found apart (no rerun needed).
    pub compared: usize,
    pub apart: usize,
}

impl RoundStats {
    /// Takes in the stats of another part of the same step.
    pub fn add(&mut self, o: &RoundStats) {
        self.clusters += o.clusters;
        self.rounds = self.rounds.max(o.rounds);
        self.reruns += o.reruns;
        self.involved += o.involved;
        self.compared += o.compared;
        self.apart += o.apart;
    }
}

/// A cluster to run: members `order[m0..m1]`, meeting pairs
/// `pairs[p0..p1]`.
#[derive(Clone, Copy)]
struct Todo {
    m0: u32,
    m1: u32,
    p0: u32,
    p1: u32,
}

#[derive(Default)]
pub(super) struct Rounds {
    /// Sphere id → slot among the involved, NONE for the rest.
    slot: Vec<u32>,
    /// Slot → sphere id.
    ids: Vec<u32>,
    /// Slots from here on were added after the first round.
    first_late: usize,
    parent: Vec<u32>,
    /// Each cluster's slots as a cycle (`next` of the last is the first),
    /// so a merged cluster's members are found without scanning everyone.
    next: Vec<u32>,
    /// Roots marked dirty since the last partition (some merged since).
    dirty_roots: Vec<u32>,
    /// By slot: where its meeting pairs (as the pair's first sphere) start
    /// in `meets_of`, indices into the step's `meets`.
    meet_start: Vec<u32>,
    meets_of: Vec<u32>,
    /// By meeting pair: the slot of its first sphere.
    meet_slot: Vec<u32>,
    /// By slot of the first round: where its partners among the step's
    /// pairs (meeting or near) start in `partners`.
    partner_start: Vec<u32>,
    partners: Vec<u32>,
    /// Set by `merge_all`: the next partition is one cluster of everyone.
    whole: bool,
    /// Scratch for one cluster's members and pairs.
    found: Vec<u32>,
    ps: Vec<u32>,
    /// By root slot: the cluster must run (again).
    dirty: Vec<bool>,
    /// By slot: the member's result from its cluster's last finished run.
    out: Vec<Option<Member>>,
    capped: Vec<Option<Coarse>>,
    /// Slot → root slot, fixed during a round (the cluster's name).
    cluster_of: Vec<u32>,
    order: Vec<u32>,
    pairs: Vec<(u32, u32)>,
    todo: Vec<Todo>,
    /// One run's scratch per lane, one output per block.
    runs: Vec<Mutex<Run>>,
    outs: Vec<Mutex<BlockOut>>,
    conflicts: Vec<(u32, u32)>,
    /// Every finished member's turns (`Member::kink0` indexes here).
    paths: Vec<Kink>,
    /// (sphere, sphere of another cluster) whose paths must be compared,
    /// from the standing runs; by slot, the round each one's run stands from.
    cross: Vec<(u32, u32)>,
    ran: Vec<u32>,
    /// The slots in sphere order, for [`Rounds::results`], and scratch for
    /// the late ones.
    in_order: Vec<u32>,
    late: Vec<u32>,
    /// Every slot's ball for the step, and a grid to find which meet.
    balls: Vec<Sphere>,
    overlap: Grid,
    overlap_pairs: Vec<(u32, u32)>,
    pub stats: RoundStats,
    /// Work (see `Run::work`) done by the last `run`'s cluster runs.
    pub work: u64,
    /// Run every step as one absorbing cluster (the plain serial loop),
    /// whatever the lanes.
    pub serial_only: bool,
}

impl Rounds {
    /// The results of the last `run`: every sphere that had events, with
    /// its run's end of the step and whether (and why) the run was capped,
    /// in sphere order (so totals summed in this order are the serial
    /// loop's to the bit, however the clusters fell).
    pub fn results(&self) -> impl Iterator<Item = (&Member, Option<Coarse>)> {
        self.in_order.iter().map(|&s| {
            let s = s as usize;
            let m = self.out[s].as_ref();
            (m.expect("every involved sphere finished"), self.capped[s])
        })
    }

    /// Runs the events of a step: `meets` are the pairs whose straight paths
    /// meet within `dt`, `near` pairs whose balls overlap but do not meet,
    /// `hits` the spheres that reach a wall. Each involved sphere's end of
    /// the step is then among [`Rounds::results`]; `spheres` is not changed.
    /// The runs may do `budget` work in all, each round's split over its
    /// runs by their members (so not by lanes); [`Rounds::work`] says how
    /// much they did.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        exec: &dyn Exec,
        spheres: &[Sphere],
        grid: &Grid,
        size: f64,
        dt: f64,
        meets: &[(u32, u32)],
        near: &[(u32, u32)],
        hits: &[u32],
        budget: u64,
    ) {
        self.work = 0;
        let serial = self.start(spheres.len(), meets, near, hits);
        let mut round = 0;
        loop {
            let mut absorb = serial || round >= PARALLEL_ROUNDS;
            if absorb {
                self.merge_all();
            }
            self.partition(meets);
            // Merges that leave most spheres to run again mean the clusters
            // percolate (dense scenes): one serial run beats more rounds.
            if !absorb && round > 0 && 2 * self.order.len() > self.ids.len() {
                absorb = true;
                self.merge_all();
                self.partition(meets);
            }
            if self.todo.is_empty() {
                break;
            }
            self.stats.rounds += 1;
            if round == 0 {
                self.stats.clusters = self.todo.len();
            } else {
                self.stats.reruns += self.todo.len();
            }
            // A few events are not worth waking other threads for.
            let lanes: &dyn Exec = if absorb || self.order.len() < LANES_MIN_MEMBERS {
                &Serial
            } else {
                exec
            };
            self.reserve(lanes);
            let sh = Shared {
                spheres,
                grid,
                slot: &self.slot,
                partner_start: &self.partner_start,
                partners: &self.partners,
                size,
                dt,
                // A round's runs start with at most every slot between them.
                work_per_member: budget.saturating_sub(self.work) / self.ids.len().max(1) as u64,
            };
            self.run_clusters(lanes, &sh, absorb);
            self.collect();
            // One run held everyone with events: nobody is left to meet.
            if absorb {
                break;
            }
            // Paths are compared once the runs agree, not every round; the
            // grown balls (a grid over all of them) once the noted pairs agree.
            if self.conflicts.is_empty() {
                self.check_cross(spheres, dt);
            }
            if self.conflicts.is_empty() {
                self.check_grown(exec, spheres, size, dt);
            }
            if self.conflicts.is_empty() {
                break;
            }
            self.merge_conflicts();
            round += 1;
        }
        self.order_results();
    }

    /// The slots in sphere order: the first round's already are; the ones
    /// runs took in later are merged in.
    fn order_results(&mut self) {
        let (m, first) = (self.ids.len(), self.first_late);
        self.in_order.clear();
        let ids = &self.ids;
        let mut late = std::mem::take(&mut self.late);
        late.clear();
        late.extend(first as u32..m as u32);
        late.sort_unstable_by_key(|&s| ids[s as usize]);
        let mut early = (0..first as u32).peekable();
        for &l in &late {
            while let Some(e) = early.next_if(|&e| ids[e as usize] < ids[l as usize]) {
                self.in_order.push(e);
            }
            self.in_order.push(l);
        }
        self.in_order.extend(early);
        self.late = late;
    }

    /// Slots for the spheres with events and their first clusters; true
    /// when the step runs as one serial loop.
    fn start(&mut self, n: usize, meets: &[(u32, u32)], near: &[(u32, u32)], hits: &[u32]) -> bool {
        for &i in &self.ids {
            self.slot[i as usize] = NONE;
        }
        self.slot.resize(n, NONE);
        self.ids.clear();
        // Marked, then read off in order: one pass over the spheres costs
        // less than sorting the tens of thousands of ends of the pairs.
        for &(i, j) in meets {
            self.slot[i as usize] = 0;
            self.slot[j as usize] = 0;
        }
        for &i in hits {
            self.slot[i as usize] = 0;
        }
        for (i, slot) in self.slot.iter_mut().enumerate() {
            if *slot != NONE {
                *slot = self.ids.len() as u32;
                self.ids.push(i as u32);
            }
        }
        self.meet_slot.clear();
        self.meet_slot
            .extend(meets.iter().map(|&(i, _)| self.slot[i as usize]));
        let m = self.ids.len();
        self.first_late = m;
        self.parent.clear();
        self.parent.extend(0..m as u32);
        self.next.clear();
        self.next.extend(0..m as u32);
        self.dirty_roots.clear();
        self.dirty.clear();
        self.dirty.resize(m, true);
        self.out.clear();
        self.out.resize(m, None);
        self.capped.clear();
        self.capped.resize(m, None);
        self.ran.clear();
        self.ran.resize(m, NONE);
        self.paths.clear();
        self.cross.clear();
        self.stats = RoundStats {
            involved: m,
            ..RoundStats::default()
        };
        // When a large share of the spheres have events, clusters percolate
        // into one as they merge (measured: beyond ~30 %, at packing 0.05 and
        // up at N = 100 000, rounds cost more than one serial run).
        let serial = self.serial_only || 10 * m > 3 * n;
        if serial {
            // One cluster: every slot's parent is slot 0. No rescan looks
            // up partners (the one run searches the grid).
            self.partner_start.clear();
            self.merge_all();
            return true;
        }
        for &(i, j) in meets {
            self.union(self.slot[i as usize], self.slot[j as usize]);
        }
        for &(i, j) in near {
            let (a, b) = (self.slot[i as usize], self.slot[j as usize]);
            if a != NONE && b != NONE {
                self.union(a, b);
            }
        }
        self.index_partners(meets, near);
        false
    }

    /// Each first-round slot's partners among the pairs the grid found
    /// (counting sort by slot): a rescan whose ball lies inside the
    /// sphere's binned one finds everyone it can meet among them.
    fn index_partners(&mut self, meets: &[(u32, u32)], near: &[(u32, u32)]) {
        let slot = &self.slot;
        let ends = meets
            .iter()
            .chain(near)
            .flat_map(|&(i, j)| [(i, j), (j, i)]);
        let by_slot = ends.filter_map(|(k, other)| {
            let a = slot[k as usize];
            (a != NONE).then_some((a, other))
        });
        group(
            &mut self.partner_start,
            &mut self.partners,
            self.ids.len(),
            by_slot,
        );
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }

    /// Joins two slots' clusters; the joined cluster must run again.
    fn union(&mut self, a: u32, b: u32) {
        let lo = self.link(a, b);
        self.dirty[lo as usize] = true;
        self.dirty_roots.push(lo);
    }

    /// Joins two slots' clusters under the lower root, which it returns.
    fn link(&mut self, a: u32, b: u32) -> u32 {
        let (ra, rb) = (self.find(a), self.find(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        if lo != hi {
            self.parent[hi as usize] = lo;
            // Splicing two cycles is swapping one successor of each.
            self.next.swap(lo as usize, hi as usize);
        }
        lo
    }

    fn add_slot(&mut self, id: u32) -> u32 {
        let k = self.ids.len() as u32;
        self.slot[id as usize] = k;
        self.ids.push(id);
        self.parent.push(k);
        self.next.push(k);
        self.dirty.push(true);
        self.dirty_roots.push(k);
        self.out.push(None);
        self.capped.push(None);
        self.ran.push(NONE);
        k
    }

    /// Every cluster, finished or not, as one: the plain serial loop over
    /// all the spheres with events, which no outsider with events can
    /// touch, so it finishes in one run.
    fn merge_all(&mut self) {
        let m = self.ids.len();
        for s in 0..m {
            self.parent[s] = 0;
            self.next[s] = ((s + 1) % m) as u32;
        }
        if m > 0 {
            self.dirty[0] = true;
            self.dirty_roots.push(0);
        }
        self.whole = true;
    }

    /// This round's clusters (named by root slot) and the ones that must
    /// run, with their members and meeting pairs: every cluster in the
    /// first round, only those marked dirty later, each found by walking
    /// its cycle.
    fn partition(&mut self, meets: &[(u32, u32)]) {
        self.todo.clear();
        if self.whole {
            self.partition_whole(meets);
        } else if self.stats.rounds == 0 {
            self.partition_all(meets);
        } else {
            self.partition_dirty(meets);
        }
    }

    /// Everyone in one cluster (after `merge_all`): the members are the
    /// slots in sphere order and the pairs all of them, as detected.
    fn partition_whole(&mut self, meets: &[(u32, u32)]) {
        self.whole = false;
        self.dirty_roots.clear();
        let m = self.ids.len();
        self.cluster_of.clear();
        self.cluster_of.resize(m, 0);
        self.order.clear();
        self.order.extend_from_slice(&self.ids);
        if m > self.first_late {
            // Slots added after the first round are not in sphere order.
            self.order.sort_unstable();
        }
        self.pairs.clear();
        self.pairs.extend_from_slice(meets);
        if m > 0 {
            self.todo.push(Todo {
                m0: 0,
                m1: m as u32,
                p0: 0,
                p1: meets.len() as u32,
            });
        }
    }

    fn partition_all(&mut self, meets: &[(u32, u32)]) {
        self.dirty_roots.clear();
        self.index_meets(meets);
        self.cluster_of.resize(self.ids.len(), NONE);
        self.order.clear();
        self.pairs.clear();
        // Every cluster, by root (a root is its own parent), walked round
        // its cycle.
        for root in 0..self.ids.len() as u32 {
            if self.parent[root as usize] == root {
                self.push_cluster(root, meets);
            }
        }
    }

    /// Each first-round slot's meeting pairs (as the pair's first sphere).
    fn index_meets(&mut self, meets: &[(u32, u32)]) {
        debug_assert_eq!(self.meet_slot.len(), meets.len());
        let by_slot = self.meet_slot.iter().copied().zip(0..);
        group(
            &mut self.meet_start,
            &mut self.meets_of,
            self.first_late,
            by_slot,
        );
    }

    /// Cluster `root` as a run to make: its members in sphere order and its
    /// meeting pairs in detection order (the order the first round has).
    fn push_cluster(&mut self, root: u32, meets: &[(u32, u32)]) {
        let (mut found, mut ps) = (
            std::mem::take(&mut self.found),
            std::mem::take(&mut self.ps),
        );
        found.clear();
        ps.clear();
        let mut s = root;
        loop {
            found.push(s);
            self.cluster_of[s as usize] = root;
            // Slots added after the first round own no meeting pairs.
            if (s as usize) < self.first_late {
                let (a, b) = (self.meet_start[s as usize], self.meet_start[s as usize + 1]);
                ps.extend_from_slice(&self.meets_of[a as usize..b as usize]);
            }
            s = self.next[s as usize];
            if s == root {
                break;
            }
        }
        // Slots of the first round are in sphere order; later ones are not.
        for s in &mut found {
            *s = self.ids[*s as usize];
        }
        found.sort_unstable();
        ps.sort_unstable();
        let (m0, p0) = (self.order.len() as u32, self.pairs.len() as u32);
        self.order.extend_from_slice(&found);
        self.pairs.extend(ps.iter().map(|&p| meets[p as usize]));
        self.todo.push(Todo {
            m0,
            m1: self.order.len() as u32,
            p0,
            p1: self.pairs.len() as u32,
        });
        (self.found, self.ps) = (found, ps);
    }

    /// The clusters marked dirty since the last partition, each with its
    /// members in sphere order and its meeting pairs in detection order
    /// (as the first round has them), in order of their roots.
    fn partition_dirty(&mut self, meets: &[(u32, u32)]) {
        let mut roots = std::mem::take(&mut self.dirty_roots);
        for r in &mut roots {
            *r = self.find(*r);
        }
        roots.sort_unstable();
        roots.dedup();
        roots.retain(|&r| self.dirty[r as usize]);
        self.cluster_of.resize(self.ids.len(), NONE);
        self.order.clear();
        self.pairs.clear();
        for &root in &roots {
            self.push_cluster(root, meets);
        }
        roots.clear();
        self.dirty_roots = roots;
    }

    /// Scratch for `run_clusters` on `exec`.
    fn reserve(&mut self, exec: &dyn Exec) {
        let blocks = self.todo.len().div_ceil(CLUSTER_BLOCK);
        while self.runs.len() < exec.lanes() {
            self.runs.push(Mutex::new(Run::default()));
        }
        while self.outs.len() < blocks {
            self.outs.push(Mutex::new(BlockOut::default()));
        }
    }

    fn run_clusters(&self, exec: &dyn Exec, sh: &Shared, absorb: bool) {
        let blocks = self.todo.len().div_ceil(CLUSTER_BLOCK);
        let lanes = exec.lanes().clamp(1, blocks.max(1));
        let (runs, outs, todo) = (&self.runs, &self.outs, &self.todo);
        let (order, pairs) = (&self.order, &self.pairs);
        let next = AtomicUsize::new(0);
        exec.for_each_lane(&|lane| {
            if lane >= lanes {
                return;
            }
            let mut run = runs[lane].lock();
            for b in next_blocks(&next, blocks) {
                let mut out = outs[b].lock();
                out.done.clear();
                out.members.clear();
                out.kinks.clear();
                out.cross.clear();
                let end = ((b + 1) * CLUSTER_BLOCK).min(todo.len());
                for t in &todo[b * CLUSTER_BLOCK..end] {
                    let members = &order[t.m0 as usize..t.m1 as usize];
                    let cp = &pairs[t.p0 as usize..t.p1 as usize];
                    run.run(sh, members, cp, absorb);
                    let before = out.members.len();
                    let base = out.kinks.len() as u32;
                    out.kinks.extend_from_slice(run.kinks());
                    out.members.extend(run.members().map(|mut m| {
                        m.kink0 += base;
                        m
                    }));
                    out.cross.extend_from_slice(&run.cross);
                    let len = (out.members.len() - before) as u32;
                    out.done.push((run.capped, len, run.work));
                }
            }
        });
    }

    /// Results of the runs just made: finished clusters' members go to
    /// their slots; conflicts are kept for merging.
    fn collect(&mut self) {
        self.conflicts.clear();
        let round = self.stats.rounds as u32;
        // Slots from here on are spheres runs took in this round.
        let known = self.ids.len();
        let mut cross = std::mem::take(&mut self.cross);
        let fresh = cross.len();
        let outs = std::mem::take(&mut self.outs);
        for block in &outs[..self.todo.len().div_ceil(CLUSTER_BLOCK)] {
            let out = block.lock();
            let mut k = 0usize;
            for &(capped, len, work) in &out.done {
                self.work += work;
                let members = &out.members[k..k + len as usize];
                k += len as usize;
                // Spheres a run took in are its members now.
                let mut root = NONE;
                let mut twice = false;
                for m in members {
                    // The run read the slot when it began; one it took in
                    // may have got one from an earlier run of this round.
                    let s = match m.slot {
                        NONE => match self.slot[m.id as usize] {
                            NONE => self.add_slot(m.id),
                            s => s,
                        },
                        s => s,
                    };
                    // Taken in by an earlier run of this round too: the two
                    // runs join (below) and run again.
                    twice |= s as usize >= known && self.ran[s as usize] == round;
                    let turns = &out.kinks[m.kink0 as usize..(m.kink0 + m.kinks) as usize];
                    let kink0 = self.paths.len() as u32;
                    self.paths.extend_from_slice(turns);
                    self.out[s as usize] = Some(Member { kink0, ..*m });
                    self.capped[s as usize] = capped;
                    self.ran[s as usize] = round;
                    root = if root == NONE {
                        self.find(s)
                    } else {
                        self.link(root, s)
                    };
                }
                if twice {
                    self.union(root, root);
                    let first = members[0].id;
                    self.conflicts.push((first, first));
                } else {
                    self.dirty[root as usize] = false;
                }
            }
            cross.extend_from_slice(&out.cross);
        }
        self.outs = outs;
        // What a rerun cluster noted before is replaced by what it noted now.
        let (slot, ran) = (&self.slot, &self.ran);
        let mut k = 0;
        cross.retain(|&(a, _)| {
            k += 1;
            k > fresh || ran[slot[a as usize] as usize] != round
        });
        self.cross = cross;
    }

    /// Pairs of spheres in different clusters whose balls met during a run
    /// conflict if their paths really come within touching distance.
    fn check_cross(&mut self, spheres: &[Sphere], dt: f64) {
        for k in 0..self.cross.len() {
            let (a, b) = self.cross[k];
            let (sa, sb) = (self.slot[a as usize], self.slot[b as usize]);
            if self.find(sa) != self.find(sb) {
                self.compare(sa, sb, spheres, dt);
            }
        }
    }

    /// Slots `a` and `b` (different clusters) conflict if their paths meet.
    fn compare(&mut self, a: u32, b: u32, spheres: &[Sphere], dt: f64) {
        self.stats.compared += 1;
        if self.view(spheres, dt).meet(a as usize, b as usize) {
            self.conflicts
                .push((self.ids[a as usize], self.ids[b as usize]));
        } else {
            self.stats.apart += 1;
        }
    }

    fn view<'a>(&'a self, spheres: &'a [Sphere], dt: f64) -> Paths<'a> {
        Paths {
            out: &self.out,
            capped: &self.capped,
            turns: &self.paths,
            spheres,
            dt,
        }
    }

    /// A finished cluster whose member's ball grew was checked against the
    /// balls the grid holds, of spheres that had events then. Two such
    /// grown balls, or any ball and that of a sphere a run took in (which
    /// other runs took to fly straight), may meet where no run could see
    /// it: such pairs in different clusters are compared by their paths.
    fn check_grown(&mut self, exec: &dyn Exec, spheres: &[Sphere], size: f64, dt: f64) {
        let any_changed =
            self.ids.len() > self.first_late || self.out.iter().any(|m| m.is_some_and(|m| m.grew));
        if !any_changed || self.ids.len() < 2 {
            return;
        }
        // Every slot's ball, indexed by slot.
        self.balls.clear();
        for s in 0..self.ids.len() {
            let (centre, reach) = self.ball(s, spheres, dt);
            self.balls.push(Sphere {
                pos: centre,
                vel: DVec3::ZERO,
                radius: reach,
                mass: 0.0,
            });
        }
        // The absorbing round joins clusters: name them afresh.
        self.cluster_of.resize(self.ids.len(), NONE);
        for s in 0..self.ids.len() as u32 {
            let r = self.find(s);
            self.cluster_of[s as usize] = r;
        }
        self.overlap.build(
            &self.balls,
            size,
            |b| (b.pos, b.radius),
            small(exec, self.balls.len()),
        );
        let mut pairs = std::mem::take(&mut self.overlap_pairs);
        let (out, cluster_of) = (&self.out, &self.cluster_of);
        let paths = Paths {
            out,
            capped: &self.capped,
            turns: &self.paths,
            spheres,
            dt,
        };
        let compared = AtomicUsize::new(0);
        let first_late = self.first_late;
        let changed = |s: usize| s >= first_late || out[s].is_some_and(|m| m.grew);
        // The paths are compared in the pair search, on its lanes.
        let meet = |a: u32, b: u32| {
            let (sa, sb) = (a as usize, b as usize);
            if !(changed(sa) || changed(sb)) || cluster_of[sa] == cluster_of[sb] {
                return false;
            }
            compared.fetch_add(1, Ordering::Relaxed);
            paths.meet(sa, sb)
        };
        self.overlap
            .pairs(small(exec, self.balls.len()), &meet, &mut pairs);
        let compared = compared.into_inner();
        self.stats.compared += compared;
        self.stats.apart += compared - pairs.len();
        for &(a, b) in &pairs {
            self.conflicts
                .push((self.ids[a as usize], self.ids[b as usize]));
        }
        self.overlap_pairs = pairs;
    }

    /// The ball slot `s`'s path stays in: from its last finished run, or
    /// its straight path.
    fn ball(&self, s: usize, spheres: &[Sphere], dt: f64) -> (DVec3, f64) {
        match &self.out[s] {
            Some(m) => (m.centre, m.reach),
            None => path_ball(&spheres[self.ids[s] as usize], dt),
        }
    }

    fn merge_conflicts(&mut self) {
        let conflicts = std::mem::take(&mut self.conflicts);
        for &(a, j) in &conflicts {
            let sj = match self.slot[j as usize] {
                NONE => self.add_slot(j),
                s => s,
            };
            self.union(self.slot[a as usize], sj);
        }
        self.conflicts = conflicts;
    }
}

/// The paths the finished runs took, by slot.
struct Paths<'a> {
    out: &'a [Option<Member>],
    capped: &'a [Option<Coarse>],
    turns: &'a [Kink],
    spheres: &'a [Sphere],
    dt: f64,
}

impl Paths<'_> {
    /// Whether the spheres of slots `a` and `b` come within touching
    /// distance during the step. A capped run's path is not fully known: it
    /// meets everyone.
    fn meet(&self, a: usize, b: usize) -> bool {
        if self.capped[a].is_some() || self.capped[b].is_some() {
            return true;
        }
        let path = |s: usize| {
            let m = self.out[s].expect("a finished run's member");
            let turns = &self.turns[m.kink0 as usize..(m.kink0 + m.kinks) as usize];
            (&self.spheres[m.id as usize], turns)
        };
        let ((sa, ta), (sb, tb)) = (path(a), path(b));
        paths_meet(sa, ta, sb, tb, self.dt)
    }
}

/// Relative margin on the touching distance when comparing two paths: far
/// above the rounding of positions (about 1e-16 of the box), so a pair the
/// serial loop would see touch is never passed as apart.
const PATH_MARGIN: f64 = 1e-8;

/// Whether two spheres, from `a` and `b` at the start of the step and
/// turning as `ta` and `tb` say (time order), come within the sum of their
/// radii (widened by [`PATH_MARGIN`]) at one moment of `0..=dt`: on each
/// stretch where both fly straight, the closest approach of the two lines.
fn paths_meet(a: &Sphere, ta: &[Kink], b: &Sphere, tb: &[Kink], dt: f64) -> bool {
    let sigma = (a.radius + b.radius) * (1.0 + PATH_MARGIN);
    let start = |s: &Sphere| Kink {
        t: 0.0,
        pos: s.pos,
        vel: s.vel,
    };
    let (mut ka, mut kb) = (start(a), start(b));
    let (mut ia, mut ib) = (0, 0);
    let mut t0 = 0.0;
    loop {
        let next = |turns: &[Kink], i: usize| turns.get(i).map_or(dt, |k| k.t.min(dt));
        let t1 = next(ta, ia).min(next(tb, ib));
        let dp = (ka.pos + ka.vel * (t0 - ka.t)) - (kb.pos + kb.vel * (t0 - kb.t));
        let dv = ka.vel - kb.vel;
        let vv = dv.length_squared();
        let s = if vv > 0.0 {
            (-dp.dot(dv) / vv).clamp(0.0, t1 - t0)
        } else {
            0.0
        };
        if (dp + dv * s).length_squared() <= sigma * sigma {
            return true;
        }
        if t1 >= dt {
            return false;
        }
        while ia < ta.len() && ta[ia].t <= t1 {
            ka = ta[ia];
            ia += 1;
        }
        while ib < tb.len() && tb[ib].t <= t1 {
            kb = tb[ib];
            ib += 1;
        }
        t0 = t1;
    }
}

/// Groups `items` by key in `0..keys`, keeping their order within a key:
/// `out[starts[k]..starts[k + 1]]` are the items of key `k`.
fn group<T: Copy + Default>(
    starts: &mut Vec<u32>,
    out: &mut Vec<T>,
    keys: usize,
    items: impl Iterator<Item = (u32, T)> + Clone,
) {
    starts.clear();
    starts.resize(keys + 1, 0);
    for (k, _) in items.clone() {
        starts[k as usize + 1] += 1;
    }
    for k in 0..keys {
        starts[k + 1] += starts[k];
    }
    out.clear();
    out.resize(starts[keys] as usize, T::default());
    for (k, v) in items {
        let at = &mut starts[k as usize];
        out[*at as usize] = v;
        *at += 1;
    }
    // Placing moved each start to the next key's; shift back.
    for k in (1..=keys).rev() {
        starts[k] = starts[k - 1];
    }
    starts[0] = 0;
}

/// `exec`, or the calling thread when `n` items are too few to be worth
/// handing to other threads (each hand-off costs tens of microseconds).
fn small(exec: &dyn Exec, n: usize) -> &dyn Exec {
    if n < LANES_MIN_BALLS { &Serial } else { exec }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(pos: [f64; 3], vel: [f64; 3]) -> Sphere {
        Sphere {
            pos: DVec3::from(pos),
            vel: DVec3::from(vel),
            radius: 0.1,
            mass: 1.0,
        }
    }

    fn turn(t: f64, pos: [f64; 3], vel: [f64; 3]) -> Kink {
        Kink {
            t,
            pos: DVec3::from(pos),
            vel: DVec3::from(vel),
        }
    }

    #[test]
    fn crossing_lines_meet_only_at_the_same_time() {
        // Both pass through the origin: at t = 1 together, or a second apart.
        let a = sphere([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let together = sphere([0.0, -1.0, 0.0], [0.0, 1.0, 0.0]);
        let late = sphere([0.0, -2.0, 0.0], [0.0, 1.0, 0.0]);
        assert!(paths_meet(&a, &[], &together, &[], 2.0));
        assert!(!paths_meet(&a, &[], &late, &[], 2.0));
        // Closest approach after the step ends does not count.
        assert!(!paths_meet(&a, &[], &together, &[], 0.5));
        // Just outside and just inside touching distance (0.2).
        let by = |gap: f64| sphere([0.0, gap, 0.0], [1.0, 0.0, 0.0]);
        let still = sphere([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(!paths_meet(&still, &[], &by(0.2 * (1.0 + 1e-6)), &[], 1.0));
        assert!(paths_meet(&still, &[], &by(0.2 * (1.0 - 1e-6)), &[], 1.0));
    }

    #[test]
    fn a_turn_decides_whether_paths_meet() {
        // `b` waits at (0, 1, 0). `a` heads along x; turned up at t = 1 (at
        // the origin) it touches `b` at t = 1.8; turned down it never does,
        // and straight it passes 1 away.
        let a = sphere([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let b = sphere([0.0, 1.0, 0.0], [0.0, 0.0, 0.0]);
        let up = [turn(1.0, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])];
        let down = [turn(1.0, [0.0, 0.0, 0.0], [0.0, -1.0, 0.0])];
        assert!(!paths_meet(&a, &[], &b, &[], 3.0));
        assert!(paths_meet(&a, &up, &b, &[], 3.0));
        assert!(paths_meet(&b, &[], &a, &up, 3.0), "either order");
        assert!(!paths_meet(&a, &down, &b, &[], 3.0));
        // The meeting at t = 1.8 lies past a step of 1.5.
        assert!(!paths_meet(&a, &up, &b, &[], 1.5));
        // Both turn: `b` runs off along +y at t = 0.5 and stays ahead.
        let away = [turn(0.5, [0.0, 1.0, 0.0], [0.0, 2.0, 0.0])];
        assert!(!paths_meet(&a, &up, &b, &away, 3.0));
    }
}
