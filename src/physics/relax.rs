//! Making room: spheres whose radii just grew are pushed apart, and off the
//! walls, until none overlaps. Only positions move, so velocities, masses and
//! energy are untouched. The work is bounded: a packing too crowded to settle
//! within the budget counts as full.
use super::broad::{Grid, Pair};
use super::exec::Serial;
use super::sphere::Sphere;
use glam::DVec3;

/// Pairs closer than this (relative to the sum of radii) still overlap, so
/// rounding cannot turn a touch into an overlap.
const GAP: f64 = 1e-9;
/// A push leaves this much room (relative), so a crowd settles in a few
/// sweeps instead of creeping towards exact contact.
const ROOM: f64 = 1e-3;
/// Work one attempt may do, in pair checks (a new pair list counts as
/// `LIST_COST` checks a sphere), so a key press stays near a second at any
/// count.
const WORK: usize = 20_000_000;
const LIST_COST: usize = 30;
/// How far (relative to the largest radius) a sphere may move before the
/// pair list is made anew.
const SKIN: f64 = 0.5;
/// Sweeps of one attempt, at most.
const MAX_SWEEPS: usize = 300;
/// The densest packing tried: random close packing is about 0.64, and near
/// it pushing apart takes far more sweeps than a key press may cost.
pub const MAX_PACKING: f64 = 0.58;

/// Fraction of the cube `[0, size]^3` that `spheres` fill.
pub fn packing(spheres: &[Sphere], size: f64) -> f64 {
    let v: f64 = spheres
        .iter()
        .map(|s| super::sphere::volume(s.radius))
        .sum();
    v / (size * size * size)
}

/// Scale every radius by `factor` and move the spheres apart until none
/// overlaps another or a wall. Returns the new spheres, or `None` when they
/// do not settle within the budget of sweeps (the input is never changed).
pub fn grown(spheres: &[Sphere], size: f64, factor: f64) -> Option<Vec<Sphere>> {
    let mut out: Vec<Sphere> = spheres.to_vec();
    for s in &mut out {
        s.radius *= factor;
        if 2.0 * s.radius * (1.0 + 2.0 * GAP) >= size {
            return None;
        }
        s.pos = inside(s.pos, s.radius, size);
    }
    // Pairs are listed for balls a skin wider than the spheres and kept
    // while no sphere has moved a skin from where the list was made, so most
    // sweeps are a pass over the list, not a new grid.
    let skin = SKIN * out.iter().map(|s| s.radius).fold(0.0, f64::max);
    let mut grid = Grid::default();
    let mut pairs: Vec<Pair> = Vec::new();
    let mut anchor: Vec<DVec3> = Vec::new();
    let mut work = 0;
    for _ in 0..MAX_SWEEPS {
        if work > WORK {
            return None;
        }
        let stale = anchor.is_empty()
            || out
                .iter()
                .zip(&anchor)
                .any(|(s, a)| s.pos.distance_squared(*a) >= skin * skin);
        if stale {
            grid.build(
                &out,
                size,
                |s| (s.pos, s.radius * (1.0 + 2.0 * GAP) + skin),
                &Serial,
            );
            grid.pairs(&Serial, &|_: u32, _: u32| true, &mut pairs);
            anchor = out.iter().map(|s| s.pos).collect();
            work += LIST_COST * out.len();
        }
        work += pairs.len();
        let mut moved = false;
        for &(i, j) in &pairs {
            moved |= push_apart(&mut out, i as usize, j as usize, size);
        }
        if !moved {
            return Some(out);
        }
    }
    None
}

/// Separate `i` and `j` if they overlap; returns whether they did. Each
/// moves a little more than half the way (over-relaxation): a crowd then
/// settles in fewer sweeps than with exact halves.
fn push_apart(s: &mut [Sphere], i: usize, j: usize, size: f64) -> bool {
    let sum = s[i].radius + s[j].radius;
    let d = s[j].pos - s[i].pos;
    let dist = d.length();
    if dist >= sum * (1.0 + GAP) {
        return false;
    }
    // Coincident centres: any direction separates them; a fixed one repeats.
    let n = if dist > 0.0 { d / dist } else { DVec3::X };
    let half = 0.9 * (sum * (1.0 + ROOM) - dist);
    s[i].pos = inside(s[i].pos - n * half, s[i].radius, size);
    s[j].pos = inside(s[j].pos + n * half, s[j].radius, size);
    true
}

/// `pos` moved into `[r, size - r]^3`, with the gap so a wall is not touched.
fn inside(pos: DVec3, r: f64, size: f64) -> DVec3 {
    let lo = r * (1.0 + 2.0 * GAP);
    pos.clamp(DVec3::splat(lo), DVec3::splat(size - lo))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_pair_is_separated_without_touching_velocities() {
        let a = Sphere::new(DVec3::splat(0.5), DVec3::new(1.0, 2.0, 3.0), 0.1);
        let b = Sphere::new(DVec3::new(0.55, 0.5, 0.5), DVec3::ZERO, 0.1);
        let out = grown(&[a, b], 1.0, 1.5).unwrap();
        let d = out[0].pos.distance(out[1].pos);
        assert!(d >= 0.3, "{d}");
        // Each moves less than the whole overlap (0.25 from 0.05 apart).
        assert!(d < 0.05 + 2.0 * 0.25, "moved too far: {d}");
        assert_eq!((out[0].vel, out[0].mass), (a.vel, a.mass));
        assert_eq!(out[0].radius, 0.150_000_000_000_000_02);
    }

    #[test]
    fn coincident_centres_and_walls_are_handled() {
        let a = Sphere::new(DVec3::new(0.01, 0.5, 0.5), DVec3::ZERO, 0.05);
        let out = grown(&[a, a], 1.0, 2.0).unwrap();
        for s in &out {
            assert!(s.pos.min_element() > s.radius && s.pos.max_element() < 1.0 - s.radius);
        }
        assert!(out[0].pos.distance(out[1].pos) >= 0.2);
    }

    #[test]
    fn too_big_for_the_box_does_not_fit() {
        let a = Sphere::new(DVec3::splat(0.5), DVec3::ZERO, 0.3);
        assert!(grown(&[a], 1.0, 2.0).is_none());
        let b = Sphere::new(DVec3::splat(0.2), DVec3::ZERO, 0.2);
        let c = Sphere::new(DVec3::splat(0.8), DVec3::ZERO, 0.2);
        // Two spheres of radius 0.3 fit only corner to corner in a unit cube.
        assert!(grown(&[b, c], 1.0, 1.5).is_some());
        assert!(grown(&[b, c], 1.0, 2.0).is_none());
    }
}
