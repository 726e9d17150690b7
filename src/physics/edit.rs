//! Changing the spheres between frames (the count and radius keys) without
//! breaking what the models promise: new spheres go only into free space,
//! radii grow only until two spheres (or a sphere and a wall) would touch.
//! The caller must `invalidate` the model afterwards.
use super::broad::Grid;
use super::exec::Serial;
use super::sphere::Sphere;
use super::world::World;
use glam::DVec3;
use rand::Rng;
use rand_distr::StandardNormal;
use std::collections::HashMap;

/// Random positions tried for one new sphere before the space counts as full.
const TRIES: usize = 1000;
/// Growth stops this far (relative) short of contact, so rounding cannot
/// turn a touch into an overlap.
const MARGIN: f64 = 1e-9;

/// The median radius (`None` for an empty world).
pub fn typical_radius(world: &World) -> Option<f64> {
    let mut r: Vec<f64> = world.spheres.iter().map(|s| s.radius).collect();
    if r.is_empty() {
        return None;
    }
    let mid = r.len() / 2;
    Some(*r.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1)
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
    let mut free = FreeSpace::new(&world.spheres, radius);
    let mut placed = 0;
    'spheres: while placed < count {
        for _ in 0..TRIES {
            let pos = DVec3::new(
                rng.random_range(radius..=size - radius),
                rng.random_range(radius..=size - radius),
                rng.random_range(radius..=size - radius),
            );
            if free.is_free(&world.spheres, pos, radius) {
                let dir = random_direction(rng);
                free.insert(world.spheres.len() as u32, pos, radius);
                world.spheres.push(Sphere::new(pos, dir * speed, radius));
                placed += 1;
                continue 'spheres;
            }
        }
        break;
    }
    placed
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

/// A hash grid of the spheres sized for the new radius; the few spheres much
/// bigger than the bulk are checked one by one.
struct FreeSpace {
    cell: f64,
    small_max: f64,
    cells: HashMap<(i64, i64, i64), Vec<u32>>,
    big: Vec<u32>,
}

impl FreeSpace {
    fn new(spheres: &[Sphere], radius: f64) -> FreeSpace {
        let mut radii: Vec<f64> = spheres.iter().map(|s| s.radius).collect();
        let small_max = if radii.is_empty() {
            radius
        } else {
            let k = (radii.len() * 98 / 100).min(radii.len() - 1);
            radii
                .select_nth_unstable_by(k, |a, b| a.total_cmp(b))
                .1
                .max(radius)
        };
        let mut free = FreeSpace {
            cell: radius + small_max,
            small_max,
            cells: HashMap::new(),
            big: Vec::new(),
        };
        for (i, s) in spheres.iter().enumerate() {
            free.insert(i as u32, s.pos, s.radius);
        }
        free
    }

    fn key(&self, p: DVec3) -> (i64, i64, i64) {
        let c = (p / self.cell).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    }

    fn insert(&mut self, id: u32, pos: DVec3, radius: f64) {
        if radius > self.small_max {
            self.big.push(id);
        } else {
            self.cells.entry(self.key(pos)).or_default().push(id);
        }
    }

    /// A sphere at `pos` with `radius` would overlap or touch nothing. The
    /// cell is at least the new radius plus any grid sphere's, so the 27
    /// cells around hold every grid sphere that could touch it.
    fn is_free(&self, spheres: &[Sphere], pos: DVec3, radius: f64) -> bool {
        let clear = |id: &u32| {
            let s = &spheres[*id as usize];
            let d = radius + s.radius;
            s.pos.distance_squared(pos) > d * d
        };
        if !self.big.iter().all(clear) {
            return false;
        }
        let (x, y, z) = self.key(pos);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(ids) = self.cells.get(&(x + dx, y + dy, z + dz))
                        && !ids.iter().all(clear)
                    {
                        return false;
                    }
                }
            }
        }
        true
    }
}

/// Scale every radius so the largest one becomes `target` (mass follows, at
/// the same density; a uniform scene simply gets radius `target`). Growth stops short of the first contact a sphere would
/// make with another or with a wall, and the returned notice says so.
/// Spheres that already overlap (the `discrete` model allows it) are left to
/// the model and do not hold the others back.
pub fn set_radius(world: &mut World, target: f64) -> Option<String> {
    let largest = world.spheres.iter().map(|s| s.radius).reduce(f64::max)?;
    if !target.is_finite() || target <= 0.0 {
        return Some(format!("radius must be a positive number, not {target}"));
    }
    let want = target / largest;
    let mut factor = want;
    let mut notice = None;
    if want > 1.0 {
        let (limit, what) = growth_limit(world, want);
        if limit < want {
            factor = (limit * (1.0 - MARGIN)).max(1.0);
            notice = Some(format!(
                "radius limit: {what} at r = {:.4}",
                largest * factor
            ));
        }
    }
    if factor != 1.0 {
        let f3 = factor * factor * factor;
        for s in &mut world.spheres {
            s.radius *= factor;
            s.mass *= f3;
        }
    }
    notice
}

/// The largest factor (up to `want`) all radii can grow by before something
/// touches, and what touches first.
fn growth_limit(world: &World, want: f64) -> (f64, &'static str) {
    let size = world.size;
    let wall = world
        .spheres
        .iter()
        .map(|s| {
            let gap = s.pos.min(DVec3::splat(size) - s.pos).min_element();
            if gap >= s.radius {
                gap / s.radius
            } else {
                f64::INFINITY
            }
        })
        .fold(f64::INFINITY, f64::min);
    let mut best = (want, "");
    if wall < best.0 {
        best = (wall, "a sphere touches a wall");
    }
    // Search outwards by doubling, so a huge request over many spheres never
    // asks the grid for all pairs at once: at each reach the spheres are at
    // most twice as crowded as where the previous round found no contact.
    let mut grid = Grid::default();
    let mut pairs = Vec::new();
    let mut reach = 1.0f64;
    loop {
        reach = (reach * 2.0).min(best.0);
        grid.build(&world.spheres, size, |s| (s.pos, s.radius * reach), &Serial);
        grid.pairs(&Serial, &|_: u32, _: u32| true, &mut pairs);
        let mut touch = f64::INFINITY;
        for &(i, j) in &pairs {
            let (a, b) = (&world.spheres[i as usize], &world.spheres[j as usize]);
            let sum = a.radius + b.radius;
            let d = a.pos.distance(b.pos);
            if d >= sum {
                touch = touch.min(d / sum);
            }
        }
        if touch < best.0 {
            best = (touch, "spheres touch");
        }
        if touch <= reach || reach >= best.0 {
            return best;
        }
    }
}
