//! The neighbour lists' grid: the spheres of each cell (by list centre) as
//! intrusive doubly linked chains, so a sphere moves between cells in O(1)
//! at a relist. Only rebuilds walk it; the cell-crossing broad phase, which
//! gathers cells far more often, keeps its cells in
//! [`CellBlocks`](crate::physics::exact::cell_grid::blocks::CellBlocks) instead.
use crate::physics::exact::ids::{Cell, Label};
#[cfg(feature = "experiments")]
use crate::physics::exact::renumber::apply;
use crate::physics::huge_pages;

#[derive(Clone, Debug, Default)]
pub struct CellChains {
    /// Each cell's first sphere, [`Label::NONE`] for an empty one.
    head: Vec<Label>,
    /// Each sphere's neighbours in its chain, [`Label::NONE`] at the ends.
    next: Vec<Label>,
    prev: Vec<Label>,
    /// The cell of each sphere, [`Cell::NONE`] for one in no cell.
    cell: Vec<Cell>,
}

impl CellChains {
    /// `spheres` spheres, none in a cell, and `cells` empty cells.
    pub fn reset(&mut self, spheres: usize, cells: usize) {
        huge_pages::refill(&mut self.next, spheres, Label::NONE);
        huge_pages::refill(&mut self.prev, spheres, Label::NONE);
        huge_pages::refill(&mut self.cell, spheres, Cell::NONE);
        huge_pages::refill(&mut self.head, cells, Label::NONE);
    }

    #[inline]
    pub fn cell(&self, i: Label) -> Cell {
        self.cell[i.index()]
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        let labels: usize = [&self.head, &self.next, &self.prev]
            .iter()
            .map(|v| v.capacity() * size_of::<Label>())
            .sum();
        labels + self.cell.capacity() * size_of::<Cell>()
    }

    pub fn insert(&mut self, i: Label, c: usize) {
        let head = self.head[c];
        self.cell[i.index()] = Cell::at(c);
        self.prev[i.index()] = Label::NONE;
        self.next[i.index()] = head;
        if head != Label::NONE {
            self.prev[head.index()] = i;
        }
        self.head[c] = i;
    }

    pub fn remove(&mut self, i: Label) {
        let (p, n) = (self.prev[i.index()], self.next[i.index()]);
        if p == Label::NONE {
            self.head[self.cell[i.index()].index()] = n;
        } else {
            self.next[p.index()] = n;
        }
        if n != Label::NONE {
            self.prev[n.index()] = p;
        }
    }

    /// The spheres are relabelled (`perm[new] = old`, `inv` its inverse);
    /// every chain keeps its order.
    #[cfg(feature = "experiments")]
    pub fn relabel(&mut self, perm: &[Label], inv: &[Label]) {
        for v in [&mut self.head, &mut self.next, &mut self.prev] {
            for x in v.iter_mut().filter(|x| **x != Label::NONE) {
                *x = inv[x.index()];
            }
        }
        apply(&mut self.next, perm);
        apply(&mut self.prev, perm);
        apply(&mut self.cell, perm);
    }

    pub fn move_to(&mut self, i: Label, c: usize) {
        self.remove(i);
        self.insert(i, c);
    }

    /// Every sphere in cell `c`.
    #[inline]
    pub fn for_each_in(&self, c: usize, mut f: impl FnMut(Label)) {
        let mut j = self.head[c];
        while j != Label::NONE {
            f(j);
            j = self.next[j.index()];
        }
    }
}
