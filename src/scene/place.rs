//! Putting spheres into the cube without overlaps, and setting them moving.
use super::presets::{Layout, Preset};
use crate::bad;
use crate::error::BadInput;
use crate::physics::edit::random_direction;
use crate::physics::free_space::FreeSpace;
use crate::physics::sphere::volume;
use crate::physics::{Sphere, World};
use glam::DVec3;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

pub type SceneRng = Xoshiro256PlusPlus;

pub fn rng(seed: u64) -> SceneRng {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// Build the spheres of `preset` with the given (already validated) values.
pub fn generate(
    preset: &Preset,
    count: usize,
    radius: f64,
    speed: f64,
    size: f64,
    rng: &mut SceneRng,
) -> Result<World, BadInput> {
    let positions = match preset.layout {
        Layout::Cradle => return cradle(count, radius, speed, size),
        Layout::Lattice => lattice(&vec![radius; count], size, rng)?,
        Layout::Mixed => {
            let mut radii: Vec<f64> = (0..count)
                .map(|_| radius * 10f64.powf(rng.random_range(-1.0..=1.0)))
                .collect();
            // Largest first: the big ones need the room.
            radii.sort_by(|a, b| b.total_cmp(a));
            random_or_lattice(&radii, size, rng)?
        }
        Layout::Gas | Layout::Uniform => random_or_lattice(&vec![radius; count], size, rng)?,
    };
    let mut spheres: Vec<Sphere> = positions
        .into_iter()
        .map(|(p, r)| Sphere::new(p, DVec3::ZERO, r))
        .collect();
    match preset.layout {
        Layout::Uniform => {
            for s in &mut spheres {
                s.vel = random_direction(rng) * speed;
            }
        }
        _ => maxwell(&mut spheres, speed, rng),
    }
    Ok(World::new(size, spheres))
}

/// Gaussian components, no net momentum, rescaled to rms speed `speed`.
fn maxwell(spheres: &mut [Sphere], speed: f64, rng: &mut SceneRng) {
    if spheres.is_empty() {
        return;
    }
    for s in spheres.iter_mut() {
        let g: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(rng));
        s.vel = DVec3::from_array(g);
    }
    if spheres.len() > 1 {
        let m: f64 = spheres.iter().map(|s| s.mass).sum();
        let p: DVec3 = spheres.iter().map(|s| s.mass * s.vel).sum();
        for s in spheres.iter_mut() {
            s.vel -= p / m;
        }
    }
    let ms = spheres.iter().map(|s| s.vel.length_squared()).sum::<f64>() / spheres.len() as f64;
    let scale = if ms > 0.0 { speed / ms.sqrt() } else { 0.0 };
    for s in spheres.iter_mut() {
        s.vel *= scale;
    }
}

fn cradle(count: usize, radius: f64, speed: f64, size: f64) -> Result<World, BadInput> {
    let gap = 2.0 * radius;
    let need = 2.0 * radius * count as f64 + if count > 1 { gap } else { 0.0 };
    if need > size {
        return bad!(
            "the cradle needs {need} box lengths for {count} spheres of radius {radius}, but the box is {size}"
        );
    }
    let c = 0.5 * size;
    let start = c - 0.5 * need + radius;
    let mut last = f64::NEG_INFINITY;
    let spheres = (0..count)
        .map(|i| {
            let mut x = if i == 0 {
                start
            } else {
                start + gap + 2.0 * radius * i as f64
            };
            // Touching, never overlapping: rounding may put a sphere a bit
            // inside the last, which `exact` refuses.
            while x - last < 2.0 * radius {
                x = x.next_up();
            }
            last = x;
            let v = if i == 0 { speed } else { 0.0 };
            Sphere::new(DVec3::new(x, c, c), DVec3::new(v, 0.0, 0.0), radius)
        })
        .collect();
    Ok(World::new(size, spheres))
}

fn random_or_lattice(
    radii: &[f64],
    size: f64,
    rng: &mut SceneRng,
) -> Result<Vec<(DVec3, f64)>, BadInput> {
    match random(radii, size, rng) {
        Some(p) => Ok(p),
        None => lattice(radii, size, rng),
    }
}

/// Random sequential placement; `None` when a sphere finds no free spot in
/// [`TRIES`](crate::physics::free_space::TRIES) tries.
fn random(radii: &[f64], size: f64, rng: &mut SceneRng) -> Option<Vec<(DVec3, f64)>> {
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    if radii.is_empty() {
        return Some(Vec::new());
    }
    if 2.0 * rmax >= size {
        return None;
    }
    let mut free = FreeSpace::new(size, rmax, rmax, radii.len());
    for &r in radii {
        free.place(rng, r)?;
    }
    Some(free.into_placed())
}

