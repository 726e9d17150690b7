//! Numerics at the extremes, for every model.
//!
//! Bounds each model states (and that every case here asserts):
//! - all models: no NaN or infinity; relative energy error at most
//!   [`ENERGY`] (every model changes energy only through elastic impulses and
//!   mirror reflections); bounded run time (an event cap reports in
//!   `capped_steps` instead of hanging);
//! - `exact`: no escapes; after every step that was not capped, overlap at
//!   most [`EXACT_OVERLAP`] of the smaller radius, or the overlap the step
//!   started from if deeper (a capped step may leave one; no model undoes
//!   it, none may deepen it);
//! - `swept`: the same, with [`SWEPT_OVERLAP`] (it follows chains of
//!   contacts within a step; every case here stays within the bound exact
//!   keeps, so it is held to the same one);
//! - `discrete`: no escapes (wall contacts mirror back inside); overlap is not
//!   bounded by the model (it grows with `dt · speed`, and fast spheres
//!   tunnel), so only its finiteness is checked.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::ballpit;
use ballpit::physics::exact::Exact;
use ballpit::physics::{Model, ModelKind, Serial, Sphere, World};
use ballpit::scene::lattice::lattice_world;
use glam::DVec3;

const ENERGY: f64 = 1e-10;
const EXACT_OVERLAP: f64 = 1e-9;
const SWEPT_OVERLAP: f64 = EXACT_OVERLAP;

struct Outcome {
    world: World,
    worst_overlap: f64,
}

/// Run `steps` steps of `dt` with `model`, checking every step.
fn run(name: &str, kind: ModelKind, world: &World, dt: f64, steps: u64) -> Outcome {
    let mut w = world.clone();
    let mut model = kind.build();
    let e0 = w.kinetic_energy();
    let mut worst: f64 = 0.0;
    let check_overlap = w.spheres.len() <= 5000;
    // The overlap the step starts from: a capped step may leave some, and
    // no model promises to undo it, only not to deepen it.
    let mut before = if check_overlap {
        w.max_overlap_rel()
    } else {
        0.0
    };
    for step in 0..steps {
        let capped = w.counters.capped_steps;
        model.advance(&mut w, dt, 1, &Serial);
        assert!(
            !w.has_non_finite(),
            "{name} {kind}: non-finite at step {step}"
        );
        let de = if e0 > 0.0 {
            (w.kinetic_energy() - e0).abs() / e0
        } else {
            w.kinetic_energy()
        };
        assert!(
            de <= ENERGY,
            "{name} {kind}: energy error {de:e} at step {step}"
        );
        assert_eq!(w.escaped(), 0, "{name} {kind}: escaped at step {step}");
        if check_overlap {
            let ov = w.max_overlap_rel();
            assert!(ov.is_finite(), "{name} {kind}: overlap not finite");
            let was_capped = w.counters.capped_steps > capped;
            let bound = match kind {
                ModelKind::Exact => Some(EXACT_OVERLAP),
                // At tolerance 0 `auto` runs `swept` or `exact`.
                ModelKind::Swept | ModelKind::Auto(_) => Some(SWEPT_OVERLAP),
                ModelKind::Discrete => None,
            };
            // Every step that was not capped is checked.
            if let Some(b) = bound
                && !was_capped
            {
                assert!(
                    ov <= b.max(before),
                    "{name} {kind}: overlap {ov:e} at step {step} (was {before:e})"
                );
            }
            worst = worst.max(ov);
            before = ov;
        }
    }
    assert!((w.time - world.time - dt * steps as f64).abs() <= 1e-9 * (dt * steps as f64));
    Outcome {
        world: w,
        worst_overlap: worst,
    }
}

fn all(name: &str, world: &World, dt: f64, steps: u64) -> Vec<Outcome> {
    ModelKind::ALL
        .iter()
        .map(|&k| run(name, k, world, dt, steps))
        .collect()
}

