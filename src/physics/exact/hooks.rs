//! The knobs tests, benchmarks and examples turn (feature `experiments`,
//! which the crate's dev-dependency on itself enables; the shipped binary
//! has none): a smaller event cap, a finer cell grid, renumbering as the
//! spheres drift ([`super::renumber`]), prefetching at any count or none,
//! and an observer of every contact.
use super::ids::Label;
use super::queue::EventQueue;
use super::{EventDriven, cell_grid};
use crate::physics::sphere::Sphere;
use glam::DVec3;

/// A sphere–sphere contact, for observers (pressure virial, collision maps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Absolute simulated time.
    pub time: f64,
    /// World ids, lower first.
    pub i: usize,
    pub j: usize,
    /// Centres at contact.
    pub pos_i: DVec3,
    pub pos_j: DVec3,
    /// Momentum exchanged (magnitude of the impulse along the line of centres).
    pub impulse: f64,
}

pub type Observer = Box<dyn FnMut(&Contact) + Send>;

/// What the knobs are set to; the defaults are the shipped model's.
#[derive(Default)]
pub(super) struct Hooks {
    cap: Option<u64>,
    cells_per_sphere: Option<u32>,
    /// Sort the spheres in space again as they drift (off by default: it
    /// measured slower, see docs/benchmarks.md "exact at scale").
    pub renumbering: bool,
    /// Prefetch whatever the count (`Some(true)`) or never (`Some(false)`);
    /// by default from [`super::PREFETCH_FROM`] spheres.
    pub prefetching: Option<bool>,
    /// Broad-phase events (crossings, relists) at the last spatial sort.
    pub sorted_at: u64,
    observer: Option<Observer>,
}

impl Hooks {
    pub fn cap(&self) -> Option<u64> {
        self.cap
    }

    pub fn cells_per_sphere(&self) -> u32 {
        self.cells_per_sphere.unwrap_or(cell_grid::CELLS_PER_SPHERE)
    }
}

impl<Q: EventQueue> EventDriven<Q> {
    /// Set the events a step may take (default: [`super::EVENT_CAP_BASE`]
    /// plus [`super::EVENT_CAP_PER_SPHERE`] per sphere).
    #[must_use]
    pub fn with_event_cap(mut self, cap: u64) -> Self {
        self.hooks.cap = Some(cap);
        self
    }

    /// Set the most cells per sphere of the cell grid (default
    /// [`cell_grid::CELLS_PER_SPHERE`]; at least 1), for comparing grids.
    #[must_use]
    pub fn with_cells_per_sphere(mut self, k: u32) -> Self {
        self.hooks.cells_per_sphere = Some(k.max(1));
        self
    }

    /// Sort the spheres by cell again as they drift (default: only at
    /// load), for comparing the two.
    #[must_use]
    pub fn with_renumbering(mut self, on: bool) -> Self {
        self.hooks.renumbering = on;
        self
    }

    /// Prefetch at any count (`true`) or never (`false`), for holding the
    /// two to the same runs and comparing their speed.
    #[must_use]
    pub fn with_prefetching(mut self, on: bool) -> Self {
        self.hooks.prefetching = Some(on);
        self
    }

    /// Call `f` for every sphere–sphere contact.
    pub fn set_observer(&mut self, f: Option<Observer>) {
        self.hooks.observer = f;
    }

    /// Tell the observer, if any, of the contact of `i` and `j`, now `a`
    /// and `b` after it, their velocities `before` it.
    pub(super) fn observe(
        &mut self,
        (i, j): (Label, Label),
        [a, b]: [&Sphere; 2],
        before: [DVec3; 2],
    ) {
        let Some(f) = &mut self.hooks.observer else {
            return;
        };
        // Lower world id first, whichever of the two predicted the contact
        // (labels decide that on a tie; `resolve_pair` gives the same
        // velocities either way round, bit for bit), so observers see the
        // same contact whatever the labels.
        let ids = [self.order[i.index()], self.order[j.index()]];
        let lo = usize::from(ids[1] < ids[0]);
        let spheres = [a, b];
        let (p, q) = (spheres[lo], spheres[1 - lo]);
        f(&Contact {
            time: self.origin + self.bodies[i].t,
            i: ids[lo].index(),
            j: ids[1 - lo].index(),
            pos_i: p.pos,
            pos_j: q.pos,
            impulse: p.mass * (p.vel - before[lo]).length(),
        });
    }
}
