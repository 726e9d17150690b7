//! The contact events of a step, cut into clusters that run side by side.
//!
//! The spheres with an event (a pair that meets, or a wall) are grouped:
//! pairs that meet, and pairs of such spheres whose balls for the step
//! overlap, end up in one cluster. Each cluster runs the serial event loop
//! on its own (`cluster::Run`), on any lane; a bystander (a sphere with no
//! events) that a run meets joins that run. Spheres of two clusters whose balls met after
//! all (a member's ball grew into the other's as its path turned) are only
//! noted. Once every run of a round is done, the paths decide, turn by turn,
//! whether such pairs really come within touching distance (with a margin
//! far above rounding), and so do all balls that meet where one sphere's
//! path turned or that is a bystander that joined a run (the others took it
//! to fly straight). Those that do conflict, as do two runs that a bystander
//! joined: conflicting clusters are merged and run again, until a round
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
//!
//! Here: the rounds and the runs of each. The clusters themselves are in
//! `partition.rs`, the path comparison and grown balls in `conflicts.rs`.
use super::cluster::{Chunk, Coarse, Member, Run, Shared};
use super::conflicts::{Conflicts, Finished};
use super::partition::{Batch, Partition, Slot};
use super::stats::RoundStats;
use crate::physics::broad::Grid;
use crate::physics::exec::{Exec, PerBlock, Serial, lanes_of, or_serial, work_ns};
use crate::physics::sphere::Sphere;

/// Predicted nanoseconds of running one cluster member through a round
/// (docs/threading.md).
const NS_PER_MEMBER: usize = 800;
/// Clusters per parallel block.
const CLUSTER_BLOCK: usize = 16;
/// Rounds run in parallel before the rest run as one absorbing cluster.
const PARALLEL_ROUNDS: usize = 8;
/// Above this share of the spheres with events from the start, clusters
/// percolate into one as they merge and one serial run is cheaper
/// (docs/benchmarks.md, "tuned constants").
const PERCOLATION: (usize, usize) = (3, 10);

/// What one block of clusters left.
#[derive(Default)]
struct BlockOut {
    /// Finished clusters, in order.
    done: Vec<RunDone>,
    /// Where in the chunk the bystanders that joined the runs are, run
    /// after run (the runs' own members are in `Finished` already).
    joined: Vec<u32>,
    /// Their members and turns, taken whole into `Finished` when collected.
    chunk: Chunk,
    /// Finished runs' (member, member of another cluster) to compare.
    cross: Vec<(u32, u32)>,
}

/// One finished run of a block.
struct RunDone {
    /// Why it was capped, if it was.
    capped: Option<Coarse>,
    /// How many of the chunk's members are its.
    len: u32,
    /// The work it did.
    work: u64,
    /// Where its bystanders end in the block's `joined`.
    joined_end: u32,
    /// A slot of its own cluster (none if it had only bystanders).
    own: Slot,
}

/// The state kept from one round to the next of a step part, and scratch
/// kept to reuse memory.
#[derive(Default)]
pub(super) struct Rounds {
    /// The spheres with events and their clusters.
    part: Partition,
    /// By slot, what its cluster's last finished run left.
    fin: Finished,
    /// The conflicts between clusters, and what finds them.
    conf: Conflicts,
    /// This round's clusters to run.
    batch: Batch,
    /// One run's scratch per lane, one output per block of clusters.
    runs: PerBlock<Run>,
    outs: PerBlock<BlockOut>,
    /// The slots in sphere order, for [`Rounds::result`], and scratch for
    /// the late ones.
    in_order: Vec<Slot>,
    late: Vec<Slot>,
    pub stats: RoundStats,
    /// Work (see `Run::work`) done by the last `run`'s cluster runs.
    pub work: u64,
    /// Run every step as one absorbing cluster (the plain serial loop),
    /// whatever the lanes.
    #[cfg(feature = "experiments")]
    pub serial_only: bool,
}

impl Rounds {
    /// How many spheres had events in the last `run`.
    pub fn involved(&self) -> usize {
        self.in_order.len()
    }

