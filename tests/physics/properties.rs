//! Random valid scenes under every model: invariants hold.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::{ModelKind, Serial, World};
use ballpit::scene::{SceneSpec, build_world};
use proptest::prelude::*;

fn scene(count: usize, radius: f64, speed: f64, seed: u64, masses: &[f64]) -> Option<World> {
    let mut w = build_world(&SceneSpec {
        count: Some(count),
        radius: Some(radius),
        speed: Some(speed),
        seed: Some(seed),
        ..Default::default()
    })
    .ok()?;
    for (s, m) in w.spheres.iter_mut().zip(masses.iter().cycle()) {
        s.mass *= m;
    }
    Some(w)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn invariants_hold(
        count in 0usize..80,
        radius in 0.01f64..0.08,
        speed in 0.0f64..6.0,
        seed in any::<u64>(),
        dt in 1e-4f64..0.1,
        steps in 1u64..120,
        masses in proptest::collection::vec(1e-3f64..1e3, 1..8),
    ) {
        let built = scene(count, radius, speed, seed, &masses);
        // Only scenes that cannot fit are refused; proptest counts them
        // and fails if too many cases are thrown away.
        prop_assume!(built.is_some(), "the scene does not fit");
        let start = built.expect("assumed above");
        for model in ModelKind::ALL {
            let mut w = start.clone();
            model.build().advance(&mut w, dt, steps, &Serial);
            prop_assert!(!w.has_non_finite(), "{model}: NaN or infinity");
            let (e0, e1) = (start.kinetic_energy(), w.kinetic_energy());
            let sim = dt * steps as f64;
            if e0 > 0.0 {
                let drift = (e1 - e0).abs() / e0;
                prop_assert!(drift <= 1e-12 * sim.max(1.0), "{model}: drift {drift}");
            }
            let p0 = start.momentum();
            prop_assert_eq!(w.spheres.len(), start.spheres.len());
            if model != ModelKind::Discrete {
                prop_assert_eq!(w.escaped(), 0, "{}: escaped", model);
                let overlap = w.max_overlap_rel();
                prop_assert!(overlap < 1e-9, "{model}: overlap {overlap}");
                prop_assert_eq!(w.counters.capped_steps, 0);
            }
            // Walls take momentum, so only check it stays finite.
            prop_assert!(p0.is_finite() && w.momentum().is_finite());
        }
    }
}
