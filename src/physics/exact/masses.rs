//! The masses as the event loop keeps them. Only collisions and wall hits
//! read them, and most scenes have few distinct masses, so each sphere keeps
//! a byte naming its mass in a small table (1 byte a sphere, not 8); a scene
//! with more distinct masses than a byte can name keeps them whole. Either
//! way a mass reads back bit for bit.
use super::renumber::apply;
use std::collections::HashMap;

#[derive(Clone, Debug)]
pub enum Masses {
    Few { table: Vec<f64>, of: Vec<u8> },
    Many(Vec<f64>),
}

impl Default for Masses {
    fn default() -> Self {
        Masses::Many(Vec::new())
    }
}

impl Masses {
    /// The masses in label order.
    pub fn new(masses: impl ExactSizeIterator<Item = f64> + Clone) -> Self {
        let mut table: Vec<f64> = Vec::new();
        let mut known: HashMap<u64, u8> = HashMap::new();
        let mut of = Vec::with_capacity(masses.len());
        // Runs of one mass (most scenes) cost a compare, not a lookup.
        let mut last: Option<(u64, u8)> = None;
        for m in masses.clone() {
            let bits = m.to_bits();
            let k = match last {
                Some((b, k)) if b == bits => k,
                _ => {
                    let k = if let Some(&k) = known.get(&bits) {
                        k
                    } else {
                        let Ok(k) = u8::try_from(table.len()) else {
                            return Masses::Many(masses.collect());
                        };
                        table.push(m);
                        known.insert(bits, k);
                        k
                    };
                    last = Some((bits, k));
                    k
                }
            };
            of.push(k);
        }
        Masses::Few { table, of }
    }

    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match self {
            Masses::Few { table, of } => table[usize::from(of[i])],
            Masses::Many(m) => m[i],
        }
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        match self {
            Masses::Few { table, of } => table.capacity() * 8 + of.capacity(),
            Masses::Many(m) => m.capacity() * 8,
        }
    }

    /// The spheres are relabelled (`perm[new] = old`).
    pub fn relabel(&mut self, perm: &[u32]) {
        match self {
            Masses::Few { of, .. } => apply(of, perm),
            Masses::Many(m) => apply(m, perm),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn back(m: &Masses) -> Vec<u64> {
        let n = match m {
            Masses::Few { of, .. } => of.len(),
            Masses::Many(v) => v.len(),
        };
        (0..n).map(|i| m.get(i).to_bits()).collect()
    }

    #[test]
    fn few_masses_are_named_by_a_byte_and_read_back_exactly() {
        let v: Vec<f64> = (0..1000)
            .map(|i| [1.0, -0.0, 0.0, 2.5e-7][i % 7 % 4])
            .collect();
        let m = Masses::new(v.iter().copied());
        assert!(matches!(m, Masses::Few { ref table, .. } if table.len() == 4));
        assert_eq!(back(&m), v.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        assert!(m.heap_bytes() < 1100);
    }

    #[test]
    fn more_than_a_byte_names_keeps_them_whole() {
        for n in [256, 257, 5000] {
            let v: Vec<f64> = (0..n).map(|i| 1.0 + f64::from(i % 300)).collect();
            let m = Masses::new(v.iter().copied());
            assert_eq!(matches!(m, Masses::Few { .. }), n == 256, "{n} spheres");
            assert_eq!(back(&m), v.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        }
    }

    #[test]
    fn relabelling_moves_each_mass_with_its_sphere() {
        let perm = [2u32, 0, 3, 1];
        for v in [vec![1.0, 2.0, 1.0, 3.0], (0..4).map(f64::from).collect()] {
            let mut m = Masses::new(v.iter().copied());
            m.relabel(&perm);
            let want: Vec<u64> = perm.iter().map(|&o| v[o as usize].to_bits()).collect();
            assert_eq!(back(&m), want);
        }
    }
}
