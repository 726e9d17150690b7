//! The overlap readout: the deepest pair overlap over the smaller radius.
//! One search for the engine's per-frame readout and `World`'s own, from a
//! grid of the spheres; the models that keep pairs anyway (`swept`'s
//! detection, `exact`'s broad phase) take the same [`overlap_rel`] of
//! theirs, and the max is order-free, so every readout agrees to the bit.
use super::broad::Grid;
use super::exec::Exec;
use super::sphere::overlap_rel;
use super::world::World;
use std::sync::atomic::{AtomicU64, Ordering};

/// An overlap readout.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overlap {
    /// Deepest pair overlap over the smaller radius.
    pub deepest_rel: f64,
    /// Only some overlapping pairs were looked at: `deepest_rel` is a lower bound.
    pub partial: bool,
}

impl Overlap {
    /// A readout that looked at every pair.
    #[must_use]
    pub fn complete(deepest_rel: f64) -> Overlap {
        Overlap {
            deepest_rel,
            partial: false,
        }
    }
}

/// The deepest overlap in `world`, searched with `grid` (rebuilt here) on
/// `exec`, looking at no more than `limit` overlapping pairs (`None`: all
/// of them). The pairs are looked at, never kept; past `limit` the search
/// stops and says the value is a lower bound.
pub fn deepest(grid: &mut Grid, world: &World, exec: &dyn Exec, limit: Option<usize>) -> Overlap {
    let sp = &world.spheres;
    grid.build(sp, world.size, |s| (s.pos, s.radius), exec);
    // Depths are never negative, and such f64s order as their bits.
    let worst = AtomicU64::new(0);
    let counted = |i: u32, j: u32| {
        let (a, b) = (&sp[i as usize], &sp[j as usize]);
        let s = a.radius + b.radius;
        if a.pos.distance_squared(b.pos) < s * s {
            let rel = overlap_rel(a.pos, a.radius, b.pos, b.radius);
            worst.fetch_max(rel.to_bits(), Ordering::Relaxed);
            return true;
        }
        false
    };
    // Counting stops past `usize::MAX` pairs only, which no world holds.
    let all = grid.count_within(exec, &counted, limit.unwrap_or(usize::MAX));
    Overlap {
        deepest_rel: f64::from_bits(worst.into_inner()),
        partial: !all,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Serial, Sphere};
    use glam::DVec3;

    /// `n` spheres of radius 0.01 within 1e-3 of the centre: every pair
    /// overlaps, by different depths.
    fn heap(n: u32) -> World {
        let spheres = (0..n)
            .map(|i| {
                let d = |k: u32| f64::from((i.wrapping_mul(2_654_435_761) >> k) % 1000) * 1e-6;
                Sphere {
                    pos: DVec3::new(0.5 + d(0), 0.5 + d(10), 0.5 + d(20)),
                    vel: DVec3::ZERO,
                    radius: 0.01,
                    mass: 1.0,
                }
            })
            .collect();
        World::new(1.0, spheres)
    }

    /// Every pair, by brute force.
    fn brute_force(world: &World) -> f64 {
        let sp = &world.spheres;
        let mut worst: f64 = 0.0;
        for (i, a) in sp.iter().enumerate() {
            for b in &sp[i + 1..] {
                let d = a.pos.distance(b.pos);
                worst = worst.max((a.radius + b.radius - d) / a.radius.min(b.radius));
            }
        }
        worst
    }

    #[test]
    fn the_readout_within_its_budget_is_the_brute_force_value() {
        let world = heap(60); // 1 770 overlapping pairs
        let full = brute_force(&world);
        assert!(full > 0.5, "{full}");
        assert_eq!(world.max_overlap_rel(), full);
        let mut grid = Grid::default();
        for limit in [Some(1_770), Some(1_771), None] {
            let o = deepest(&mut grid, &world, &Serial, limit);
            assert_eq!(o, Overlap::complete(full), "limit {limit:?}");
        }
    }

    #[test]
    fn past_its_budget_the_readout_stops_and_says_it_gives_a_lower_bound() {
        let world = heap(60);
        let full = brute_force(&world);
        let mut grid = Grid::default();
        let o = deepest(&mut grid, &world, &Serial, Some(1_769));
        assert!(o.partial);
        assert!(
            o.deepest_rel > 0.0 && o.deepest_rel <= full,
            "{o:?} vs {full}"
        );
        let o = deepest(&mut grid, &world, &Serial, Some(10));
        assert!(o.partial && o.deepest_rel <= full, "{o:?}");
    }

    #[test]
    fn spheres_apart_or_touching_read_zero() {
        let s = |x: f64| Sphere {
            pos: DVec3::new(x, 0.5, 0.5),
            vel: DVec3::ZERO,
            radius: 0.1,
            mass: 1.0,
        };
        let world = World::new(1.0, vec![s(0.2), s(0.4), s(0.7)]);
        let o = deepest(&mut Grid::default(), &world, &Serial, None);
        assert_eq!(o, Overlap::complete(0.0));
    }
}
