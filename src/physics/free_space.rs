//! Free space in the cube, for putting spheres where they overlap nothing:
//! a hash grid of the spheres placed so far, each cell's spheres a list
//! threaded through `next` (about 40 bytes a sphere, where a `Vec` a cell
//! took about 160). Scene placement and the count key both use it.
use glam::DVec3;
use rand::Rng;
use std::collections::HashMap;

/// Random spots tried for one sphere before the space counts as full.
pub const TRIES: usize = 2000;

/// The end of a cell's list.
const NO_SPHERE: u32 = u32::MAX;

pub struct FreeSpace {
    size: f64,
    cell: f64,
    /// Spheres above this radius are checked one by one, not through the
    /// grid (the few much bigger than the bulk).
    small_max: f64,
    /// Each cell's last sphere; `next` goes on from there.
    last: HashMap<[i32; 3], u32>,
    next: Vec<u32>,
    placed: Vec<(DVec3, f64)>,
    big: Vec<u32>,
}

impl FreeSpace {
    /// A grid for a box of `size` holding spheres of radius up to
    /// `small_max` in its cells (bigger ones beside it), to test new
    /// spheres of radius up to `new_max`; room for `capacity` spheres.
    pub fn new(size: f64, small_max: f64, new_max: f64, capacity: usize) -> FreeSpace {
        // A cell spans a new sphere's radius plus any grid sphere's, so the
        // 27 cells around a spot hold every grid sphere that could touch it;
        // at least 1/2^20 of the box, so a cell index never saturates.
        let cell = (small_max + new_max).max(size / f64::from(1u32 << 20));
        FreeSpace {
            size,
            cell,
            small_max,
            last: HashMap::with_capacity(capacity),
            next: Vec::with_capacity(capacity),
            placed: Vec::with_capacity(capacity),
            big: Vec::new(),
        }
    }

    fn key(&self, p: DVec3) -> [i32; 3] {
        (p / self.cell).floor().as_ivec3().to_array()
    }

    /// Count a sphere at `pos` as taking its space.
    pub fn insert(&mut self, pos: DVec3, radius: f64) {
        let id = u32::try_from(self.placed.len()).unwrap_or(NO_SPHERE - 1);
        self.placed.push((pos, radius));
        if radius > self.small_max {
            self.big.push(id);
            self.next.push(NO_SPHERE);
        } else {
            let at = self.last.entry(self.key(pos)).or_insert(NO_SPHERE);
            self.next.push(*at);
            *at = id;
        }
    }

    /// A sphere at `pos` with `radius` would overlap or touch nothing.
    pub fn is_free(&self, pos: DVec3, radius: f64) -> bool {
        let clear = |j: u32| {
            let (q, r) = self.placed[j as usize];
            let d = radius + r;
            q.distance_squared(pos) > d * d
        };
        if !self.big.iter().all(|&j| clear(j)) {
            return false;
        }
        let k = self.key(pos);
        let mut cells = (0..27).map(|c| [k[0] + c / 9 - 1, k[1] + c / 3 % 3 - 1, k[2] + c % 3 - 1]);
        cells.all(|cell| {
            let mut j = self.last.get(&cell).map_or(NO_SPHERE, |&j| j);
            while j != NO_SPHERE {
                if !clear(j) {
                    return false;
                }
                j = self.next[j as usize];
            }
            true
        })
    }

    /// A free spot for a sphere of `radius` inside the box, tried at random
    /// up to [`TRIES`] times, and taken; `None` when none was found.
    pub fn place(&mut self, rng: &mut impl Rng, radius: f64) -> Option<DVec3> {
        let size = self.size;
        for _ in 0..TRIES {
            let pos = DVec3::new(
                rng.random_range(radius..=size - radius),
                rng.random_range(radius..=size - radius),
                rng.random_range(radius..=size - radius),
            );
            if self.is_free(pos, radius) {
                self.insert(pos, radius);
                return Some(pos);
            }
        }
        None
    }

    /// Every sphere placed, in the order they came.
    pub fn into_placed(self) -> Vec<(DVec3, f64)> {
        self.placed
    }
}

#[cfg(test)]
mod tests {
    use super::FreeSpace;
    use glam::DVec3;
    use rand::SeedableRng;

    #[test]
    fn placed_spheres_never_overlap_and_a_full_box_says_so() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let mut free = FreeSpace::new(1.0, 0.1, 0.1, 0);
        // One big sphere beside the grid, checked one by one.
        free.insert(DVec3::splat(0.5), 0.3);
        let mut n = 0;
        while free.place(&mut rng, 0.1).is_some() {
            n += 1;
        }
        assert!(n > 5, "{n} placed");
        let all = free.into_placed();
        for (i, &(p, r)) in all.iter().enumerate() {
            assert!(p.cmpge(DVec3::splat(r)).all() && p.cmple(DVec3::splat(1.0 - r)).all());
            for &(q, s) in &all[..i] {
                assert!(p.distance(q) > r + s, "overlap at {p} and {q}");
            }
        }
    }
}
