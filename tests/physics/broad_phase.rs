//! The grid finds exactly the pairs whose balls meet, in every regime.
use ballpit::physics::Serial;
use ballpit::physics::Sphere;
use ballpit::physics::broad::Grid;
use glam::DVec3;
use proptest::prelude::*;
use std::collections::BTreeSet;

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]
    #[test]
    fn grid_pairs_match_brute_force(
        balls in proptest::collection::vec(
            ((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), prop_oneof![4 => 0.001f64..0.03, 1 => 0.03f64..0.4]),
            0..400,
        ),
    ) {
        check(&balls)?;
    }

    /// Spheres crowded into a corner: many to a cell, so the pair and near
    /// loops take their paths for long candidate lists.
    #[test]
    fn crowded_grid_pairs_match_brute_force(
        balls in proptest::collection::vec(
            ((0.0f64..0.12, 0.0f64..0.12, 0.0f64..0.12), prop_oneof![8 => 0.004f64..0.02, 1 => 0.02f64..0.2]),
            0..600,
        ),
    ) {
        check(&balls)?;
    }
}

fn check(balls: &[((f64, f64, f64), f64)]) -> Result<(), TestCaseError> {
    let spheres: Vec<Sphere> = balls
        .iter()
        .map(|&((x, y, z), r)| Sphere::new(DVec3::new(x, y, z), DVec3::ZERO, r))
        .collect();
    let mut grid = Grid::default();
    grid.build(&spheres, 1.0, |s| (s.pos, s.radius), &Serial);
    let mut out = Vec::new();
    grid.pairs(&Serial, &|_: u32, _: u32| true, &mut out);
    let found: BTreeSet<(u32, u32)> = out.iter().map(|&(i, j)| (i.min(j), i.max(j))).collect();
    prop_assert_eq!(found.len(), out.len(), "a pair was reported twice");
    let mut want = BTreeSet::new();
    for i in 0..spheres.len() {
        for j in i + 1..spheres.len() {
            let (a, b) = (&spheres[i], &spheres[j]);
            let s = a.radius + b.radius;
            if a.pos.distance_squared(b.pos) <= s * s {
                want.insert((i as u32, j as u32));
            }
        }
    }
    prop_assert_eq!(found, want);
    // `near_faces` names the balls that reach a face of the box, each once,
    // and no other (up to rounding at the face).
    let mut faced = Vec::new();
    grid.near_faces(&mut |i| faced.push(i as usize));
    let faced_set: BTreeSet<usize> = faced.iter().copied().collect();
    prop_assert_eq!(faced_set.len(), faced.len(), "a sphere was named twice");
    let gap = |s: &Sphere| s.pos.min_element().min(1.0 - s.pos.max_element());
    for (i, s) in spheres.iter().enumerate() {
        if gap(s) <= s.radius {
            prop_assert!(faced_set.contains(&i), "near_faces missed {}", i);
        } else if gap(s) > s.radius + 1e-12 {
            prop_assert!(!faced_set.contains(&i), "near_faces named {}", i);
        }
    }
    // `near` finds every sphere whose ball meets a query ball.
    for (k, a) in spheres.iter().enumerate().step_by(7) {
        let mut seen = BTreeSet::new();
        grid.near(a.pos, a.radius, 1.0, &mut |j, _, _| {
            seen.insert(j as usize);
        });
        for (j, b) in spheres.iter().enumerate() {
            let s = a.radius + b.radius;
            if a.pos.distance_squared(b.pos) <= s * s {
                prop_assert!(seen.contains(&j), "near({k}) missed {j}");
            }
        }
    }
    Ok(())
}
