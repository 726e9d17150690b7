//! The one seam between the model and what tests, benchmarks and examples
//! turn: a smaller event cap, a finer cell grid, prefetching at any count
//! or none, and an observer of every contact. The model asks [`Hooks`] for
//! each; built without the feature `experiments` (which the crate's
//! dev-dependency on itself enables; the shipped binary has none), `Hooks`
//! holds nothing and answers the defaults, and the observer's contact is
//! never made.
use super::ids::{Label, WorldId};
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

/// The contact of labels `i` and `j` at absolute `time`, now `a` and `b`
/// after it, their velocities `before` it; `order` maps labels to world ids.
pub(super) fn contact(
    order: &[WorldId],
    time: f64,
    (i, j): (Label, Label),
    [a, b]: [&Sphere; 2],
    before: [DVec3; 2],
) -> Contact {
    // Lower world id first, whichever of the two predicted the contact
    // (labels decide that on a tie; `resolve_pair` gives the same
    // velocities either way round, bit for bit), so observers see the
    // same contact whatever the labels.
    let ids = [order[i.index()], order[j.index()]];
    let lo = usize::from(ids[1] < ids[0]);
    let spheres = [a, b];
    let (p, q) = (spheres[lo], spheres[1 - lo]);
    Contact {
        time,
        i: ids[lo].index(),
        j: ids[1 - lo].index(),
        pos_i: p.pos,
        pos_j: q.pos,
        impulse: p.mass * (p.vel - before[lo]).length(),
    }
}

/// What the knobs are set to; the defaults are the shipped model's.
#[cfg(feature = "experiments")]
#[derive(Default)]
pub(super) struct Hooks {
    cap: Option<u64>,
    cells_per_sphere: Option<u32>,
    /// Prefetch whatever the count (`Some(true)`) or never (`Some(false)`).
    prefetching: Option<bool>,
    observer: Option<Observer>,
}

/// Nothing to turn: the defaults.
#[cfg(not(feature = "experiments"))]
#[derive(Default)]
pub(super) struct Hooks;

#[cfg(feature = "experiments")]
impl Hooks {
    /// The events a step may take, `default` unless set.
    pub fn event_cap(&self, default: u64) -> u64 {
        self.cap.unwrap_or(default)
    }

    /// The most cells per sphere of the cell grid.
    pub fn cells_per_sphere(&self) -> u32 {
        self.cells_per_sphere
            .unwrap_or(super::cell_grid::CELLS_PER_SPHERE)
    }

    /// Whether the loop prefetches, `default` unless set.
    pub fn prefetching(&self, default: bool) -> bool {
        self.prefetching.unwrap_or(default)
    }

    /// Tell the observer, if any, of a contact (made only then).
    pub fn observe(&mut self, contact: impl FnOnce() -> Contact) {
        if let Some(f) = &mut self.observer {
            f(&contact());
        }
    }
}

// The same answers as the knobs' defaults, for the model to ask either way.
#[cfg(not(feature = "experiments"))]
#[expect(clippy::unused_self, reason = "the knobs' signatures, with none set")]
impl Hooks {
    #[inline(always)]
    pub fn event_cap(&self, default: u64) -> u64 {
        default
    }

    #[inline(always)]
    pub fn cells_per_sphere(&self) -> u32 {
        super::cell_grid::CELLS_PER_SPHERE
    }

    #[inline(always)]
    pub fn prefetching(&self, default: bool) -> bool {
        default
    }

    #[inline(always)]
    pub fn observe(&mut self, _contact: impl FnOnce() -> Contact) {}
}

#[cfg(feature = "experiments")]
impl super::Exact {
    /// Set the events a step may take (default: [`super::EVENT_CAP_BASE`]
    /// plus [`super::EVENT_CAP_PER_SPHERE`] per sphere).
    #[must_use]
    pub fn with_event_cap(mut self, cap: u64) -> Self {
        self.hooks.cap = Some(cap);
        self
    }

    /// Set the most cells per sphere of the cell grid (default
    /// [`super::cell_grid::CELLS_PER_SPHERE`]; at least 1), for comparing grids.
    #[must_use]
    pub fn with_cells_per_sphere(mut self, k: u32) -> Self {
        self.hooks.cells_per_sphere = Some(k.max(1));
        self
    }

    /// Prefetch at any count (`true`) or never (`false`; by default from
    /// [`super::PREFETCH_FROM`] spheres), for holding the two to the same
    /// runs and comparing their speed.
    #[must_use]
    pub fn with_prefetching(mut self, on: bool) -> Self {
        self.hooks.prefetching = Some(on);
        self
    }

    /// Call `f` for every sphere–sphere contact.
    pub fn set_observer(&mut self, f: Option<Observer>) {
        self.hooks.observer = f;
    }
}
