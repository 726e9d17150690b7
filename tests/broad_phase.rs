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
    }
}
