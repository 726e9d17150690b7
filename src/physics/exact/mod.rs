//! `exact`: event-driven hard spheres. Every contact is processed in time
//! order; between events spheres fly in straight lines. Built the way the
//! fast hard-sphere codes are (Rapaport; `DynamO`; Smallenburg's EDMD):
//!
//! - lazy update: each sphere carries its own time stamp ([`body`]) and is
//!   moved only when an event touches it or when `advance` returns;
//! - one pending event per sphere (the earliest of contact, wall, or its
//!   locality event), in an [`EventQueue`] (a tournament tree of eight
//!   children a node, [`EightWay`]);
//! - a locality (how a sphere's possible partners are found, `locality`)
//!   chosen once at load by packing fraction ([`LISTS_ABOVE_PACKING`]): a
//!   cell grid with cell-crossing events for dilute and moderate scenes
//!   ([`cell_grid`]), neighbour lists with a skin for dense ones
//!   (`neighbour_lists`); both keep the few spheres far larger than the
//!   bulk on a second level (`large`), so radii 100x apart stay cheap. The
//!   event loop (`event_loop`) is generic over it: the model holds the
//!   loaded world behind one trait object, and nothing else asks which
//!   locality it has;
//! - stale predictions detected by per-sphere collision counts ([`schedule`]);
//! - from [`PREFETCH_FROM`] spheres, prefetching: while an event is
//!   processed, the loop starts loading the cells a crossing reads, a
//!   contact partner's records, the candidates' bodies, and the records of
//!   the queue's runner-up (the next event's sphere nearly always), so their
//!   cache misses overlap instead of following one another;
//! - spheres sorted in space at load (`spatial`); the world keeps every
//!   sphere at its id (`ids`: labels and world ids are apart).
//!
//! Time of impact comes from [`pair_toi`](crate::physics::contact::pair_toi)
//! (stable quadratic, rounding guard: overlapping and approaching collides
//! now, receding is left alone). Simultaneous events are processed in a
//! fixed order: by the sphere whose prediction it is, in the model's
//! internal order (sorted in space at load: a pure function of the world
//! and its history; a contact taken by either of its spheres is the same
//! contact, bit for bit, and is reported lower world id first); a sphere's
//! own candidates tie its locality event (relist or crossing) first, then
//! walls, then partners in the order the locality offers them.
//! Runs are therefore reproducible, and the event loop runs on one thread
//! whatever the executor.
//!
//! `dt` is only the sampling interval: on return, every position is exact at
//! `world.time`.
//!
//! **Bounds** (asserted in `tests/physics/extremes.rs` and `tests/physics/fuzz_exact.rs`):
//! energy is conserved to rounding (relative error below `1e-10` in the
//! extreme cases; `benches/exact.rs` measures about `4e-14` over 10 million
//! collisions); overlap is below `1e-9` of the smaller radius; no sphere
//! leaves the box. Within a step at
//! most `event_cap` events are processed; a step that hits the cap is counted
//! in `counters.capped_steps` and finished by free flight with wall bounces
//! (contacts in its remainder are missed, so overlaps may then appear), and
//! the schedule is rebuilt for the next step.
mod ahead;
mod body;
mod cell_grid;
mod eight_way;
mod event_loop;
mod hooks;
mod ids;
mod large;
mod locality;
mod neighbour_lists;
mod overlap;
mod queue;
mod schedule;
mod spatial;
mod species;
mod sync;

use super::exec::Exec;
use super::model::{Model, ModelKind};
use super::world::World;
use body::Bodies;
pub use eight_way::EightWay;
use event_loop::{EventLoop, Run};
pub use hooks::{Contact, Observer};
use locality::{Cells, Neighbours};
pub use queue::EventQueue;

/// Events (contacts, wall hits, relists, stale predictions) a step may take,
/// at least; scenes add [`EVENT_CAP_PER_SPHERE`] per sphere.
pub const EVENT_CAP_BASE: u64 = 1_000_000;
pub const EVENT_CAP_PER_SPHERE: u64 = 100;

/// The events a step of `n` spheres may take (its event cap).
#[must_use]
pub fn event_cap(n: usize) -> u64 {
    EVENT_CAP_BASE.saturating_add(EVENT_CAP_PER_SPHERE.saturating_mul(n as u64))
}

