//! The event loop over one loaded world, generic over its [`Locality`]:
//! every contact, wall hit and locality event in time order, spheres moved
//! lazily between them. The model holds it behind [`Run`], which it asks
//! once a call, so the loop is compiled for each locality and its hot path
//! never asks which it has.
use super::body::Bodies;
use super::hooks::{self, Hooks};
use super::ids::{Label, WorldId};
use super::locality::Locality;
use super::schedule::Kind;
use super::{EightWay, EventQueue, EventStats, PREFETCH_FROM};
use crate::physics::contact::{reflect_walls, resolve_pair};
use crate::physics::exec::Exec;
use crate::physics::flight::fly;
use crate::physics::sphere::Sphere;
use crate::physics::world::{Counters, Stamp, World};

/// Internal times are kept relative to an origin that moves with the frames,
/// so lazy positions `x + v (t - t_i)` never subtract large times.
const ORIGIN_SPAN: f64 = 1.0;

/// What the model asks of the world it loaded, whichever its locality.
pub(super) trait Run: Send {
    /// Whether `world` is the one last written back, untouched since.
    fn matches(&self, world: &World) -> bool;
    /// `steps` steps of `dt`, written back to `world` after.
    fn advance(
        &mut self,
        world: &mut World,
        dt: f64,
        steps: u64,
        hooks: &mut Hooks,
        stats: &mut EventStats,
    );
    /// The deepest overlap, relative to the smaller radius ([`super::overlap`]).
    fn deepest_overlap(&self, exec: &dyn Exec) -> f64;
    /// Bytes held on the heap: the bodies, the queue and the locality.
    fn heap_bytes(&self) -> usize;
    /// Bytes the event queue holds on the heap.
    fn queue_heap_bytes(&self) -> usize;
}

pub(super) struct EventLoop<L> {
    pub(super) bodies: Bodies,
    /// World index of each body: bodies are kept in a spatial order (sorted
    /// by cell when loaded), so neighbours sit close in memory and a
    /// prediction touches few cache lines.
    pub(super) order: Vec<WorldId>,
    pub(super) queue: EightWay,
    /// The spheres each sphere could meet next, and each sphere's event.
    pub(super) locality: L,
    pub(super) size: f64,
    /// Absolute time of internal time zero.
    pub(super) origin: f64,
    /// The stamp of the world the bodies were last written to.
    pub(super) synced: Stamp,
    pub(super) valid: bool,
    /// Whether the loop prefetches ([`PREFETCH_FROM`]).
    pub(super) prefetching: bool,
}

impl<L: Locality> EventLoop<L> {
    fn event_cap(&self, hooks: &Hooks) -> u64 {
        hooks.event_cap(super::event_cap(self.bodies.len()))
    }

    /// A new locality and a prediction for every sphere, at the bodies'
    /// common time stamp.
    pub(super) fn reschedule_all(&mut self, hooks: &Hooks, stats: &mut EventStats) {
        stats.rebuilds += 1;
        let n = self.bodies.len();
        for b in self.bodies.iter_mut() {
            b.count = 0;
        }
        // The old locality goes first, so a rebuild never holds two.
        self.locality = L::default();
        self.locality = L::new(&self.bodies, self.size, hooks);
        self.prefetching = hooks.prefetching(n >= PREFETCH_FROM);
        self.queue.reset(n);
        for i in self.bodies.labels() {
            let t = if self.prefetching {
                self.locality.predict::<true>(i, &self.bodies, self.size)
            } else {
                self.locality.predict::<false>(i, &self.bodies, self.size)
            };
            self.queue.set_leaf(i.index(), t);
        }
        self.queue.rebuild();
        self.valid = true;
    }

    #[inline]
    fn schedule<const PF: bool>(&mut self, i: Label) {
        let t = self.locality.predict::<PF>(i, &self.bodies, self.size);
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
        self.locality.shift(now);
        self.origin = world_time;
    }

