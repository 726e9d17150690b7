//! The neighbour lists' grid: the spheres of each cell (by list centre) as
//! intrusive doubly linked chains, so a sphere moves between cells in O(1)
//! at a relist. Only rebuilds walk it; the cell-crossing broad phase, which
//! gathers cells far more often, keeps its cells in
//! [`CellBlocks`](crate::physics::exact::cell_grid::blocks::CellBlocks) instead.
use crate::physics::exact::NONE;
use crate::physics::exact::renumber::apply;

#[derive(Clone, Debug, Default)]
pub struct CellChains {
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    /// The cell of each sphere, `NONE` for one in no cell.
    cell: Vec<u32>,
}

impl CellChains {
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
        if p == NONE {
            self.head[self.cell[i] as usize] = n;
        } else {
            self.next[p as usize] = n;
        }
        if n != NONE {
            self.prev[n as usize] = p;
        }
    }

    /// The spheres are relabelled (`perm[new] = old`, `inv` its inverse);
    /// every chain keeps its order.
    pub fn relabel(&mut self, perm: &[u32], inv: &[u32]) {
        for v in [&mut self.head, &mut self.next, &mut self.prev] {
            for x in v.iter_mut().filter(|x| **x != NONE) {
                *x = inv[*x as usize];
            }
        }
        for v in [&mut self.next, &mut self.prev, &mut self.cell] {
            apply(v, perm);
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
