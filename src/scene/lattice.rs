//! Dense starting states for the exact model's tests and benchmarks: random
//! placement jams long before packing 0.45, so spheres go on a simple cubic
//! lattice (up to packing π/6 ≈ 0.52 when N is a cube) with Gaussian
//! velocities, then the dynamics melts the lattice within a few collisions
//! per sphere.
use crate::error::BadInput;
use crate::physics::exact::Exact;
use crate::physics::{Model, Serial, Sphere, World};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// `n` equal spheres (density 1) in the unit box at packing fraction
/// `packing`, on the first `n` sites of a `k^3` lattice, velocity components
/// normal with standard deviation `speed / sqrt(3)` (so the rms speed is
/// `speed`), from `seed`.
pub fn lattice_world(n: usize, packing: f64, speed: f64, seed: u64) -> Result<World, BadInput> {
    if n == 0 {
        return Ok(World::new(1.0, Vec::new()));
    }
    if !(packing > 0.0 && packing.is_finite()) {
        return crate::bad!("packing fraction {packing} must be a positive number");
    }
    let k = (n as f64).cbrt().ceil() as usize;
    let k = if (k - 1).pow(3) >= n { k - 1 } else { k };
    let spacing = 1.0 / k as f64;
    let radius = (packing / (n as f64 * 4.0 / 3.0 * std::f64::consts::PI)).cbrt();
    if 2.0 * radius > spacing {
        let most = std::f64::consts::PI / 6.0 * n as f64 / (k * k * k) as f64;
        return crate::bad!(
            "packing fraction {packing} does not fit {n} spheres on a lattice (at most {most:.4})"
        );
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let sd = speed / 3f64.sqrt();
    let mut spheres = Vec::with_capacity(n);
    'fill: for z in 0..k {
        for y in 0..k {
            for x in 0..k {
                if spheres.len() == n {
                    break 'fill;
                }
                let pos = (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * spacing;
                let g =
                    |rng: &mut Xoshiro256PlusPlus| -> f64 { rng.sample::<f64, _>(StandardNormal) };
                let vel = DVec3::new(g(&mut rng), g(&mut rng), g(&mut rng)) * sd;
                spheres.push(Sphere::new(pos, vel, radius));
            }
        }
    }
    Ok(World::new(1.0, spheres))
}

/// The exact benchmark's start: `n` spheres from the lattice, melted by
/// about 20 collisions per sphere, with the model that melted them (its
/// schedule warm) and a step that holds about `per_step` collisions. The
/// counters start from zero.
pub fn melted(n: usize, packing: f64, per_step: f64) -> Result<(World, Exact, f64), BadInput> {
    let mut w = lattice_world(n, packing, 1.0, 42)?;
    let mut m = Exact::default();
    while w.counters.sphere_collisions < 10 * n as u64 {
        m.advance(&mut w, 0.01, 1, &Serial);
    }
    let (c0, t0) = (w.counters.sphere_collisions, w.time);
    m.advance(&mut w, 0.01, 5, &Serial);
    let rate = (w.counters.sphere_collisions - c0) as f64 / (w.time - t0);
    w.counters = Default::default();
    Ok((w, m, per_step / rate))
}
