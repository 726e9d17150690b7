//! A sphere as the event loop holds it: position valid at its own time stamp
//! `t` (lazy update: a sphere is moved only when an event touches it or the
//! frame asks for positions), its collision count and its species. One
//! cache line, so checking a neighbour, and whether a prediction about it
//! still holds, costs one line; radii and masses live in the small
//! `SpeciesTable`.
use super::ids::{Label, SpeciesId};
use super::species::{Species, SpeciesTable};
use crate::physics::huge_pages;
use crate::physics::sphere::Sphere;
use glam::DVec3;
use std::ops::{Deref, DerefMut, Index, IndexMut};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct Body {
    pub pos: DVec3,
    pub vel: DVec3,
    /// Time (from the model's time origin) at which `pos` holds.
    pub t: f64,
    /// Collisions so far (sphere or wall): a prediction naming this sphere
    /// as partner holds while its count is the one it saw.
    pub count: u32,
    pub species: SpeciesId,
}

impl Body {
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
}

/// The bodies in label order, with the table of their species.
#[derive(Clone, Debug, Default)]
pub struct Bodies {
    list: Vec<Body>,
    species: SpeciesTable,
}

impl Bodies {
    /// The spheres, in this order, at time stamp `t`, every count zero.
    pub fn from_spheres<'a>(spheres: impl Iterator<Item = &'a Sphere>, t: f64) -> Self {
        let mut species = SpeciesTable::default();
        let mut list = Vec::new();
        huge_pages::reserve(&mut list, spheres.size_hint().0);
        list.extend(spheres.map(|s| Body {
            pos: s.pos,
            vel: s.vel,
            t,
            count: 0,
            species: species.name(s.radius, s.mass),
        }));
        species.seal();
        Bodies { list, species }
    }

    #[inline(always)]
    pub fn species_of(&self, b: &Body) -> Species {
        self.species.get(b.species)
    }

    #[inline(always)]
    pub fn radius_of(&self, b: &Body) -> f64 {
        self.radius_of_species(b.species)
    }

    #[inline(always)]
    pub fn radius_of_species(&self, s: SpeciesId) -> f64 {
        self.species.get(s).radius
    }

    /// How many species the table names (every one has a body).
    pub fn species_count(&self) -> usize {
        self.species.len()
    }

    #[inline(always)]
    pub fn radius(&self, i: Label) -> f64 {
        self.radius_of(&self[i])
    }

    /// The labels of the bodies, in order.
    pub fn labels(&self) -> impl Iterator<Item = Label> + use<> {
        (0..self.list.len()).map(Label::at)
    }

    /// A [`Sphere`] view of body `i`, so the shared contact code applies
    /// unchanged.
    #[inline(always)]
    pub fn sphere(&self, i: Label) -> Sphere {
        let b = &self[i];
        let Species { radius, mass } = self.species_of(b);
        Sphere {
            pos: b.pos,
            vel: b.vel,
            radius,
            mass,
        }
    }

    /// Start loading the bodies of `labels` ([`Label::raw`]s), so a scan
    /// over them waits for their misses together, not one by one.
    #[inline(always)]
    pub fn prefetch(&self, labels: &[u32]) {
        for &j in labels {
            self.prefetch_one(Label::from_raw(j));
        }
    }

    /// Start loading body `j`.
    #[inline(always)]
    pub fn prefetch_one(&self, j: Label) {
        if let Some(b) = self.list.get(j.index()) {
            crate::physics::prefetch::line(b);
        }
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.list.capacity() * size_of::<Body>() + self.species.heap_bytes()
    }
}

impl Deref for Bodies {
    type Target = [Body];
    fn deref(&self) -> &[Body] {
        &self.list
    }
}

impl DerefMut for Bodies {
    fn deref_mut(&mut self) -> &mut [Body] {
        &mut self.list
    }
}

impl Index<Label> for Bodies {
    type Output = Body;
    #[inline(always)]
    fn index(&self, i: Label) -> &Body {
        &self.list[i.index()]
    }
}

impl IndexMut<Label> for Bodies {
    #[inline(always)]
    fn index_mut(&mut self, i: Label) -> &mut Body {
        &mut self.list[i.index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_body_is_one_cache_line() {
        assert_eq!(size_of::<Body>(), 64);
        assert_eq!(align_of::<Body>(), 64);
    }
}
