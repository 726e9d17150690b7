//! Time of impact and elastic response: the forms docs/design.md fixes.
use super::sphere::Sphere;
use glam::DVec3;

/// Smallest `t >= 0` with `|dp + dv t| = sigma`, or `None` if the pair never
/// touches while approaching. `dp = p_i - p_j`, `dv = v_i - v_j`.
///
/// Rounding guard, as event-driven codes do it: a pair that already overlaps
/// (or touches) and approaches collides now (`Some(0)`); one that recedes is
/// left alone until it separates. The root is taken in the cancellation-free
/// form `t = c / (-b + sqrt(b^2 - a c))`, never `distance / speed`.
#[inline]
pub fn pair_toi(dp: DVec3, dv: DVec3, sigma: f64) -> Option<f64> {
    let b = dp.dot(dv);
    if b >= 0.0 {
        return None;
    }
    let c = dp.length_squared() - sigma * sigma;
    if c <= 0.0 {
        return Some(0.0);
    }
    let a = dv.length_squared();
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    Some(c / (-b + disc.sqrt()))
}

/// Earliest wall contact of a sphere at `pos` moving at `vel`: the time
/// (infinite if it moves towards none; 0 if it overlaps a wall it moves
/// into) and the mask of the axes hit then (bit `k` for axis `k`; a corner
/// hit flips every axis that ties). The one wall time of impact of every
/// model, with selects instead of branches on the signs of the velocity.
#[inline]
pub fn wall_toi(pos: DVec3, vel: DVec3, radius: f64, size: f64) -> (f64, u8) {
    let mut t = [f64::INFINITY; 3];
    for (k, tk) in t.iter_mut().enumerate() {
        let v = vel[k];
        // Indexing, not `if`: LLVM turns a select on the (random) sign back
        // into a branch, and that branch mispredicted half the time.
        let gap = [size - radius - pos[k], pos[k] - radius][(v < 0.0) as usize];
        let dt = (gap / v.abs()).max(0.0);
        *tk = [f64::INFINITY, dt][(v != 0.0) as usize];
    }
    let tmin = t[0].min(t[1]).min(t[2]);
    let mask = (t[0] == tmin) as u8 | ((t[1] == tmin) as u8) << 1 | ((t[2] == tmin) as u8) << 2;
    (tmin, mask)
}

/// Reflect `v' = v - 2 (v·n) n` on every axis in `mask` (from
/// [`wall_toi`], so the sphere moves into that wall). Returns the momentum
/// given to the walls and the number of wall collisions.
#[inline]
pub fn reflect_walls(s: &mut Sphere, mask: u8) -> (f64, u64) {
    let mut impulse = 0.0;
    let mut hits = 0;
    for k in 0..3 {
        if mask & (1 << k) != 0 && s.vel[k] != 0.0 {
            impulse += reflect_axis(s, k);
            hits += 1;
        }
    }
    (impulse, hits)
}

/// Reflect the velocity along axis `k` off a wall: the one reflection of
/// every model. Returns the momentum given to the wall, `2 m |v_k|`.
#[inline]
pub fn reflect_axis(s: &mut Sphere, k: usize) -> f64 {
    let v = s.vel[k];
    s.vel[k] = -v;
    2.0 * s.mass * v.abs()
}

/// Elastic impulse between two spheres, only if they approach along the line
/// of centres (`u = (v1 - v2)·n > 0`, `n` from 1 to 2). Returns whether it acted.
#[inline]
pub fn resolve_pair(a: &mut Sphere, b: &mut Sphere) -> bool {
    let d = b.pos - a.pos;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return false;
    }
    let n = d / len2.sqrt();
    let u = (a.vel - b.vel).dot(n);
    if u <= 0.0 {
        return false;
    }
    let mt = a.mass + b.mass;
    a.vel -= (2.0 * b.mass / mt * u) * n;
    b.vel += (2.0 * a.mass / mt * u) * n;
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: f64 = 0.1;

    #[test]
    fn the_wall_time_is_the_gap_over_the_speed_towards_it() {
        let pos = DVec3::new(0.3, 0.5, 0.5);
        // Towards x = 0: the gap 0.3 - R at speed 2.
        let (t, mask) = wall_toi(pos, DVec3::new(-2.0, 0.0, 0.0), R, 1.0);
        assert_eq!((t, mask), ((0.3 - R) / 2.0, 0b001));
        // Towards y = 1 and z = 0 at once from the centre: a corner, both axes.
        let centre = DVec3::splat(0.5);
        let (t, mask) = wall_toi(centre, DVec3::new(0.0, 1.0, -1.0), R, 1.0);
        assert_eq!((t, mask), (0.5 - R, 0b110));
        // At rest: no wall, ever.
        let (t, _) = wall_toi(centre, DVec3::ZERO, R, 1.0);
        assert_eq!(t, f64::INFINITY);
        // Past a wall it moves into: now.
        let (t, mask) = wall_toi(DVec3::new(0.95, 0.5, 0.5), DVec3::X, R, 1.0);
        assert_eq!((t, mask), (0.0, 0b001));
    }

    #[test]
    fn a_reflection_turns_the_axes_hit_and_keeps_the_energy() {
        let mut s = Sphere::new(DVec3::splat(0.5), DVec3::new(1.0, -2.0, 3.0), R);
        let e0 = s.kinetic_energy();
        let (impulse, hits) = reflect_walls(&mut s, 0b011);
        assert_eq!(s.vel, DVec3::new(-1.0, 2.0, 3.0));
        assert_eq!((impulse, hits), (2.0 * s.mass * 3.0, 2));
        assert!((s.kinetic_energy() - e0).abs() <= 1e-15 * e0);
    }
}
