//! The spheres of each cell, for the cell-crossing locality, laid out for
//! gathering a stencil of cells fast: each cell names a small block holding
//! its count and its first [`BLOCK`] spheres, so collecting a cell is one
//! fixed-size copy. Walking a linked list instead ends each cell with a
//! data-dependent branch (how many spheres?) that mispredicts about once per
//! cell, which measured as the largest cost of a prediction. Most cells are
//! empty (up to 4 a sphere) and most of the others hold one sphere, so a
//! cell is one word: empty, its lone sphere, or the index of its block in
//! a pool with a free list. A cell costs 4 bytes, one of two spheres or
//! more 16 more, and the gather stays without a branch (a lone sphere is
//! written and counted by its flag, then a block is copied: the shared
//! empty one unless the cell has its own). The rare spheres beyond
//! [`BLOCK`] in one cell wait in a map from the cell.
use crate::physics::exact::ids::Label;
use crate::physics::huge_pages;
use std::collections::HashMap;

/// Spheres a cell's block holds (cells are about a diameter wide, so most
/// hold fewer).
pub const BLOCK: usize = 3;
/// Words of a cell's block: its spheres, then its count.
const WORDS: usize = BLOCK + 1;
/// Length of the scratch window the stencils are gathered into.
const SCRATCH: usize = WINDOW + WORDS;
/// The slot of an empty cell, and the block every cell without one of its
/// own copies (never written).
const EMPTY: u32 = 0;
/// Flag of a slot holding a lone sphere (the rest of the word).
const ONE: u32 = 1 << 31;
/// End of the free list (a block's number, as `slot` and a free block's
/// first word keep it).
const NO_BLOCK: u32 = u32::MAX;

#[derive(Clone, Debug, Default)]
pub struct CellBlocks {
    /// Per cell: [`EMPTY`], `ONE | sphere` when it holds one, or its block
    /// in `pool` when it holds more.
    slot: Vec<u32>,
    /// The blocks: the first `BLOCK` spheres, then the count. A free block
    /// links the next free one in its first word.
    pool: Vec<[u32; WORDS]>,
    free: u32,
    /// Spheres `BLOCK..count` of the cells holding more than `BLOCK`.
    overflow: HashMap<u32, Vec<u32>>,
}

impl CellBlocks {
    /// `cells` empty cells, with room for blocks for as many cells as
    /// `spheres` can fill two at a time (reserved, not touched: the pool
    /// never needs more, so it never moves).
    pub fn reset(&mut self, spheres: usize, cells: usize) {
        self.slot = huge_pages::filled(cells, EMPTY);
        self.pool = Vec::new();
        huge_pages::reserve(&mut self.pool, (spheres / 2).min(cells) + 1);
        self.pool.push([0; WORDS]);
        self.free = NO_BLOCK;
        self.overflow.clear();
    }

    /// Bytes held on the heap (the pool's untouched reserve not counted).
    pub fn heap_bytes(&self) -> usize {
        let over: usize = self.overflow.values().map(|v| v.capacity() * 4 + 32).sum();
        self.slot.capacity() * 4
            + self.pool.len() * size_of::<[u32; WORDS]>()
            + self.overflow.capacity() * (size_of::<(u32, Vec<u32>)>() + 1)
            + over
    }

    /// Cells, padding included.
    pub fn cells(&self) -> usize {
        self.slot.len()
    }

    /// A slot read for a gather: its lone sphere (meaningful when the flag
    /// is 1), that flag, and its block (the empty one but for a cell of
    /// two spheres or more).
    #[inline(always)]
    fn parts(&self, s: u32) -> (u32, usize, &[u32; WORDS]) {
        let one = s >> 31;
        let block = s & one.wrapping_sub(1);
        (s & !ONE, one as usize, &self.pool[block as usize])
    }

    /// Cell `c`'s block (it has one: it holds two spheres or more).
    #[inline]
    fn block(&self, c: usize) -> &[u32; WORDS] {
        &self.pool[self.slot[c] as usize]
    }

    #[inline]
    fn block_mut(&mut self, c: usize) -> &mut [u32; WORDS] {
        &mut self.pool[self.slot[c] as usize]
    }

