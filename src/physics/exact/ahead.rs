//! Prefetching for the event loop (from [`PREFETCH_FROM`](super::PREFETCH_FROM)
//! spheres): what the loop will read next is asked for while the current
//! event runs, so the cache misses of one event wait together and beside
//! the next one's, instead of one after another (docs/perf-log.md,
//! 2026-12-05).
use super::cell_grid::CellGrid;
use super::event_loop::EventLoop;
use super::ids::Label;
use super::locality::Locality;
use super::queue::EventQueue;
use super::schedule::{Event, Kind, Queued};

impl<L: Locality> EventLoop<L> {
    /// Start loading what the loop will read next: what a crossing of `i`
    /// (event `ev`) reads; after a contact or a wall, what predicting `i`
    /// reads first, and the partner's records; and the records of the
    /// sphere whose event is likely next (the queue's runner-up), so their
    /// cache misses wait together while this event is processed. Returns
    /// the runner-up, for a crossing to prefetch for it part-way through
    /// ([`prefetch_next_crossing`]).
    #[inline(always)]
    pub(super) fn prefetch_ahead(&self, i: Label, ev: Event) -> Option<Label> {
        match ev.kind() {
            Kind::Cross => self.locality.prefetch_cross(i, ev.mask(), &self.bodies),
            Kind::Pair => {
                self.prefetch_records(ev.partner().index());
                self.locality.prefetch_around(i, &self.bodies);
            }
            Kind::Wall => self.locality.prefetch_around(i, &self.bodies),
            _ => {}
        }
        let next = self.queue.runner_up();
        if let Some(k) = next {
            self.prefetch_records(k);
        }
        next.map(Label::at)
    }

    /// Start loading sphere `k`'s records, if `k` is a sphere: its body,
    /// queue leaf, and what its locality keeps and reads first.
    #[inline(always)]
    fn prefetch_records(&self, k: usize) {
        if let Some(body) = self.bodies.get(k) {
            crate::physics::prefetch::line(body);
            self.queue.prefetch(k);
            self.locality.prefetch_records(k);
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
        && q.is_locality()
        && q.event().kind() == Kind::Cross
    {
        cells.prefetch_cross(next, q.event().mask());
    }
}
