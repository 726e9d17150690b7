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

proptest! {
    #![proptest_config(ProptestConfig { cases: 20, ..ProptestConfig::default() })]
    /// A bulk of small balls with a tail a few times wider: the bulk's cells
    /// are sized for it, the tail goes up a level.
    #[test]
    fn tailed_grid_pairs_match_brute_force(
        balls in proptest::collection::vec(
            ((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), prop_oneof![16 => 0.002f64..0.004, 1 => 0.01f64..0.05]),
            500..1500,
        ),
    ) {
        check(&balls)?;
    }
}

/// The bulk's cells follow the bulk, not a wide tail: a twenty-fifth of the
/// balls ten times wider would make every cell of a level sized by them
/// hold tens of times the candidates.
#[test]
fn a_wide_tail_does_not_size_the_bulks_cells() {
    let n = 20_000;
    let at = |k: usize| {
        let f = |m: usize| ((k * m + 7) % 10_007) as f64 / 10_007.0;
        DVec3::new(f(7_919), f(104_729), f(1_299_709))
    };
    let bulk: Vec<Sphere> = (0..n)
        .map(|k| Sphere::new(at(k), DVec3::ZERO, 0.004))
        .collect();
    // Every 25th ball wide: one sample in 25 too (the grid samples every
    // 32nd), past the 90th percentile and at the 98th.
    let mut tailed = bulk.clone();
    for s in tailed.iter_mut().step_by(25) {
        s.radius = 0.04;
    }
    let shape = |s: &[Sphere]| {
        let mut grid = Grid::default();
        grid.build(s, 1.0, |b| (b.pos, b.radius), &Serial);
        grid.shape()
    };
    let (plain, _) = shape(&bulk);
    let (with_tail, _) = shape(&tailed);
    assert_eq!(plain.len(), 1, "one level for equal balls: {plain:?}");
    assert_eq!(
        with_tail[0].0, plain[0].0,
        "the bulk's cells as without the tail: {with_tail:?} against {plain:?}"
    );
    assert!(with_tail.len() >= 2, "the tail goes up: {with_tail:?}");
    assert_eq!(with_tail[0].1, n - n / 25, "the bulk stays: {with_tail:?}");
}

/// Radii spread evenly (log-uniform over 50×): the first level is sized
/// for a share of them below the widest, where its cells hold the bulk
/// once, not for the 98th percentile, where they held it dozens of times.
#[test]
fn a_smooth_spread_of_radii_gets_levels_of_its_own() {
    let n = 20_000;
    let f = |k: usize, m: usize| ((k * m + 7) % 10_007) as f64 / 10_007.0;
    let (r0, spread) = (0.0005, 50.0_f64);
    let balls: Vec<Sphere> = (0..n)
        .map(|k| {
            let p = DVec3::new(f(k, 7_919), f(k, 104_729), f(k, 1_299_709));
            Sphere::new(p, DVec3::ZERO, r0 * spread.powf(f(k, 15_485_863)))
        })
        .collect();
    let mut grid = Grid::default();
    grid.build(&balls, 1.0, |b| (b.pos, b.radius), &Serial);
    let (levels, _) = grid.shape();
    // Cells a side for the 98th percentile radius, as before.
    let at_98 = (1.0 / (2.0 * r0 * spread.powf(0.98))).floor() as usize;
    assert!(
        levels[0].0 > 2 * at_98,
        "first level {levels:?}, {at_98} a side at the 98th percentile"
    );
    assert!(levels.len() >= 2, "the wider go up: {levels:?}");
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
