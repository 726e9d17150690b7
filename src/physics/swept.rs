//! `swept`: the article's model done right. Each step finds the contacts it
//! can foresee — pairs that meet on straight paths within the step, spheres
//! that reach a wall — and processes them in time order, each sphere moved
//! only when touched (lazy update). Whenever a contact changes a velocity,
//! that sphere looks again for partners within its reach, so chains of
//! contacts inside a step are followed, not missed. The rest fly straight.
//! A pathological step (near jamming) is cut off by an event cap, finished
//! in free flight and counted in `capped_steps`.
use super::contact::{pair_toi, reflect_walls, resolve_pair, wall_toi};
use super::detect::{Detection, SPHERE_BLOCK};
use super::exec::{Exec, for_each_chunk};
use super::flight::fly;
use super::model::{Model, ModelKind};
use super::sphere::Sphere;
use super::world::World;
use glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

const NONE: u32 = u32::MAX;
/// Reach balls are widened by this much so touching spheres, whose distance
/// rounds either way, are always seen.
const REACH_SLACK: f64 = 1.0 + 1e-9;

#[derive(Default)]
pub struct Swept {
    detect: Detection,
    /// The spheres whose path reaches a wall this step.
    hits: Vec<u32>,
    /// Sphere index → local index among the spheres with events, or NONE.
    local: Vec<u32>,
    involved: Vec<u32>,
    t_local: Vec<f64>,
    count: Vec<u32>,
    /// Each sphere's ball for the step: it stays within `reach` of `centre`.
    centre: Vec<DVec3>,
    reach: Vec<f64>,
    /// How far each reach may grow before the grid can no longer find it.
    cap: Vec<f64>,
    grown: Vec<u32>,
    heap: BinaryHeap<Event>,
    found: Vec<u32>,
}

#[derive(Clone, Copy, Debug)]
struct Event {
    t: f64,
    a: u32,
    b: u32,
    ca: u32,
    cb: u32,
}

impl PartialEq for Event {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Event {
    /// Reversed so the heap pops the earliest; simultaneous events in a fixed
    /// order: lower local index first, pair events before wall events.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t)
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
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
            self.step(world, dt, exec);
            world.time += dt;
        }
    }
}

impl Swept {
    fn step(&mut self, world: &mut World, dt: f64, exec: &dyn Exec) {
        let size = world.size;
        let sp = &world.spheres;
        let meets = |i: u32, j: u32| {
            let (a, b) = (&sp[i as usize], &sp[j as usize]);
            pair_toi(a.pos - b.pos, a.vel - b.vel, a.radius + b.radius).is_some_and(|t| t <= dt)
        };
        self.detect
            .run(exec, sp, size, |s| path_ball(s, dt), &meets, &|s| {
                reaches_wall(s, size, dt)
            });
        self.detect.wall_hits(&mut self.hits);
        self.events(world, dt);
        // Everyone without an event flies straight and meets no wall.
        let local = &self.local;
        for_each_chunk(exec, &mut world.spheres, SPHERE_BLOCK, &|b, chunk| {
            for (k, s) in chunk.iter_mut().enumerate() {
                if local[b * SPHERE_BLOCK + k] == NONE {
                    s.pos += s.vel * dt;
                }
            }
        });
    }

    fn involve(&mut self, sp: &[Sphere], i: u32, dt: f64, size: f64) -> u32 {
        let l = self.local[i as usize];
        if l != NONE {
            return l;
        }
        let l = self.involved.len() as u32;
        let s = &sp[i as usize];
        self.local[i as usize] = l;
        self.involved.push(i);
        self.t_local.push(0.0);
        self.count.push(0);
        let (centre, reach) = path_ball(s, dt);
        self.centre.push(centre);
        self.reach.push(reach);
        self.cap.push(self.detect.grid.growth_cap(reach));
        push_wall(&mut self.heap, s, l, 0.0, 0, size, dt);
        l
    }

    /// Contacts in time order within `[0, dt]`; leaves every sphere with an
    /// event at `dt`, and `local` marking them.
    fn events(&mut self, world: &mut World, dt: f64) {
        for &i in &self.involved {
            self.local[i as usize] = NONE;
        }
        let n = world.spheres.len();
        self.local.resize(n, NONE);
        self.involved.clear();
        self.t_local.clear();
        self.count.clear();
        self.centre.clear();
        self.reach.clear();
        self.cap.clear();
        self.grown.clear();
        self.heap.clear();
        let size = world.size;
        let pairs = std::mem::take(&mut self.detect.pairs);
        let sp = &mut world.spheres;
        for &(i, j) in &pairs {
            let a = self.involve(sp, i, dt, size);
            let b = self.involve(sp, j, dt, size);
            let (si, sj) = (&sp[i as usize], &sp[j as usize]);
            if let Some(t) = pair_toi(si.pos - sj.pos, si.vel - sj.vel, si.radius + sj.radius) {
                self.heap.push(pair_event(t, a, b, 0, 0));
            }
        }
        self.detect.pairs = pairs;
        let hits = std::mem::take(&mut self.hits);
        for &i in &hits {
            self.involve(sp, i, dt, size);
        }
        self.hits = hits;
        let cap = 10_000 + 64 * self.involved.len();
        let mut done = 0usize;
        while let Some(e) = self.heap.pop() {
            if self.count[e.a as usize] != e.ca || (e.b != NONE && self.count[e.b as usize] != e.cb)
            {
                continue;
            }
            done += 1;
            if done > cap {
                world.counters.capped_steps += 1;
                break;
            }
            let ia = self.involved[e.a as usize] as usize;
            advance_to(&mut sp[ia], &mut self.t_local[e.a as usize], e.t);
            self.count[e.a as usize] += 1;
            if e.b == NONE {
                let (_, mask) = wall_toi(&sp[ia], size);
                let (imp, hits) = reflect_walls(&mut sp[ia], mask);
                world.counters.wall_momentum += imp;
                world.counters.wall_collisions += hits;
                self.rescan(sp, e.a, e.t, size, dt);
            } else {
                let ib = self.involved[e.b as usize] as usize;
                advance_to(&mut sp[ib], &mut self.t_local[e.b as usize], e.t);
                self.count[e.b as usize] += 1;
                let (x, y) = pair_mut(sp, ia, ib);
                if resolve_pair(x, y) {
                    world.counters.sphere_collisions += 1;
                }
                self.rescan(sp, e.a, e.t, size, dt);
                self.rescan(sp, e.b, e.t, size, dt);
            }
        }
        for l in 0..self.involved.len() {
            let s = &mut sp[self.involved[l] as usize];
            let (imp, hits) = fly(s, size, dt - self.t_local[l]);
            world.counters.wall_momentum += imp;
            world.counters.wall_collisions += hits;
        }
    }