fn sphere(pos: [f64; 3], vel: [f64; 3], r: f64) -> Sphere {
    Sphere::new(DVec3::from(pos), DVec3::from(vel), r)
}

#[test]
fn empty_single_and_pair() {
    for n in [0, 1, 2] {
        let w = lattice_world(n, 0.01, 1.0, 9).unwrap();
        let out = all(&format!("N={n}"), &w, 1.0 / 60.0, 120);
        for o in &out {
            assert_eq!(o.world.spheres.len(), n);
        }
    }
    // One sphere: every model agrees with closed-form flight.
    let w = World::new(1.0, vec![sphere([0.3, 0.6, 0.5], [1.3, -0.7, 0.2], 0.1)]);
    let mut s = w.spheres[0];
    ballpit::physics::flight::fly(&mut s, 1.0, 2.0);
    for o in all("one", &w, 1.0 / 60.0, 120) {
        assert!(o.world.spheres[0].pos.distance(s.pos) < 1e-9);
    }
}

#[test]
fn a_hundred_thousand_spheres() {
    let w = lattice_world(100_000, 0.01, 1.0, 4).unwrap();
    for o in all("N=100000", &w, 1.0 / 240.0, 2) {
        assert_eq!(o.world.spheres.len(), 100_000);
    }
}

#[test]
fn radius_from_a_millionth_to_just_under_half_the_box() {
    // Tiny: a head-on pair and a sprinkling of others.
    let r = 1e-6;
    let mut spheres = vec![
        sphere([0.5 - 1e-3, 0.5, 0.5], [1.0, 0.0, 0.0], r),
        sphere([0.5 + 1e-3, 0.5, 0.5], [-1.0, 0.0, 0.0], r),
    ];
    let rest = lattice_world(125, 0.001, 1.0, 5).unwrap();
    spheres.extend(
        rest.spheres
            .iter()
            .filter(|s| s.pos.distance(DVec3::splat(0.5)) > 0.05)
            .map(|s| Sphere::new(s.pos, s.vel, r)),
    );
    let w = World::new(1.0, spheres);
    let out = all("tiny", &w, 1.0 / 60.0, 30);
    // Exact and swept see the head-on contact at t = 1e-3 - 1e-6.
    for o in &out[1..] {
        assert!(o.world.counters.sphere_collisions >= 1);
    }
    // Huge: one sphere with 2e-9 of room, rattling between the walls.
    let big = 0.5 - 1e-9;
    let w = World::new(1.0, vec![sphere([0.5, 0.5, 0.5], [1e-3, 2e-3, -1e-3], big)]);
    let out = all("huge", &w, 1.0 / 60.0, 10);
    // Swept and exact take every bounce (~16 000 per step on y); discrete
    // mirrors once per step and axis.
    for o in &out[1..] {
        assert!(
            o.world.counters.wall_collisions > 100_000,
            "{:?}",
            o.world.counters
        );
    }
    assert!(out[0].world.counters.wall_collisions <= 30);
}

#[test]
fn speeds_from_a_nanometre_to_ten_thousand_boxes_per_second() {
    let slow = lattice_world(216, 0.2, 1e-9, 6).unwrap();
    for o in all("slow", &slow, 1.0 / 60.0, 60) {
        for (a, b) in o.world.spheres.iter().zip(&slow.spheres) {
            // 60 steps of rounding at ~1e-16 each, on positions near 0.5.
            assert!(a.pos.distance(b.pos + b.vel * 1.0) < 1e-13);
        }
    }
    let fast = lattice_world(64, 0.05, 1e4, 6).unwrap();
    let out = all("fast", &fast, 1.0 / 60.0, 3);
    // Exact takes every contact (thousands per step) and stays exact.
    let exact = &out[2];
    assert!(exact.world.counters.sphere_collisions > 1000);
    assert_eq!(exact.world.counters.capped_steps, 0);
    assert!(exact.worst_overlap <= EXACT_OVERLAP);
}

