//! The locality: how the event loop finds the spheres a sphere could meet
//! next, and the event at which that answer must be renewed (its locality
//! event). Two kinds, chosen once at load by packing fraction
//! ([`LISTS_ABOVE_PACKING`](super::LISTS_ABOVE_PACKING)):
//!
//! - [`Neighbours`]: neighbour lists with a skin, for dense scenes; the
//!   locality event is a relist. Each sphere's event is kept alone, its
//!   time the queue's.
//! - [`Cells`]: a cell grid with cell-crossing events, for dilute and
//!   moderate scenes. Each sphere's best contact or wall event is kept in
//!   a slot with its time, apart from its next crossing, so a crossing
//!   rescans only the cells it brings next to the sphere.
//!
//! Each kind owns what it keeps for every sphere. The event loop
//! ([`EventLoop`](super::event_loop::EventLoop)) is generic over it, so
//! its hot path is compiled once for each and never asks which it has.
mod cells;
mod neighbours;

use super::body::Bodies;
use super::hooks::Hooks;
use super::ids::Label;
use super::schedule::Event;
use crate::physics::exec::Exec;
pub(super) use cells::Cells;
pub(super) use neighbours::Neighbours;

/// What the event loop asks of its locality. Times are internal and
/// absolute unless said; `PF` says whether to prefetch
/// ([`PREFETCH_FROM`](super::PREFETCH_FROM)).
pub(super) trait Locality: Default + Send {
    /// Built for `bodies` at their common time stamp in a box of side
    /// `size`, with no sphere's event predicted yet.
    fn new(bodies: &Bodies, size: f64, hooks: &Hooks) -> Self;

    /// Bytes held on the heap.
    fn heap_bytes(&self) -> usize;

    /// The event the queue holds for sphere `i`.
    fn queued(&self, i: Label) -> Event;

    /// Sphere `i`'s next event, kept; returns its time.
    fn predict<const PF: bool>(&mut self, i: Label, bodies: &Bodies, size: f64) -> f64;

    /// Sphere `i` (moved to now) is at its relist event: it gets a new
    /// neighbour list, or as a large sphere among cells a new scan.
    fn relist(&mut self, i: Label, bodies: &Bodies);

    /// Sphere `i` (moved to now) is at a crossing into the next cell as
    /// `mask` says; `next` is the sphere whose event is likely next.
    /// Returns the time of `i`'s next event, kept.
    fn cross<const PF: bool>(
        &mut self,
        i: Label,
        mask: u8,
        next: Option<Label>,
        bodies: &Bodies,
        size: f64,
    ) -> f64;

    /// The time origin moved on by `now`: times kept are made relative to it.
    fn shift(&mut self, now: f64);

    /// The deepest overlap between `bodies`, relative to the smaller radius
    /// (0 if none), from the pairs this locality can tell touch ([`overlap`](super::overlap)).
    fn deepest_overlap(&self, bodies: &Bodies, exec: &dyn Exec) -> f64;

    /// Start loading what a crossing of sphere `i` as `mask` says reads.
    fn prefetch_cross(&self, i: Label, mask: u8, bodies: &Bodies);

    /// Start loading what predicting sphere `i` reads first.
    fn prefetch_around(&self, i: Label, bodies: &Bodies);

    /// Start loading sphere `k`'s records kept here, if `k` is a sphere.
    fn prefetch_records(&self, k: usize);
}
