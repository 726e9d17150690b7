//! What the engine keeps of the spheres: a headless engine (`bench`) gives
//! the same figures and the same world as one with a screen, Reset brings
//! back the start bit for bit, and the screen's single-precision views stay
//! within rounding of the world.
use crate::common::bits::bits;
use ballpit::engine::{Command, Engine, Settings, Snapshot, Threading};
use ballpit::physics::{ModelKind, Sphere, World};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// `n` spheres of radius about `r` on a jittered lattice (none overlap),
/// random velocities in `[-1, 1]³`.
fn scene(n: usize, r: f64, seed: u64) -> World {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let m = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / m as f64;
    assert!(1.1 * r < 0.5 * cell, "scene too dense for its lattice");
    let spheres = (0..n)
        .map(|i| {
            let c = DVec3::new((i % m) as f64, ((i / m) % m) as f64, (i / (m * m)) as f64);
            let radius = r * rng.random_range(0.9..=1.1);
            let room = 0.5 * cell - radius;
            let mut jitter = || rng.random_range(-room..=room);
            let pos = (c + 0.5) * cell + DVec3::new(jitter(), jitter(), jitter());
            let mut v = || rng.random_range(-1.0..=1.0);
            Sphere::new(pos, DVec3::new(v(), v(), v()), radius)
        })
        .collect();
    World::new(1.0, spheres)
}

fn settings(model: ModelKind, threading: Threading) -> Settings {
    Settings {
        model,
        dt: 1.0 / 60.0,
        tick: 2,
        threading,
        threads: 2,
    }
}

/// The figures a snapshot reports, as bits (everything but the views and
/// the timing).
fn figures(s: &Snapshot) -> Vec<u64> {
    vec![
        s.frame,
        s.time.to_bits(),
        s.count as u64,
        s.max_radius.map_or(u64::MAX, f64::to_bits),
        s.energy.to_bits(),
        s.energy_reset.to_bits(),
        s.max_overlap_rel.to_bits(),
        s.escaped as u64,
        s.counters.sphere_collisions,
        s.counters.wall_collisions,
        s.counters.wall_momentum.to_bits(),
        s.counters.capped_steps,
        u64::from(s.parts),
        s.steps,
    ]
}

/// Energy kept, nothing outside, no overlap beyond rounding.
fn check_invariants(start: &World, s: &Snapshot) {
    let e0 = start.kinetic_energy();
    assert!(
        (s.energy - e0).abs() / e0 < 1e-9,
        "energy {e0} -> {}",
        s.energy
    );
    assert_eq!(s.escaped, 0);
    assert!(s.max_overlap_rel <= 1e-9, "overlap {}", s.max_overlap_rel);
}

#[test]
fn a_headless_engine_reports_what_a_full_one_does() {
    let start = scene(3000, 0.012, 7);
    for model in [ModelKind::Swept, ModelKind::Exact] {
        for threading in [Threading::Off, Threading::Pool] {
            let s = settings(model, threading);
            let mut full = Engine::new(start.clone(), s).unwrap();
            let mut bare = Engine::headless(start.clone(), s).unwrap();
            assert_eq!(figures(full.snapshot()), figures(bare.snapshot()));
            for _ in 0..6 {
                for e in [&mut full, &mut bare] {
                    e.start_frame().unwrap();
                    e.finish_frame().unwrap();
                }
                let (a, b) = (full.snapshot(), bare.snapshot());
                assert_eq!(figures(a), figures(b), "{model} {threading}");
                assert_eq!(a.spheres.len(), 3000);
                assert!(b.spheres.is_empty());
                check_invariants(&start, b);
            }
            assert!(bare.snapshot().counters.sphere_collisions > 0);
            // The figures are the world's own.
            let w = bare.world();
            assert_eq!(bare.snapshot().max_overlap_rel, w.max_overlap_rel());
            assert_eq!(bare.snapshot().escaped, w.escaped());
            assert_eq!(bare.snapshot().energy, w.kinetic_energy());
            assert_eq!(bits(full.world()), bits(w), "{model} {threading}");
            // No start kept: Reset says so and changes nothing.
            let before = bits(w);
            bare.command(Command::Reset);
            bare.command(Command::SetTick(0));
            bare.start_frame().unwrap();
            let snap = bare.finish_frame().unwrap();
            assert!(snap.notice.as_deref().is_some_and(|n| n.contains("reset")));
            assert_eq!(bits(bare.world()), before);
            let moved = bare.into_world().unwrap();
            assert_eq!(bits(&moved), before);
        }
    }
}