    /// Spheres in cell `c`.
    #[cfg(test)]
    #[inline]
    pub fn count(&self, c: usize) -> u32 {
        let (_, one, b) = self.parts(self.slot[c]);
        one as u32 + b[BLOCK]
    }

    /// Whether cell `c` holds no sphere.
    #[inline]
    pub fn is_empty(&self, c: usize) -> bool {
        self.slot[c] == EMPTY
    }

    #[inline]
    fn set(&mut self, c: usize, k: usize, j: u32) {
        if k < BLOCK {
            self.block_mut(c)[k] = j;
        } else {
            let o = self.overflow.entry(c as u32).or_default();
            if k - BLOCK == o.len() {
                o.push(j);
            } else {
                o[k - BLOCK] = j;
            }
        }
    }

    #[inline]
    fn get(&self, c: usize, k: usize) -> u32 {
        if k < BLOCK {
            self.block(c)[k]
        } else {
            self.overflow[&(c as u32)][k - BLOCK]
        }
    }

    /// Put sphere `i` last in cell `c`.
    #[inline]
    pub fn insert(&mut self, i: Label, c: usize) {
        let s = self.slot[c];
        let i = i.raw();
        if s == EMPTY {
            self.slot[c] = ONE | i;
        } else if s & ONE != 0 {
            let b = if self.free == NO_BLOCK {
                self.pool.push([0; WORDS]);
                self.pool.len() - 1
            } else {
                let b = self.free as usize;
                self.free = self.pool[b][0];
                b
            };
            let mut block = [0; WORDS];
            (block[0], block[1], block[BLOCK]) = (s & !ONE, i, 2);
            self.pool[b] = block;
            self.slot[c] = b as u32;
        } else {
            let k = self.block(c)[BLOCK] as usize;
            self.set(c, k, i);
            self.block_mut(c)[BLOCK] += 1;
        }
    }

    /// Sphere `i`'s place in cell `c`, a cell with a block (it holds a few;
    /// the rare crowded one is searched past its block).
    #[inline]
    fn place(&self, i: u32, c: usize) -> usize {
        let b = self.block(c);
        let inline = (b[BLOCK] as usize).min(BLOCK);
        if let Some(k) = b[..inline].iter().position(|&j| j == i) {
            return k;
        }
        let more = self
            .overflow
            .get(&(c as u32))
            .map_or(&[][..], Vec::as_slice);
        let k = more.iter().position(|&j| j == i);
        debug_assert!(k.is_some(), "sphere {i} is not in cell {c}");
        BLOCK + k.unwrap_or(0)
    }

    /// Take sphere `i` out of cell `c`, its cell; the cell's last sphere
    /// fills its place (so every cell keeps the order it had).
    #[inline(always)]
    pub fn remove(&mut self, i: Label, c: usize) {
        let s = self.slot[c];
        let i = i.raw();
        if s & ONE != 0 {
            debug_assert_eq!(s & !ONE, i, "cell {c}");
            self.slot[c] = EMPTY;
            return;
        }
        let k = self.place(i, c);
        let last = self.block(c)[BLOCK] as usize - 1;
        if k != last {
            let moved = self.get(c, last);
            self.set(c, k, moved);
        }
        if last == BLOCK {
            self.overflow.remove(&(c as u32));
        } else if last > BLOCK
            && let Some(o) = self.overflow.get_mut(&(c as u32))
        {
            o.pop();
        }
        self.block_mut(c)[BLOCK] -= 1;
        if last == 1 {
            // One sphere left, first in the block: the cell holds it alone.
            let b = s as usize;
            let lone = self.pool[b][0];
            self.pool[b][0] = self.free;
            self.free = b as u32;
            self.slot[c] = ONE | lone;
        }
    }

    /// Start loading cell `c`'s word.
    #[inline(always)]
    pub fn prefetch(&self, c: usize) {
        if let Some(s) = self.slot.get(c) {
            crate::physics::prefetch::line(s);
        }
    }

    /// Move sphere `i` from cell `from` to the end of cell `to`.
    #[inline]
    pub fn move_to(&mut self, i: Label, from: usize, to: usize) {
        self.remove(i, from);
        self.insert(i, to);
    }

