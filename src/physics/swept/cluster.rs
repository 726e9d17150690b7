//! One cluster's contact events within a step, on private copies of its
//! spheres: the serial event loop of `swept` (time order, lazy clocks,
//! collision counters, rescans on every velocity change), run for a set of
//! spheres that should not touch anyone outside it. A bystander (a sphere
//! with no events of its own) that a member meets joins the run (the caller
//! sees it if it joined two runs); a member of another cluster, whose
//! path is not known here, is only noted, and the caller checks the two
//! paths once both runs are done (see `rounds`). Each member's path is kept
//! as the turns it took.
use super::event::{Event, Local, WALL, pair_event, push_wall};
use super::partition::Slot;
use super::{REACH_SLACK, path_ball};
use crate::physics::broad::Grid;
use crate::physics::contact::{pair_toi, reflect_walls, resolve_pair, wall_toi};
use crate::physics::flight::fly;
use crate::physics::sphere::Sphere;
use glam::DVec3;
use std::collections::BinaryHeap;

/// Runs with at most this many members check each other one by one on a
/// rescan; bigger ones (and the absorbing run) find members through the
/// grid.
const SMALL_RUN: usize = 32;
/// A ball may grow to this many times its grid level's widest and still be
/// found through the grid: wider searches cost more each, a narrower cap
/// puts more balls on the run's own `grown` list (docs/benchmarks.md, "tuned
/// constants").
const GROWTH_CAP: f64 = 1.25;

/// An event's own cost in pair checks: the queue, the grid cells its
/// rescans visit, its turns kept and compared (measured: about 400 pair
/// checks' time in the close-packed lattice, where events dominate).
pub(super) const EVENT_WORK: u64 = 256;
/// What a sphere a rescan finds within reach costs beyond its check (a
/// sort, a path solved), in pair checks (measured at `--speed 1e4`, where
/// rescans find much of the box).
const FOUND_WORK: u64 = 4;

/// What every run of a step reads: the state at the start of the step and
/// who has events.
pub(super) struct Shared<'a> {
    pub spheres: &'a [Sphere],
    pub grid: &'a Grid,
    /// Sphere id → its slot among the involved spheres, or `Slot::NONE`.
    pub slot: &'a [Slot],
    /// By slot of the first round: where its partners among the step's
    /// pairs start in `partners` (see [`Shared::partners_of`]).
    pub partner_start: &'a [u32],
    pub partners: &'a [u32],
    pub size: f64,
    pub dt: f64,
    /// Work (see [`Run::work`]) a run may do per member it starts with.
    pub work_per_member: u64,
}

impl Shared<'_> {
    /// Every sphere whose binned ball meets the binned ball of the sphere
    /// in `slot`, if that slot was indexed.
    fn partners_of(&self, slot: Slot) -> Option<&[u32]> {
        let s = slot.index();
        let end = *self.partner_start.get(s.checked_add(1)?)?;
        Some(&self.partners[self.partner_start[s] as usize..end as usize])
    }
}

/// Why a run stopped taking events and finished in free flight.
/// Ordered by weight: a step with both says "work".
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Coarse {
    /// More events than the cap for its members.
    Events,
    /// More work than its share of the step's budget.
    Work,
}

/// A turn in a member's path: from time `t` of the step it is at
/// `pos + vel (t' - t)`, until its next turn. Its position there is not
/// kept: contacts change velocities only, so it is the last turn's (or the
/// start's) position plus that velocity times the time since, to the bit
/// (see [`Turn::after`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Turn {
    pub t: f64,
    pub vel: DVec3,
}

impl Turn {
    /// Where a sphere at `pos` at `t0`, flying at `vel`, is at this turn:
    /// the same sum a run's lazy clock makes.
    #[inline]
    pub fn after(&self, pos: DVec3, vel: DVec3, t0: f64) -> DVec3 {
        pos + vel * (self.t - t0)
    }
}