#[test]
fn reset_gives_back_the_start_bit_for_bit() {
    let start = scene(1500, 0.015, 11);
    for model in ModelKind::ALL {
        let mut e = Engine::new(start.clone(), settings(model, Threading::Worker)).unwrap();
        // Run, edit the count and the radius, run on, then reset.
        for cmd in [
            None,
            Some(Command::SetCount(1800)),
            None,
            Some(Command::SetRadius(0.013)),
            None,
            Some(Command::SetCount(200)),
            None,
        ] {
            e.command(cmd.unwrap_or(Command::SetTick(3)));
            e.start_frame().unwrap();
            e.finish_frame().unwrap();
        }
        assert_ne!(bits(e.world()), bits(&start));
        e.command(Command::Reset);
        e.command(Command::SetTick(0));
        e.start_frame().unwrap();
        let snap = e.finish_frame().unwrap();
        assert_eq!(snap.count, 1500);
        assert_eq!(snap.energy, start.kinetic_energy());
        assert_eq!(bits(e.world()), bits(&start), "{model}");
        // And it runs on as a fresh engine does from the start.
        let mut fresh = Engine::new(start.clone(), settings(model, Threading::Worker)).unwrap();
        for en in [&mut e, &mut fresh] {
            en.command(Command::SetTick(4));
            en.start_frame().unwrap();
            en.finish_frame().unwrap();
        }
        assert_eq!(bits(e.world()), bits(fresh.world()), "{model}");
        if model != ModelKind::Discrete {
            check_invariants(&start, e.snapshot());
        }
    }
}

#[test]
fn views_are_the_spheres_to_single_precision() {
    let start = scene(2000, 0.01, 3);
    let mut e = Engine::new(start, settings(ModelKind::Swept, Threading::Pool)).unwrap();
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    let (snap, w) = (e.snapshot(), e.world());
    assert_eq!(snap.spheres.len(), w.spheres.len());
    let close = |v: f32, x: f64| (f64::from(v) - x).abs() <= x.abs() * f64::from(f32::EPSILON);
    for (v, s) in snap.spheres.iter().zip(&w.spheres) {
        assert!((0..3).all(|k| close(v.pos[k], s.pos[k])), "{v:?} {s:?}");
        assert!(close(v.radius, s.radius) && close(v.speed, s.vel.length()));
    }
    let widest = w.spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
    assert_eq!(snap.max_radius, Some(widest));
}

#[test]
fn a_rebuilt_start_comes_back_bit_for_bit_or_not_at_all() {
    use ballpit::scene::{SceneSpec, build_world_for};
    let spec = SceneSpec {
        count: Some(2000),
        seed: Some(9),
        ..Default::default()
    };
    let model = ModelKind::Swept;
    let first = build_world_for(&spec, Some(model)).unwrap();
    let edit_and_reset = |e: &mut Engine| {
        for cmd in [Command::SetCount(2300), Command::SetRadius(0.01)] {
            e.command(cmd);
            e.start_frame().unwrap();
            e.finish_frame().unwrap();
        }
        let edited = bits(e.world());
        e.command(Command::Reset);
        e.command(Command::SetTick(0));
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
        edited
    };
    let s = settings(model, Threading::Worker);
    let again = spec.clone();
    let rebuild = Box::new(move || Ok(build_world_for(&again, Some(model))?));
    let mut e = Engine::with_rebuild(first.clone(), s, rebuild).unwrap();
    let edited = edit_and_reset(&mut e);
    assert_ne!(edited, bits(&first));
    assert_eq!(bits(e.world()), bits(&first));
    assert_eq!(e.snapshot().notice, None);
    check_invariants(&first, e.snapshot());
    // A description that no longer gives the start: Reset says so and the
    // world stays as it was.
    let other = SceneSpec {
        seed: Some(10),
        ..spec
    };
    let rebuild = Box::new(move || Ok(build_world_for(&other, Some(model))?));
    let mut e = Engine::with_rebuild(first.clone(), s, rebuild).unwrap();
    let edited = edit_and_reset(&mut e);
    assert_eq!(bits(e.world()), edited);
    let notice = e.snapshot().notice.clone().unwrap_or_default();
    assert!(notice.contains("rebuilt differently"), "{notice}");
    // One that fails: the notice says why.
    let rebuild = Box::new(|| Err(anyhow::anyhow!("scene file gone")));
    let mut e = Engine::with_rebuild(first.clone(), s, rebuild).unwrap();
    let edited = edit_and_reset(&mut e);
    assert_eq!(bits(e.world()), edited);
    let notice = e.snapshot().notice.clone().unwrap_or_default();
    assert!(notice.contains("scene file gone"), "{notice}");
}