    /// The `k`-th result of the last `run`: of every sphere that had
    /// events, in sphere order (so totals summed in this order are the
    /// serial loop's to the bit, however the clusters fell), its run's end
    /// of the step and whether (and why) the run was capped.
    pub fn result(&self, k: usize) -> (&Member, Option<Coarse>) {
        let s = self.in_order[k].index();
        let Some((m, _)) = self.fin.record(s) else {
            unreachable!("every involved sphere finished");
        };
        (m, self.fin.capped(s))
    }

    /// Runs the events of a step: `meets` are the pairs whose straight paths
    /// meet within `dt`, `near` pairs whose balls overlap but do not meet,
    /// `hits` the spheres that reach a wall. Each involved sphere's end of
    /// the step is then among the results ([`Rounds::result`]); `spheres` is not changed.
    /// The runs may do `budget` work in all, each round's split over its
    /// runs by their members (so not by lanes); [`Rounds::work`] says how
    /// much they did.
    #[allow(clippy::too_many_arguments)] // the step's inputs, each a borrow of a different owner in `Swept::advance`
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
        let serial = self.start(exec, spheres.len(), meets, near, hits);
        let mut round = 0;
        loop {
            let mut absorb = serial || round >= PARALLEL_ROUNDS;
            if absorb {
                self.part.merge_all();
                self.fin.forget();
            }
            let first = self.stats.rounds == 0;
            self.part.partition(exec, meets, first, &mut self.batch);
            // Merges that leave most spheres to run again mean the clusters
            // percolate (dense scenes): one serial run beats more rounds.
            if !absorb && round > 0 && 2 * self.batch.order.len() > self.part.ids.len() {
                absorb = true;
                self.part.merge_all();
                self.fin.forget();
                self.part.partition(exec, meets, first, &mut self.batch);
            }
            if self.batch.todo.is_empty() {
                break;
            }
            self.stats.rounds += 1;
            if round == 0 {
                self.stats.clusters = self.batch.todo.len();
            } else {
                self.stats.reruns += self.batch.todo.len();
            }
            // A few events are not worth waking other threads for.
            let lanes: &dyn Exec = if absorb {
                &Serial
            } else {
                let blocks = self.batch.todo.len().div_ceil(CLUSTER_BLOCK);
                or_serial(exec, blocks, work_ns(self.batch.order.len(), NS_PER_MEMBER))
            };
            self.reserve(lanes);
            let sh = Shared {
                spheres,
                grid,
                slot: &self.part.slot,
                partner_start: &self.part.partner_start,
                partners: &self.part.partners,
                size,
                dt,
                // A round's runs start with at most every slot between them.
                work_per_member: budget.saturating_sub(self.work)
                    / self.part.ids.len().max(1) as u64,
            };
            self.run_clusters(lanes, &sh, absorb);
            self.collect();
            // One run held everyone with events: nobody is left to meet.
            if absorb {
                break;
            }
            // Paths are compared once the runs agree, not every round; the
            // grown balls (a grid over all of them) once the noted pairs agree.
            let (part, fin, stats) = (&mut self.part, &self.fin, &mut self.stats);
            if self.conf.found.is_empty() {
                self.conf.check_cross(part, fin, spheres, dt, stats);
            }
            if self.conf.found.is_empty() {
                self.conf
                    .check_grown(exec, part, fin, spheres, size, dt, stats);
            }
            if self.conf.found.is_empty() {
                break;
            }
            self.merge_conflicts();
            round += 1;
        }
        self.order_results();
    }

    /// The slots in sphere order: the first round's already are; the ones
    /// that joined runs later are merged in.
    fn order_results(&mut self) {
        let (m, first) = (self.part.ids.len(), self.part.first_late);
        self.in_order.clear();
        let ids = &self.part.ids;
        let mut late = std::mem::take(&mut self.late);
        late.clear();
        late.extend((first..m).map(Slot::at));
        late.sort_unstable_by_key(|&s| ids[s.index()]);
        let mut early = (0..first).map(Slot::at).peekable();
        for &l in &late {
            while let Some(e) = early.next_if(|&e| ids[e.index()] < ids[l.index()]) {
                self.in_order.push(e);
            }
            self.in_order.push(l);
        }
        self.in_order.extend(early);
        self.late = late;
    }

    /// Slots for the spheres with events and their first clusters; true
    /// when the step runs as one serial loop.
    fn start(
        &mut self,
        exec: &dyn Exec,
        n: usize,
        meets: &[(u32, u32)],
        near: &[(u32, u32)],
        hits: &[u32],
    ) -> bool {
        let m = self.part.start(exec, n, meets, hits);
        self.fin.reset(m);
        self.conf.cross.clear();
        self.stats = RoundStats {
            involved: m,
            ..RoundStats::default()
        };
        #[cfg(feature = "experiments")]
        let forced = self.serial_only;
        #[cfg(not(feature = "experiments"))]
        let forced = false;
        let serial = forced || PERCOLATION.1 * m > PERCOLATION.0 * n;
        if serial {
            self.part.no_partners();
            self.part.merge_all();
            return true;
        }
        self.part.join_pairs(exec, meets, near);
        false
    }

    /// A slot for sphere `id`, a bystander that joined a run or that one
    /// met after the first round.
    fn add_slot(&mut self, id: u32) -> Slot {
        self.fin.push();
        self.part.add(id)
    }

    /// Scratch for `run_clusters` on `exec`.
    fn reserve(&mut self, exec: &dyn Exec) {
        let blocks = self.batch.todo.len().div_ceil(CLUSTER_BLOCK);
        self.runs.ensure(exec.lanes());
        self.outs.ensure(blocks);
    }

    fn run_clusters(&self, exec: &dyn Exec, sh: &Shared, absorb: bool) {
        let blocks = self.batch.todo.len().div_ceil(CLUSTER_BLOCK);
        let (runs, outs, todo) = (&self.runs, &self.outs, &self.batch.todo);
        let (order, pairs) = (&self.batch.order, &self.batch.pairs);
        let lanes = lanes_of(exec, blocks, work_ns(order.len(), NS_PER_MEMBER));
        // Chunks are kept in block order: block `b`'s will be `first + b`.
        let (fin, first, round) = (&self.fin, self.fin.next_chunk(), self.stats.rounds as u32);
        exec.for_blocks(lanes, blocks, &|lane, b| {
            let mut run = runs[lane].lock();
            let mut out = outs[b].lock();
            let out = &mut *out;
            out.done.clear();
            out.joined.clear();
            out.chunk.clear();
            out.cross.clear();
            let end = ((b + 1) * CLUSTER_BLOCK).min(todo.len());
            // The chunk is new (the last went to `Finished`): room for
            // about what its runs write at once, not grown by doubling.
            let members: usize = todo[b * CLUSTER_BLOCK..end]
                .iter()
                .map(|t| (t.m1 - t.m0) as usize)
                .sum();
            out.chunk.members.reserve_exact(members + members / 8);
            out.chunk.turns.reserve_exact(2 * members);
            for t in &todo[b * CLUSTER_BLOCK..end] {
                let members = &order[t.m0 as usize..t.m1 as usize];
                let cp = &pairs[t.p0 as usize..t.p1 as usize];
                run.run(sh, members, cp, absorb);
                let before = out.chunk.members.len();
                run.emit(&mut out.chunk);
                out.cross.extend_from_slice(&run.cross);
                let own = set_own(
                    fin,
                    run.slots(),
                    out,
                    before,
                    first + b as u32,
                    (run.capped, round),
                );
                out.done.push(RunDone {
                    capped: run.capped,
                    len: (out.chunk.members.len() - before) as u32,
                    work: run.work,
                    joined_end: out.joined.len() as u32,
                    own,
                });
            }
            // Kept at its size (room was reserved by estimate): the copy is
            // made here, on the block's lane, not where the chunks are taken.
            out.chunk.members.shrink_to_fit();
            out.chunk.turns.shrink_to_fit();
        });
    }

    /// Results of the runs just made: finished clusters' members go to
    /// their slots; conflicts are kept for merging.
    fn collect(&mut self) {
        self.conf.found.clear();
        let round = self.stats.rounds as u32;
        // Slots from here on are bystanders that joined runs this round.
        let known = self.part.ids.len();
        let mut cross = std::mem::take(&mut self.conf.cross);
        let fresh = cross.len();
        let mut outs = std::mem::take(&mut self.outs);
        for block in &mut outs[..self.batch.todo.len().div_ceil(CLUSTER_BLOCK)] {
            let out = block.get_mut();
            let chunk = std::mem::take(&mut out.chunk);
            let c = self.fin.keep(chunk);
            let (mut k, mut j) = (0usize, 0usize);
            for r in &out.done {
                self.work += r.work;
                let joined = &out.joined[j..r.joined_end as usize];
                self.take_run(c, k, joined, r, known);
                (k, j) = (k + r.len as usize, r.joined_end as usize);
            }
            cross.extend_from_slice(&out.cross);
        }
        self.outs = outs;
        // What a rerun cluster noted before is replaced by what it noted now.
        let (slot, fin) = (&self.part.slot, &self.fin);
        let mut k = 0;
        cross.retain(|&(a, _)| {
            k += 1;
            k > fresh || fin.ran(slot[a as usize].index()) != round
        });
        self.conf.cross = cross;
    }

    /// One finished run `r` of this round, its members from `k0` on in
    /// chunk `c` (of `Finished`), its own members' records set already (a
    /// slot from before this round is of the run's own cluster: the run
    /// only notes others'). Each bystander that joined it (at `joined`)
    /// gets its slot and record, and joins the run's cluster; when one
    /// joined another run of this round too (slots from `known` on are
    /// this round's), the two must run again as one.
    fn take_run(&mut self, c: u32, k0: usize, joined: &[u32], r: &RunDone, known: usize) {
        let round = self.stats.rounds as u32;
        let mut root = if r.own.is_none() {
            Slot::NONE
        } else {
            self.part.find(r.own)
        };
        let mut twice = false;
        let first = self.fin.record_in(c, k0).map(|(m, _)| m.id);
        for &k in joined {
            let Some((&Member { id, grew, .. }, _)) = self.fin.record_in(c, k as usize) else {
                unreachable!("a chunk holds the members its runs wrote");
            };
            // It may have got a slot from an earlier run of this round.
            let s = match self.part.slot[id as usize] {
                Slot::NONE => self.add_slot(id),
                s => s,
            };
            debug_assert!(s.index() >= known, "a bystander's slot is this round's");
            twice |= self.fin.ran(s.index()) == round;
            self.fin
                .set(s.index(), c, k as usize, grew, r.capped, round);
            root = if root.is_none() {
                self.part.find(s)
            } else {
                self.part.link(root, s)
            };
        }
        match (twice, first) {
            (true, Some(first)) => {
                self.part.union(root, root);
                self.conf.found.push((first, first));
            }
            _ => self.part.ran(root),
        }
    }

    fn merge_conflicts(&mut self) {
        let conflicts = std::mem::take(&mut self.conf.found);
        for &(a, j) in &conflicts {
            let sj = match self.part.slot[j as usize] {
                Slot::NONE => self.add_slot(j),
                s => s,
            };
            self.part.union(self.part.slot[a as usize], sj);
        }
        self.conf.found = conflicts;
    }
}

/// The members a run just wrote (`out.chunk.members[from..]`, in the chunk
/// that will be number `c`): those with a slot at the run's start are of
/// its own cluster, whose slots no other run of the round writes, so their
/// records are set here, on the run's lane; the places of the rest,
/// bystanders that joined it, go to `out.joined`. `(capped, round)` are
/// the run's. Returns a slot of its own (none if it had only bystanders).
fn set_own(
    fin: &Finished,
    slots: &[Slot],
    out: &mut BlockOut,
    from: usize,
    c: u32,
    (capped, round): (Option<Coarse>, u32),
) -> Slot {
    let mut own = Slot::NONE;
    let members = out.chunk.members.iter().enumerate().skip(from);
    for ((k, m), &s) in members.zip(slots) {
        if s.is_none() {
            out.joined.push(k as u32);
        } else {
            own = s;
            fin.set(s.index(), c, k, m.grew, capped, round);
        }
    }
    own
}
