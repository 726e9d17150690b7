//! The neighbour lists' grid: the spheres of each cell (by list centre) as
//! intrusive singly linked chains, so a sphere moves between cells at a
//! relist by unlinking it from its old cell's chain (a few spheres at most:
//! cells are about a sphere and its skin wide) and pushing it on the new.
//! Only rebuilds walk it; the cell grid (the other locality), which gathers
//! cells far more often, keeps its cells in
//! [`CellBlocks`](crate::physics::exact::cell_grid::blocks::CellBlocks) instead.
//! A sphere's cell is not stored: its owner recomputes it from the list
//! centre, which is where the sphere was put in.
use crate::physics::exact::ids::{Cell, Label};
use crate::physics::huge_pages;

#[derive(Clone, Debug, Default)]
pub struct CellChains {
    /// Each cell's first sphere, [`Label::NONE`] for an empty one.
    head: Vec<Label>,
    /// The next sphere in each sphere's chain, [`Label::NONE`] at the end.
    next: Vec<Label>,
}

impl CellChains {
    /// `spheres` spheres, none in a cell, and `cells` empty cells.
    pub fn reset(&mut self, spheres: usize, cells: usize) {
        huge_pages::refill(&mut self.next, spheres, Label::NONE);
        huge_pages::refill(&mut self.head, cells, Label::NONE);
    }

    /// Bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        (self.head.capacity() + self.next.capacity()) * size_of::<Label>()
    }

    /// Put sphere `i` first in cell `c`.
    pub fn insert(&mut self, i: Label, c: Cell) {
        let head = &mut self.head[c.index()];
        self.next[i.index()] = *head;
        *head = i;
    }

    /// Take sphere `i` out of cell `c`, its cell; the others keep their order.
    pub fn remove(&mut self, i: Label, c: Cell) {
        let after = self.next[i.index()];
        let mut at = self.head[c.index()];
        if at == i {
            self.head[c.index()] = after;
            return;
        }
        while at != Label::NONE {
            let n = self.next[at.index()];
            if n == i {
                self.next[at.index()] = after;
                return;
            }
            at = n;
        }
        debug_assert!(false, "sphere {i:?} is not in cell {c:?}");
    }

    /// Sphere `i` from cell `from` to cell `to`, first there.
    #[inline]
    pub fn move_to(&mut self, i: Label, from: Cell, to: Cell) {
        self.remove(i, from);
        self.insert(i, to);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(ch: &CellChains, c: usize) -> Vec<usize> {
        let mut v = Vec::new();
        ch.for_each_in(c, |j| v.push(j.index()));
        v
    }

    /// Removing from the head, the middle and the end keeps the others'
    /// order, as the doubly linked chains did.
    #[test]
    fn removal_keeps_the_order_of_the_rest() {
        let mut ch = CellChains::default();
        ch.reset(6, 2);
        for i in 0..5 {
            ch.insert(Label::at(i), Cell::at(0));
        }
        assert_eq!(cell(&ch, 0), [4, 3, 2, 1, 0]);
        ch.remove(Label::at(2), Cell::at(0));
        assert_eq!(cell(&ch, 0), [4, 3, 1, 0]);
        ch.remove(Label::at(4), Cell::at(0));
        assert_eq!(cell(&ch, 0), [3, 1, 0]);
        ch.move_to(Label::at(0), Cell::at(0), Cell::at(1));
        assert_eq!(cell(&ch, 0), [3, 1]);
        assert_eq!(cell(&ch, 1), [0]);
        ch.insert(Label::at(5), Cell::at(1));
        assert_eq!(cell(&ch, 1), [5, 0]);
    }
}