/// One member's result of a finished run: only what the rounds read (its
/// radius, mass and the centre of its ball are the start's, found there).
#[derive(Clone, Copy, Debug)]
pub(super) struct Member {
    pub id: u32,
    /// Its end of the step.
    pub pos: DVec3,
    pub vel: DVec3,
    /// Momentum given to the walls, for the pressure.
    pub wall_momentum: f64,
    pub wall_hits: u32,
    /// Sphere–sphere collisions this member was the lower id of.
    pub pair_hits: u32,
    /// The reach of the ball (around its start's path ball's centre) its
    /// whole path of the step stays in, and whether that grew past the
    /// ball the grid holds for it.
    pub reach: f64,
    pub grew: bool,
    /// Its turns: `turns` of them from `turn0` on, in time order, in the
    /// [`Chunk`] it was written to.
    pub turn0: u32,
    pub turns: u32,
}

/// Finished runs' members and their turns, as written by [`Run::emit`].
#[derive(Default)]
pub(super) struct Chunk {
    pub members: Vec<Member>,
    pub turns: Vec<Turn>,
}

impl Chunk {
    pub fn clear(&mut self) {
        self.members.clear();
        self.turns.clear();
    }

    /// The turns of `m`, one of this chunk's members.
    pub fn path(&self, m: &Member) -> &[Turn] {
        &self.turns[m.turn0 as usize..(m.turn0 + m.turns) as usize]
    }
}

/// Scratch for one run, kept to reuse memory.
#[derive(Default)]
pub(super) struct Run {
    ids: Vec<u32>,
    slots: Vec<Slot>,
    /// Sphere id → local index for members, `Local::NONE` for everyone
    /// else; kept so between runs (one lookup per candidate, the hot path).
    local_of: Vec<Local>,
    sp: Vec<Sphere>,
    t_local: Vec<f64>,
    count: Vec<u32>,
    centre: Vec<DVec3>,
    reach: Vec<f64>,
    reach0: Vec<f64>,
    /// How far each reach may grow before the grid can no longer find it.
    cap: Vec<f64>,
    grown: Vec<u32>,
    wall_momentum: Vec<f64>,
    wall_hits: Vec<u32>,
    pair_hits: Vec<u32>,
    heap: BinaryHeap<Event>,
    found: Vec<u32>,
    /// Turns, by local index, in the order they happened; sorted by member
    /// when the run is written out.
    turn_log: Vec<(u32, Turn)>,
    /// (member, member of another cluster) whose balls met: the caller
    /// compares their paths when both runs are done.
    pub cross: Vec<(u32, u32)>,
    /// Set when the run hit its event cap or its work budget.
    pub capped: Option<Coarse>,
    /// Pair checks made: the pairs handed in, every sphere a rescan looked
    /// at, and [`EVENT_WORK`] per event. Counted, not timed, so a capped run
    /// is the same on any machine and any lanes.
    pub work: u64,
}

impl Run {
    /// Runs the events of a cluster (its `members` and the `pairs`
    /// detection found among them). `absorb`: this is the one run of the
    /// step's last round, holding everyone with events.
    pub fn run(&mut self, sh: &Shared, members: &[u32], pairs: &[(u32, u32)], absorb: bool) {
        self.clear(sh.spheres.len());
        for &i in members {
            self.involve(sh, i);
        }
        self.events(sh, pairs, absorb);
        for &i in &self.ids {
            self.local_of[i as usize] = Local::NONE;
        }
        self.cross.sort_unstable();
        self.cross.dedup();
    }

