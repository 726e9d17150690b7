//! `swept`: the article's model done right. Each step finds the contacts it
//! can foresee — pairs that meet on straight paths within the step, spheres
//! that reach a wall — and processes them in time order, each sphere moved
//! only when touched (lazy update). Whenever a contact changes a velocity,
//! that sphere looks again for partners within its reach, so chains of
//! contacts inside a step are followed, not missed. The rest fly straight.
//! A pathological step (near jamming, or paths that cross much of the box)
//! is cut off by an event cap or by the step's work budget (pair checks,
//! counted, so the same on any machine), finished in free flight with wall
//! bounces and counted in `capped_steps` (`budget_steps` for the budget).
//!
//! The spheres with events are cut into clusters that cannot touch each
//! other, each with its own event queue, run side by side on the executor's
//! lanes (`rounds.rs`, `cluster.rs`); the result is the serial loop's to the
//! bit. The engine's overlap readout comes from the next step's detection,
//! which that step then reuses.
//!
//! When paths are long against the gaps between spheres (fast or crowded
//! scenes), a step is cut into equal parts, each run as above, so the
//! pairs and clusters stay those of short paths (`parts.rs`).
mod cluster;
mod conflicts;
mod event;
mod group;
#[cfg(feature = "experiments")]
mod knobs;
mod partition;
mod parts;
mod results;
mod rounds;
mod stats;

use super::broad::Pair;
use super::contact::pair_toi;
use super::detect::Detection;
use super::exec::{Exec, PerBlock, for_each_block_of, work_ns};
use super::flight::{fly, fly_straight};
use super::model::{Model, ModelKind};
use super::sphere::{Sphere, overlap_rel};
use super::wide::wide;
use super::world::{Stamp, World};
use cluster::Coarse;
use glam::DVec3;
pub use parts::{ADDED_PAIRS, parts};
use results::{Totals, take_results};
use rounds::Rounds;
pub use stats::RoundStats;

/// Reach balls are widened by this much so touching spheres, whose distance
/// rounds either way, are always seen.
const REACH_SLACK: f64 = 1.0 + 1e-9;
/// Candidate pairs per parallel block when sorting them into meeting and
/// merely near.
const PAIR_BLOCK: usize = 1024;
/// Predicted nanoseconds of sorting one near pair (docs/threading.md).
const NS_PER_PAIR_SORT: usize = 70;
/// The work budget of one step, in pair checks (pairs detection finds,
/// spheres a rescan looks at, weights per event: `cluster.rs`): a base plus
/// so much per sphere, so the worst step of 1 000 spheres (120 M) costs
/// under a second of CPU here (docs/benchmarks.md).
pub const BUDGET_BASE: u64 = 20_000_000;
pub const BUDGET_PER_SPHERE: u64 = 100_000;
/// A cluster's event cap: a base plus so much per member (`cluster.rs`).
pub const EVENT_CAP_BASE: usize = 10_000;
pub const EVENT_CAP_PER_SPHERE: usize = 64;

/// The events a cluster of `members` spheres may take (its event cap).
#[must_use]
pub fn event_cap(members: usize) -> usize {
    EVENT_CAP_BASE.saturating_add(EVENT_CAP_PER_SPHERE.saturating_mul(members))
}

/// The work budget of a step of `n` spheres, in pair checks.
#[must_use]
pub fn budget(n: usize) -> u64 {
    budget_from(BUDGET_BASE, BUDGET_PER_SPHERE, n)
}

fn budget_from(base: u64, per: u64, n: usize) -> u64 {
    base.saturating_add(per.saturating_mul(n as u64))
}

#[derive(Default)]
pub struct Swept {
    detect: Detection,
    /// The spheres whose path reaches a wall this step.
    hits: Vec<u32>,
    /// Per block of candidate pairs: (meeting, near).
    sorted: PerBlock<(Vec<Pair>, Vec<Pair>)>,
    meets: Vec<Pair>,
    near: Vec<Pair>,
    /// Per block of candidate pairs: the deepest overlap among them.
    overlap: PerBlock<f64>,
    rounds: Rounds,
    /// Per block of results taken in parallel, their totals.
    totals: PerBlock<Totals>,
    /// The last step's `rounds` stats, over all its parts.
    step_stats: RoundStats,
    /// Parts the last step was cut into.
    last_parts: u32,
    /// Detection already made for the next step of the world it names.
    ahead: Option<Ahead>,
    #[cfg(feature = "experiments")]
    knobs: knobs::Knobs,
}

/// A detection made ahead of its step (when the engine asked for the
/// overlap of the world a frame ended with): valid for the world with this
/// stamp and this `dt` only.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ahead {
    dt: f64,
    stamp: Stamp,
    overlap: f64,
    /// The detection found more pairs than a step's budget allows.
    overran: bool,
}

/// How a part of a step ended.
enum PartEnd {
    /// Its events ran, all of them or up to a cap (which one).
    Ran(Option<Coarse>),
    /// Its detection alone found more pairs than the budget left: the world
    /// is as it was.
    Overran,
}

