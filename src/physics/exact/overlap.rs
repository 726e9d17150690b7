//! The overlap readout from the broad phase the event loop keeps anyway, so
//! the engine builds no grid of its own for `exact`.
//!
//! Every overlapping pair is among the pairs checked here, by the invariants
//! the event loop already relies on to miss no contact: in cell mode, cells
//! are wider than a small sphere's diameter and crossings keep each small
//! sphere in its cell, so overlapping small spheres sit in neighbouring
//! cells, and every small sphere's candidates include every large one; with
//! neighbour lists, relists keep each sphere within the skin of its list
//! centre, so two spheres that touch are listed.
use super::body::Body;
use super::queue::EventQueue;
use super::{Broad, EventDriven};
use crate::physics::exec::{Exec, for_each_block};
use parking_lot::Mutex;

/// Spheres per block of the search, spread over the executor's lanes.
const BLOCK: usize = 1 << 12;

impl<Q: EventQueue> EventDriven<Q> {
    /// The deepest overlap between the bodies divided by the smaller radius
    /// (0 if none), as `World::max_overlap_rel` gives it for the world the
    /// bodies were last written to (the max is order-free, so the same bits).
    pub(super) fn deepest_overlap(&self, exec: &dyn Exec) -> f64 {
        let (bodies, broad) = (&self.bodies[..], &self.broad);
        let n = bodies.len();
        let worst = Mutex::new(0.0f64);
        for_each_block(exec, n.div_ceil(BLOCK), &|b| {
            let spheres = b * BLOCK..((b + 1) * BLOCK).min(n);
            let deepest = match broad {
                Broad::Lists(nl) => spheres.fold(0.0, |w: f64, i| {
                    nl.of(i)
                        .iter()
                        .filter(|l| l.j as usize > i)
                        .fold(w, |w, l| deeper(w, bodies, i, l.j as usize))
                }),
                Broad::Cells(cells) => {
                    let mut out = Vec::new();
                    spheres.fold(0.0, |w: f64, i| {
                        if cells.is_big(i) {
                            // Its small partners are found from their side.
                            return cells
                                .bigs()
                                .iter()
                                .filter(|&&j| j as usize > i)
                                .fold(w, |w, &j| deeper(w, bodies, i, j as usize));
                        }
                        let k = cells.candidates(i, &bodies[i], &mut out);
                        out[..k]
                            .iter()
                            .filter(|&&j| j as usize > i || cells.is_big(j as usize))
                            .fold(w, |w, &j| deeper(w, bodies, i, j as usize))
                    })
                }
            };
            let mut w = worst.lock();
            *w = w.max(deepest);
        });
        worst.into_inner()
    }
}

/// `worst`, or the overlap of bodies `i` and `j` relative to the smaller
/// radius if deeper: the depth computed as `World::max_overlap_rel` does.
#[inline]
fn deeper(worst: f64, bodies: &[Body], i: usize, j: usize) -> f64 {
    let (a, b) = (&bodies[i], &bodies[j]);
    let s = a.radius + b.radius;
    // sqrt(fl(s * s)) == s, so a pair this skips has a depth of at most 0.
    if a.pos.distance_squared(b.pos) >= s * s {
        return worst;
    }
    let depth = s - a.pos.distance(b.pos);
    if depth > 0.0 {
        worst.max(depth / a.radius.min(b.radius))
    } else {
        worst
    }
}
