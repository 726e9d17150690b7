//! The second level both localities keep: the few spheres far larger than
//! the bulk stay out of the grid (every small sphere checks them; a large
//! one scans the cells over its own reach plus a skin and rescans when it
//! leaves that skin), so radii 100x apart stay cheap.
use super::body::Bodies;
use super::ids::SpeciesId;
use glam::DVec3;

/// A sphere counts as large (second level) above this multiple of the bulk radius.
pub const BIG_FACTOR: f64 = 3.0;

/// How a scene's radii split between the grid and the second level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    /// The bulk radius: the 98th percentile.
    pub bulk: f64,
    /// Spheres above this radius go to the second level (infinite when the
    /// largest is within `factor` times the bulk).
    pub big_above: f64,
    /// The largest radius at or under `big_above`.
    pub small_rmax: f64,
}

/// Spheres larger than `factor` times the bulk (98th percentile) radius go
/// to the second level. Counted by species, so a scene of a few species
/// (every preset) needs no array as long as the spheres: at a million that
/// array stayed resident after it was freed. `bodies` is not empty.
pub fn split_big(bodies: &Bodies, factor: f64) -> Split {
    let n = bodies.len();
    let radius = |s: usize| bodies.radius_of_species(SpeciesId::at(s));
    let mut count = vec![0_usize; bodies.species_count()];
    for b in bodies.iter() {
        count[b.species.index()] += 1;
    }
    let mut by_radius: Vec<usize> = (0..count.len()).filter(|&s| count[s] > 0).collect();
    by_radius.sort_by(|&a, &b| radius(a).total_cmp(&radius(b)));
    // The radius the kth sphere in order of radius has.
    let k = (n * 98 / 100).min(n - 1);
    let mut seen = 0;
    let bulk = by_radius
        .iter()
        .map(|&s| {
            seen += count[s];
            (seen, radius(s))
        })
        .find(|&(seen, _)| seen > k)
        .map_or(0.0, |(_, r)| r);
    split_at(bulk, by_radius.iter().map(|&s| radius(s)), factor)
}

/// The split once the bulk radius is known, from the scene's `radii` (each
/// at least once, in any order).
fn split_at(bulk: f64, radii: impl Iterator<Item = f64> + Clone, factor: f64) -> Split {
    let rmax = radii.clone().fold(0.0, f64::max);
    let big_above = if rmax <= factor * bulk {
        f64::INFINITY
    } else {
        factor * bulk
    };
    let small_rmax = radii.filter(|&r| r <= big_above).fold(0.0, f64::max);
    Split {
        bulk,
        big_above,
        small_rmax,
    }
}

/// Time until a point at offset `d` from a ball's centre, moving at `v`,
/// reaches the ball's edge (radius `r`): 0 if already outside, infinite if
/// at rest. The root of `a t^2 + 2 b t + c = 0` (c < 0) in the form that
/// never subtracts nearly equal numbers.
#[inline]
pub fn time_to_leave(d: DVec3, v: DVec3, r: f64) -> f64 {
    let a = v.length_squared();
    if a == 0.0 {
        return f64::INFINITY;
    }
    let c = d.length_squared() - r * r;
    if c >= 0.0 {
        return 0.0;
    }
    let b = d.dot(v);
    let disc = (b * b - a * c).sqrt();
    if b > 0.0 {
        -c / (b + disc)
    } else {
        (disc - b) / a
    }
}

#[cfg(test)]
mod tests {
    use super::{Split, split_at, split_big};
    use crate::physics::exact::body::Bodies;
    use crate::physics::sphere::Sphere;
    use glam::DVec3;

    /// What sorting every radius gives: the 98th percentile, then the same
    /// rule for the threshold.
    fn by_sorting(radii: &[f64], factor: f64) -> Split {
        let mut sorted = radii.to_vec();
        sorted.sort_by(f64::total_cmp);
        let bulk = sorted[(radii.len() * 98 / 100).min(radii.len() - 1)];
        split_at(bulk, sorted.iter().copied(), factor)
    }

    fn bodies(radii: &[f64]) -> Bodies {
        let spheres: Vec<Sphere> = radii
            .iter()
            .map(|&r| Sphere::new(DVec3::ZERO, DVec3::ZERO, r))
            .collect();
        Bodies::from_spheres(spheres.iter(), 0.0)
    }

    /// Counted by species, the split is the one sorting every radius gives:
    /// a few species in any order and share (the percentile falling on a
    /// boundary between two), one species, and every sphere its own.
    #[test]
    fn the_split_counted_by_species_is_the_sorted_one() {
        let mut cases: Vec<Vec<f64>> = vec![vec![0.5; 7]];
        // 98 small then 2 large: the 98th sphere (index 98) is large.
        cases.push([vec![0.5; 98], vec![4.0; 2]].concat());
        cases.push([vec![4.0; 2], vec![0.5; 97], vec![0.2; 1]].concat());
        cases.push([vec![4.0; 1], vec![0.5; 150], vec![1.2; 40], vec![0.3; 9]].concat());
        cases.push(
            (0..500)
                .map(|k| 0.1 + f64::from(k * 37 % 500) * 0.01)
                .collect(),
        );
        for radii in &cases {
            assert_eq!(
                split_big(&bodies(radii), 3.0),
                by_sorting(radii, 3.0),
                "{radii:?}"
            );
        }
        let two = split_big(&bodies(&cases[1]), 3.0);
        assert_eq!(
            (two.bulk, two.small_rmax),
            (4.0, 4.0),
            "the 98th of 100 is large"
        );
        let few_large = split_big(&bodies(&cases[3]), 3.0);
        assert_eq!(
            (few_large.bulk, few_large.big_above, few_large.small_rmax),
            (1.2, 1.2 * 3.0, 1.2),
            "one large sphere among 200 goes to the second level"
        );
    }
}