    fn events(&mut self, sh: &Shared, pairs: &[(u32, u32)], absorb: bool) {
        for &(i, j) in pairs {
            let (a, b) = (self.local_of[i as usize], self.local_of[j as usize]);
            let (si, sj) = (&self.sp[a.index()], &self.sp[b.index()]);
            if let Some(t) = pair_toi(si.pos - sj.pos, si.vel - sj.vel, si.radius + sj.radius) {
                self.heap.push(pair_event(t, i, j, a, b, 0, 0));
            }
        }
        let cap = super::event_cap(self.ids.len());
        let work_cap = sh.work_per_member.saturating_mul(self.ids.len() as u64);
        self.work = pairs.len() as u64;
        let mut done = 0usize;
        while let Some(e) = self.heap.pop() {
            let (la, lb) = (e.la.index(), e.lb.index());
            if self.count[la] != e.ca || (e.b != WALL && self.count[lb] != e.cb) {
                continue;
            }
            done += 1;
            self.work += EVENT_WORK;
            if done > cap {
                self.capped = Some(Coarse::Events);
                break;
            }
            if self.work > work_cap {
                self.capped = Some(Coarse::Work);
                break;
            }
            self.advance_to(la, e.t);
            self.count[la] += 1;
            if e.b == WALL {
                let s = &self.sp[la];
                let (_, mask) = wall_toi(s.pos, s.vel, s.radius, sh.size);
                let (imp, hits) = reflect_walls(&mut self.sp[la], mask);
                self.wall_momentum[la] += imp;
                self.wall_hits[la] += hits as u32;
                self.turn(la, e.t);
                self.rescan(sh, la, e.t, absorb);
            } else {
                self.advance_to(lb, e.t);
                self.count[lb] += 1;
                // Two members: a pair event never names one sphere twice.
                let Ok([x, y]) = self.sp.get_disjoint_mut([la, lb]) else {
                    unreachable!("a pair event of one sphere");
                };
                if resolve_pair(x, y) {
                    self.pair_hits[la.min(lb)] += 1;
                }
                self.turn(la, e.t);
                self.turn(lb, e.t);
                self.rescan(sh, la, e.t, absorb);
                self.rescan(sh, lb, e.t, absorb);
            }
        }
        for l in 0..self.ids.len() {
            if self.count[l] == 0 {
                // No event after all: the straight flight everyone without
                // one makes, to the bit, whoever counted it in.
                let s = &mut self.sp[l];
                s.pos += s.vel * sh.dt;
                continue;
            }
            let rest = sh.dt - self.t_local[l];
            if self.capped.is_none() {
                // Every wall it reaches before the step ends was an event:
                // the rest of its path is straight.
                let s = &mut self.sp[l];
                s.pos += s.vel * rest;
                continue;
            }
            let (imp, hits) = fly(&mut self.sp[l], sh.size, rest);
            self.wall_momentum[l] += imp;
            self.wall_hits[l] += hits as u32;
        }
    }

    /// Member `l` changed velocity at `t` (it is there now).
    fn turn(&mut self, l: usize, t: f64) {
        let s = &self.sp[l];
        self.turn_log.push((l as u32, Turn { t, vel: s.vel }));
    }

