//! `exact`: event-driven hard spheres. Every contact is processed in time
//! order; between events spheres fly in straight lines. Built the way the
//! fast hard-sphere codes are (Rapaport; `DynamO`; Smallenburg's EDMD):
//!
//! - lazy update: each sphere carries its own time stamp ([`body`]) and is
//!   moved only when an event touches it or when `advance` returns;
//! - one pending event per sphere (the earliest of contact, wall, or its
//!   broad-phase event), in an [`EventQueue`] (a tournament tree of eight
//!   children a node, [`EightWay`]);
//! - a broad phase chosen by packing fraction ([`LISTS_ABOVE_PACKING`]):
//!   a cell grid with cell-crossing events for dilute and moderate scenes
//!   ([`cell_grid`]), neighbour lists with a skin for dense ones
//!   (`neighbour_lists`); both keep the few spheres far larger than the
//!   bulk on a second level (`large`), so radii 100x apart stay cheap;
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
//! own candidates tie its broad-phase
//! event (relist or crossing) first, then walls, then partners in the order
//! the broad phase offers them.
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
pub mod body;
pub mod cell_grid;
mod eight_way;
mod hooks;
mod ids;
mod large;
mod neighbour_lists;
mod overlap;
mod queue;
pub mod schedule;
mod spatial;
mod species;
mod sync;

use super::contact::{reflect_walls, resolve_pair};
use super::exec::Exec;
use super::flight::fly;
use super::model::{Model, ModelKind};
use super::sphere::Sphere;
use super::world::{Counters, World};
use ahead::prefetch_next_crossing;
use body::Bodies;
use cell_grid::CellGrid;
pub use eight_way::EightWay;
pub use hooks::{Contact, Observer};
use ids::{Label, WorldId};
use neighbour_lists::NeighbourLists;
pub use queue::EventQueue;
use schedule::{Event, Kind, Predictor, Queued, Slot};

/// Events (contacts, wall hits, relists, stale predictions) a step may take,
/// at least; scenes add [`EVENT_CAP_PER_SPHERE`] per sphere.
pub const EVENT_CAP_BASE: u64 = 1_000_000;
pub const EVENT_CAP_PER_SPHERE: u64 = 100;
/// Internal times are kept relative to an origin that moves with the frames,
/// so lazy positions `x + v (t - t_i)` never subtract large times.
const ORIGIN_SPAN: f64 = 1.0;

/// Above this packing fraction the broad phase is neighbour lists (a
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

/// Which broad phase the schedule uses; chosen from the packing fraction at
/// each rebuild.
#[derive(Clone, Debug)]
enum Broad {
    Lists(Box<NeighbourLists>),
    Cells(Box<CellGrid>),
}

impl Default for Broad {
    fn default() -> Self {
        Broad::Cells(Box::default())
    }
}

/// The model. Its event queue is the eight-way tournament, faster than the
/// binary one from 4k to 1M spheres and level at 4k dense; a calendar
/// measured slower but at 1M dilute (docs/perf-log.md, 2026-12-05 and
/// 2026-12-07).
#[derive(Default)]
pub struct Exact {
    bodies: Bodies,
    /// World index of each body: bodies are kept in a spatial order (sorted
    /// by cell when loaded), so neighbours sit close in memory and a
    /// prediction touches few cache lines.
    order: Vec<WorldId>,
    /// Cell mode: each sphere's best contact or wall event and its
    /// (absolute) time, kept apart from its crossing so a crossing rescans
    /// only new cells. Empty with neighbour lists.
    slots: Vec<Slot>,
    /// Cell mode: which of its two events the queue holds for each sphere.
    /// A byte apart from the slots (1 MB at a million, which stays in a
    /// core's cache), so a crossing can read the next sphere's at once.
    holds: Vec<Queued>,
    /// With neighbour lists: each sphere's event, whose time the queue
    /// alone keeps (8 bytes a sphere less than a slot). Empty in cell mode.
    events: Vec<Event>,
    queue: EightWay,
    broad: Broad,
    /// Scratch for the candidates a prediction gathers: labels, as the
    /// cell grid packs them ([`Label::raw`]).
    candidates: Vec<u32>,
    size: f64,
    /// Absolute time of internal time zero.
    origin: f64,
    /// World time the bodies were last written back at.
    synced_time: f64,
    /// `World::generation` of the world they were last written to.
    synced_generation: u64,
    valid: bool,
    /// Whether the loop prefetches ([`PREFETCH_FROM`]).
    prefetching: bool,
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
    /// schedule and the broad phase; not the world's own spheres).
    pub fn heap_bytes(&self) -> usize {
        let broad = match &self.broad {
            Broad::Lists(nl) => nl.heap_bytes(),
            Broad::Cells(cells) => cells.heap_bytes(),
        };
        self.bodies.heap_bytes()
            + self.order.capacity() * size_of::<WorldId>()
            + self.candidates.capacity() * size_of::<u32>()
            + self.slots.capacity() * size_of::<Slot>()
            + self.holds.capacity() * size_of::<Queued>()
            + self.events.capacity() * size_of::<Event>()
            + self.queue.heap_bytes()
            + broad
    }

