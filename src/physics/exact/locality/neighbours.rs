//! Neighbour lists as the event loop's locality: a sphere's partners are
//! those in its list, and its locality event is the relist, when it
//! reaches the edge of its skin.
use super::super::body::Bodies;
use super::super::hooks::Hooks;
use super::super::ids::Label;
use super::super::neighbour_lists::NeighbourLists;
use super::super::overlap;
use super::super::schedule::{Event, Kind, Predictor};
use super::Locality;
use crate::physics::exec::Exec;
use crate::physics::huge_pages;

#[derive(Default)]
pub(in super::super) struct Neighbours {
    lists: NeighbourLists,
    /// Each sphere's event, whose time the queue alone keeps (8 bytes a
    /// sphere less than a cell mode's slot).
    events: Vec<Event>,
}

impl Locality for Neighbours {
    fn new(bodies: &Bodies, size: f64, _hooks: &Hooks) -> Self {
        let mut lists = NeighbourLists::default();
        lists.build(bodies, size);
        let events = huge_pages::filled(bodies.len(), Event::default());
        Neighbours { lists, events }
    }

    fn heap_bytes(&self) -> usize {
        self.lists.heap_bytes() + self.events.capacity() * size_of::<Event>()
    }

    #[inline(always)]
    fn queued(&self, i: Label) -> Event {
        self.events[i.index()]
    }

    #[inline]
    fn predict<const PF: bool>(&mut self, i: Label, bodies: &Bodies, size: f64) -> f64 {
        let a = &bodies[i];
        let relist = Event::of(Kind::Relist, 0);
        let t = self.lists.relist_time(i, a);
        // No prefetch here: the loop asked for these bodies as the event
        // began (a relist has just read them).
        let mut p = Predictor::new(a, bodies, size, t, relist);
        for l in self.lists.of(i) {
            p.pair(l.j);
        }
        let (t, ev) = p.finish();
        self.events[i.index()] = ev;
        t
    }

    #[inline]
    fn relist(&mut self, i: Label, bodies: &Bodies) {
        self.lists.rebuild(i, bodies);
    }

    /// Lists queue no crossings; were one asked for, `i` is predicted anew.
    #[inline]
    fn cross<const PF: bool>(
        &mut self,
        i: Label,
        _mask: u8,
        _next: Option<Label>,
        bodies: &Bodies,
        size: f64,
    ) -> f64 {
        self.predict::<PF>(i, bodies, size)
    }

    /// The queue alone keeps times.
    #[inline]
    fn shift(&mut self, _now: f64) {}

    fn deepest_overlap(&self, bodies: &Bodies, exec: &dyn Exec) -> f64 {
        overlap::in_lists(&self.lists, bodies, exec)
    }

    #[inline(always)]
    fn prefetch_cross(&self, _i: Label, _mask: u8, _bodies: &Bodies) {}

    /// The bodies in `i`'s list.
    #[inline(always)]
    fn prefetch_around(&self, i: Label, bodies: &Bodies) {
        for l in self.lists.of(i) {
            bodies.prefetch_one(l.j);
        }
    }

    /// Its event, and what its list's prediction reads first.
    #[inline(always)]
    fn prefetch_records(&self, k: usize) {
        if let Some(ev) = self.events.get(k) {
            crate::physics::prefetch::record(ev);
        }
        self.lists.prefetch(k);
    }
}
