//! Predicting a sphere's next event: the earliest of a contact with one of its
//! candidate partners, a wall contact, or a broad-phase event (leaving its
//! neighbour-list skin, or crossing into another cell). Only that earliest
//! event is kept (one per sphere, as Smallenburg's EDMD does); a contact
//! stays valid while the partner's collision count is unchanged, and is
//! recomputed when it comes due otherwise.
use super::body::{Bodies, Body};
use crate::physics::contact::pair_toi;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
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

#[derive(Clone, Copy, Debug, Default)]
pub struct Event {
    pub kind: Kind,
    pub mask: u8,
    /// In a [`Slot`] in cell mode: 0 when the queue holds this event,
    /// else the broad-phase event it holds (it came first): `8 | mask` of a
    /// crossing, or 24 for a large sphere's rescan. It fills what was padding.
    pub cross: u8,
    pub partner: u32,
    pub partner_count: u32,
}

/// What the loop keeps of a sphere's prediction, 20 bytes: its best event
/// other than a crossing and that event's absolute time (cell mode; lists
/// keep the time in the queue alone), and whether the next crossing comes
/// first. A crossing is cheap to tell from the grid, so only its direction
/// is kept.
#[derive(Clone, Copy, Debug)]
#[repr(C, packed(4))]
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
    /// The event the queue holds for this sphere.
    #[inline]
    pub fn queued(self) -> Event {
        let ev = self.ev;
        let crossing = Event {
            kind: [Kind::Cross, Kind::Relist][usize::from(ev.cross & 16 != 0)],
            mask: ev.cross & 7,
            ..Event::default()
        };
        // By index: which of the two it is is random (see `with_crossing`).
        [ev, crossing][usize::from(ev.cross != 0)]
    }

    /// The pending event itself (not the crossing).
    #[inline]
    pub fn pending(self) -> (f64, Event) {
        (
            self.t,
            Event {
                cross: 0,
                ..self.ev
            },
        )
    }
}

/// The running earliest event of sphere `a` (already moved to `now = a.t`).
/// Ties keep the first found: the broad-phase event, then walls, then
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
    /// Start from the broad-phase event `(in_t, ev)` (relative time) and the walls.
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
            p.ev = Event {
                kind: Kind::Wall,
                mask,
                ..Event::default()
            };
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
    pub fn pair(&mut self, j: u32) {
        let a = &self.a;
        let b = &self.bodies[j as usize];
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
            self.ev = Event {
                kind: Kind::Pair,
                partner: j,
                partner_count: b.count,
                ..Event::default()
            };
        }
    }

    /// The absolute event time and the event.
    #[inline]
    pub fn finish(self) -> (f64, Event) {
        (self.a.t + self.best, self.ev)
    }
}

/// Earliest wall contact of `a` (relative time) and the mask of the axes hit
/// then (a corner hit flips every axis that ties); as
/// [`wall_toi`](crate::physics::contact::wall_toi), with selects instead of
/// branches on the signs of the velocity.
#[inline]
pub fn wall_toi(a: &Body, radius: f64, size: f64) -> (f64, u8) {
    let mut t = [f64::INFINITY; 3];
    for (k, tk) in t.iter_mut().enumerate() {
        let v = a.vel[k];
        // Indexing, not `if`: LLVM turns a select on the (random) sign back
        // into a branch, and that branch mispredicted half the time.
        let gap = [size - radius - a.pos[k], a.pos[k] - radius][(v < 0.0) as usize];
        let dt = (gap / v.abs()).max(0.0);
        *tk = [f64::INFINITY, dt][(v != 0.0) as usize];
    }
    let tmin = t[0].min(t[1]).min(t[2]);
    let mask = (t[0] == tmin) as u8 | ((t[1] == tmin) as u8) << 1 | ((t[2] == tmin) as u8) << 2;
    (tmin, mask)
}