    /// Bytes the event queue holds on the heap (part of [`Self::heap_bytes`]).
    pub fn queue_heap_bytes(&self) -> usize {
        self.queue.heap_bytes()
    }

    fn event_cap(&self) -> u64 {
        let cap = EVENT_CAP_BASE + EVENT_CAP_PER_SPHERE * self.bodies.len() as u64;
        self.hooks.event_cap(cap)
    }

    /// New neighbour lists and a prediction for every sphere, at the bodies'
    /// common time stamp.
    fn reschedule_all(&mut self) {
        self.stats.rebuilds += 1;
        let n = self.bodies.len();
        for b in self.bodies.iter_mut() {
            b.count = 0;
        }
        // The old broad phase and events go first, so a rebuild never holds two.
        self.broad = Broad::default();
        (self.slots, self.holds, self.events) = (Vec::new(), Vec::new(), Vec::new());
        let filled: f64 = self
            .bodies
            .iter()
            .map(|b| crate::physics::sphere::volume(self.bodies.radius_of(b)))
            .sum();
        if filled > LISTS_ABOVE_PACKING * self.size.powi(3) {
            let mut nl = Box::<NeighbourLists>::default();
            nl.build(&self.bodies, self.size);
            self.broad = Broad::Lists(nl);
            self.events = super::huge_pages::filled(n, Event::default());
        } else {
            self.slots = super::huge_pages::filled(n, Slot::default());
            self.holds = super::huge_pages::filled(n, Queued::PENDING);
            let mut cells = Box::<CellGrid>::default();
            cells.build(&self.bodies, self.size, self.hooks.cells_per_sphere());
            self.broad = Broad::Cells(cells);
        }
        self.prefetching = self.hooks.prefetching(n >= PREFETCH_FROM);
        self.queue.reset(n);
        for i in self.bodies.labels() {
            let t = if self.prefetching {
                self.predict::<true>(i)
            } else {
                self.predict::<false>(i)
            };
            self.queue.set_leaf(i.index(), t);
        }
        self.queue.rebuild();
        self.valid = true;
    }

    /// Sphere `i`'s next event, into its slot; returns its absolute time.
    /// `PF`: whether to prefetch ([`PREFETCH_FROM`]; a parameter, so the
    /// loop has no test for it).
    #[inline]
    fn predict<const PF: bool>(&mut self, i: Label) -> f64 {
        let a = &self.bodies[i];
        match &self.broad {
            Broad::Lists(nl) => {
                let relist = Event::of(Kind::Relist, 0);
                let t = nl.relist_time(i, a);
                // No prefetch here: the loop asked for these bodies as the
                // event began (a relist has just read them).
                let mut p = Predictor::new(a, &self.bodies, self.size, t, relist);
                for l in nl.of(i) {
                    p.pair(l.j);
                }
                let (t, ev) = p.finish();
                self.events[i.index()] = ev;
                t
            }
            Broad::Cells(cells) => {
                let idle = Event::default();
                let mut p = Predictor::new(a, &self.bodies, self.size, f64::INFINITY, idle);
                let n = cells.candidates(i, p.radius(), &mut self.candidates);
                if PF {
                    self.bodies.prefetch(&self.candidates[..n]);
                }
                for &j in &self.candidates[..n] {
                    if j != i.raw() {
                        p.pair(Label::from_raw(j));
                    }
                }
                let slot = &mut self.slots[i.index()];
                with_crossing(cells, slot, &mut self.holds[i.index()], p.finish(), i, a)
            }
        }
    }

