//! A cell grid as the event loop's locality: a sphere's partners are the
//! spheres in the cells around it, and its locality event is the crossing
//! into the next cell (for a large sphere, the edge of its scan's skin).
//! Its best other event is kept in a slot with its time, so a crossing
//! checks only the layer of cells it brings next to the sphere.
use super::super::ahead::prefetch_next_crossing;
use super::super::body::{Bodies, Body};
use super::super::cell_grid::CellGrid;
use super::super::hooks::Hooks;
use super::super::ids::Label;
use super::super::overlap;
use super::super::schedule::{Event, Kind, Predictor, Queued, Slot};
use super::Locality;
use crate::physics::exec::Exec;
use crate::physics::huge_pages;

#[derive(Default)]
pub(in super::super) struct Cells {
    grid: CellGrid,
    /// Each sphere's best contact or wall event and its time, kept apart
    /// from its crossing so a crossing rescans only new cells.
    slots: Vec<Slot>,
    /// Which of its two events the queue holds for each sphere. A byte
    /// apart from the slots (1 MB at a million, which stays in a core's
    /// cache), so a crossing can read the next sphere's at once.
    holds: Vec<Queued>,
    /// Scratch for the candidates a prediction gathers: labels, as the
    /// grid packs them ([`Label::raw`]).
    candidates: Vec<u32>,
}

impl Locality for Cells {
    fn new(bodies: &Bodies, size: f64, hooks: &Hooks) -> Self {
        let n = bodies.len();
        let slots = huge_pages::filled(n, Slot::default());
        let holds = huge_pages::filled(n, Queued::PENDING);
        let mut grid = CellGrid::default();
        grid.build(bodies, size, hooks.cells_per_sphere());
        Cells {
            grid,
            slots,
            holds,
            candidates: Vec::new(),
        }
    }

    fn heap_bytes(&self) -> usize {
        self.grid.heap_bytes()
            + self.slots.capacity() * size_of::<Slot>()
            + self.holds.capacity() * size_of::<Queued>()
            + self.candidates.capacity() * size_of::<u32>()
    }

    #[inline(always)]
    fn queued(&self, i: Label) -> Event {
        self.slots[i.index()].queued(self.holds[i.index()])
    }

    #[inline]
    fn predict<const PF: bool>(&mut self, i: Label, bodies: &Bodies, size: f64) -> f64 {
        let a = &bodies[i];
        let idle = Event::default();
        let mut p = Predictor::new(a, bodies, size, f64::INFINITY, idle);
        let n = self.grid.candidates(i, p.radius(), &mut self.candidates);
        if PF {
            bodies.prefetch(&self.candidates[..n]);
        }
        for &j in &self.candidates[..n] {
            if j != i.raw() {
                p.pair(Label::from_raw(j));
            }
        }
        let (slot, hold) = (&mut self.slots[i.index()], &mut self.holds[i.index()]);
        with_crossing(&self.grid, slot, hold, p.finish(), i, a)
    }

    /// A large sphere rescans the cells from where it is now.
    #[inline]
    fn relist(&mut self, i: Label, bodies: &Bodies) {
        self.grid.rescan(i, &bodies[i]);
    }

    /// Its pending event still holds unless its partner has moved on; only
    /// the layer of cells the crossing brings next to it needs checking.
    #[inline]
    fn cross<const PF: bool>(
        &mut self,
        i: Label,
        mask: u8,
        next: Option<Label>,
        bodies: &Bodies,
        size: f64,
    ) -> f64 {
        let n = self.grid.next_layer(i, mask, &mut self.candidates);
        if PF {
            bodies.prefetch(&self.candidates[..n]);
        }
        self.grid.cross(i, mask);
        if PF {
            prefetch_next_crossing(&self.grid, &self.holds, next);
        }
        let (tp, evp) = self.slots[i.index()].pending();
        if evp.kind() == Kind::Pair && bodies[evp.partner()].count != evp.partner_count() {
            return self.predict::<PF>(i, bodies, size);
        }
        let a = &bodies[i];
        let mut p = Predictor::resume(a, bodies, tp - a.t, evp);
        for &j in &self.candidates[..n] {
            p.pair(Label::from_raw(j));
        }
        let (slot, hold) = (&mut self.slots[i.index()], &mut self.holds[i.index()]);
        with_crossing(&self.grid, slot, hold, p.finish(), i, a)
    }

    #[inline]
    fn shift(&mut self, now: f64) {
        for p in &mut self.slots {
            p.t -= now;
        }
    }

    fn deepest_overlap(&self, bodies: &Bodies, exec: &dyn Exec) -> f64 {
        overlap::in_cells(&self.grid, bodies, exec)
    }

    /// The cells it reads, and its pending partner's body (the crossing
    /// checks whether that contact still holds).
    #[inline(always)]
    fn prefetch_cross(&self, i: Label, mask: u8, bodies: &Bodies) {
        self.grid.prefetch_cross(i, mask);
        let (_, pending) = self.slots[i.index()].pending();
        if pending.kind() == Kind::Pair {
            bodies.prefetch_one(pending.partner());
        }
    }

    /// The cells around `i`.
    #[inline(always)]
    fn prefetch_around(&self, i: Label, _bodies: &Bodies) {
        self.grid.prefetch_around(i);
    }

    /// Its slot and byte of `holds`, and its place in the grid.
    #[inline(always)]
    fn prefetch_records(&self, k: usize) {
        use crate::physics::prefetch::{line, record};
        if let (Some(slot), Some(holds)) = (self.slots.get(k), self.holds.get(k)) {
            record(slot);
            line(holds);
        }
        self.grid.prefetch_place(k);
    }
}

/// Sphere `i`'s pending event `(tp, pending)` kept in `slot`, and the
/// earlier of it and its next crossing (the crossing first on a tie)
/// marked in `holds`; returns that one's time.
#[inline]
fn with_crossing(
    grid: &CellGrid,
    slot: &mut Slot,
    holds: &mut Queued,
    (tp, pending): (f64, Event),
    i: Label,
    a: &Body,
) -> f64 {
    *slot = Slot { t: tp, ev: pending };
    let (tc, ev) = grid.next_event(i, a);
    let tc = a.t + tc;
    // By index: which comes first is random, and a branch on it
    // mispredicted a third of the time.
    let first = usize::from(tc <= tp);
    *holds = [Queued::PENDING, Queued::locality(ev)][first];
    [tp, tc][first]
}
