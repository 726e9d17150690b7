//! `discrete`: move everything by `dt`, then find what overlaps and answer
//! with velocity impulses. Cheapest per step; spheres may overlap by up to
//! about `dt·speed` and fast ones can pass through each other (tunnelling).
//! Wall contacts mirror the position back inside (no energy is added: only
//! velocities carry energy).
use super::broad::{Grid, Pair};
use super::contact::resolve_pair;
use super::exec::{Exec, for_each_block};
use super::model::{Model, ModelKind};
use super::sphere::Sphere;
use super::swept::{SPHERE_BLOCK, pair_mut};
use super::world::World;
use parking_lot::Mutex;

#[derive(Default)]
pub struct Discrete {
    grid: Grid,
    pairs: Vec<Pair>,
    block_walls: Vec<Mutex<(f64, u64)>>,
}

impl Model for Discrete {
    fn kind(&self) -> ModelKind {
        ModelKind::Discrete
    }

    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec) {
        for _ in 0..steps {
            self.step(world, dt, exec);
            world.time += dt;
        }
    }
}

impl Discrete {
    fn step(&mut self, world: &mut World, dt: f64, exec: &dyn Exec) {
        let size = world.size;
        let blocks = world.spheres.len().div_ceil(SPHERE_BLOCK);
        while self.block_walls.len() < blocks {
            self.block_walls.push(Mutex::new((0.0, 0)));
        }
        {
            let chunks: Vec<Mutex<&mut [Sphere]>> = world
                .spheres
                .chunks_mut(SPHERE_BLOCK)
                .map(Mutex::new)
                .collect();
            let walls = &self.block_walls;
            for_each_block(exec, blocks, &|b| {
                let mut tally = (0.0, 0u64);
                for s in chunks[b].lock().iter_mut() {
                    s.pos += s.vel * dt;
                    let (imp, hits) = bounce(s, size);
                    tally.0 += imp;
                    tally.1 += hits;
                }
                *walls[b].lock() = tally;
            });
        }
        for w in &self.block_walls[..blocks] {
            let (imp, hits) = *w.lock();
            world.counters.wall_momentum += imp;
            world.counters.wall_collisions += hits;
        }
        self.grid.build(&world.spheres, size, |s| (s.pos, s.radius));
        let sp = &world.spheres;
        let overlapping = |i: u32, j: u32| {
            let (a, b) = (&sp[i as usize], &sp[j as usize]);
            let s = a.radius + b.radius;
            a.pos.distance_squared(b.pos) < s * s
        };
        self.grid.pairs(exec, &overlapping, &mut self.pairs);
        // Resolution in a fixed order: a sphere in several pairs sees them
        // one after another, whatever thread found them.
        for &(i, j) in &self.pairs {
            let (a, b) = pair_mut(&mut world.spheres, i as usize, j as usize);
            if resolve_pair(a, b) {
                world.counters.sphere_collisions += 1;
            }
        }
    }
}

/// A sphere past a wall and moving out is mirrored back in and reflected.
fn bounce(s: &mut Sphere, size: f64) -> (f64, u64) {
    let mut imp = 0.0;
    let mut hits = 0;
    for k in 0..3 {
        let (lo, hi) = (s.radius, size - s.radius);
        let v = s.vel[k];
        if s.pos[k] < lo && v < 0.0 {
            s.pos[k] = (2.0 * lo - s.pos[k]).min(hi.max(lo));
        } else if s.pos[k] > hi && v > 0.0 {
            s.pos[k] = (2.0 * hi - s.pos[k]).max(lo.min(hi));
        } else {
            continue;
        }
        s.vel[k] = -v;
        imp += 2.0 * s.mass * v.abs();
        hits += 1;
    }
    (imp, hits)
}