    #[inline]
    fn schedule<const PF: bool>(&mut self, i: Label) {
        let t = self.predict::<PF>(i);
        self.queue.update(i.index(), t);
    }

    /// Cell mode: sphere `i` crosses into the next cell as `mask` says. Its
    /// pending event still holds unless its partner has moved on; only the
    /// layer of cells the crossing brings next to it needs checking.
    fn cross<const PF: bool>(&mut self, i: Label, mask: u8, next: Option<Label>) {
        let Broad::Cells(cells) = &mut self.broad else {
            // Only cells have crossings; any other broad phase predicts anew.
            self.schedule::<PF>(i);
            return;
        };
        let n = cells.next_layer(i, mask, &mut self.candidates);
        if PF {
            self.bodies.prefetch(&self.candidates[..n]);
        }
        cells.cross(i, mask);
        if PF {
            prefetch_next_crossing(cells, &self.holds, next);
        }
        let (tp, evp) = self.slots[i.index()].pending();
        if evp.kind() == Kind::Pair && self.bodies[evp.partner()].count != evp.partner_count() {
            self.schedule::<PF>(i);
            return;
        }
        let a = &self.bodies[i];
        let mut p = Predictor::resume(a, &self.bodies, tp - a.t, evp);
        for &j in &self.candidates[..n] {
            p.pair(Label::from_raw(j));
        }
        let slot = &mut self.slots[i.index()];
        let t = with_crossing(cells, slot, &mut self.holds[i.index()], p.finish(), i, a);
        self.queue.update(i.index(), t);
    }

    /// Move the time origin to `world_time`: every body is moved to it first.
    fn reorigin(&mut self, world_time: f64) {
        let now = world_time - self.origin;
        if now == 0.0 {
            return;
        }
        for b in self.bodies.iter_mut() {
            b.advance(now);
            b.t = 0.0;
        }
        self.queue.shift(now);
        // Only cell mode keeps times in the slots (lists have none).
        for p in &mut self.slots {
            p.t -= now;
        }
        self.origin = world_time;
    }

    /// The event the queue holds for sphere `i`.
    #[inline(always)]
    fn queued(&self, i: Label) -> Event {
        match self.broad {
            Broad::Lists(_) => self.events[i.index()],
            Broad::Cells(_) => self.slots[i.index()].queued(self.holds[i.index()]),
        }
    }

    /// Process every event up to internal time `target`. Returns false if the
    /// cap stopped it first.
    // Never inlined: profilers count the event loop by this name.
    #[inline(never)]
    fn run_until<const PF: bool>(&mut self, target: f64, c: &mut Counters) -> bool {
        let cap = self.event_cap();
        let mut done = 0u64;
        loop {
            let (t, i) = self.queue.peek();
            let i = Label::at(i);
            if t.is_nan() || t > target {
                return true;
            }
            if done == cap {
                return false;
            }
            done += 1;
            let ev = self.queued(i);
            // The sphere whose event is likely next (none without prefetching).
            let next = if PF { self.prefetch_ahead(i, ev) } else { None };
            self.bodies[i].advance(t);
            match ev.kind() {
                Kind::Pair => {
                    let j = ev.partner();
                    if self.bodies[j].count != ev.partner_count() {
                        self.stats.stale += 1;
                        self.schedule::<PF>(i);
                        continue;
                    }
                    self.stats.pairs += 1;
                    self.bodies[j].advance(t);
                    self.collide(i, j, c);
                    if PF {
                        // Its misses then wait beside `i`'s prediction's.
                        self.prefetch_neighbours(j);
                    }
                    let ti = self.predict::<PF>(i);
                    let tj = self.predict::<PF>(j);
                    self.queue.update_two(i.index(), ti, j.index(), tj);
                }
                Kind::Wall => {
                    self.stats.walls += 1;
                    let mut s = self.bodies.sphere(i);
                    let mask = [ev.mask() & 1 != 0, ev.mask() & 2 != 0, ev.mask() & 4 != 0];
                    onto_walls(&mut s, mask, self.size);
                    let (imp, hits) = reflect_walls(&mut s, mask);
                    let b = &mut self.bodies[i];
                    b.pos = s.pos;
                    b.vel = s.vel;
                    b.count = b.count.wrapping_add(1);
                    c.wall_momentum += imp;
                    c.wall_collisions += hits;
                    self.schedule::<PF>(i);
                }
                Kind::Relist => {
                    self.stats.relists += 1;
                    match &mut self.broad {
                        Broad::Lists(nl) => nl.rebuild(i, &self.bodies),
                        Broad::Cells(cells) => cells.rescan(i, &self.bodies[i]),
                    }
                    self.schedule::<PF>(i);
                }
                Kind::Cross => {
                    self.stats.crossings += 1;
                    self.cross::<PF>(i, ev.mask(), next);
                }
                // An idle sphere's time is infinite: it is never popped
                // before the end of a step, and nothing happens to it.
                Kind::Idle => {}
            }
        }
    }

