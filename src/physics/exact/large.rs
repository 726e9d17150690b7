//! The second level both broad phases keep: the few spheres far larger than
//! the bulk stay out of the grid (every small sphere checks them; a large
//! one scans the cells over its own reach plus a skin and rescans when it
//! leaves that skin), so radii 100x apart stay cheap.
use super::body::Bodies;
use glam::DVec3;

/// A sphere counts as large (second level) above this multiple of the bulk radius.
pub const BIG_FACTOR: f64 = 3.0;

/// Spheres larger than `factor` times the bulk (98th percentile) radius go
/// to the second level. Returns that threshold (infinite when the largest
/// is within it) and the largest radius at or under it. `bodies` is not empty.
pub fn split_big(bodies: &Bodies, factor: f64) -> (f64, f64) {
    let n = bodies.len();
    let mut radii: Vec<f64> = bodies.iter().map(|b| bodies.radius_of(b)).collect();
    let k = (n * 98 / 100).min(n - 1);
    let bulk = *radii.select_nth_unstable_by(k, f64::total_cmp).1;
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    let big_above = if rmax <= factor * bulk {
        f64::INFINITY
    } else {
        factor * bulk
    };
    let small_rmax = bodies
        .iter()
        .map(|b| bodies.radius_of(b))
        .filter(|&r| r <= big_above)
        .fold(0.0, f64::max);
    (big_above, small_rmax)
}

/// Time until a point at offset `d` from a ball's centre, moving at `v`,
/// reaches the ball's edge (radius `r`): 0 if already outside, infinite if
/// at rest. The root of `a t^2 + 2 b t + c = 0` (c < 0) in the form that
/// never subtracts nearly equal numbers.
#[inline]
pub fn time_to_leave(d: DVec3, v: DVec3, r: f64) -> f64 {
    let a = v.length_squared();
    if a == 0.0 {
        return f64::INFINITY;
    }
    let c = d.length_squared() - r * r;
    if c >= 0.0 {
        return 0.0;
    }
    let b = d.dot(v);
    let disc = (b * b - a * c).sqrt();
    if b > 0.0 {
        -c / (b + disc)
    } else {
        (disc - b) / a
    }
}
