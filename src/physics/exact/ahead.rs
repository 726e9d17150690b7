//! Prefetching for the event loop (from [`PREFETCH_FROM`](super::PREFETCH_FROM)
//! spheres): what the loop will read next is asked for while the current
//! event runs, so the cache misses of one event wait together and beside
//! the next one's, instead of one after another (docs/perf-log.md,
//! 2026-12-05).
use super::cell_grid::CellGrid;
use super::ids::Label;
use super::queue::EventQueue;
use super::schedule::{Event, Kind, Queued};
use super::{Broad, Exact};

impl Exact {
    /// Start loading what the loop will read next: the cells a crossing
    /// of `i` (event `ev`) reads and its pending partner's body; after a
    /// contact or a wall, what predicting `i` reads first, and the
    /// partner's records; and the records of the sphere whose event is
    /// likely next (the queue's runner-up), so their cache misses wait
    /// together while this event is processed. Returns the runner-up, for
    /// a crossing to prefetch for it part-way through
    /// ([`prefetch_next_crossing`]).
    #[inline(always)]
    pub(super) fn prefetch_ahead(&self, i: Label, ev: Event) -> Option<Label> {
        match (ev.kind(), &self.broad) {
            (Kind::Cross, Broad::Cells(cells)) => {
                cells.prefetch_cross(i, ev.mask());
                // The crossing checks whether its pending contact still holds.
                let (_, pending) = self.slots[i.index()].pending();
                if pending.kind() == Kind::Pair {
                    self.bodies.prefetch_one(pending.partner());
                }
            }
            (Kind::Pair, _) => {
                self.prefetch_records(ev.partner().index());
                self.prefetch_neighbours(i);
            }
            (Kind::Wall, _) => self.prefetch_neighbours(i),
            _ => {}
        }
        let next = self.queue.runner_up();
        if let Some(k) = next {
            self.prefetch_records(k);
        }
        next.map(Label::at)
    }

    /// Start loading what predicting `i` reads first: the bodies in its
    /// neighbour list, or the cells around it.
    #[inline(always)]
    pub(super) fn prefetch_neighbours(&self, i: Label) {
        match &self.broad {
            Broad::Lists(nl) => {
                for l in nl.of(i) {
                    self.bodies.prefetch_one(l.j);
                }
            }
            Broad::Cells(cells) => cells.prefetch_around(i),
        }
    }

    /// Start loading sphere `k`'s records, if `k` is a sphere: its slot,
    /// body and queue leaf, and what its broad phase reads first.
    #[inline(always)]
    pub(super) fn prefetch_records(&self, k: usize) {
        use crate::physics::prefetch::{line, record};
        if let Some(body) = self.bodies.get(k) {
            line(body);
            self.queue.prefetch(k);
            match &self.broad {
                Broad::Cells(cells) => {
                    if let (Some(slot), Some(holds)) = (self.slots.get(k), self.holds.get(k)) {
                        record(slot);
                        line(holds);
                    }
                    cells.prefetch_place(k);
                }
                Broad::Lists(nl) => {
                    if let Some(ev) = self.events.get(k) {
                        record(ev);
                    }
                    nl.prefetch(k);
                }
            }
        }
    }
}

/// Cell mode: if sphere `next`'s queued event is a crossing, start loading
/// the cells it will read. Called part-way through a crossing (after its
/// gather and move): `next`'s byte in `holds` was asked for as the
/// crossing began and has arrived by then, so the next crossing's cells
/// load while the rest of this one runs, a whole event before they are
/// read. (In a contact or a wall event it has not arrived in time:
/// docs/perf-log.md.)
#[inline(always)]
pub(super) fn prefetch_next_crossing(cells: &CellGrid, holds: &[Queued], next: Option<Label>) {
    if let Some(next) = next
        && let Some(&q) = holds.get(next.index())
        && q.is_broad()
        && q.event().kind() == Kind::Cross
    {
        cells.prefetch_cross(next, q.event().mask());
    }
}
