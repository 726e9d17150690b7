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

/// Time until the sphere touches a wall along each axis (infinite if it is
/// not moving towards one). Overlapping a wall while moving into it gives 0.
#[inline]
pub fn wall_toi_axes(s: &Sphere, size: f64) -> DVec3 {
    let mut t = DVec3::splat(f64::INFINITY);
    for k in 0..3 {
        let v = s.vel[k];
        let p = s.pos[k];
        if v < 0.0 {
            t[k] = ((p - s.radius) / -v).max(0.0);
        } else if v > 0.0 {
            t[k] = ((size - s.radius - p) / v).max(0.0);
        }
    }
    t
}

/// Earliest wall contact: time and the mask of axes hit at that time (a corner
/// hit flips every axis that ties).
#[inline]
pub fn wall_toi(s: &Sphere, size: f64) -> (f64, [bool; 3]) {
    let t = wall_toi_axes(s, size);
    let tmin = t.min_element();
    (tmin, [t.x == tmin, t.y == tmin, t.z == tmin])
}

/// Reflect `v' = v - 2 (v·n) n` on every axis in `mask` (axes from
/// [`wall_toi`], so the sphere moves into that wall). Returns the momentum
/// given to the walls and the number of wall collisions.
#[inline]
pub fn reflect_walls(s: &mut Sphere, mask: [bool; 3]) -> (f64, u64) {
    let mut impulse = 0.0;
    let mut hits = 0;
    for (k, &hit) in mask.iter().enumerate() {
        if hit && s.vel[k] != 0.0 {
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