#[test]
fn mass_ratios_of_a_million_either_way() {
    // Head-on, m1/m2 = 1e12: the closed form for 1-D elastic collisions.
    let mut a = sphere([0.3, 0.5, 0.5], [1.0, 0.0, 0.0], 0.05);
    let mut b = sphere([0.7, 0.5, 0.5], [-1.0, 0.0, 0.0], 0.05);
    a.mass = 1e6;
    b.mass = 1e-6;
    let w = World::new(1.0, vec![a, b]);
    let out = run("ratio", ModelKind::Exact, &w, 0.1, 2);
    let (m1, m2) = (a.mass, b.mass);
    let (u1, u2) = (a.vel.x, b.vel.x);
    let v1 = ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2);
    let v2 = ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2);
    assert_eq!(out.world.counters.sphere_collisions, 1);
    assert!((out.world.spheres[0].vel.x - v1).abs() < 1e-12);
    assert!((out.world.spheres[1].vel.x - v2).abs() < 1e-9 * v2.abs());
    // A gas with masses spread log-uniformly over 1e-6..1e6.
    let mut w = lattice_world(343, 0.2, 1.0, 8).unwrap();
    for (i, s) in w.spheres.iter_mut().enumerate() {
        s.mass = 10f64.powf(-6.0 + 12.0 * ((i * 7919) % 343) as f64 / 342.0);
    }
    // Light spheres rattling between heavy ones speed up fast (energy flows
    // towards equipartition), so the collision rate climbs: keep it short.
    let out = all("masses", &w, 1.0 / 120.0, 10);
    assert!(
        out[2].world.counters.sphere_collisions > 500,
        "{:?}",
        out[2].world.counters
    );
}

#[test]
fn packing_up_to_one_half() {
    let w = lattice_world(1000, 0.5, 1.0, 3).unwrap();
    let out = all("packing 0.5", &w, 1.0 / 120.0, 12);
    assert!(
        out[2].world.counters.sphere_collisions > 500,
        "{:?}",
        out[2].world.counters
    );
    assert_eq!(out[2].world.counters.capped_steps, 0);
}

#[test]
fn dt_from_a_nanosecond_to_a_second() {
    let w = lattice_world(216, 0.2, 1.0, 12).unwrap();
    all("dt 1e-9", &w, 1e-9, 1000);
    let out = all("dt 1", &w, 1.0, 2);
    // Exact does not care about dt: a second in one step is still exact.
    assert!(out[2].world.counters.sphere_collisions > 1000);
    assert_eq!(out[2].world.counters.capped_steps, 0);
}

#[test]
fn exactly_touching_spheres_and_walls() {
    // A row touching each other and both walls, every gap exactly zero in
    // binary, the middle ones moving apart.
    let r = 0.125;
    let xs = [0.125, 0.375, 0.625, 0.875];
    let vs = [0.0, -0.5, 0.5, 0.0];
    let w = World::new(
        1.0,
        xs.iter()
            .zip(vs)
            .map(|(&x, v)| sphere([x, 0.5, 0.5], [v, 0.3, 0.0], r))
            .collect(),
    );
    let out = all("touching", &w, 1.0 / 60.0, 60);
    assert!(out[2].world.counters.sphere_collisions >= 2);
    // The outer pairs are pressed between a sphere and a wall at zero gap:
    // momentum rattles without end, the cap stops it, and the overlap that
    // leaves (about 0.07 r) is only where a step says it was capped.
    for o in &out[1..] {
        assert!(o.world.counters.capped_steps > 0, "{:?}", o.world.counters);
    }
    // Fully jammed: touching each other and both walls, pushed into the
    // row. Momentum bounces along the row without moving anything; the cap
    // stops it and reports.
    let jammed = World::new(
        1.0,
        xs.iter()
            .enumerate()
            .map(|(k, &x)| sphere([x, 0.5, 0.5], [if k == 0 { 1.0 } else { 0.0 }, 0.0, 0.0], r))
            .collect(),
    );
    let mut w = jammed.clone();
    let mut m = Exact::default().with_event_cap(10_000);
    m.advance(&mut w, 1.0 / 60.0, 3, &Serial);
    assert_eq!(w.counters.capped_steps, 3);
    assert!(!w.has_non_finite());
    assert_eq!(w.escaped(), 0);
    let e0 = jammed.kinetic_energy();
    assert!((w.kinetic_energy() - e0).abs() <= ENERGY * e0);
    for kind in [ModelKind::Swept, ModelKind::Discrete] {
        let mut w = jammed.clone();
        kind.build().advance(&mut w, 1.0 / 60.0, 3, &Serial);
        assert!(!w.has_non_finite());
        assert_eq!(w.escaped(), 0, "{kind}");
        assert!((w.kinetic_energy() - e0).abs() <= ENERGY * e0, "{kind}");
    }
}

