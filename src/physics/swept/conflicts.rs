//! Whether clusters that ran apart really kept apart. The runs' paths are
//! kept by slot, as turns; pairs in different clusters whose balls met
//! (noted by a run, or grown balls found by a grid over all of them) are
//! compared turn by turn, and those that come within touching distance are
//! conflicts: their clusters merge and run again.
use super::cluster::{Chunk, Coarse, Member, Turn};
use super::partition::{Partition, Slot};
use super::path_ball;
use super::stats::RoundStats;
use crate::physics::broad::Grid;
use crate::physics::exec::{Exec, for_each_chunk, or_serial, work_ns};
use crate::physics::sphere::Sphere;
use crate::physics::wide::wide;
use glam::DVec3;
use std::sync::atomic::{AtomicU8, AtomicU32, AtomicU64, AtomicUsize, Ordering};

/// Predicted nanoseconds of making a grown ball and comparing it with its
/// neighbours (docs/threading.md).
const NS_PER_BALL: usize = 50;
/// Slots per block when making their balls in parallel.
const BALL_BLOCK: usize = 2048;

/// By slot, what the cluster's last finished run left. Kept in atomics so
/// a block of runs writes its own members' slots on its lane (each slot is
/// one cluster's, and one cluster runs once a round); the bystanders that
/// joined are written where the runs are collected.
#[derive(Default)]
pub(super) struct Finished {
    /// Where the member's record is (chunk in the high half, index in the
    /// low), [`NO_RECORD`] until its cluster ran.
    at: Vec<AtomicU64>,
    /// The round that run was made in ([`NOT_RUN`] before any).
    ran: Vec<AtomicU32>,
    /// Whether (and why) that run was capped, and whether the member's ball
    /// grew past the one the grid holds for it ([`marks`]).
    marks: Vec<AtomicU8>,
    /// The runs' outputs, each taken whole from the block that wrote it
    /// (not copied: a record and its turns are kept once). Not pooled for
    /// reuse: chunks of any size would each keep the largest they ever held.
    chunks: Vec<Chunk>,
}

/// No record: no chunk has this number.
const NO_RECORD: u64 = u64::MAX;

/// `Finished::ran` of a slot whose cluster has not run.
const NOT_RUN: u32 = u32::MAX;

/// In a slot's marks byte: its ball grew (the low two bits are the cap).
const GREW: u8 = 1 << 2;

/// A slot's cap and growth, packed in a byte.
fn marks(capped: Option<Coarse>, grew: bool) -> u8 {
    let c = match capped {
        None => 0,
        Some(Coarse::Events) => 1,
        Some(Coarse::Work) => 2,
    };
    c | if grew { GREW } else { 0 }
}

/// The cap a marks byte holds.
fn capped_of(marks: u8) -> Option<Coarse> {
    match marks & 3 {
        0 => None,
        1 => Some(Coarse::Events),
        _ => Some(Coarse::Work),
    }
}

impl Finished {
    pub fn reset(&mut self, m: usize) {
        self.at.clear();
        self.at.resize_with(m, || AtomicU64::new(NO_RECORD));
        self.ran.clear();
        self.ran.resize_with(m, || AtomicU32::new(NOT_RUN));
        self.marks.clear();
        self.marks.resize_with(m, || AtomicU8::new(0));
        self.chunks.clear();
    }

    /// Drops every record: all the slots are about to run again as one
    /// cluster, so none is read again, and its memory is free for theirs.
    pub fn forget(&mut self) {
        self.at.iter_mut().for_each(|a| *a.get_mut() = NO_RECORD);
        // The caps stay (the one run sets them all again); growth goes.
        for m in &mut self.marks {
            *m.get_mut() &= !GREW;
        }
        self.chunks.clear();
    }

    /// Room for a slot added after the first round.
    pub fn push(&mut self) {
        self.at.push(AtomicU64::new(NO_RECORD));
        self.ran.push(AtomicU32::new(NOT_RUN));
        self.marks.push(AtomicU8::new(0));
    }

    /// The number the next chunk kept will have.
    pub fn next_chunk(&self) -> u32 {
        self.chunks.len() as u32
    }

    /// Takes a block's chunk in (its runs shrank it to its size); returns
    /// its number, for [`Finished::set`].
    pub fn keep(&mut self, chunk: Chunk) -> u32 {
        self.chunks.push(chunk);
        (self.chunks.len() - 1) as u32
    }

    /// Slot `s` finished in round `round` as member `k` of chunk `c` (its
    /// ball `grew` or not), its run capped as `capped`. A chunk not yet
    /// kept is named by the number it will have.
    pub fn set(&self, s: usize, c: u32, k: usize, grew: bool, capped: Option<Coarse>, round: u32) {
        let at = (u64::from(c) << 32) | k as u64;
        self.at[s].store(at, Ordering::Relaxed);
        self.ran[s].store(round, Ordering::Relaxed);
        self.marks[s].store(marks(capped, grew), Ordering::Relaxed);
    }

