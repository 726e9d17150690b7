//! What the physics tests compare to the bit, shared by the test files that
//! hold results identical across executors, budgets and engines.
use ballpit::physics::{Exec, World};

/// Every number of the state, as bits: the box, the time, every counter and
/// every field of every sphere.
pub fn bits(w: &World) -> Vec<u64> {
    let c = &w.counters;
    let mut v = vec![
        w.size.to_bits(),
        w.time.to_bits(),
        c.sphere_collisions,
        c.wall_collisions,
        c.wall_momentum.to_bits(),
        c.capped_steps,
        c.budget_steps,
    ];
    for s in &w.spheres {
        v.extend(s.pos.to_array().map(f64::to_bits));
        v.extend(s.vel.to_array().map(f64::to_bits));
        v.extend([s.radius.to_bits(), s.mass.to_bits()]);
    }
    v
}

/// Lanes run one after another, last first: an order no real pool has, so
/// a result that depends on the lanes' order shows.
pub struct Lanes(pub usize);

impl Exec for Lanes {
    fn lanes(&self) -> usize {
        self.0
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        (0..self.0).rev().for_each(f);
    }
    fn lane_cost(&self) -> usize {
        1
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        b();
        a();
    }
}
