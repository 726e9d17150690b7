//! Predicting a sphere's next event: the earliest of a contact with one of its
//! neighbours, a wall contact, or the edge of its neighbour-list skin. Only
//! that earliest event is kept (one per sphere, as Smallenburg's EDMD does);
//! a contact stays valid while the partner's collision count is unchanged,
//! and is recomputed when it comes due otherwise.
use super::body::Body;
use super::neighbours::Link;
use crate::physics::contact::{pair_toi, wall_toi};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Kind {
    /// Nothing will ever happen to this sphere (it stands still).
    #[default]
    Idle,
    /// Contact with `partner`, valid while its count is `partner_count`.
    Pair,
    /// Contact with the walls of the axes in `mask` (bits 0..3).
    Wall,
    /// The sphere reaches the edge of its skin: rebuild its neighbour list.
    Relist,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Event {
    pub kind: Kind,
    pub mask: u8,
    pub partner: u32,
    pub partner_count: u32,
}

/// The next event of `a` (already moved to `now = a.t`) given its neighbours,
/// their collision counts and its relist time. Returns the absolute time.
/// Ties keep the first found: relist, then walls, then neighbours in list order.
#[inline]
pub fn predict(
    a: &Body,
    neighbours: &[Link],
    bodies: &[Body],
    counts: &[u32],
    size: f64,
    relist_in: f64,
) -> (f64, Event) {
    let now = a.t;
    let mut best = relist_in;
    let mut ev = Event {
        kind: if relist_in.is_finite() {
            Kind::Relist
        } else {
            Kind::Idle
        },
        ..Event::default()
    };
    let (tw, mask) = wall_toi(&a.sphere(0.0), size);
    if tw < best {
        best = tw;
        ev = Event {
            kind: Kind::Wall,
            mask: mask[0] as u8 | (mask[1] as u8) << 1 | (mask[2] as u8) << 2,
            ..Event::default()
        };
    }
    for &Link { j, .. } in neighbours {
        let b = &bodies[j as usize];
        let dp = a.pos - b.pos_at(now);
        let dv = a.vel - b.vel;
        let bb = dp.dot(dv);
        if bb >= 0.0 {
            continue;
        }
        let sigma = a.radius + b.radius;
        let c = dp.length_squared() - sigma * sigma;
        // The root is at least c / (-2 bb): skip pairs that cannot beat `best`
        // without taking a square root.
        if c > -2.0 * bb * best {
            continue;
        }
        if let Some(t) = pair_toi(dp, dv, sigma)
            && t < best
        {
            best = t;
            ev = Event {
                kind: Kind::Pair,
                mask: 0,
                partner: j,
                partner_count: counts[j as usize],
            };
        }
    }
    (now + best, ev)
}