/// The ball a sphere on a straight path stays in during the step: centred
/// on the middle of its path, half the path plus its radius wide (an eighth
/// of the volume of the ball around the start point).
#[inline]
fn path_ball(s: &Sphere, dt: f64) -> (DVec3, f64) {
    let half = 0.5 * dt;
    (
        s.pos + s.vel * half,
        (s.radius + s.vel.length() * half) * REACH_SLACK,
    )
}

impl Model for Swept {
    fn kind(&self) -> ModelKind {
        ModelKind::Swept
    }

    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec) {
        for _ in 0..steps {
            let k = self.parts_of(world, dt);
            self.last_parts = k;
            let part = dt / f64::from(k);
            let mut capped = None;
            let mut left = self.budget_of(world.spheres.len());
            self.step_stats = RoundStats::default();
            for p in 0..k {
                let PartEnd::Ran(cap) = self.step(world, part, exec, &mut left) else {
                    // Out of budget: the rest of the step in free flight.
                    fly_all(world, part * f64::from(k - p));
                    capped = Some(Coarse::Work);
                    break;
                };
                self.step_stats.add(&self.rounds.stats);
                // A part stopped by the budget outranks one by the cap.
                capped = capped.max(cap);
            }
            world.counters.capped_steps += u64::from(capped.is_some());
            world.counters.budget_steps += u64::from(capped == Some(Coarse::Work));
            world.time += dt;
        }
    }

    /// See `parts.rs`.
    fn last_parts(&self) -> u32 {
        self.last_parts
    }

    /// The next step's detection finds every pair whose balls meet, and a
    /// sphere's ball holds the sphere: the overlapping pairs are among them.
    /// So the overlap costs nothing extra, and the next step reuses the
    /// detection if the world is still the same.
    fn max_overlap_rel(&mut self, world: &World, dt: f64, exec: &dyn Exec) -> Option<f64> {
        // The detection of the next step's first part.
        let dt = dt / f64::from(self.parts_of(world, dt));
        let stamp = world.stamp();
        if let Some(a) = self.ahead
            && a.dt == dt
            && a.stamp == stamp
        {
            return (!a.overran).then_some(a.overlap);
        }
        let limit = self.budget_of(world.spheres.len());
        let overlap = self.detect(world, dt, exec, limit);
        let overran = self.detect.overran;
        self.ahead = Some(Ahead {
            dt,
            stamp,
            overlap,
            overran,
        });
        // Only some pairs were found: the engine measures the overlap itself.
        (!overran).then_some(overlap)
    }
}

impl Swept {
    /// How the last step's events were cut into clusters.
    pub fn round_stats(&self) -> RoundStats {
        self.step_stats
    }

    /// The parts a step of `dt` from `world` is cut into.
    // Without the experiments' knobs, the default alone.
    #[cfg_attr(not(feature = "experiments"), expect(clippy::unused_self))]
    fn parts_of(&self, world: &World, dt: f64) -> u32 {
        #[cfg(feature = "experiments")]
        if let Some(k) = self.knobs.fixed_parts {
            return k;
        }
        parts::parts(&world.spheres, world.size, dt)
    }

    /// The work budget for a step of `n` spheres.
    // Without the experiments' knobs, the default alone.
    #[cfg_attr(not(feature = "experiments"), expect(clippy::unused_self))]
    fn budget_of(&self, n: usize) -> u64 {
        #[cfg(feature = "experiments")]
        if let Some((base, per)) = self.knobs.budget {
            return budget_from(base, per, n);
        }
        budget(n)
    }

    /// One part of a step (see `parts.rs`), with `left` work of the step's
    /// budget, which it takes what it used from.
    fn step(&mut self, world: &mut World, dt: f64, exec: &dyn Exec, left: &mut u64) -> PartEnd {
        let size = world.size;
        let ready = self.ahead.take().filter(|a| {
            a.dt == dt && a.stamp == world.stamp() && (a.overran || self.pairs_fit(*left))
        });
        let overran = if let Some(a) = ready {
            a.overran
        } else {
            self.detect(world, dt, exec, *left);
            self.detect.overran
        };
        if overran {
            return PartEnd::Overran;
        }
        *left -= self.detect.pairs.len() as u64;
        self.rounds.run(
            exec,
            &world.spheres,
            &self.detect.grid,
            size,
            dt,
            &self.meets,
            &self.near,
            &self.hits,
            *left,
        );
        *left = left.saturating_sub(self.rounds.work);
        // Everyone flies straight; then the spheres with events take their
        // run's end, and the counters are summed in sphere order: the same
        // bits on any lanes and however the clusters fell.
        fly_straight(exec, &mut world.spheres, dt);
        let (spheres, c) = (&mut world.spheres, &mut world.counters);
        let capped = take_results(exec, &self.rounds, spheres, c, &mut self.totals);
        PartEnd::Ran(capped)
    }

    /// Whether the pairs of the detection last made fit in `left` work.
    fn pairs_fit(&self, left: u64) -> bool {
        self.detect.pairs.len() as u64 <= left
    }

