//! Spatial renumbering (feature `experiments`): the load sorts the spheres
//! in space ([`super::spatial`]); as they drift, [`EventDriven::renumber`]
//! sorts them again (when asked: `with_renumbering(true)`; at 100k and 1M
//! spheres it cost more than it saved, see docs/benchmarks.md "exact at
//! scale"). The pins of `tests/physics/exact_pin.rs` run with it on, so they hold
//! it to changing nothing.
//! Only labels change: every record moves with its sphere and keeps its
//! value (and each cell and list keeps its order), and `order` maps the
//! labels back to the world's ids, so the world, the CSV and the screen
//! see every sphere at its id.
use super::body::Body;
use super::ids::Label;
use super::queue::EventQueue;
use super::schedule::{Event, Kind};
use super::spatial::spatial_order;
use super::{Broad, EventDriven};

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
    if ev.kind() == Kind::Pair {
        *ev = ev.with_partner(inv[ev.partner().index()]);
    }
}

impl<Q: EventQueue> EventDriven<Q> {
    /// Renumber, if on, once the spheres have crossed about a cell each on
    /// average since the last sort.
    pub(super) fn renumber_if_drifted(&mut self) {
        let moved = self.stats.crossings + self.stats.relists;
        if self.valid
            && self.hooks.renumbering
            && moved - self.hooks.sorted_at >= self.bodies.len().max(1) as u64
        {
            self.renumber();
            self.hooks.sorted_at = moved;
        }
    }

    /// Sort the spheres by cell again (their positions at their own time
    /// stamps), moving every per-sphere record with its sphere.
    pub(super) fn renumber(&mut self) {
        let start = std::time::Instant::now();
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
        // One of the two is empty: slots in cell mode, events with lists.
        if !self.slots.is_empty() {
            apply(&mut self.slots, &perm);
            apply(&mut self.holds, &perm);
        }
        for slot in &mut self.slots {
            relabel(&mut slot.ev, &inv);
        }
        if !self.events.is_empty() {
            apply(&mut self.events, &perm);
        }
        for ev in &mut self.events {
            relabel(ev, &inv);
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
        let took = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.stats.renumber_nanos = self.stats.renumber_nanos.saturating_add(took);
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
}
