//! Free flight with wall bounces only, in closed form: along each axis the
//! motion between the walls is a triangle wave, so a sphere that crosses many
//! box lengths in one step costs the same as one that crosses none. And
//! the straight flight of a per-step model, where the walls come after.
use super::detect::SPHERE_BLOCK;
use super::exec::{Exec, for_each_chunk};
use super::sphere::Sphere;

/// Predicted nanoseconds of a sphere's straight flight over a step
/// (docs/threading.md).
const NS_PER_FLIGHT: usize = 3;

/// Moves every sphere along its velocity for `dt`, walls or not: the
/// per-step models mend what crossed a wall or met a sphere afterwards.
pub fn fly_straight(exec: &dyn Exec, spheres: &mut [Sphere], dt: f64) {
    for_each_chunk(exec, spheres, SPHERE_BLOCK, NS_PER_FLIGHT, &|_, chunk| {
        for s in chunk {
            s.pos += s.vel * dt;
        }
    });
}

/// Moves `s` for time `t` bouncing off the walls of `[0, size]^3`. Returns
/// the momentum given to the walls and the number of wall collisions.
#[inline]
pub fn fly(s: &mut Sphere, size: f64, t: f64) -> (f64, u64) {
    let mut impulse = 0.0;
    let mut hits = 0u64;
    for k in 0..3 {
        let v = s.vel[k];
        if v == 0.0 || t <= 0.0 {
            continue;
        }
        let lo = s.radius;
        let w = size - 2.0 * s.radius;
        // Mirror so the sphere moves up the axis; u is the distance already
        // covered from the low wall, unfolded.
        let x = if v > 0.0 { s.pos[k] } else { size - s.pos[k] };
        let speed = v.abs();
        let u0 = (x - lo).clamp(0.0, w.max(0.0));
        let u1 = u0 + speed * t;
        if w <= 0.0 {
            continue;
        }
        // u1 >= 0, so truncation is floor; segments beyond 2^53 lose
        // their parity, and a sphere that fast has no meaningful position.
        let whole = (u1 / w) as u64;
        let segs = whole as f64;
        let f = (u1 - segs * w).clamp(0.0, w);
        let odd = whole & 1 == 1;
        let (xm, vm) = if odd {
            (lo + w - f, -speed)
        } else {
            (lo + f, speed)
        };
        let (xn, vn) = if v > 0.0 { (xm, vm) } else { (size - xm, -vm) };
        s.pos[k] = xn;
        s.vel[k] = vn;
        if segs > 0.0 {
            hits += segs as u64;
            impulse += segs * 2.0 * s.mass * speed;
        }
    }
    (impulse, hits)
}