    /// Each member's slot at the run's start, in the order `emit` writes
    /// them (`Slot::NONE` for the bystanders that joined).
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }

    /// Writes the members of the last finished run, each with its turns
    /// together in time order, to `out`.
    pub fn emit(&mut self, out: &mut Chunk) {
        // Stable: each member's turns stay in time order.
        self.turn_log.sort_by_key(|&(l, _)| l);
        let base = out.turns.len();
        out.turns.extend(self.turn_log.iter().map(|&(_, k)| k));
        let mut k = 0;
        for l in 0..self.ids.len() {
            let first = k;
            while k < self.turn_log.len() && self.turn_log[k].0 as usize == l {
                k += 1;
            }
            let s = &self.sp[l];
            out.members.push(Member {
                id: self.ids[l],
                pos: s.pos,
                vel: s.vel,
                wall_momentum: self.wall_momentum[l],
                wall_hits: self.wall_hits[l],
                pair_hits: self.pair_hits[l],
                reach: self.reach[l],
                grew: self.reach[l] > self.reach0[l],
                turn0: (base + first) as u32,
                turns: (k - first) as u32,
            });
        }
    }

    fn clear(&mut self, n: usize) {
        if self.local_of.len() < n {
            self.local_of.resize(n, Local::NONE);
        }
        self.ids.clear();
        self.slots.clear();
        self.sp.clear();
        self.t_local.clear();
        self.count.clear();
        self.centre.clear();
        self.reach.clear();
        self.reach0.clear();
        self.cap.clear();
        self.grown.clear();
        self.wall_momentum.clear();
        self.wall_hits.clear();
        self.pair_hits.clear();
        self.heap.clear();
        self.turn_log.clear();
        self.capped = None;
        self.work = 0;
        self.cross.clear();
    }

    /// Local index of sphere `j` if it is a member of this run.
    #[inline(always)]
    fn member(&self, j: u32) -> Option<usize> {
        match self.local_of[j as usize] {
            Local::NONE => None,
            l => Some(l.index()),
        }
    }

    /// Adds sphere `i` (at the start of the step) to the run; returns its
    /// local index.
    fn involve(&mut self, sh: &Shared, i: u32) -> Local {
        let l = Local::at(self.ids.len());
        let s = sh.spheres[i as usize];
        self.local_of[i as usize] = l;
        self.ids.push(i);
        self.slots.push(sh.slot[i as usize]);
        self.sp.push(s);
        self.t_local.push(0.0);
        self.count.push(0);
        let (centre, reach) = path_ball(&s, sh.dt);
        self.centre.push(centre);
        self.reach.push(reach);
        self.reach0.push(reach);
        self.cap.push(GROWTH_CAP * sh.grid.widest_in_level(reach));
        self.wall_momentum.push(0.0);
        self.wall_hits.push(0);
        self.pair_hits.push(0);
        push_wall(&mut self.heap, &s, i, l, 0.0, 0, sh.size, sh.dt);
        l
    }

    #[inline]
    fn advance_to(&mut self, l: usize, t: f64) {
        let s = &mut self.sp[l];
        s.pos += s.vel * (t - self.t_local[l]);
        self.t_local[l] = t;
    }

    /// Member `la` changed velocity at `t`: widen its ball if its new path
    /// needs it, and schedule its next wall and every member it can now meet
    /// before the step ends. Anyone else it might meet is a conflict.
    fn rescan(&mut self, sh: &Shared, la: usize, t: f64, absorb: bool) {
        let sa = self.sp[la];
        self.grow_reach(sh, la, &sa, t);
        let ca = self.count[la];
        push_wall(
            &mut self.heap,
            &sa,
            self.ids[la],
            Local::at(la),
            t,
            ca,
            sh.size,
            sh.dt,
        );
        let mut found = std::mem::take(&mut self.found);
        found.clear();
        let seen = self.search(sh, la, &sa, t, absorb, &mut found);
        // A sphere found within reach is sorted and its path solved too.
        self.work += seen + FOUND_WORK * found.len() as u64;
        found.sort_unstable();
        found.dedup();
        self.schedule(sh, la, &sa, t, &found);
        self.found = found;
    }

    /// Widens member `la`'s ball for the step to hold the rest of its new
    /// path (`sa` from `t` on); one grown past its cap joins `grown`.
    #[inline(always)]
    fn grow_reach(&mut self, sh: &Shared, la: usize, sa: &Sphere, t: f64) {
        let need =
            ((sa.pos - self.centre[la]).length() + sa.vel.length() * (sh.dt - t) + sa.radius)
                * REACH_SLACK;
        // A sphere may grow up to its cap and still be found through the
        // grid; beyond that it joins `grown`, which every rescan checks.
        if need > self.reach[la] {
            if need > self.cap[la] && self.reach[la] <= self.cap[la] {
                self.grown.push(la as u32);
            }
            self.reach[la] = need;
        }
    }

    /// The spheres whose balls may meet the rest of member `la`'s path
    /// (`sa` from `t` on), into `found` (unsorted, maybe twice, maybe
    /// itself); returns how many it looked at.
    #[inline(always)]
    fn search(
        &self,
        sh: &Shared,
        la: usize,
        sa: &Sphere,
        t: f64,
        absorb: bool,
        found: &mut Vec<u32>,
    ) -> u64 {
        // Only what is left of the path can meet anyone: the ball around
        // the rest of it is searched, not the whole step's.
        let rem = 0.5 * (sh.dt - t);
        let (q, rq) = (
            sa.pos + sa.vel * rem,
            (sa.radius + sa.vel.length() * rem) * REACH_SLACK,
        );
        let mut seen = 0u64;
        if !absorb && self.ids.len() <= SMALL_RUN {
            // Members are few: they are checked one by one with their grown
            // balls, so the grid is searched only for non-members.
            let mut non_member = |j: u32, pj0: DVec3, rj: f64| {
                seen += 1;
                // The distance first: it reads what the grid handed over,
                // the member table is a read elsewhere in memory.
                if q.distance_squared(pj0) <= (rq + rj) * (rq + rj) && self.member(j).is_none() {
                    found.push(j);
                }
            };
            // When the ball around the rest of the path lies inside the
            // sphere's binned ball (well inside: far above rounding), every
            // non-member it can meet is one of the pairs the grid already
            // found for it, and the same test picks the same ones.
            let inside = (q - self.centre[la]).length() + rq <= self.reach0[la] * (1.0 - 1e-9);
            match sh.partners_of(self.slots[la]).filter(|_| inside) {
                Some(partners) => {
                    for &j in partners {
                        let (pj0, rj) = path_ball(&sh.spheres[j as usize], sh.dt);
                        non_member(j, pj0, rj);
                    }
                }
                None => sh.grid.near(q, rq, 1.0, &mut non_member),
            }
            seen += self.ids.len() as u64;
            for l in 0..self.ids.len() {
                let r = rq + self.reach[l];
                if l != la && q.distance_squared(self.centre[l]) <= r * r {
                    found.push(self.ids[l]);
                }
            }
        } else {
            // Non-members are judged by the ball the grid holds for them: a
            // run never reads another run's state. A member grown past its
            // cap is no longer found through the grid, so `grown` is
            // checked by hand.
            let mut consider = |j: u32, pj0: DVec3, rj: f64| {
                seen += 1;
                let rj = self.member(j).map_or(rj, |l| self.reach[l]);
                if q.distance_squared(pj0) <= (rq + rj) * (rq + rj) {
                    found.push(j);
                }
            };
            sh.grid.near(q, rq, GROWTH_CAP, &mut consider);
            for &g in &self.grown {
                let lg = g as usize;
                consider(self.ids[lg], self.centre[lg], self.reach[lg]);
            }
        }
        seen
    }

    /// Solves member `la`'s new path (`sa` at `t`) against each of `found`
    /// and queues the contacts within the step; a bystander it meets joins
    /// the run, a member of another cluster is noted in `cross`.
    #[inline(always)]
    fn schedule(&mut self, sh: &Shared, la: usize, sa: &Sphere, t: f64, found: &[u32]) {
        let (ia, ca) = (self.ids[la], self.count[la]);
        for &j in found {
            if j == ia {
                continue;
            }
            let l = self.member(j);
            if l.is_none() && !sh.slot[j as usize].is_none() {
                // A member of another cluster whose ball meets ours: its path
                // is not known here, so the caller compares the paths.
                self.cross.push((ia, j));
                continue;
            }
            let s = if let Some(l) = l {
                let s = &self.sp[l];
                Sphere {
                    pos: s.pos + s.vel * (t - self.t_local[l]),
                    ..*s
                }
            } else {
                let s = &sh.spheres[j as usize];
                Sphere {
                    pos: s.pos + s.vel * t,
                    ..*s
                }
            };
            let Some(dtc) = pair_toi(sa.pos - s.pos, sa.vel - s.vel, sa.radius + s.radius) else {
                continue;
            };
            if t + dtc > sh.dt {
                continue;
            }
            // A bystander that a member meets joins the run; if it joined
            // another run too, the caller sees it joined twice.
            let lb = match l {
                Some(l) => Local::at(l),
                None => self.involve(sh, j),
            };
            let cb = self.count[lb.index()];
            self.heap
                .push(pair_event(t + dtc, ia, j, Local::at(la), lb, ca, cb));
        }
    }
}