    /// Collect the spheres of the cells `base + offsets[..]` into `out[..n]`
    /// and return `n` (`out` is scratch: its length past `n` means nothing).
    /// Order: each cell's block in turn, then any overflow in the same order.
    #[inline(always)]
    pub fn gather(&self, base: usize, offsets: &[usize], out: &mut Vec<u32>) -> usize {
        // Room to copy a whole block for every cell, so each copy is
        // unconditional: one 16-byte move, the count landing past the end.
        let room = (offsets.len() * BLOCK).max(WINDOW) + WORDS;
        if out.len() < room {
            out.resize(room, 0);
        }
        let mut n = 0;
        // The OR of the counts exceeds BLOCK exactly when one count does
        // (WORDS is a power of two): one OR per cell, one test at the end.
        let mut counts = 0;
        // The stencils: writing at `n` masked to the window lets the
        // compiler drop the bounds checks on `out` (the mask never bites, as
        // `n` stays within it); they were half the work per cell. `out` has
        // the room (made above), so the window is always there.
        let window = if offsets.len() * BLOCK <= WINDOW {
            out.first_chunk_mut::<SCRATCH>()
        } else {
            None
        };
        if let Some(window) = window {
            for &o in offsets {
                let (lone, one, b) = self.parts(self.slot[base + o]);
                window[n & (WINDOW - 1)] = lone;
                n += one;
                let at = n & (WINDOW - 1);
                window[at..at + WORDS].copy_from_slice(b);
                counts |= b[BLOCK];
                n += (b[BLOCK] as usize).min(BLOCK);
            }
        } else {
            for &o in offsets {
                let (lone, one, b) = self.parts(self.slot[base + o]);
                out[n] = lone;
                n += one;
                out[n..n + WORDS].copy_from_slice(b);
                counts |= b[BLOCK];
                n += (b[BLOCK] as usize).min(BLOCK);
            }
        }
        if counts as usize > BLOCK {
            out.truncate(n);
            for &o in offsets {
                if let Some(more) = self.overflow.get(&((base + o) as u32)) {
                    out.extend_from_slice(more);
                }
            }
            n = out.len();
        }
        n
    }
}

impl CellBlocks {
    /// [`Self::gather`] for a stencil of a fixed `K` cells (the 27 around a
    /// cell, the 9 a crossing brings), all within the grid: per cell one
    /// index, one 16-byte copy and two adds, no clamp. A count over `BLOCK` anywhere falls back to [`Self::gather`].
    #[inline(always)]
    pub fn gather_stencil<const K: usize>(
        &self,
        base: usize,
        offsets: &[usize; K],
        out: &mut Vec<u32>,
    ) -> usize {
        const { assert!(K * WORDS <= WINDOW) };
        if out.len() < SCRATCH {
            out.resize(SCRATCH, 0);
        }
        // Always there (room made above); the general gather otherwise.
        let Some(window) = out.first_chunk_mut::<SCRATCH>() else {
            return self.gather(base, offsets, out);
        };
        // One bounds check per cell remains, never taken (a cell in the
        // grid has its stencil in the grid, padding included).
        let slot = &self.slot[base..];
        let mut n = 0;
        let mut counts = 0;
        for &o in offsets {
            let (lone, one, b) = self.parts(slot[o]);
            // Each count is at most BLOCK on this path, so `n` stays within
            // the window; the mask only lets the compiler see that.
            window[n & (WINDOW - 1)] = lone;
            n += one;
            let at = n & (WINDOW - 1);
            window[at..at + WORDS].copy_from_slice(b);
            counts |= b[BLOCK];
            n += b[BLOCK] as usize;
        }
        if counts as usize > BLOCK {
            return self.gather(base, offsets, out);
        }
        n
    }
}

