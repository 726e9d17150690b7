//! Predicting a sphere's next event: the earliest of a contact with one of its
//! candidate partners, a wall contact, or a locality event (leaving its
//! neighbour-list skin, or crossing into another cell). Only that earliest
//! event is kept (one per sphere, as Smallenburg's EDMD does); a contact
//! stays valid while the partner's collision count is unchanged, and is
//! recomputed when it comes due otherwise.
use super::body::{Bodies, Body};
use super::ids::Label;
use crate::physics::contact::pair_toi;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// Nothing will ever happen to this sphere (it stands still).
    #[default]
    Idle,
    /// Contact with `partner`, valid while its count is `partner_count`.
    Pair,
    /// Contact with the walls of the axes in `mask` (bits 0..3).
    Wall,
    /// The sphere reaches the edge of its skin: rebuild its neighbour list
    /// (or, for a large sphere in cell mode, its scan of the cells).
    Relist,
    /// The centre crosses into the next cell along axis `mask & 3`, upwards
    /// if `mask & 4`.
    Cross,
}

/// A sphere's predicted event, 8 bytes: its kind, the walls' axes of a
/// [`Kind::Wall`] or the direction of a [`Kind::Cross`] (its mask), and
/// the other sphere of a [`Kind::Pair`] in one word, and that partner's
/// count. At a million spheres the one word saves 4 MB over three fields.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Event {
    /// The kind in bits 0..3, the mask in bits 3..6, the partner above.
    word: u32,
    partner_count: u32,
}

/// Where the partner starts in [`Event`]'s word.
const PARTNER_SHIFT: u32 = 6;
/// Spheres an event can name as partners: the event loop takes at most
/// this many (67 million; a scene holds at most 10 million).
pub const MAX_SPHERES: usize = 1 << (32 - PARTNER_SHIFT);

impl Event {
    #[inline(always)]
    fn new(kind: Kind, mask: u8, partner: Label, partner_count: u32) -> Event {
        debug_assert!(mask < 8 && partner.index() < MAX_SPHERES);
        Event {
            word: kind as u32 | u32::from(mask) << 3 | partner.raw() << PARTNER_SHIFT,
            partner_count,
        }
    }

    /// A contact with `partner`, valid while its count is `partner_count`.
    #[inline(always)]
    pub fn pair(partner: Label, partner_count: u32) -> Event {
        Event::new(Kind::Pair, 0, partner, partner_count)
    }

    /// An event with no partner: a wall contact, a relist or a crossing.
    #[inline(always)]
    pub fn of(kind: Kind, mask: u8) -> Event {
        Event::new(kind, mask, Label::at(0), 0)
    }

    #[inline(always)]
    pub fn kind(self) -> Kind {
        const KINDS: [Kind; 8] = [
            Kind::Idle,
            Kind::Pair,
            Kind::Wall,
            Kind::Relist,
            Kind::Cross,
            Kind::Idle,
            Kind::Idle,
            Kind::Idle,
        ];
        KINDS[(self.word & 7) as usize]
    }

    #[inline(always)]
    pub fn mask(self) -> u8 {
        (self.word >> 3 & 7) as u8
    }

    #[inline(always)]
    pub fn partner(self) -> Label {
        Label::from_raw(self.word >> PARTNER_SHIFT)
    }

    #[inline(always)]
    pub fn partner_count(self) -> u32 {
        self.partner_count
    }
}

/// Which event the queue holds for a sphere in cell mode: its pending
/// event ([`Queued::PENDING`]), or the locality event that came first
/// (a crossing, with its direction, or a large sphere's rescan), which the
/// grid tells cheaply, so only its kind and mask are kept. One byte: the
/// mask in bits 0..3, bit 3 set for any locality event, bit 4 for a rescan.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Queued(u8);

impl Queued {
    /// The queue holds the pending event itself.
    pub const PENDING: Queued = Queued(0);
    const LOCALITY: u8 = 8;
    const RESCAN_BIT: u8 = 4;
    const RESCAN: u8 = 1 << Self::RESCAN_BIT;
    const MASK: u8 = 7;

    /// The queue holds `ev`, a crossing or a large sphere's rescan ([`Kind::Relist`]).
    #[inline(always)]
    pub fn locality(ev: Event) -> Queued {
        Queued(Self::LOCALITY | ev.mask() | u8::from(ev.kind() == Kind::Relist) << Self::RESCAN_BIT)
    }

    /// Whether the queue holds a locality event, not the pending one.
    #[inline(always)]
    pub fn is_locality(self) -> bool {
        self != Self::PENDING
    }

    /// The locality event held (meaningful when [`Self::is_locality`]).
    #[inline(always)]
    pub fn event(self) -> Event {
        Event::of(
            [Kind::Cross, Kind::Relist][usize::from(self.0 & Self::RESCAN != 0)],
            self.0 & Self::MASK,
        )
    }
}

/// What the loop keeps of a sphere's prediction in cell mode, 16 bytes:
/// its best event other than a crossing and that event's absolute time
/// (whether the next crossing comes first is a [`Queued`] kept apart).
/// With neighbour lists the loop keeps the [`Event`] alone: its time is
/// the queue's.
#[derive(Clone, Copy, Debug)]
pub struct Slot {
    pub t: f64,
    pub ev: Event,
}

impl Default for Slot {
    fn default() -> Self {
        Slot {
            t: f64::INFINITY,
            ev: Event::default(),
        }
    }
}

impl Slot {
    /// The event the queue holds for this sphere, as `queued` says.
    #[inline]
    pub fn queued(self, queued: Queued) -> Event {
        let ev = self.ev;
        // By index: which of the two it is is random (see `with_crossing`).
        [ev, queued.event()][usize::from(queued.is_locality())]
    }