    /// Process every event up to internal time `target`. Returns false if the
    /// cap stopped it first.
    // Never inlined: profilers count the event loop by this name.
    #[inline(never)]
    fn run_until<const PF: bool>(
        &mut self,
        target: f64,
        c: &mut Counters,
        hooks: &mut Hooks,
        stats: &mut EventStats,
    ) -> bool {
        let cap = self.event_cap(hooks);
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
            let ev = self.locality.queued(i);
            // The sphere whose event is likely next (none without prefetching).
            let next = if PF { self.prefetch_ahead(i, ev) } else { None };
            self.bodies[i].advance(t);
            match ev.kind() {
                Kind::Pair => {
                    let j = ev.partner();
                    if self.bodies[j].count != ev.partner_count() {
                        stats.stale += 1;
                        self.schedule::<PF>(i);
                        continue;
                    }
                    stats.pairs += 1;
                    self.bodies[j].advance(t);
                    self.collide(i, j, c, hooks);
                    if PF {
                        // Its misses then wait beside `i`'s prediction's.
                        self.locality.prefetch_around(j, &self.bodies);
                    }
                    let ti = self.locality.predict::<PF>(i, &self.bodies, self.size);
                    let tj = self.locality.predict::<PF>(j, &self.bodies, self.size);
                    self.queue.update_two(i.index(), ti, j.index(), tj);
                }
                Kind::Wall => {
                    stats.walls += 1;
                    let mut s = self.bodies.sphere(i);
                    let mask = ev.mask();
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
                    stats.relists += 1;
                    self.locality.relist(i, &self.bodies);
                    self.schedule::<PF>(i);
                }
                Kind::Cross => {
                    stats.crossings += 1;
                    let t = self
                        .locality
                        .cross::<PF>(i, ev.mask(), next, &self.bodies, self.size);
                    self.queue.update(i.index(), t);
                }
                // An idle sphere's time is infinite: it is never popped
                // before the end of a step, and nothing happens to it.
                Kind::Idle => {}
            }
        }
    }

    fn collide(&mut self, i: Label, j: Label, c: &mut Counters, hooks: &mut Hooks) {
        let mut a = self.bodies.sphere(i);
        let mut b = self.bodies.sphere(j);
        let before = [a.vel, b.vel];
        if resolve_pair(&mut a, &mut b) {
            c.sphere_collisions += 1;
            // The contact is made only for an observer (none when shipped).
            hooks.observe(|| {
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

impl<L: Locality> Run for EventLoop<L> {
    fn matches(&self, world: &World) -> bool {
        EventLoop::matches(self, world)
    }

    fn advance(
        &mut self,
        world: &mut World,
        dt: f64,
        steps: u64,
        hooks: &mut Hooks,
        stats: &mut EventStats,
    ) {
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
                self.reschedule_all(hooks, stats);
            }
            let c = &mut world.counters;
            let finished = if self.prefetching {
                self.run_until::<true>(target, c, hooks, stats)
            } else {
                self.run_until::<false>(target, c, hooks, stats)
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

    fn deepest_overlap(&self, exec: &dyn Exec) -> f64 {
        self.locality.deepest_overlap(&self.bodies, exec)
    }

    fn heap_bytes(&self) -> usize {
        self.bodies.heap_bytes()
            + self.order.capacity() * size_of::<WorldId>()
            + self.queue.heap_bytes()
            + self.locality.heap_bytes()
    }

    fn queue_heap_bytes(&self) -> usize {
        self.queue.heap_bytes()
    }
}

/// A sphere at a wall event, put on the walls of the axes it hits exactly:
/// lazy positions never drift out.
fn onto_walls(s: &mut Sphere, mask: u8, size: f64) {
    for k in 0..3 {
        if mask & (1 << k) != 0 && s.vel[k] != 0.0 {
            s.pos[k] = if s.vel[k] < 0.0 {
                s.radius
            } else {
                size - s.radius
            };
        }
    }
}
