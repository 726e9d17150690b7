//! A sphere as the event loop holds it: position valid at its own time stamp
//! `t` (lazy update: a sphere is moved only when an event touches it or the
//! frame asks for positions). One cache line, so checking a neighbour costs
//! one line; masses live apart because only collisions read them.
use crate::physics::sphere::Sphere;
use glam::DVec3;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Body {
    pub pos: DVec3,
    pub vel: DVec3,
    /// Time (from the model's time origin) at which `pos` holds.
    pub t: f64,
    pub radius: f64,
}

impl Body {
    pub fn from_sphere(s: &Sphere, t: f64) -> Self {
        Body {
            pos: s.pos,
            vel: s.vel,
            t,
            radius: s.radius,
        }
    }

    /// Where the sphere is at time `t`, without moving it.
    #[inline(always)]
    pub fn pos_at(&self, t: f64) -> DVec3 {
        self.pos + self.vel * (t - self.t)
    }

    /// Move the sphere along its straight line to time `t`.
    #[inline(always)]
    pub fn advance(&mut self, t: f64) {
        self.pos += self.vel * (t - self.t);
        self.t = t;
    }

    /// A [`Sphere`] view, so the shared contact code applies unchanged.
    #[inline(always)]
    pub fn sphere(&self, mass: f64) -> Sphere {
        Sphere {
            pos: self.pos,
            vel: self.vel,
            radius: self.radius,
            mass,
        }
    }
}
