//! Random scenes for `auto`: the accuracy sweep in `tests/physics/auto.rs` and the
//! cost sweep of `examples/auto_sweep.rs` draw from the same generator.
use ballpit::physics::{Sphere, World};
use glam::DVec3;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Spheres on a jittered cubic lattice, radii log-uniform over `spread`
/// scaled to `packing` (less where the lattice cannot hold it), speeds
/// `speed` × [0.5, 1.5) in random directions.
pub fn random_scene(
    rng: &mut Xoshiro256PlusPlus,
    n: usize,
    packing: f64,
    spread: f64,
    speed: f64,
) -> World {
    let side = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / side as f64;
    let unit: Vec<f64> = (0..n)
        .map(|_| spread.powf(rng.random_range(0.0..1.0)))
        .collect();
    let cubes: f64 = unit.iter().map(|u| u.powi(3)).sum();
    let want = (packing / (4.0 / 3.0 * std::f64::consts::PI * cubes)).cbrt();
    let top = unit.iter().copied().fold(0.0, f64::max);
    let base = want.min(0.45 * cell / top);
    let spheres = unit
        .iter()
        .enumerate()
        .map(|(i, u)| {
            let r = base * u;
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            let centre = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5) * cell;
            let room = 0.5 * cell - r;
            let jitter = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ) * room
                * 0.9;
            let dir = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize_or(DVec3::X);
            let v = dir * speed * rng.random_range(0.5..1.5);
            Sphere::new(centre + jitter, v, r)
        })
        .collect();
    World::new(1.0, spheres)
}
