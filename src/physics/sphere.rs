use glam::DVec3;

/// A frictionless hard sphere. 64 bytes, aligned to a cache line, so the hot
/// loops touch one line per sphere (only 8-aligned, a `Vec` of them from
/// `malloc` put every sphere across two lines).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Sphere {
    pub pos: DVec3,
    pub vel: DVec3,
    pub radius: f64,
    pub mass: f64,
}

impl Sphere {
    /// A sphere of density 1 (mass = volume), as docs/design.md defaults it.
    pub fn new(pos: DVec3, vel: DVec3, radius: f64) -> Self {
        Sphere {
            pos,
            vel,
            radius,
            mass: volume(radius),
        }
    }

    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.vel.length_squared()
    }
}

pub fn volume(radius: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * radius * radius * radius
}

/// How deep two balls sink into each other, over the smaller radius; 0 when
/// apart or touching. The one definition every readout and model uses, so
/// their figures agree to the bit.
#[inline]
pub fn overlap_rel(pa: DVec3, ra: f64, pb: DVec3, rb: f64) -> f64 {
    let depth = ra + rb - pa.distance(pb);
    if depth > 0.0 { depth / ra.min(rb) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_is_one_cache_line() {
        assert_eq!((size_of::<Sphere>(), align_of::<Sphere>()), (64, 64));
    }
}
