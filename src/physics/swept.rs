//! `swept`: the article's model done right. Within a step, the pairs that can
//! meet (their reach spheres overlap at the start of the step) are found once;
//! their contacts are then processed in time order, each sphere advanced only
//! when touched, until the step is used up. Spheres with no partner in reach
//! fly in closed form. A contact with a sphere that was out of reach at the
//! start of the step (a chain the step did not foresee) is missed: that is
//! the model's trade against `exact`.
use super::broad::{Grid, Pair};
use super::contact::{pair_toi, reflect_walls, resolve_pair, wall_toi};
use super::exec::{Exec, for_each_block};
use super::flight::fly;
use super::model::{Model, ModelKind};
use super::sphere::Sphere;
use super::world::{Counters, World};
use parking_lot::Mutex;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Spheres per parallel block for flight; fixed so sums never depend on the
/// number of threads.
pub(crate) const SPHERE_BLOCK: usize = 2048;
const NONE: u32 = u32::MAX;

#[derive(Default)]
pub struct Swept {
    grid: Grid,
    pairs: Vec<Pair>,
    local: Vec<u32>,
    involved: Vec<u32>,
    t_local: Vec<f64>,
    count: Vec<u32>,
    adj_start: Vec<u32>,
    adj: Vec<u32>,
    heap: BinaryHeap<Event>,
    flown: Vec<(Sphere, f64, u64)>,
    block_walls: Vec<Mutex<(f64, u64)>>,
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
    /// Reversed: the heap pops the earliest; ties in a fixed order (lower
    /// sphere first, wall events after pair events of the same sphere).
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t)
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
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
        let n = world.spheres.len();
        self.grid
            .build(&world.spheres, size, |s| s.radius + s.vel.length() * dt);
        let blocks = n.div_ceil(SPHERE_BLOCK);
        while self.block_walls.len() < blocks {
            self.block_walls.push(Mutex::new((0.0, 0)));
        }
        if exec.functional() {
            // Functional decomposition: sphere–sphere work (which pairs can
            // meet) beside sphere–wall work (every sphere's flight, kept for
            // the ones that turn out to have no partner).
            let serial = super::exec::Serial;
            let detect = Mutex::new((&mut self.grid, &mut self.pairs));
            let flown = Mutex::new(&mut self.flown);
            let spheres = &world.spheres;
            exec.join(
                &|| {
                    let mut g = detect.lock();
                    let (grid, pairs) = &mut *g;
                    grid.pairs(&serial, &|_, _| true, pairs);
                },
                &|| {
                    let mut out = flown.lock();
                    out.clear();
                    out.extend(spheres.iter().map(|s| {
                        let mut s = *s;
                        let (imp, hits) = fly(&mut s, size, dt);
                        (s, imp, hits)
                    }));
                },
            );
            self.mark_involved(n);
            // Same sums in the same order as the block path below.
            let mut total = (0.0, 0u64);
            for (b, chunk) in self.flown.chunks(SPHERE_BLOCK).enumerate() {
                let mut tally = (0.0, 0u64);
                for (k, (s, imp, hits)) in chunk.iter().enumerate() {
                    let i = b * SPHERE_BLOCK + k;
                    if self.local[i] == NONE {
                        world.spheres[i] = *s;
                        tally.0 += imp;
                        tally.1 += hits;
                    }
                }
                total.0 += tally.0;
                total.1 += tally.1;
            }
            add_walls(&mut world.counters, total);
        } else {
            self.grid.pairs(exec, &|_, _| true, &mut self.pairs);
            self.mark_involved(n);
            fly_blocks(
                &mut world.spheres,
                Some(&self.local),
                size,
                dt,
                &self.block_walls,
                exec,
            );
            add_walls(&mut world.counters, sum_walls(&self.block_walls[..blocks]));
        }
        self.events(world, dt);
    }

    /// Give every sphere in a candidate pair a local index, in pair order.
    fn mark_involved(&mut self, n: usize) {
        for &i in &self.involved {
            self.local[i as usize] = NONE;
        }
        self.local.resize(n, NONE);
        self.involved.clear();
        for &(i, j) in &self.pairs {
            for k in [i, j] {
                if self.local[k as usize] == NONE {
                    self.local[k as usize] = self.involved.len() as u32;
                    self.involved.push(k);
                }
            }
        }
        let m = self.involved.len();
        self.adj_start.clear();
        self.adj_start.resize(m + 1, 0);
        for &(i, j) in &self.pairs {
            self.adj_start[self.local[i as usize] as usize + 1] += 1;
            self.adj_start[self.local[j as usize] as usize + 1] += 1;
        }
        for k in 0..m {
            self.adj_start[k + 1] += self.adj_start[k];
        }
        self.adj.clear();
        self.adj.resize(self.adj_start[m] as usize, 0);
        let mut fill = self.adj_start[..m].to_vec();
        for &(i, j) in &self.pairs {
            let (a, b) = (self.local[i as usize], self.local[j as usize]);
            self.adj[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            self.adj[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
    }

    /// Contacts among the involved spheres, in time order, within `[0, dt]`.
    fn events(&mut self, world: &mut World, dt: f64) {
        let m = self.involved.len();
        if m == 0 {
            return;
        }
        let size = world.size;
        self.t_local.clear();
        self.t_local.resize(m, 0.0);
        self.count.clear();
        self.count.resize(m, 0);
        self.heap.clear();
        let sp = &mut world.spheres;
        for &(i, j) in &self.pairs {
            let (a, b) = (self.local[i as usize], self.local[j as usize]);
            let (si, sj) = (&sp[i as usize], &sp[j as usize]);
            if let Some(t) = pair_toi(si.pos - sj.pos, si.vel - sj.vel, si.radius + sj.radius)
                && t <= dt
            {
                let (a, b) = (a.min(b), a.max(b));
                self.heap.push(Event {
                    t,
                    a,
                    b,
                    ca: 0,
                    cb: 0,
                });
            }
        }
        for a in 0..m as u32 {
            push_wall(
                &mut self.heap,
                &sp[self.involved[a as usize] as usize],
                a,
                0.0,
                0,
                size,
                dt,
            );
        }
        let cap = 10_000 + 64 * m;
        let mut done = 0usize;
        let c = &mut world.counters;
        while let Some(e) = self.heap.pop() {
            if self.count[e.a as usize] != e.ca || (e.b != NONE && self.count[e.b as usize] != e.cb)
            {
                continue;
            }
            done += 1;
            if done > cap {
                c.capped_steps += 1;
                break;
            }
            let ia = self.involved[e.a as usize] as usize;
            advance_to(&mut sp[ia], &mut self.t_local[e.a as usize], e.t);
            if e.b == NONE {
                let (_, mask) = wall_toi(&sp[ia], size);
                let (imp, hits) = reflect_walls(&mut sp[ia], mask);
                c.wall_momentum += imp;
                c.wall_collisions += hits;
                self.count[e.a as usize] += 1;
                self.reschedule(sp, e.a, e.t, size, dt);
            } else {
                let ib = self.involved[e.b as usize] as usize;
                advance_to(&mut sp[ib], &mut self.t_local[e.b as usize], e.t);
                let (x, y) = pair_mut(sp, ia, ib);
                if resolve_pair(x, y) {
                    c.sphere_collisions += 1;
                }
                self.count[e.a as usize] += 1;
                self.count[e.b as usize] += 1;
                self.reschedule(sp, e.a, e.t, size, dt);
                self.reschedule(sp, e.b, e.t, size, dt);
            }
        }
        for a in 0..m {
            let s = &mut sp[self.involved[a] as usize];
            let (imp, hits) = fly(s, size, dt - self.t_local[a]);
            c.wall_momentum += imp;
            c.wall_collisions += hits;
        }
    }

    fn reschedule(&mut self, sp: &[Sphere], a: u32, t: f64, size: f64, dt: f64) {
        let ids = &self.involved;
        let sa = &sp[ids[a as usize] as usize];
        let ca = self.count[a as usize];
        push_wall(&mut self.heap, sa, a, t, ca, size, dt);
        let range = self.adj_start[a as usize] as usize..self.adj_start[a as usize + 1] as usize;
        for &b in &self.adj[range] {
            let sb = &sp[ids[b as usize] as usize];
            let pb = sb.pos + sb.vel * (t - self.t_local[b as usize]);
            if let Some(dtc) = pair_toi(sa.pos - pb, sa.vel - sb.vel, sa.radius + sb.radius)
                && t + dtc <= dt
            {
                let cb = self.count[b as usize];
                let (x, y, cx, cy) = if a < b {
                    (a, b, ca, cb)
                } else {
                    (b, a, cb, ca)
                };
                self.heap.push(Event {
                    t: t + dtc,
                    a: x,
                    b: y,
                    ca: cx,
                    cb: cy,
                });
            }
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

/// Closed-form flight for every sphere (or, with `skip`, every sphere whose
/// entry is `NONE`), block-parallel, wall tallies per block.
fn fly_blocks(
    spheres: &mut [Sphere],
    skip: Option<&[u32]>,
    size: f64,
    dt: f64,
    walls: &[Mutex<(f64, u64)>],
    exec: &dyn Exec,
) {
    let chunks: Vec<Mutex<&mut [Sphere]>> =
        spheres.chunks_mut(SPHERE_BLOCK).map(Mutex::new).collect();
    for_each_block(exec, chunks.len(), &|b| {
        let mut chunk = chunks[b].lock();
        let mut tally = (0.0, 0u64);
        for (k, s) in chunk.iter_mut().enumerate() {
            if skip.is_some_and(|l| l[b * SPHERE_BLOCK + k] != NONE) {
                continue;
            }
            let (imp, hits) = fly(s, size, dt);
            tally.0 += imp;
            tally.1 += hits;
        }
        *walls[b].lock() = tally;
    });
}

fn sum_walls(walls: &[Mutex<(f64, u64)>]) -> (f64, u64) {
    walls.iter().fold((0.0, 0), |acc, w| {
        let w = *w.lock();
        (acc.0 + w.0, acc.1 + w.1)
    })
}

fn add_walls(c: &mut Counters, (imp, hits): (f64, u64)) {
    c.wall_momentum += imp;
    c.wall_collisions += hits;
}