    fn collide(&mut self, i: Label, j: Label, c: &mut Counters) {
        let mut a = self.bodies.sphere(i);
        let mut b = self.bodies.sphere(j);
        let before = [a.vel, b.vel];
        if resolve_pair(&mut a, &mut b) {
            c.sphere_collisions += 1;
            // The contact is made only for an observer (none when shipped).
            self.hooks.observe(|| {
                let time = self.origin + self.bodies[i].t;
                hooks::contact(&self.order, time, (i, j), [&a, &b], before)
            });
        }
        for (k, v) in [(i, a.vel), (j, b.vel)] {
            let body = &mut self.bodies[k];
            body.vel = v;
            body.count = body.count.wrapping_add(1);
        }
    }

    /// After a capped step: finish it by free flight with wall bounces.
    fn fly_all(&mut self, target: f64, c: &mut Counters) {
        for i in self.bodies.labels() {
            let mut s = self.bodies.sphere(i);
            let (imp, hits) = fly(&mut s, self.size, target - self.bodies[i].t);
            c.wall_momentum += imp;
            c.wall_collisions += hits;
            let b = &mut self.bodies[i];
            (b.pos, b.vel, b.t) = (s.pos, s.vel, target);
        }
    }
}

impl Model for Exact {
    fn kind(&self) -> ModelKind {
        ModelKind::Exact
    }

    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, _exec: &dyn Exec) {
        if steps == 0 {
            return;
        }
        if !self.matches(world) {
            self.load(world);
        }
        for _ in 0..steps {
            let end = world.time + dt;
            if end - self.origin > ORIGIN_SPAN {
                self.reorigin(world.time);
            }
            let target = end - self.origin;
            if !self.valid {
                for b in self.bodies.iter_mut() {
                    b.advance(world.time - self.origin);
                }
                self.reschedule_all();
            }
            let finished = if self.prefetching {
                self.run_until::<true>(target, &mut world.counters)
            } else {
                self.run_until::<false>(target, &mut world.counters)
            };
            if !finished {
                world.counters.capped_steps += 1;
                self.fly_all(target, &mut world.counters);
                self.valid = false;
            }
            world.time = end;
        }
        self.write_back(world);
    }

    /// From the broad phase the next step uses anyway (see [`overlap`]); a
    /// world the model does not hold is loaded first, as that step would.
    fn max_overlap_rel(&mut self, world: &World, _dt: f64, exec: &dyn Exec) -> Option<f64> {
        if !self.matches(world) {
            self.load(world);
        }
        Some(self.deepest_overlap(exec))
    }
}

/// Cell mode: sphere `i`'s pending event `(tp, pending)` kept in `slot`,
/// and the earlier of it and its next crossing (the crossing first on a
/// tie) marked in `holds`; returns that one's time.
#[inline]
fn with_crossing(
    cells: &CellGrid,
    slot: &mut Slot,
    holds: &mut Queued,
    (tp, pending): (f64, Event),
    i: Label,
    a: &body::Body,
) -> f64 {
    *slot = Slot { t: tp, ev: pending };
    let (tc, ev) = cells.next_event(i, a);
    let tc = a.t + tc;
    // By index: which comes first is random, and a branch on it
    // mispredicted a third of the time.
    let first = usize::from(tc <= tp);
    *holds = [Queued::PENDING, Queued::broad(&ev)][first];
    [tp, tc][first]
}

/// A sphere at a wall event, put on the walls of the axes it hits exactly:
/// lazy positions never drift out.
fn onto_walls(s: &mut Sphere, mask: [bool; 3], size: f64) {
    for (k, &hit) in mask.iter().enumerate() {
        if hit && s.vel[k] != 0.0 {
            s.pos[k] = if s.vel[k] < 0.0 {
                s.radius
            } else {
                size - s.radius
            };
        }
    }
}