/// A cubic lattice over the whole box, `k = ⌈∛n⌉` sites a side (the
/// widest pitch that holds `n`), each sphere jittered within its site. A
/// finer lattice (pitch near a diameter) starts a dense scene nearly
/// jammed, colliding several times faster than the fluid at its packing.
/// Fails with a message when the pitch is under `2 r_max`.
fn lattice(radii: &[f64], size: f64, rng: &mut SceneRng) -> Result<Vec<(DVec3, f64)>, BadInput> {
    let n = radii.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    let per_side = cube_root_up(n);
    // Capped so the sites can be counted in a usize.
    let most = (size / (2.0 * rmax)).floor().min(f64::from(1u32 << 20)) as usize;
    if per_side > most {
        let fraction: f64 = radii.iter().map(|&r| volume(r)).sum::<f64>() / size.powi(3);
        return bad!(
            "cannot fit {n} spheres (largest radius {rmax}) in a box of {size}: packing fraction {fraction:.3}, at most {} fit on a lattice",
            most.saturating_pow(3)
        );
    }
    let pitch = size / per_side as f64;
    let mut sites = spread_sites(per_side, n);
    // Unequal radii (`mixed`, largest first) go to sites at random, so the
    // large ones do not fill the bottom layers; equal ones keep the sites'
    // order, neighbours in space next in memory.
    if radii.iter().any(|&r| r != rmax) {
        sites.shuffle(rng);
    }
    Ok(radii
        .iter()
        .zip(sites)
        .map(|(&r, site)| {
            let idx = [
                site % per_side,
                (site / per_side) % per_side,
                site / (per_side * per_side),
            ];
            let slack = 0.5 * pitch - r;
            let p = DVec3::from_array(idx.map(|i| {
                let centre = (i as f64 + 0.5) * pitch;
                centre
                    + if slack > 0.0 {
                        rng.random_range(-slack..=slack)
                    } else {
                        0.0
                    }
            }));
            (p, r)
        })
        .collect())
}

/// The least `k` with `k³ >= n` (the float root corrected for rounding).
pub(crate) fn cube_root_up(n: usize) -> usize {
    let mut k = (n as f64).cbrt().round() as usize;
    while k.saturating_pow(3) < n {
        k += 1;
    }
    while k > 1 && (k - 1).pow(3) >= n {
        k -= 1;
    }
    k
}

/// `n` of the `per_side³` sites, skipping the spare ones evenly through the
/// lattice (site `⌊i · sites / n⌋` for sphere `i`), so no region of the box
/// is denser than another.
fn spread_sites(per_side: usize, n: usize) -> Vec<usize> {
    let total = per_side.pow(3) as u128;
    (0..n as u128)
        .map(|i| (i * total / n as u128) as usize)
        .collect()
}

/// Whether a scene may hold overlapping spheres: only for `discrete`, which
/// makes them itself (so its `--dump` reads back), never for the models that
/// promise none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Overlaps {
    #[default]
    Refuse,
    Allow,
}

/// Why a world is not a valid scene, if it isn't: centres outside the cube,
/// overlaps, non-finite or non-positive values. `source` names the file (or
/// what made the scene) once; `item(i)` names sphere `i` in it (e.g. its CSV
/// line).
pub fn check(world: &World, source: &str, item: &dyn Fn(usize) -> String) -> Result<(), BadInput> {
    check_with(world, Overlaps::Refuse, source, item)
}

/// [`check`], with overlaps refused or allowed.
pub fn check_with(
    world: &World,
    overlaps: Overlaps,
    source: &str,
    item: &dyn Fn(usize) -> String,
) -> Result<(), BadInput> {
    let what = |i: usize| format!("{source} {}", item(i));
    let size = world.size;
    let tol = 1e-9 * size;
    for (i, s) in world.spheres.iter().enumerate() {
        if !(s.pos.is_finite() && s.vel.is_finite() && s.radius.is_finite() && s.mass.is_finite()) {
            return bad!("{}: a value is not a finite number", what(i));
        }
        if !speed_ok(s) {
            return bad!(
                "{}: velocity {:?} is too fast (its kinetic energy, or a relative speed squared, is not a finite number)",
                what(i),
                s.vel.to_array()
            );
        }
        if s.radius <= 0.0 {
            return bad!("{}: radius must be positive, got {}", what(i), s.radius);
        }
        if s.mass <= 0.0 {
            return bad!("{}: mass must be positive, got {}", what(i), s.mass);
        }
        if 2.0 * s.radius >= size {
            return bad!(
                "{}: radius {} does not fit in a box of {size}",
                what(i),
                s.radius
            );
        }
        for k in 0..3 {
            if s.pos[k] < s.radius - tol || s.pos[k] > size - s.radius + tol {
                return bad!(
                    "{}: sphere at {:?} with radius {} is outside the cube [0, {size}]^3",
                    what(i),
                    s.pos.to_array(),
                    s.radius
                );
            }
        }
    }
    if overlaps == Overlaps::Refuse
        && let Some((i, j, depth)) = first_overlap(world)
    {
        return bad!(
            "{source}: {} and {} overlap by {depth} (only --model discrete takes overlapping spheres)",
            item(i),
            item(j)
        );
    }
    if !world.kinetic_energy().is_finite() {
        return bad!(
            "the spheres' total kinetic energy is not a finite number: speeds or masses too large"
        );
    }
    Ok(())
}

/// The overlapping pair with the lowest indices, and its depth.
fn first_overlap(world: &World) -> Option<(usize, usize, f64)> {
    let mut first: Option<(usize, usize, f64)> = None;
    crate::physics::broad::for_each_near_pair(&world.spheres, world.size, |i, j| {
        let (a, b) = (&world.spheres[i], &world.spheres[j]);
        let sum = a.radius + b.radius;
        let d = a.pos.distance(b.pos);
        if d < sum * (1.0 - 1e-12) && first.is_none_or(|f| (i.min(j), i.max(j)) < (f.0, f.1)) {
            first = Some((i.min(j), i.max(j), sum - d));
        }
    });
    first
}

/// Whether a sphere's speed leaves the physics finite numbers: times of
/// impact square relative speeds (up to twice its own), and the energy
/// figures square its own.
pub fn speed_ok(s: &Sphere) -> bool {
    (2.0 * s.vel).length_squared().is_finite() && s.kinetic_energy().is_finite()
}
