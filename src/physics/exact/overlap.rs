//! The overlap readout from the locality the event loop keeps anyway, so
//! the engine builds no grid of its own for `exact`.
//!
//! Every overlapping pair is among the pairs checked here, by the invariants
//! the event loop already relies on to miss no contact: in cell mode, cells
//! are wider than a small sphere's diameter and crossings keep each small
//! sphere in its cell, so overlapping small spheres sit in neighbouring
//! cells, and a large sphere scans every cell it could reach; with
//! neighbour lists, relists keep each sphere within the skin of its list
//! centre, so two spheres that touch are listed.
use super::body::Bodies;
use super::cell_grid::CellGrid;
use super::ids::Label;
use super::neighbour_lists::NeighbourLists;
use crate::physics::exec::{Exec, for_each_block};
use crate::physics::sphere::overlap_rel;
use parking_lot::Mutex;

/// Spheres (lists) or cells (grid) per block of the search, spread over
/// the executor's lanes.
const BLOCK: usize = 1 << 12;
const CELL_BLOCK: usize = 1 << 14;

/// The deepest overlap between the bodies divided by the smaller radius
/// (0 if none), as `World::max_overlap_rel` gives it for the world the
/// bodies were last written to (the max is order-free, so the same bits),
/// from neighbour lists: each listed pair once.
pub(super) fn in_lists(lists: &NeighbourLists, bodies: &Bodies, exec: &dyn Exec) -> f64 {
    let worst = Mutex::new(0.0f64);
    let n = bodies.len();
    for_each_block(exec, n.div_ceil(BLOCK), &|b| {
        let spheres = (b * BLOCK..((b + 1) * BLOCK).min(n)).map(Label::at);
        keep(
            &worst,
            spheres.fold(0.0, |w: f64, i| {
                lists
                    .of(i)
                    .iter()
                    .filter(|l| l.j > i)
                    .fold(w, |w, l| deeper(w, bodies, i, l.j))
            }),
        );
    });
    worst.into_inner()
}

/// As [`in_lists`], from the cell grid: the pairs in neighbouring cells,
/// and the large spheres' scans.
pub(super) fn in_cells(cells: &CellGrid, bodies: &Bodies, exec: &dyn Exec) -> f64 {
    let worst = Mutex::new(0.0f64);
    let n = cells.cells();
    for_each_block(exec, n.div_ceil(CELL_BLOCK), &|b| {
        let (mut own, mut near, mut w) = (Vec::new(), Vec::new(), 0.0);
        let range = b * CELL_BLOCK..((b + 1) * CELL_BLOCK).min(n);
        cells.for_each_near_pair(range, &mut own, &mut near, |i, j| {
            w = deeper(w, bodies, i, j);
        });
        keep(&worst, w);
    });
    // The few large ones: each small one they could touch, from their
    // scan, and each other.
    let mut out = Vec::new();
    for &i in cells.bigs() {
        let k = cells.candidates(i, bodies.radius(i), &mut out);
        keep(
            &worst,
            out[..k]
                .iter()
                .map(|&j| Label::from_raw(j))
                .filter(|&j| !cells.is_big(j) || j > i)
                .fold(0.0, |w, j| deeper(w, bodies, i, j)),
        );
    }
    worst.into_inner()
}

/// `worst` raised to `deepest`, from any lane.
#[inline]
fn keep(worst: &Mutex<f64>, deepest: f64) {
    let mut w = worst.lock();
    *w = w.max(deepest);
}

/// `worst`, or the overlap of bodies `i` and `j` relative to the smaller
/// radius if deeper (`overlap_rel`).
#[inline]
fn deeper(worst: f64, bodies: &Bodies, i: Label, j: Label) -> f64 {
    let (a, b) = (&bodies[i], &bodies[j]);
    let (ra, rb) = (bodies.radius_of(a), bodies.radius_of(b));
    let s = ra + rb;
    // sqrt(fl(s * s)) == s, so a pair this skips has a depth of at most 0.
    if a.pos.distance_squared(b.pos) >= s * s {
        return worst;
    }
    worst.max(overlap_rel(a.pos, ra, b.pos, rb))
}