/// A power of two above the blocks of the 27-cell stencil.
const WINDOW: usize = 128;
const _: () = assert!(WORDS.is_power_of_two() && 27 * BLOCK <= WINDOW);

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Random inserts, moves and removals, crowding a few cells well past
    /// `BLOCK`, checked against a plain list per cell.
    #[test]
    fn matches_a_plain_list_per_cell() {
        let (spheres, cells) = (40, 6);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut s = CellBlocks::default();
        s.reset(spheres, cells);
        assert_eq!(s.pool.capacity(), cells + 1);
        s.reset(3, cells);
        assert_eq!(s.pool.capacity(), 2);
        s.reset(spheres, cells);
        let mut reference: Vec<Vec<u32>> = vec![Vec::new(); cells];
        let mut out = Vec::new();
        let mut most_blocks = 0;
        for step in 0..20_000 {
            let i = rng.random_range(0..spheres);
            let to = rng.random_range(0..cells);
            let here = reference.iter().position(|l| l.contains(&(i as u32)));
            let removed = match (here, rng.random_range(0..4)) {
                (None, _) => {
                    s.insert(Label::at(i), to);
                    false
                }
                (Some(c), 0) => {
                    s.remove(Label::at(i), c);
                    true
                }
                (Some(c), _) => {
                    s.move_to(Label::at(i), c, to);
                    false
                }
            };
            if let Some(c) = here {
                // The last fills the place, as the blocks do: order is kept.
                let l = &mut reference[c];
                let k = l.iter().position(|&j| j == i as u32).unwrap();
                l.swap_remove(k);
            }
            if !removed {
                reference[to].push(i as u32);
            }
            for (c, want) in reference.iter().enumerate() {
                let n = s.gather(c, &[0], &mut out);
                assert_eq!(out[..n], want[..], "cell {c} after step {step}");
                assert_eq!(s.count(c) as usize, want.len());
            }
            // One block a cell of two spheres or more, and the empty one.
            let occupied = reference.iter().filter(|l| l.len() > 1).count();
            most_blocks = most_blocks.max(occupied);
            assert_eq!(s.pool.len(), most_blocks + 1, "step {step}");
            let all = s.gather(0, &(0..cells).collect::<Vec<_>>(), &mut out);
            assert_eq!(all, reference.iter().map(Vec::len).sum::<usize>());
            // More cells than the fast path's window holds (a large sphere's scan).
            let many: Vec<usize> = (0..cells).cycle().take(60).collect();
            let n = s.gather(0, &many, &mut out);
            let mut got = out[..n].to_vec();
            got.sort_unstable();
            let mut want: Vec<u32> = many.iter().flat_map(|&c| reference[c].clone()).collect();
            want.sort_unstable();
            assert_eq!(got, want, "60 cells after step {step}");
        }
        assert!(reference.iter().any(|l| l.len() > BLOCK));
    }

    /// The fixed-stencil gather gives what the general one gives, in the
    /// same order (the order ties are broken in), with blocks full, part
    /// full and overflowing, and on a grid whose cell count is not a power
    /// of two.
    #[test]
    fn stencil_gather_matches_the_general_one() {
        let (spheres, cells) = (120, 100);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut s = CellBlocks::default();
        s.reset(spheres, cells);
        let mut at = vec![0; spheres];
        for (i, a) in at.iter_mut().enumerate() {
            // Crowd the low cells, so some hold more than BLOCK.
            let crowd = rng.random_range(1..=cells);
            *a = rng.random_range(0..crowd);
            s.insert(Label::at(i), *a);
        }
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut overflowed = 0;
        for _ in 0..2000 {
            let i = rng.random_range(0..spheres);
            let to = rng.random_range(0..cells);
            s.move_to(Label::at(i), at[i], to);
            at[i] = to;
            let base = rng.random_range(0..cells - 30);
            let o27: [usize; 27] = std::array::from_fn(|_| rng.random_range(0..30));
            let o9: [usize; 9] = std::array::from_fn(|_| rng.random_range(0..30));
            let n = s.gather(base, &o27, &mut a);
            assert_eq!(s.gather_stencil(base, &o27, &mut b), n);
            assert_eq!(a[..n], b[..n]);
            let n = s.gather(base, &o9, &mut a);
            assert_eq!(s.gather_stencil(base, &o9, &mut b), n);
            assert_eq!(a[..n], b[..n]);
            overflowed += o27.iter().any(|&o| s.count(base + o) as usize > BLOCK) as u32;
        }
        assert!(overflowed > 100, "only {overflowed} gathers overflowed");
    }
}
