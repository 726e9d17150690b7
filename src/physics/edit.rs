//! Changing the spheres between frames (the count and radius keys) without
//! breaking what the models promise: new spheres go only into free space,
//! growing radii push the spheres apart, never into each other or a wall.
//! The caller must `World::touch` the world afterwards.
use super::free_space::FreeSpace;
use super::relax;
use super::sphere::Sphere;
use super::world::World;
use glam::DVec3;
use rand::Rng;
use rand_distr::StandardNormal;

/// The median radius (`None` for an empty world).
pub fn typical_radius(world: &World) -> Option<f64> {
    let mut r: Vec<f64> = world.spheres.iter().map(|s| s.radius).collect();
    if r.is_empty() {
        return None;
    }
    let mid = r.len() / 2;
    Some(*r.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// Root-mean-square speed (0 for an empty world).
pub fn rms_speed(world: &World) -> f64 {
    let n = world.spheres.len();
    if n == 0 {
        return 0.0;
    }
    (world
        .spheres
        .iter()
        .map(|s| s.vel.length_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt()
}

/// Make the world hold `n` spheres: drop the last ones, or add spheres of
/// `radius` moving at `speed` in random directions into free space. Returns a
/// notice when the space ran out before `n` was reached.
pub fn set_count(
    world: &mut World,
    n: usize,
    radius: f64,
    speed: f64,
    rng: &mut impl Rng,
) -> Option<String> {
    let have = world.spheres.len();
    if n <= have {
        world.spheres.truncate(n);
        return None;
    }
    let placed = add_spheres(world, n - have, radius, speed, rng);
    (placed < n - have).then(|| {
        format!(
            "count limit: no free space for more spheres ({} of {n})",
            have + placed
        )
    })
}

/// Add up to `count` spheres that overlap nothing; returns how many fit.
pub fn add_spheres(
    world: &mut World,
    count: usize,
    radius: f64,
    speed: f64,
    rng: &mut impl Rng,
) -> usize {
    let size = world.size;
    if radius.is_nan() || radius <= 0.0 || 2.0 * radius >= size {
        return 0;
    }
    let mut free = free_space(&world.spheres, size, radius, count);
    let mut placed = 0;
    while placed < count {
        let Some(pos) = free.place(rng, radius) else {
            break;
        };
        let dir = random_direction(rng);
        world.spheres.push(Sphere::new(pos, dir * speed, radius));
        placed += 1;
    }
    placed
}

/// The free space around `spheres` for `more` new ones of `radius`: the
/// grid is sized for the bulk (the 98th percentile of radius), the few
/// larger spheres are checked one by one.
fn free_space(spheres: &[Sphere], size: f64, radius: f64, more: usize) -> FreeSpace {
    let mut radii: Vec<f64> = spheres.iter().map(|s| s.radius).collect();
    let small_max = if radii.is_empty() {
        radius
    } else {
        let k = (radii.len() * 98 / 100).min(radii.len() - 1);
        radii
            .select_nth_unstable_by(k, f64::total_cmp)
            .1
            .max(radius)
    };
    let mut free = FreeSpace::new(size, small_max, radius, spheres.len() + more);
    for s in spheres {
        free.insert(s.pos, s.radius);
    }
    free
}

/// A uniformly random unit vector.
pub fn random_direction(rng: &mut impl Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.sample(StandardNormal),
            rng.sample(StandardNormal),
            rng.sample(StandardNormal),
        );
        let len = v.length();
        if len > 1e-9 {
            return v / len;
        }
    }
}

/// Scale every radius so the largest one becomes `target` (a uniform scene
/// simply gets radius `target`). Growing pushes spheres apart where they
/// would overlap (see [`relax`]); each sphere keeps its mass and velocity, so
/// energy and momentum are unchanged. When the box cannot hold the spheres at
/// `target`, they grow as far as the packing allows and the returned notice
/// says so.
pub fn set_radius(world: &mut World, target: f64) -> Option<String> {
    let largest = world.spheres.iter().map(|s| s.radius).reduce(f64::max)?;
    if !target.is_finite() || target <= 0.0 {
        return Some(format!("radius must be a positive number, not {target}"));
    }
    let want = target / largest;
    if want <= 1.0 {
        // Shrinking opens gaps and never makes an overlap.
        for s in &mut world.spheres {
            s.radius *= want;
        }
        return None;
    }
    let size = world.size;
    let filled = relax::packing(&world.spheres, size);
    let cap = (relax::MAX_PACKING / filled).cbrt();
    let first = want.min(cap);
    let (factor, spheres) = match relax::grown(&world.spheres, size, first) {
        Some(s) => (first, Some(s)),
        None => largest_fit(&world.spheres, size, first),
    };
    if let Some(s) = spheres {
        world.spheres = s;
    }
    (factor < want).then(|| {
        format!(
            "radius limit: no room to grow further at r = {:.4} (packing {:.2})",
            largest * factor,
            relax::packing(&world.spheres, size)
        )
    })
}

/// Bisection steps between no growth and a factor that did not fit.
const FIT_STEPS: usize = 4;

/// The largest factor below `too_big` found to fit, with the grown spheres
/// (1 and `None` when not even a little growth fits).
fn largest_fit(spheres: &[Sphere], size: f64, too_big: f64) -> (f64, Option<Vec<Sphere>>) {
    let (mut lo, mut hi) = (1.0, too_big);
    let mut best = None;
    for _ in 0..FIT_STEPS {
        let mid = 0.5 * (lo + hi);
        match relax::grown(spheres, size, mid) {
            Some(s) => {
                lo = mid;
                best = Some(s);
            }
            None => hi = mid,
        }
    }
    (lo, best)
}
