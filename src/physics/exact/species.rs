//! The radius and mass of each species of sphere (a radius–mass pair).
//! Most scenes have a few (every preset one), so a body names its species
//! in 4 bytes of its own cache line and the table stays in L1; a scene
//! where every sphere differs keeps a table as long as the spheres (16 B a
//! sphere, as a radius in the body and a mass array did). Either way a
//! radius and a mass read back bit for bit.
use super::ids::SpeciesId;
use std::collections::HashMap;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Species {
    pub radius: f64,
    pub mass: f64,
}

#[derive(Clone, Debug, Default)]
pub struct SpeciesTable {
    list: Vec<Species>,
    known: HashMap<(u64, u64), SpeciesId>,
    /// The last species named: runs of one species (most scenes) cost a
    /// compare, not a lookup.
    last: Option<((u64, u64), SpeciesId)>,
}

impl SpeciesTable {
    /// The species of a sphere of this radius and mass, added if new.
    pub fn name(&mut self, radius: f64, mass: f64) -> SpeciesId {
        let bits = (radius.to_bits(), mass.to_bits());
        if let Some((b, k)) = self.last
            && b == bits
        {
            return k;
        }
        // At most one species a sphere, and a world holds at most 10^7.
        let next = SpeciesId::at(self.list.len());
        let k = *self.known.entry(bits).or_insert(next);
        if k == next {
            self.list.push(Species { radius, mass });
        }
        self.last = Some((bits, k));
        k
    }

    /// Forget the lookup used while naming (the table stays).
    pub fn seal(&mut self) {
        self.known = HashMap::new();
        self.last = None;
        self.list.shrink_to_fit();
    }

    #[inline(always)]
    pub fn get(&self, k: SpeciesId) -> Species {
        self.list[k.index()]
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.list.capacity() * size_of::<Species>()
            + self.known.capacity() * (size_of::<((u64, u64), SpeciesId)>() + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_radius_and_mass_pair_is_named_once_and_reads_back_exactly() {
        let pairs = [(1.0, 2.0), (1.0, -0.0), (1.0, 0.0), (2.5e-7, 2.0)];
        let mut t = SpeciesTable::default();
        let names: Vec<SpeciesId> = (0..1000)
            .map(|i| {
                let (r, m) = pairs[i % 7 % 4];
                t.name(r, m)
            })
            .collect();
        t.seal();
        assert_eq!(t.len(), 4, "-0 and 0 are two masses, bit for bit");
        for (i, &k) in names.iter().enumerate() {
            let (r, m) = pairs[i % 7 % 4];
            let s = t.get(k);
            assert_eq!(
                (s.radius.to_bits(), s.mass.to_bits()),
                (r.to_bits(), m.to_bits())
            );
        }
        assert!(t.heap_bytes() <= 4 * 16);
    }

    #[test]
    fn a_scene_of_all_different_spheres_keeps_one_species_each() {
        let mut t = SpeciesTable::default();
        let names: Vec<SpeciesId> = (0..5000).map(|i| t.name(1.0 + f64::from(i), 2.0)).collect();
        assert_eq!(names, (0..5000).map(SpeciesId::at).collect::<Vec<_>>());
        assert_eq!(t.get(SpeciesId::at(4999)).radius, 5000.0);
    }
}