#[test]
fn newtons_cradle() {
    let r = 0.04;
    let mut spheres = vec![sphere([0.1, 0.5, 0.5], [2.0, 0.0, 0.0], r)];
    for k in 0..7 {
        spheres.push(sphere([0.3 + 2.0 * r * k as f64, 0.5, 0.5], [0.0; 3], r));
    }
    let w = World::new(1.0, spheres);
    let out = all("cradle", &w, 1.0 / 60.0, 6);
    // Exact: the momentum reaches the far end untouched.
    let e = &out[2].world;
    assert_eq!(e.spheres[7].vel, DVec3::new(2.0, 0.0, 0.0));
    assert!(e.spheres[..7].iter().all(|s| s.vel == DVec3::ZERO));
}

#[test]
fn grazing_contacts() {
    // Paths that meet at exactly the sum of radii (1e-12 inside) and miss by
    // 1e-12: one contact, then none.
    let r = 0.05;
    for (offset, hits) in [(2.0 * r * (1.0 - 1e-12), 1), (2.0 * r * (1.0 + 1e-12), 0)] {
        let w = World::new(
            1.0,
            vec![
                sphere([0.2, 0.5, 0.5], [1.0, 0.0, 0.0], r),
                sphere([0.6, 0.5 + offset, 0.5], [0.0; 3], r),
            ],
        );
        let out = all("graze", &w, 1.0 / 60.0, 30);
        assert_eq!(
            out[2].world.counters.sphere_collisions, hits,
            "offset {offset}"
        );
        assert_eq!(
            out[1].world.counters.sphere_collisions, hits,
            "offset {offset}"
        );
    }
}

#[test]
fn everything_moving_in_parallel() {
    // The whole lattice with one velocity: whole layers reach the walls at
    // the same instant (simultaneous events), then bounce into the others.
    let mut w = lattice_world(512, 0.3, 1.0, 1).unwrap();
    for s in &mut w.spheres {
        s.vel = DVec3::new(1.0, 0.5, 0.25);
    }
    let out = all("parallel", &w, 1.0 / 60.0, 30);
    assert!(out[2].world.counters.sphere_collisions > 100);
}

#[test]
fn impossible_requests_exit_2() {
    for args in [
        &["bench", "--steps", "1", "--count", "1", "--radius", "0.5"][..],
        &["bench", "--steps", "1", "--dt", "0"],
        &[
            "bench", "--steps", "1", "--count", "100000", "--radius", "0.1",
        ],
        &["bench", "--steps", "1", "--speed", "NaN"],
        &["bench", "--steps", "1", "--model", "psychic"],
        &["tradeoff", "--radius=-1"],
    ] {
        let out = ballpit().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        // One message (clap adds the allowed values and a line pointing to --help).
        let err = String::from_utf8_lossy(&out.stderr);
        let lines = err.lines().filter(|l| !l.trim().is_empty()).count();
        assert!((1..=3).contains(&lines), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
