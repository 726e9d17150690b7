//! A gas with three spheres 15x the bulk among it (the broad phases' second
//! level): the gas spheres they would overlap are left out.
use ballpit::physics::{Sphere, World};
use glam::DVec3;

pub fn with_three_large(gas: World) -> World {
    let big = [[0.25, 0.3, 0.4], [0.7, 0.6, 0.5], [0.4, 0.75, 0.7]]
        .map(|p| Sphere::new(DVec3::from(p), DVec3::new(0.3, -0.2, 0.1), 0.075));
    let clear = |s: &Sphere| {
        big.iter()
            .all(|b| s.pos.distance(b.pos) > s.radius + b.radius)
    };
    let mut spheres: Vec<Sphere> = gas.spheres.into_iter().filter(clear).collect();
    spheres.extend(big);
    World::new(1.0, spheres)
}
