//! A cluster run's events: the record its heap orders (earliest first, ties
//! in an order that does not depend on how spheres were grouped), the
//! run-local index it carries, and the two ways an event is made.
use crate::physics::contact::wall_toi;
use crate::physics::sphere::Sphere;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A sphere's index among a run's members: what the run's tables are
/// indexed with, never a sphere id or a slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Local(u32);

impl Local {
    /// Not a member (of the run, or the wall of a wall event).
    pub(super) const NONE: Local = Local(u32::MAX);

    pub(super) fn at(index: usize) -> Local {
        Local(index as u32)
    }

    pub(super) fn index(self) -> usize {
        self.0 as usize
    }
}

/// `Event::b` of a wall event: no sphere.
pub(super) const WALL: u32 = u32::MAX;

/// An event; `a`, `b` are sphere ids (`b` [`WALL`] for a wall), `la`, `lb` the
/// run's local indices, `ca`, `cb` the collision counts it was predicted at.
#[derive(Clone, Copy, Debug)]
pub(super) struct Event {
    pub t: f64,
    pub a: u32,
    pub b: u32,
    pub la: Local,
    pub lb: Local,
    pub ca: u32,
    pub cb: u32,
}

impl PartialEq for Event {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Event {
    /// Reversed so the heap pops the earliest. Simultaneous events in a
    /// fixed order that does not depend on how spheres were grouped: lower
    /// sphere id first, pair events before wall events.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t)
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
}

/// The event of a pair, with the lower sphere id first.
pub(super) fn pair_event(t: f64, a: u32, b: u32, la: Local, lb: Local, ca: u32, cb: u32) -> Event {
    if a < b {
        Event {
            t,
            a,
            b,
            la,
            lb,
            ca,
            cb,
        }
    } else {
        Event {
            t,
            a: b,
            b: a,
            la: lb,
            lb: la,
            ca: cb,
            cb: ca,
        }
    }
}

/// `s`'s next wall event, if it falls within the step.
#[allow(clippy::too_many_arguments)] // one sphere's event stamp (ids, time, count) and the box: values the hot loop already holds
pub(super) fn push_wall(
    heap: &mut BinaryHeap<Event>,
    s: &Sphere,
    a: u32,
    la: Local,
    t: f64,
    ca: u32,
    size: f64,
    dt: f64,
) {
    let (tw, _) = wall_toi(s.pos, s.vel, s.radius, size);
    if t + tw <= dt {
        heap.push(Event {
            t: t + tw,
            a,
            b: WALL,
            la,
            lb: Local::NONE,
            ca,
            cb: 0,
        });
    }
}
