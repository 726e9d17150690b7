//! The model's own copy of the world: loaded from it (in spatial order),
//! checked against it before each step, and written back after.
use super::body::Bodies;
use super::ids::WorldId;
use super::{Exact, schedule, spatial};
use crate::physics::world::World;

impl Exact {
    /// Whether `world` is the one we last wrote, untouched since: its
    /// generation (every edit from outside a model calls `World::touch`),
    /// time, size and count are those of our write-back. The edit signal
    /// is the generation alone, as for `swept`: no pass over the spheres.
    pub(super) fn matches(&self, world: &World) -> bool {
        self.valid
            && world.generation() == self.synced_generation
            && world.size == self.size
            && world.time == self.synced_time
            && world.spheres.len() == self.bodies.len()
    }

    pub(super) fn load(&mut self, world: &World) {
        // An event names its partner in 26 bits; a scene holds at most 10^7.
        assert!(
            world.spheres.len() <= schedule::MAX_SPHERES,
            "exact takes at most {} spheres",
            schedule::MAX_SPHERES
        );
        self.size = world.size;
        self.origin = world.time;
        self.synced_time = world.time;
        self.synced_generation = world.generation();
        let positions = world.spheres.iter().map(|s| s.pos);
        self.order = spatial::spatial_order(positions, world.size, WorldId::at);
        self.bodies =
            Bodies::from_spheres(self.order.iter().map(|&k| &world.spheres[k.index()]), 0.0);
        self.reschedule_all();
    }

    pub(super) fn write_back(&mut self, world: &mut World) {
        let now = world.time - self.origin;
        for (&k, b) in self.order.iter().zip(self.bodies.iter_mut()) {
            b.advance(now);
            let s = &mut world.spheres[k.index()];
            s.pos = b.pos;
            s.vel = b.vel;
        }
        self.synced_time = world.time;
        self.synced_generation = world.generation();
    }
}
