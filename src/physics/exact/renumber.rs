//! Spatial renumbering: the event loop keeps its spheres in the order of
//! their cells, so a sphere's neighbours sit close to it in every
//! per-sphere array and a prediction touches few cache lines. The load
//! sorts them; as they drift, [`EventDriven::renumber`] sorts them again
//! (when asked: `with_renumbering(true)`; at 100k and 1M spheres it cost
//! more than it saved, see docs/benchmarks.md "exact at scale").
//! Only labels change: every record moves with its sphere and keeps its
//! value (and each cell and list keeps its order), and `order` maps the
//! labels back to the world's ids, so the world, the CSV and the screen
//! see every sphere at its id.
use super::body::Body;
use super::ids::Label;
use super::queue::EventQueue;
use super::schedule::{Event, Kind};
use super::{Broad, EventDriven};
use glam::DVec3;

/// The spheres' numbers (`number(i)` of the `i`th position: world ids at
/// load, labels at a renumbering) in the order of their cells on a grid of
/// about one cell a sphere, z then y then x; ties keep their current order
/// (a counting sort: linear, and stable). `perm[new] = old`.
#[must_use]
pub fn spatial_order<T: Copy + Default>(
    positions: impl ExactSizeIterator<Item = DVec3>,
    size: f64,
    number: impl Fn(usize) -> T,
) -> Vec<T> {
    let n = positions.len();
    let per_side = ((n as f64).cbrt().ceil() as usize).max(1);
    let cell = |x: f64| ((x / size * per_side as f64) as usize).min(per_side - 1);
    let key = |p: DVec3| {
        cell(p.x.max(0.0)) + per_side * (cell(p.y.max(0.0)) + per_side * cell(p.z.max(0.0)))
    };
    let keys: Vec<u32> = positions.map(|p| key(p) as u32).collect();
    let mut start = vec![0u32; per_side * per_side * per_side + 1];
    for &k in &keys {
        start[k as usize + 1] += 1;
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    let mut perm = vec![T::default(); n];
    for (i, &k) in keys.iter().enumerate() {
        let at = &mut start[k as usize];
        perm[*at as usize] = number(i);
        *at += 1;
    }
    perm
}

/// The inverse of a permutation: `inv[old] = new`.
#[must_use]
pub fn inverse(perm: &[Label]) -> Vec<Label> {
    let mut inv = vec![Label::default(); perm.len()];
    for (new, &old) in perm.iter().enumerate() {
        inv[old.index()] = Label::at(new);
    }
    inv
}

/// Reorder `v` in place so that `v[new] = v_before[perm[new]]`, following
/// the cycles of the permutation (no copy of `v`).
pub fn apply<T: Copy>(v: &mut [T], perm: &[Label]) {
    let mut done = vec![false; perm.len()];
    for start in 0..perm.len() {
        if done[start] {
            continue;
        }
        let first = v[start];
        let mut at = start;
        loop {
            done[at] = true;
            let from = perm[at].index();
            if from == start {
                v[at] = first;
                break;
            }
            v[at] = v[from];
            at = from;
        }
    }
}

/// [`apply`] to the records of `width` items each that `v` holds, one a sphere.
pub fn apply_chunks<T: Copy + Default>(v: &mut [T], width: usize, perm: &[Label]) {
    let mut done = vec![false; perm.len()];
    let mut first = vec![T::default(); width];
    for start in 0..perm.len() {
        if done[start] {
            continue;
        }
        first.copy_from_slice(&v[start * width..(start + 1) * width]);
        let mut at = start;
        loop {
            done[at] = true;
            let from = perm[at].index();
            if from == start {
                v[at * width..(at + 1) * width].copy_from_slice(&first);
                break;
            }
            v.copy_within(from * width..(from + 1) * width, at * width);
            at = from;
        }
    }
}

/// A pair event names its partner by label: relabel it.
fn relabel(ev: &mut Event, inv: &[Label]) {
    if ev.kind == Kind::Pair {
        ev.partner = inv[ev.partner.index()];
    }
}

impl<Q: EventQueue> EventDriven<Q> {
    /// Sort the spheres by cell again (their positions at their own time
    /// stamps), moving every per-sphere record with its sphere.
    pub(super) fn renumber(&mut self) {
        let perm = spatial_order(
            self.bodies.iter().map(|b: &Body| b.pos),
            self.size,
            Label::at,
        );
        let inv = inverse(&perm);
        let times: Vec<f64> = perm
            .iter()
            .map(|&old| self.queue.time_of(old.index()))
            .collect();
        apply(self.bodies.list_mut(), &perm);
        apply(&mut self.order, &perm);
        apply(&mut self.slots, &perm);
        for slot in &mut self.slots {
            let mut ev = slot.ev;
            relabel(&mut ev, &inv);
            slot.ev = ev;
        }
        match &mut self.broad {
            Broad::Lists(nl) => nl.relabel(&perm, &inv),
            Broad::Cells(cells) => cells.relabel(&perm, &inv),
        }
        self.queue.reset(perm.len());
        for (i, &t) in times.iter().enumerate() {
            self.queue.set_leaf(i, t);
        }
        self.queue.rebuild();
        self.stats.renumberings += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apply_moves_each_record_to_its_new_label() {
        let raw = [3u32, 0, 4, 1, 2, 6, 5];
        let perm = raw.map(Label::from_raw);
        let mut v: Vec<u32> = (100..107).collect();
        apply(&mut v, &perm);
        assert_eq!(v, raw.map(|o| 100 + o));
        let mut w: Vec<u32> = (0..14).collect();
        apply_chunks(&mut w, 2, &perm);
        let want: Vec<u32> = raw.iter().flat_map(|&o| [2 * o, 2 * o + 1]).collect();
        assert_eq!(w, want);
        let inv = inverse(&perm);
        for (new, &old) in perm.iter().enumerate() {
            assert_eq!(inv[old.index()], Label::at(new));
        }
    }

    #[test]
    fn spatial_order_sorts_by_cell_and_keeps_ties_in_order() {
        // Two per cell of a 2-a-side grid, given in reverse cell order.
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let pos = [
            p(0.9, 0.9, 0.9),
            p(0.1, 0.1, 0.1),
            p(0.6, 0.1, 0.1),
            p(0.2, 0.2, 0.2),
            p(0.1, 0.1, 0.9),
            p(0.1, 0.9, 0.1),
            p(0.7, 0.7, 0.7),
            p(0.3, 0.3, 0.3),
        ];
        let perm = spatial_order(pos.into_iter(), 1.0, |i| i);
        assert_eq!(perm, [1, 3, 7, 2, 5, 4, 0, 6]);
    }
}