    /// The round slot `s`'s cluster last ran in ([`NOT_RUN`] before any).
    pub fn ran(&self, s: usize) -> u32 {
        self.ran[s].load(Ordering::Relaxed)
    }

    /// Whether (and why) slot `s`'s last run was capped.
    pub fn capped(&self, s: usize) -> Option<Coarse> {
        capped_of(self.marks[s].load(Ordering::Relaxed))
    }

    /// Slot `s`'s record and its turns, if its cluster ran.
    pub fn record(&self, s: usize) -> Option<(&Member, &[Turn])> {
        let at = self.at[s].load(Ordering::Relaxed);
        self.record_in((at >> 32) as u32, (at & u64::from(u32::MAX)) as usize)
    }

    /// Member `k` of chunk `c` and its turns.
    pub fn record_in(&self, c: u32, k: usize) -> Option<(&Member, &[Turn])> {
        let chunk = self.chunks.get(c as usize)?;
        let m = chunk.members.get(k)?;
        Some((m, chunk.path(m)))
    }

    /// Whether slot `s`'s ball grew past the one the grid holds for it.
    pub fn grew(&self, s: usize) -> bool {
        self.marks[s].load(Ordering::Relaxed) & GREW != 0
    }

    /// Whether the spheres of slots `a` and `b` come within touching
    /// distance during the step. A path not fully known (a capped run's,
    /// or one not run) meets everyone: a merge costs time, never a result.
    fn meet(&self, a: usize, b: usize, spheres: &[Sphere], dt: f64) -> bool {
        let path = |s: usize| {
            let (m, turns) = self.record(s).filter(|_| self.capped(s).is_none())?;
            Some((&spheres[m.id as usize], turns))
        };
        let (Some((sa, ta)), Some((sb, tb))) = (path(a), path(b)) else {
            return true;
        };
        paths_meet(sa, ta, sb, tb, dt)
    }

    /// The ball slot `s` (sphere `id`) stays in: from its last finished
    /// run (around the same centre), or its straight path.
    #[inline]
    fn ball(&self, s: usize, id: u32, spheres: &[Sphere], dt: f64) -> (DVec3, f64) {
        let straight = path_ball(&spheres[id as usize], dt);
        match self.record(s) {
            Some((m, _)) => (straight.0, m.reach),
            None => straight,
        }
    }
}

/// The conflicts of a round, and what finds them.
#[derive(Default)]
pub(super) struct Conflicts {
    /// Pairs of spheres whose clusters must merge and run again.
    pub found: Vec<(u32, u32)>,
    /// (sphere, sphere of another cluster) whose balls met in a standing
    /// run: their paths are compared once the runs agree.
    pub cross: Vec<(u32, u32)>,
    /// Scratch of the grown-ball check: every slot's ball, a grid over
    /// them, the pairs it found, each slot's cluster. A ball is its
    /// centre and reach (32 bytes; a whole `Sphere` was 64).
    balls: Vec<(DVec3, f64)>,
    overlap: Grid,
    overlap_pairs: Vec<(u32, u32)>,
    cluster_of: Vec<Slot>,
}

impl Conflicts {
    /// Pairs of spheres in different clusters whose balls met during a run
    /// conflict if their paths really come within touching distance.
    pub fn check_cross(
        &mut self,
        part: &mut Partition,
        fin: &Finished,
        spheres: &[Sphere],
        dt: f64,
        stats: &mut RoundStats,
    ) {
        for &(a, b) in &self.cross {
            let (sa, sb) = (part.slot[a as usize], part.slot[b as usize]);
            if part.find(sa) == part.find(sb) {
                continue;
            }
            stats.compared += 1;
            if fin.meet(sa.index(), sb.index(), spheres, dt) {
                self.found
                    .push((part.ids[sa.index()], part.ids[sb.index()]));
            } else {
                stats.apart += 1;
            }
        }
    }

