//! `discrete`: move everything by `dt`, then find what overlaps and answer
//! with velocity impulses. Cheapest per step; spheres may overlap by up to
//! about `dt·speed` and fast ones can pass through each other (tunnelling).
//! Wall contacts mirror the position back inside (no energy is added: only
//! velocities carry energy). Overlaps are found on the moved positions,
//! before the wall mirror.
use super::contact::{reflect_axis, resolve_pair};
use super::detect::Detection;
use super::exec::Exec;
use super::flight::fly_straight;
use super::model::{Model, ModelKind};
use super::sphere::Sphere;
use super::world::World;

/// Overlapping pairs a step may answer: far more than spheres in contact
/// ever make (a dozen a sphere), far fewer than a heap of overlapping
/// spheres from a file (all pairs), whose list would fill the memory.
const PAIRS_BASE: usize = 20_000_000;
const PAIRS_PER_SPHERE: usize = 100;

/// The overlapping pairs a step of `n` spheres may answer; the engine's
/// overlap readout looks at no more either.
pub fn pair_budget(n: usize) -> usize {
    PAIRS_BASE.saturating_add(PAIRS_PER_SPHERE.saturating_mul(n))
}

#[derive(Default)]
pub struct Discrete {
    detect: Detection,
    /// The spheres found past a wall this step.
    hits: Vec<u32>,
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
        fly_straight(exec, &mut world.spheres, dt);
        let sp = &world.spheres;
        let overlapping = |i: u32, j: u32| {
            let (a, b) = (&sp[i as usize], &sp[j as usize]);
            let s = a.radius + b.radius;
            a.pos.distance_squared(b.pos) < s * s
        };
        // Sphere–sphere work (which pairs overlap) beside sphere–wall work
        // (which spheres are past a wall).
        self.detect.pair_limit = Some(pair_budget(sp.len()));
        self.detect
            .run(exec, sp, size, |s| (s.pos, s.radius), &overlapping, &|s| {
                outside(s, size)
            });
        self.detect.wall_hits(&mut self.hits);
        // Answers in a fixed order: walls, then pairs, whatever thread found
        // them; a sphere in several pairs sees them one after another.
        for &i in &self.hits {
            let (imp, hits) = bounce(&mut world.spheres[i as usize], size);
            world.counters.wall_momentum += imp;
            world.counters.wall_collisions += hits;
        }
        if self.detect.overran {
            // Too many to answer: this step answers none of them.
            world.counters.capped_steps += 1;
            world.counters.budget_steps += 1;
            return;
        }
        for &(i, j) in &self.detect.pairs {
            let Ok([a, b]) = world.spheres.get_disjoint_mut([i as usize, j as usize]) else {
                unreachable!("detection pairs two distinct spheres, got ({i}, {j})");
            };
            if resolve_pair(a, b) {
                world.counters.sphere_collisions += 1;
            }
        }
    }
}

fn outside(s: &Sphere, size: f64) -> bool {
    s.pos.min_element() < s.radius || s.pos.max_element() > size - s.radius
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
        imp += reflect_axis(s, k);
        hits += 1;
    }
    (imp, hits)
}