    /// The pending event itself (not the crossing).
    #[inline]
    pub fn pending(self) -> (f64, Event) {
        (self.t, self.ev)
    }
}

/// The running earliest event of sphere `a` (already moved to `now = a.t`).
/// Ties keep the first found: the locality event, then walls, then
/// partners in the order offered.
pub struct Predictor<'a> {
    a: Body,
    /// `a`'s radius.
    ra: f64,
    bodies: &'a Bodies,
    best: f64,
    /// `best`, finite (an infinite one times zero would be NaN and pass the
    /// cheap test); kept beside it so the test per candidate skips a `min`.
    bound: f64,
    ev: Event,
}

impl<'a> Predictor<'a> {
    /// Start from the locality event `(in_t, ev)` (relative time) and the walls.
    #[inline]
    pub fn new(a: &Body, bodies: &'a Bodies, size: f64, in_t: f64, ev: Event) -> Self {
        let ra = bodies.radius_of(a);
        let mut p = Predictor {
            a: *a,
            ra,
            bodies,
            best: in_t,
            bound: in_t.min(f64::MAX),
            ev: if in_t.is_finite() {
                ev
            } else {
                Event::default()
            },
        };
        let (tw, mask) = wall_toi(a, ra, size);
        if tw < p.best {
            p.best = tw;
            p.bound = tw.min(f64::MAX);
            p.ev = Event::of(Kind::Wall, mask);
        }
        p
    }

    /// Continue from an earlier prediction's best `(t, ev)` (relative time),
    /// which already weighed the walls: sphere `a` has not turned since.
    #[inline]
    pub fn resume(a: &Body, bodies: &'a Bodies, t: f64, ev: Event) -> Self {
        Predictor {
            a: *a,
            ra: bodies.radius_of(a),
            bodies,
            best: t,
            bound: t.min(f64::MAX),
            ev,
        }
    }

    /// Sphere `a`'s radius.
    #[inline(always)]
    pub fn radius(&self) -> f64 {
        self.ra
    }

    /// Consider a contact with sphere `j`.
    #[inline(always)]
    pub fn pair(&mut self, j: Label) {
        let a = &self.a;
        let b = &self.bodies[j];
        let dp = a.pos - b.pos_at(a.t);
        let dv = a.vel - b.vel;
        let bb = dp.dot(dv);
        let sigma = self.ra + self.bodies.radius_of(b);
        let c = dp.length_squared() - sigma * sigma;
        // Only approaching pairs (bb < 0) can touch, and then the root is at
        // least c / (-2 bb): skip pairs that cannot beat `best` without a
        // square root. A receding pair gets a limit of zero, so only an
        // overlapping one passes, and `pair_toi` turns it away. Pairs that
        // miss (bb^2 < a c, no real root) are skipped too: before the first
        // hit the bound is the far-off wall, and misses were half of what
        // passed. One branch for all of it: which pairs pass is random, so
        // every pass costs a mispredict, and a test of bb's sign alone would
        // mispredict half the time. It is a `max` of two differences (the
        // sign of a difference of floats is exact, so these are `c > lim`
        // and `bb^2 < a c` as `pair_toi` computes them): LLVM split a plain
        // `|` of the two back into a branch on the sign of bb.
        let lim = -2.0 * bb.min(-0.0) * self.bound;
        if (c - lim).max(dv.length_squared() * c - bb * bb) > 0.0 {
            return;
        }
        if let Some(t) = pair_toi(dp, dv, sigma)
            && t < self.best
        {
            self.best = t;
            self.bound = t;
            self.ev = Event::pair(j, b.count);
        }
    }

    /// The absolute event time and the event.
    #[inline]
    pub fn finish(self) -> (f64, Event) {
        (self.a.t + self.best, self.ev)
    }
}

/// Earliest wall contact of `a` (relative time) and the axes hit then:
/// [`contact::wall_toi`](crate::physics::contact::wall_toi) of its body.
#[inline]
pub fn wall_toi(a: &Body, radius: f64, size: f64) -> (f64, u8) {
    crate::physics::contact::wall_toi(a.pos, a.vel, radius, size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_event_is_8_bytes_and_a_slot_16() {
        let sizes = [size_of::<Event>(), size_of::<Slot>(), size_of::<Queued>()];
        assert_eq!(sizes, [8, 16, 1], "Event, Slot, Queued");
    }

    /// Every kind, mask and partner (up to the largest) reads back.
    #[test]
    fn an_event_reads_back_as_made() {
        let last = Label::at(MAX_SPHERES - 1);
        for partner in [Label::at(0), Label::at(12345), last] {
            let ev = Event::pair(partner, u32::MAX - 3);
            assert_eq!((ev.kind(), ev.partner()), (Kind::Pair, partner));
            assert_eq!((ev.mask(), ev.partner_count()), (0, u32::MAX - 3));
        }
        for kind in [Kind::Idle, Kind::Wall, Kind::Relist, Kind::Cross] {
            for mask in 0..8 {
                let ev = Event::of(kind, mask);
                assert_eq!((ev.kind(), ev.mask()), (kind, mask));
            }
        }
        assert_eq!(Event::default().kind(), Kind::Idle);
    }

    /// A locality event reads back as it went in, and marks the slot.
    #[test]
    fn a_queued_locality_event_reads_back() {
        assert!(!Queued::PENDING.is_locality());
        for (kind, mask) in [(Kind::Cross, 0), (Kind::Cross, 6), (Kind::Relist, 0)] {
            let q = Queued::locality(Event::of(kind, mask));
            assert!(q.is_locality());
            assert_eq!((q.event().kind(), q.event().mask()), (kind, mask));
        }
    }
}
