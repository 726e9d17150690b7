//! What both broad phases of `exact` share: the split of the few large
//! spheres off to a second level, and the exit time from a ball; and the
//! neighbour lists' grid: the spheres of each cell as intrusive doubly
//! linked lists (a sphere moves between cells in O(1); the cell-crossing
//! broad phase, which gathers cells far more often, keeps them in
//! [`CellSlots`](super::cell_slots::CellSlots) instead).
use super::body::Body;
use glam::DVec3;

pub const NONE: u32 = u32::MAX;

#[derive(Clone, Debug, Default)]
pub struct CellList {
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    /// The cell of each sphere, `NONE` for one in no cell.
    cell: Vec<u32>,
}

impl CellList {
    /// `spheres` spheres, none in a cell, and `cells` empty cells.
    pub fn reset(&mut self, spheres: usize, cells: usize) {
        for v in [&mut self.next, &mut self.prev, &mut self.cell] {
            v.clear();
            v.resize(spheres, NONE);
        }
        self.head.clear();
        self.head.resize(cells, NONE);
    }

    #[inline]
    pub fn cell(&self, i: usize) -> u32 {
        self.cell[i]
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        [&self.head, &self.next, &self.prev, &self.cell]
            .iter()
            .map(|v| v.capacity() * 4)
            .sum()
    }

    pub fn insert(&mut self, i: usize, c: usize) {
        self.cell[i] = c as u32;
        self.prev[i] = NONE;
        self.next[i] = self.head[c];
        if self.head[c] != NONE {
            self.prev[self.head[c] as usize] = i as u32;
        }
        self.head[c] = i as u32;
    }

    pub fn remove(&mut self, i: usize) {
        let (p, n) = (self.prev[i], self.next[i]);
        if p != NONE {
            self.next[p as usize] = n;
        } else {
            self.head[self.cell[i] as usize] = n;
        }
        if n != NONE {
            self.prev[n as usize] = p;
        }
    }

    pub fn move_to(&mut self, i: usize, c: usize) {
        self.remove(i);
        self.insert(i, c);
    }

    /// Every sphere in cell `c`.
    #[inline]
    pub fn for_each_in(&self, c: usize, mut f: impl FnMut(u32)) {
        let mut j = self.head[c];
        while j != NONE {
            f(j);
            j = self.next[j as usize];
        }
    }
}

/// Spheres larger than `factor` times the bulk (98th percentile) radius go
/// to the second level. Returns that threshold (infinite when the largest
/// is within it) and the largest radius at or under it. `bodies` is not empty.
pub fn split_big(bodies: &[Body], factor: f64) -> (f64, f64) {
    let n = bodies.len();
    let mut radii: Vec<f64> = bodies.iter().map(|b| b.radius).collect();
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
        .map(|b| b.radius)
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
