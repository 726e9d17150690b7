//! The spatial order the event loop keeps its spheres in: the order of
//! their cells, so a sphere's neighbours sit close to it in every
//! per-sphere array and a prediction touches few cache lines. The load
//! sorts them; `order` maps the labels back to the world's ids, so the
//! world, the CSV and the screen see every sphere at its id.
use glam::DVec3;

/// The spheres' numbers (`number(i)` of the `i`th position: world ids at
/// load) in the order of their cells on a grid of
/// about one cell a sphere, z then y then x; ties keep their current order
/// (a counting sort: linear, and stable). `perm[new] = old`.
#[must_use]
pub fn spatial_order<T: Copy + Default>(
    positions: impl ExactSizeIterator<Item = DVec3>,
    size: f64,
    number: impl Fn(usize) -> T,
) -> Vec<T> {
    let n = positions.len();
    let per_side = ((n as f64).cbrt().ceil() as usize).max(1);
    let cell = |x: f64| ((x / size * per_side as f64) as usize).min(per_side - 1);
    let key = |p: DVec3| {
        cell(p.x.max(0.0)) + per_side * (cell(p.y.max(0.0)) + per_side * cell(p.z.max(0.0)))
    };
    let keys: Vec<u32> = positions.map(|p| key(p) as u32).collect();
    let mut start = vec![0u32; per_side * per_side * per_side + 1];
    for &k in &keys {
        start[k as usize + 1] += 1;
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    let mut perm = vec![T::default(); n];
    for (i, &k) in keys.iter().enumerate() {
        let at = &mut start[k as usize];
        perm[*at as usize] = number(i);
        *at += 1;
    }
    perm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spatial_order_sorts_by_cell_and_keeps_ties_in_order() {
        // Two per cell of a 2-a-side grid, given in reverse cell order.
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let pos = [
            p(0.9, 0.9, 0.9),
            p(0.1, 0.1, 0.1),
            p(0.6, 0.1, 0.1),
            p(0.2, 0.2, 0.2),
            p(0.1, 0.1, 0.9),
            p(0.1, 0.9, 0.1),
            p(0.7, 0.7, 0.7),
            p(0.3, 0.3, 0.3),
        ];
        let perm = spatial_order(pos.into_iter(), 1.0, |i| i);
        assert_eq!(perm, [1, 3, 7, 2, 5, 4, 0, 6]);
    }
}