/// Above this packing fraction the locality is neighbour lists (a
/// sphere's free path is short, so it meets its skin's edge rarely and
/// checks fewer partners than 27 cells hold); below it, cells with crossing
/// events (a free path is long, and crossing a cell is cheaper than
/// rebuilding a list). Measured at N = 4000.
pub const LISTS_ABOVE_PACKING: f64 = 0.3;

/// From this many spheres on, the event loop prefetches (`prefetch_ahead`):
/// the model's arrays (about 125 B a sphere dilute, 200 dense) then
/// outgrow a core's own cache, and every record an event reads is a miss
/// worth starting early. Below it the prefetches are instructions for
/// nothing: at 10k they cost up to 15 % (dilute); at 20k they were level
/// dilute and 13 % faster dense, at 30k and up faster at every packing
/// (docs/perf-log.md, 2026-12-05).
pub const PREFETCH_FROM: usize = 20_000;

/// The model. Its event queue is the eight-way tournament, faster than the
/// binary one from 4k to 1M spheres and level at 4k dense; a calendar
/// measured slower but at 1M dilute (docs/perf-log.md, 2026-12-05 and
/// 2026-12-07).
#[derive(Default)]
pub struct Exact {
    /// The world last loaded, in the event loop of its locality (none
    /// before the first).
    run: Option<Box<dyn Run>>,
    /// What tests and examples turn ([`hooks`]).
    hooks: hooks::Hooks,
    /// Events processed since construction, by kind.
    pub stats: EventStats,
}

/// Events the loop has processed, by kind (for tuning and the benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventStats {
    pub pairs: u64,
    /// Contact predictions found stale (the partner moved on) when due.
    pub stale: u64,
    pub walls: u64,
    pub relists: u64,
    pub crossings: u64,
    /// Full rebuilds of the schedule (start, outside changes, capped steps).
    pub rebuilds: u64,
}

impl Exact {
    /// Bytes the model holds on the heap (its copy of the spheres, the
    /// schedule and the locality; not the world's own spheres).
    pub fn heap_bytes(&self) -> usize {
        self.run.as_ref().map_or(0, |r| r.heap_bytes())
    }

    /// Bytes the event queue holds on the heap (part of [`Self::heap_bytes`]).
    pub fn queue_heap_bytes(&self) -> usize {
        self.run.as_ref().map_or(0, |r| r.queue_heap_bytes())
    }
}

/// The run holding `world`: the one loaded if `world` is still the one it
/// wrote, or else `world` loaded anew. The one place the locality is
/// chosen, by packing fraction ([`LISTS_ABOVE_PACKING`]).
fn run_for<'a>(
    run: &'a mut Option<Box<dyn Run>>,
    world: &World,
    hooks: &hooks::Hooks,
    stats: &mut EventStats,
) -> &'a mut dyn Run {
    if !run.as_ref().is_some_and(|r| r.matches(world)) {
        // The old run goes first, so a load never holds two.
        *run = None;
    }
    &mut **run.get_or_insert_with(|| {
        let copy = sync::copy(world);
        if dense(&copy.1, world.size) {
            Box::new(EventLoop::<Neighbours>::load(world, copy, hooks, stats))
        } else {
            Box::new(EventLoop::<Cells>::load(world, copy, hooks, stats))
        }
    })
}

/// Whether `bodies` fill more than [`LISTS_ABOVE_PACKING`] of a box of side `size`.
fn dense(bodies: &Bodies, size: f64) -> bool {
    let filled: f64 = bodies
        .iter()
        .map(|b| crate::physics::sphere::volume(bodies.radius_of(b)))
        .sum();
    filled > LISTS_ABOVE_PACKING * size.powi(3)
}

impl Model for Exact {
    fn kind(&self) -> ModelKind {
        ModelKind::Exact
    }

    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, _exec: &dyn Exec) {
        if steps == 0 {
            return;
        }
        let run = run_for(&mut self.run, world, &self.hooks, &mut self.stats);
        run.advance(world, dt, steps, &mut self.hooks, &mut self.stats);
    }

    /// From the locality the next step uses anyway (see [`overlap`]); a
    /// world the model does not hold is loaded first, as that step would.
    fn max_overlap_rel(&mut self, world: &World, _dt: f64, exec: &dyn Exec) -> Option<f64> {
        let run = run_for(&mut self.run, world, &self.hooks, &mut self.stats);
        Some(run.deepest_overlap(exec))
    }
}