    /// Sphere `a` changed velocity at `t`: widen its reach ball if its new
    /// path needs it, and schedule its next wall and every partner it can
    /// now meet before the step ends.
    fn rescan(&mut self, sp: &[Sphere], a: u32, t: f64, size: f64, dt: f64) {
        let la = a as usize;
        let ia = self.involved[la] as usize;
        let sa = sp[ia];
        let need = ((sa.pos - self.centre[la]).length() + sa.vel.length() * (dt - t) + sa.radius)
            * REACH_SLACK;
        // A sphere may grow up to its cap and still be found through the
        // grid; beyond that it joins `grown`, which every rescan checks.
        if need > self.reach[la] {
            if need > self.cap[la] && self.reach[la] <= self.cap[la] {
                self.grown.push(a);
            }
            self.reach[la] = need;
        }
        let ca = self.count[la];
        push_wall(&mut self.heap, &sa, a, t, ca, size, dt);
        let (p0, ra) = (self.centre[la], self.reach[la]);
        let mut found = std::mem::take(&mut self.found);
        found.clear();
        let local = &self.local;
        let reach = &self.reach;
        let mut consider = |j: u32, pj0: DVec3, rj: f64| {
            let rj = match local[j as usize] {
                NONE => rj,
                l => reach[l as usize],
            };
            if p0.distance_squared(pj0) <= (ra + rj) * (ra + rj) {
                found.push(j);
            }
        };
        self.detect.grid.near(p0, ra, &mut consider);
        for &g in &self.grown {
            let lg = g as usize;
            consider(self.involved[lg], self.centre[lg], self.reach[lg]);
        }
        found.sort_unstable();
        found.dedup();
        for &j in &found {
            if j as usize == ia {
                continue;
            }
            let s = &sp[j as usize];
            let since = match self.local[j as usize] {
                NONE => t,
                l => t - self.t_local[l as usize],
            };
            let pj = s.pos + s.vel * since;
            if let Some(dtc) = pair_toi(sa.pos - pj, sa.vel - s.vel, sa.radius + s.radius)
                && t + dtc <= dt
            {
                let b = self.involve(sp, j, dt, size);
                let cb = self.count[b as usize];
                self.heap.push(pair_event(t + dtc, a, b, ca, cb));
            }
        }
        self.found = found;
    }
}

/// Whether the straight path of `s` over `dt` leaves `[r, L - r]^3` (the
/// box is convex, so the end point tells), touching included.
#[inline]
fn reaches_wall(s: &Sphere, size: f64, dt: f64) -> bool {
    let end = s.pos + s.vel * dt;
    let (lo, hi) = (s.radius, size - s.radius);
    end.min_element() <= lo
        || end.max_element() >= hi
        || s.pos.min_element() <= lo
        || s.pos.max_element() >= hi
}

fn pair_event(t: f64, a: u32, b: u32, ca: u32, cb: u32) -> Event {
    if a < b {
        Event { t, a, b, ca, cb }
    } else {
        Event {
            t,
            a: b,
            b: a,
            ca: cb,
            cb: ca,
        }
    }
}

fn push_wall(
    heap: &mut BinaryHeap<Event>,
    s: &Sphere,
    a: u32,
    t: f64,
    ca: u32,
    size: f64,
    dt: f64,
) {
    let (tw, _) = wall_toi(s, size);
    if t + tw <= dt {
        heap.push(Event {
            t: t + tw,
            a,
            b: NONE,
            ca,
            cb: 0,
        });
    }
}

#[inline]
fn advance_to(s: &mut Sphere, t_local: &mut f64, t: f64) {
    s.pos += s.vel * (t - *t_local);
    *t_local = t;
}

pub(crate) fn pair_mut<T>(v: &mut [T], i: usize, j: usize) -> (&mut T, &mut T) {
    if i < j {
        let (lo, hi) = v.split_at_mut(j);
        (&mut lo[i], &mut hi[0])
    } else {
        let (lo, hi) = v.split_at_mut(i);
        (&mut hi[0], &mut lo[j])
    }
}
