//! The model's own copy of the world: loaded from it (in spatial order),
//! checked against it before each step, and written back after.
use super::body::Bodies;
use super::event_loop::EventLoop;
use super::hooks::Hooks;
use super::ids::WorldId;
use super::locality::Locality;
use super::{EventStats, schedule, spatial};
use crate::physics::world::World;

/// The world's spheres as bodies in spatial order (at internal time zero,
/// the world's time), and the world id of each.
pub(super) fn copy(world: &World) -> (Vec<WorldId>, Bodies) {
    // An event names its partner in 26 bits; a scene holds at most 10^7.
    assert!(
        world.spheres.len() <= schedule::MAX_SPHERES,
        "exact takes at most {} spheres",
        schedule::MAX_SPHERES
    );
    let positions = world.spheres.iter().map(|s| s.pos);
    let order = spatial::spatial_order(positions, world.size, WorldId::at);
    let bodies = Bodies::from_spheres(order.iter().map(|&k| &world.spheres[k.index()]), 0.0);
    (order, bodies)
}

impl<L: Locality> EventLoop<L> {
    /// `world`, copied as [`copy`] gives it, scheduled.
    pub(super) fn load(
        world: &World,
        (order, bodies): (Vec<WorldId>, Bodies),
        hooks: &Hooks,
        stats: &mut EventStats,
    ) -> Self {
        let mut run = EventLoop {
            bodies,
            order,
            queue: super::EightWay::default(),
            locality: L::default(),
            size: world.size,
            origin: world.time,
            synced: world.stamp(),
            valid: false,
            prefetching: false,
        };
        run.reschedule_all(hooks, stats);
        run
    }

    /// Whether `world` is the one we last wrote, untouched since: its
    /// stamp is our write-back's (no pass over the spheres).
    pub(super) fn matches(&self, world: &World) -> bool {
        self.valid && world.stamp() == self.synced
    }

    pub(super) fn write_back(&mut self, world: &mut World) {
        let now = world.time - self.origin;
        for (&k, b) in self.order.iter().zip(self.bodies.iter_mut()) {
            b.advance(now);
            let s = &mut world.spheres[k.index()];
            s.pos = b.pos;
            s.vel = b.vel;
        }
        self.synced = world.stamp();
    }
}