    /// Finds the pairs and walls of a step of `dt` from `world`; returns the
    /// deepest overlap among the pairs (relative to the smaller radius).
    /// Finding more than `limit` pairs stops it (`self.detect.overran`).
    fn detect(&mut self, world: &World, dt: f64, exec: &dyn Exec, limit: u64) -> f64 {
        self.detect.pair_limit = Some(usize::try_from(limit).unwrap_or(usize::MAX));
        let size = world.size;
        let sp = &world.spheres;
        let ball = |s: &Sphere| path_ball(s, dt);
        if exec.functional() {
            // `split`: the sphere–wall job (every sphere's path against the
            // walls) runs on its own thread beside the sphere–sphere job.
            let wall = |s: &Sphere| reaches_wall(s, size, dt);
            self.detect.run(exec, sp, size, ball, &|_, _| true, &wall);
            self.detect.wall_hits(&mut self.hits);
        } else {
            // Otherwise walls come from the grid: only a sphere in a cell
            // on a face can reach one, and most are not. The same set.
            self.detect
                .run(exec, sp, size, ball, &|_, _| true, &|_| false);
            self.hits.clear();
            if self.detect.overran {
                return 0.0;
            }
            self.grid_hits(exec, sp, size, dt);
        }
        if self.detect.overran {
            return 0.0;
        }
        self.sort_pairs(sp, dt, exec)
    }

    /// The spheres the grid has on a face whose path reaches a wall, into
    /// `hits`: on many lanes block by block of planes, in the same order.
    fn grid_hits(&mut self, exec: &dyn Exec, sp: &[Sphere], size: f64, dt: f64) {
        let keep = |i: u32| reaches_wall(&sp[i as usize], size, dt);
        if wide(exec) {
            let grid = &mut self.detect.grid;
            grid.near_faces_lanes(exec, &keep, &mut self.hits);
            return;
        }
        let hits = &mut self.hits;
        self.detect.grid.near_faces(&mut |i| {
            if keep(i) {
                hits.push(i);
            }
        });
    }

    /// Splits the pairs whose balls overlap into those whose straight paths
    /// meet within the step and the rest, keeping their order; returns the
    /// deepest overlap among them.
    fn sort_pairs(&mut self, sp: &[Sphere], dt: f64, exec: &dyn Exec) -> f64 {
        let pairs = &self.detect.pairs;
        let blocks = pairs.len().div_ceil(PAIR_BLOCK);
        self.sorted.ensure(blocks);
        self.overlap.ensure(blocks);
        let (sorted, overlap) = (&self.sorted, &self.overlap);
        for_each_block_of(exec, blocks, work_ns(pairs.len(), NS_PER_PAIR_SORT), &|b| {
            let mut guard = sorted[b].lock();
            let (meets, near) = &mut *guard;
            meets.clear();
            near.clear();
            let mut deepest: f64 = 0.0;
            let end = ((b + 1) * PAIR_BLOCK).min(pairs.len());
            for &(i, j) in &pairs[b * PAIR_BLOCK..end] {
                let (a, c) = (&sp[i as usize], &sp[j as usize]);
                let (dp, sigma) = (a.pos - c.pos, a.radius + c.radius);
                if dp.length_squared() <= sigma * sigma * (1.0 + 1e-9) {
                    deepest = deepest.max(overlap_rel(a.pos, a.radius, c.pos, c.radius));
                }
                if pair_toi(dp, a.vel - c.vel, sigma).is_some_and(|t| t <= dt) {
                    meets.push((i, j));
                } else {
                    near.push((i, j));
                }
            }
            *overlap[b].lock() = deepest;
        });
        self.meets.clear();
        self.near.clear();
        for m in &self.sorted[..blocks] {
            let guard = m.lock();
            self.meets.extend_from_slice(&guard.0);
            self.near.extend_from_slice(&guard.1);
        }
        self.overlap[..blocks]
            .iter()
            .fold(0.0, |worst, d| worst.max(*d.lock()))
    }
}

/// Every sphere flies `t` with wall bounces only (how a step out of budget
/// ends): energy is kept and nobody leaves the box. Counters summed in
/// sphere order, so the same bits on any lanes.
fn fly_all(world: &mut World, t: f64) {
    let (size, c) = (world.size, &mut world.counters);
    for s in &mut world.spheres {
        let (momentum, hits) = fly(s, size, t);
        c.wall_momentum += momentum;
        c.wall_collisions += hits;
    }
}

/// Whether the straight path of `s` over `dt` leaves `[r, L - r]^3` (the
/// box is convex, so the end point tells), touching included.
#[inline]
fn reaches_wall(s: &Sphere, size: f64, dt: f64) -> bool {
    let end = s.pos + s.vel * dt;
    let (lo, hi) = (s.radius, size - s.radius);
    // `|`, not `||`: one well-predicted branch instead of four.
    (end.min(s.pos).min_element() <= lo) | (end.max(s.pos).max_element() >= hi)
}