    /// A finished cluster whose member's ball grew was checked against the
    /// balls the grid holds, of spheres that had events then. Two such
    /// grown balls, or any ball and that of a bystander that joined a run (which
    /// other runs took to fly straight), may meet where no run could see
    /// it: such pairs in different clusters are compared by their paths.
    #[allow(clippy::too_many_arguments)] // borrows of separate owners (the partition, the finished paths, the spheres), not one value
    pub fn check_grown(
        &mut self,
        exec: &dyn Exec,
        part: &mut Partition,
        fin: &Finished,
        spheres: &[Sphere],
        size: f64,
        dt: f64,
        stats: &mut RoundStats,
    ) {
        let m = part.ids.len();
        if m < 2 || !(m > part.first_late || (0..m).any(|s| fin.grew(s))) {
            return;
        }
        // Merges since the round began joined clusters: name them afresh.
        part.roots_into(exec, &mut self.cluster_of);
        // Every slot's ball, indexed by slot.
        self.balls.clear();
        if wide(exec) {
            self.balls.resize(m, (DVec3::ZERO, 0.0));
            let ids = &part.ids;
            for_each_chunk(
                exec,
                &mut self.balls,
                BALL_BLOCK,
                NS_PER_BALL,
                &|b, chunk| {
                    for (k, ball) in chunk.iter_mut().enumerate() {
                        let s = b * BALL_BLOCK + k;
                        *ball = fin.ball(s, ids[s], spheres, dt);
                    }
                },
            );
        } else {
            for s in 0..m {
                self.balls.push(fin.ball(s, part.ids[s], spheres, dt));
            }
        }
        self.overlap.build(
            &self.balls,
            size,
            |&ball| ball,
            small(exec, self.balls.len()),
        );
        let mut pairs = std::mem::take(&mut self.overlap_pairs);
        let cluster_of = &self.cluster_of;
        let compared = AtomicUsize::new(0);
        let first_late = part.first_late;
        let changed = |s: usize| s >= first_late || fin.grew(s);
        // The paths are compared in the pair search, on its lanes.
        let meet = |a: u32, b: u32| {
            let (sa, sb) = (a as usize, b as usize);
            if !(changed(sa) || changed(sb)) || cluster_of[sa] == cluster_of[sb] {
                return false;
            }
            compared.fetch_add(1, Ordering::Relaxed);
            fin.meet(sa, sb, spheres, dt)
        };
        self.overlap
            .pairs(small(exec, self.balls.len()), &meet, &mut pairs);
        let compared = compared.into_inner();
        stats.compared += compared;
        stats.apart += compared - pairs.len();
        for &(a, b) in &pairs {
            self.found
                .push((part.ids[a as usize], part.ids[b as usize]));
        }
        self.overlap_pairs = pairs;
    }
}

/// `exec`, or the calling thread when `n` balls are too little work to
/// be worth handing to other threads (the lane rule).
fn small(exec: &dyn Exec, n: usize) -> &dyn Exec {
    or_serial(exec, n.div_ceil(BALL_BLOCK), work_ns(n, NS_PER_BALL))
}

/// Relative margin on the touching distance when comparing two paths: far
/// above the rounding of positions (about 1e-16 of the box), so a pair the
/// serial loop would see touch is never passed as apart.
const PATH_MARGIN: f64 = 1e-8;

/// Whether two spheres, from `a` and `b` at the start of the step and
/// turning as `ta` and `tb` say (time order), come within the sum of their
/// radii (widened by [`PATH_MARGIN`]) at one moment of `0..=dt`: on each
/// stretch where both fly straight, the closest approach of the two lines.
fn paths_meet(a: &Sphere, ta: &[Turn], b: &Sphere, tb: &[Turn], dt: f64) -> bool {
    /// A stretch of a path: from time `t` at `pos`, flying at `vel`.
    #[derive(Clone, Copy)]
    struct Leg {
        t: f64,
        pos: DVec3,
        vel: DVec3,
    }
    let sigma = (a.radius + b.radius) * (1.0 + PATH_MARGIN);
    let start = |s: &Sphere| Leg {
        t: 0.0,
        pos: s.pos,
        vel: s.vel,
    };
    let turn = |l: Leg, k: &Turn| Leg {
        t: k.t,
        pos: k.after(l.pos, l.vel, l.t),
        vel: k.vel,
    };
    let (mut ka, mut kb) = (start(a), start(b));
    let (mut ia, mut ib) = (0, 0);
    let mut t0 = 0.0;
    loop {
        let next = |turns: &[Turn], i: usize| turns.get(i).map_or(dt, |k| k.t.min(dt));
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
            ka = turn(ka, &ta[ia]);
            ia += 1;
        }
        while ib < tb.len() && tb[ib].t <= t1 {
            kb = turn(kb, &tb[ib]);
            ib += 1;
        }
        t0 = t1;
    }
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

    /// A turn at `t` to `vel`; where the path is then follows from its
    /// start and earlier turns.
    fn turn(t: f64, vel: [f64; 3]) -> Turn {
        Turn {
            t,
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
        let up = [turn(1.0, [0.0, 1.0, 0.0])];
        let down = [turn(1.0, [0.0, -1.0, 0.0])];
        assert!(!paths_meet(&a, &[], &b, &[], 3.0));
        assert!(paths_meet(&a, &up, &b, &[], 3.0));
        assert!(paths_meet(&b, &[], &a, &up, 3.0), "either order");
        assert!(!paths_meet(&a, &down, &b, &[], 3.0));
        // The meeting at t = 1.8 lies past a step of 1.5.
        assert!(!paths_meet(&a, &up, &b, &[], 1.5));
        // Both turn: `b` runs off along +y at t = 0.5 and stays ahead.
        let away = [turn(0.5, [0.0, 2.0, 0.0])];
        assert!(!paths_meet(&a, &up, &b, &away, 3.0));
    }
}
