//! `exact` gives the overlap readout from its own broad phase (cells or
//! neighbour lists, large spheres on their second level), so the engine
//! builds no grid for it: the value must be `World::max_overlap_rel`'s to
//! the bit, on worlds with overlaps made by hand (an exact run makes none)
//! and without, and asking for it must change nothing in the physics.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::Lanes;
use ballpit::physics::exact::{Exact, LISTS_ABOVE_PACKING};
use ballpit::physics::sphere::volume;
use ballpit::physics::{Exec, Model, Serial, Sphere, World};
use ballpit::scene::lattice::lattice_world;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn packing(w: &World) -> f64 {
    w.spheres.iter().map(|s| volume(s.radius)).sum::<f64>() / w.size.powi(3)
}

fn random_velocity(rng: &mut impl Rng) -> DVec3 {
    DVec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    )
}

/// `n` spheres placed at random inside the unit box (so many overlap when
/// crowded), radius `r`, and `big` of them `big_factor` times larger (the
/// second level of both broad phases).
fn random_world(n: usize, r: f64, big: usize, big_factor: f64, seed: u64) -> World {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let spheres = (0..n)
        .map(|i| {
            let radius = if i % (n / big.max(1)).max(1) == 0 && i / (n / big.max(1)).max(1) < big {
                r * big_factor
            } else {
                r
            };
            let pos = DVec3::new(
                rng.random_range(radius..1.0 - radius),
                rng.random_range(radius..1.0 - radius),
                rng.random_range(radius..1.0 - radius),
            );
            Sphere::new(pos, random_velocity(&mut rng), radius)
        })
        .collect();
    World::new(1.0, spheres)
}

/// A world without overlaps (a jittered lattice), then `pairs` spheres
/// moved onto a neighbour's surface, pushed in by a random fraction of
/// their radius.
fn with_overlaps(n: usize, packing: f64, pairs: usize, seed: u64) -> World {
    let mut w = lattice_world(n, packing, 1.0, seed).unwrap();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    for _ in 0..pairs {
        let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
        if i == j {
            continue;
        }
        let (a, b) = (w.spheres[i], w.spheres[j]);
        let dir = random_velocity(&mut rng).normalize_or(DVec3::X);
        let gap = (a.radius + b.radius) * (1.0 - rng.random_range(0.0..0.3));
        let pos = a.pos + dir * gap;
        let lo = DVec3::splat(b.radius);
        w.spheres[j].pos = pos.clamp(lo, DVec3::splat(w.size) - lo);
    }
    w.touch();
    w
}

/// The readout on `w` as it is, then after each of `steps` steps, against
/// the brute-force search of the world, bit for bit; returns the deepest
/// overlap seen, so a caller can check the scene had some.
fn check(w: &mut World, steps: u64, exec: &dyn Exec) -> f64 {
    let mut m = Exact::default();
    let mut seen: f64 = 0.0;
    for step in 0..=steps {
        if step > 0 {
            m.advance(w, 1.0 / 60.0, 1, exec);
        }
        let want = w.max_overlap_rel();
        let got = m.max_overlap_rel(w, 1.0 / 60.0, exec);
        assert_eq!(
            got.map(f64::to_bits),
            Some(want.to_bits()),
            "step {step}: {got:?} against {want:e}"
        );
        assert!(!w.has_non_finite());
        assert_eq!(w.escaped(), 0, "step {step}");
        seen = seen.max(want);
    }
    seen
}

#[test]
fn cells_give_the_brute_force_overlap() {
    let mut w = with_overlaps(3000, 0.05, 40, 1);
    assert!(packing(&w) < LISTS_ABOVE_PACKING);
    assert!(check(&mut w, 4, &Serial) > 0.05);
}

#[test]
fn cells_with_large_spheres_give_the_brute_force_overlap() {
    // Random placement: smalls overlap each other and the large ones.
    let mut w = random_world(4000, 0.01, 12, 8.0, 2);
    let p = packing(&w);
    assert!(p < LISTS_ABOVE_PACKING, "packing {p}");
    assert!(check(&mut w, 3, &Serial) > 0.5);
}

#[test]
fn neighbour_lists_give_the_brute_force_overlap() {
    let mut w = with_overlaps(2000, 0.4, 30, 3);
    assert!(packing(&w) > LISTS_ABOVE_PACKING);
    assert!(check(&mut w, 3, &Serial) > 0.05);
}

#[test]
fn neighbour_lists_with_large_spheres_give_the_brute_force_overlap() {
    let mut w = random_world(1500, 0.035, 6, 5.0, 4);
    let p = packing(&w);
    assert!(p > LISTS_ABOVE_PACKING, "packing {p}");
    assert!(check(&mut w, 2, &Serial) > 0.5);
}

/// Many blocks of the search over several lanes, in any order: the same bits.
#[test]
fn lanes_give_the_brute_force_overlap() {
    let mut w = with_overlaps(20_000, 0.02, 200, 5);
    assert!(check(&mut w, 2, &Lanes(3)) > 0.05);
}

/// An exact run from a scene without overlaps has none, and says so.
#[test]
fn no_overlap_reads_zero() {
    for (packing, seed) in [(0.01, 6), (0.35, 7)] {
        let mut w = lattice_world(2000, packing, 1.0, seed).unwrap();
        assert_eq!(check(&mut w, 3, &Serial), 0.0, "packing {packing}");
    }
    assert_eq!(check(&mut World::new(1.0, Vec::new()), 1, &Serial), 0.0);
}

/// Asking for the overlap between steps (and on an edited world, which the
/// model loads as the next step would) leaves the run bit for bit the same.
#[test]
fn asking_changes_nothing() {
    for (packing, seed) in [(0.05, 8), (0.4, 9)] {
        let start = with_overlaps(2000, packing, 20, seed);
        let (mut a, mut b) = (start.clone(), start);
        let (mut ma, mut mb) = (Exact::default(), Exact::default());
        // Asked before the first step: the model loads the world here.
        assert!(ma.max_overlap_rel(&a, 1.0 / 60.0, &Serial).is_some());
        for _ in 0..6 {
            ma.advance(&mut a, 1.0 / 60.0, 2, &Serial);
            assert!(ma.max_overlap_rel(&a, 1.0 / 60.0, &Serial).is_some());
            mb.advance(&mut b, 1.0 / 60.0, 2, &Serial);
        }
        assert!(a.counters.sphere_collisions > 100, "packing {packing}");
        assert_eq!(a, b, "packing {packing}");
        assert_eq!(ma.stats, mb.stats, "packing {packing}");
    }
}

/// A world edited after a step (`World::touch`) is read afresh, not taken
/// for the one the model last wrote.
#[test]
fn an_edited_world_is_read_afresh() {
    let mut w = lattice_world(2000, 0.05, 1.0, 10).unwrap();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 2, &Serial);
    assert_eq!(m.max_overlap_rel(&w, 1.0 / 60.0, &Serial), Some(0.0));
    let (a, b) = (w.spheres[0], w.spheres[1]);
    w.spheres[1].pos = a.pos + DVec3::X * (a.radius + b.radius) * 0.5;
    let lo = DVec3::splat(b.radius);
    w.spheres[1].pos = w.spheres[1].pos.clamp(lo, DVec3::splat(w.size) - lo);
    w.touch();
    let want = w.max_overlap_rel();
    assert!(want > 0.1, "{want}");
    assert_eq!(
        m.max_overlap_rel(&w, 1.0 / 60.0, &Serial).map(f64::to_bits),
        Some(want.to_bits())
    );
}
