//! The exact model against closed forms and its invariants.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::exact::Exact;
use ballpit::physics::{Model, Serial, Sphere, World};
use ballpit::scene::lattice::lattice_world;
use glam::DVec3;

fn sphere(pos: [f64; 3], vel: [f64; 3], r: f64) -> Sphere {
    Sphere::new(DVec3::from(pos), DVec3::from(vel), r)
}

fn check_invariants(w: &World, e0: f64, energy_tol: f64, overlap_tol: f64) {
    assert!(!w.has_non_finite());
    assert_eq!(w.escaped(), 0);
    let de = (w.kinetic_energy() - e0).abs() / e0;
    assert!(de <= energy_tol, "energy drift {de:e}");
    let ov = w.max_overlap_rel();
    assert!(ov <= overlap_tol, "overlap {ov:e}");
}

#[test]
fn head_on_pair_meets_at_the_predicted_time_and_swaps_velocities() {
    // Gap 0.2 closing at 2 L/s: contact at t = 0.1, then equal masses swap.
    let mut w = World::new(
        1.0,
        vec![
            sphere([0.3, 0.5, 0.5], [1.0, 0.0, 0.0], 0.1),
            sphere([0.7, 0.5, 0.5], [-1.0, 0.0, 0.0], 0.1),
        ],
    );
    let mut m = Exact::default();
    m.advance(&mut w, 0.25, 1, &Serial);
    assert_eq!(w.counters.sphere_collisions, 1);
    assert_eq!(w.counters.wall_collisions, 0);
    // After the contact at 0.1 each moves back for 0.15 s.
    assert!((w.spheres[0].pos.x - (0.4 - 0.15)).abs() < 1e-15);
    assert!((w.spheres[1].pos.x - (0.6 + 0.15)).abs() < 1e-15);
    assert_eq!(w.spheres[0].vel.x, -1.0);
    assert_eq!(w.spheres[1].vel.x, 1.0);
    assert_eq!(w.time, 0.25);
}

#[test]
fn wall_bounces_are_counted_with_their_momentum() {
    // One sphere crossing the box 10 times a second: 5 bounces in 0.5 s, as
    // closed-form flight says.
    let mut w = World::new(1.0, vec![sphere([0.5, 0.5, 0.5], [8.0, 0.0, 0.0], 0.1)]);
    let mut m = Exact::default();
    m.advance(&mut w, 0.05, 10, &Serial);
    let mut s = sphere([0.5, 0.5, 0.5], [8.0, 0.0, 0.0], 0.1);
    let (imp, hits) = ballpit::physics::flight::fly(&mut s, 1.0, 0.5);
    assert_eq!(w.counters.wall_collisions, hits);
    assert!((w.counters.wall_momentum - imp).abs() <= 1e-12 * imp);
    assert!((w.spheres[0].pos.x - s.pos.x).abs() < 1e-12);
    assert_eq!(w.spheres[0].vel, s.vel);
}

#[test]
fn newtons_cradle_passes_the_momentum_down_the_line() {
    // Five touching spheres at rest, a sixth hits the end: the far one leaves
    // with the striker's velocity, the rest stay at rest.
    let r = 0.05;
    let mut spheres = vec![sphere([0.2, 0.5, 0.5], [1.0, 0.0, 0.0], r)];
    for k in 0..5 {
        spheres.push(sphere([0.4 + 2.0 * r * k as f64, 0.5, 0.5], [0.0; 3], r));
    }
    let mut w = World::new(1.0, spheres);
    let e0 = w.kinetic_energy();
    let mut m = Exact::default();
    m.advance(&mut w, 0.01, 20, &Serial);
    assert_eq!(w.counters.sphere_collisions, 5);
    for s in &w.spheres[..5] {
        assert_eq!(s.vel, DVec3::ZERO);
    }
    assert_eq!(w.spheres[5].vel, DVec3::new(1.0, 0.0, 0.0));
    check_invariants(&w, e0, 1e-15, 1e-12);
}

#[test]
fn dense_lattice_run_keeps_energy_no_overlap_no_escape() {
    let mut w = lattice_world(1000, 0.45, 1.0, 7).unwrap();
    let e0 = w.kinetic_energy();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 30, &Serial);
    assert!(w.counters.sphere_collisions > 20_000, "{:?}", w.counters);
    assert_eq!(w.counters.capped_steps, 0);
    check_invariants(&w, e0, 1e-12, 1e-10);
}

#[test]
fn mixed_radii_a_hundred_times_apart() {
    // A few big spheres among many small: the second level of the broad phase.
    let mut w = lattice_world(512, 0.1, 1.0, 3).unwrap();
    let big = [0usize, 100, 300];
    let mut kept = Vec::new();
    for (i, s) in w.spheres.iter().enumerate() {
        if big.contains(&i) {
            kept.push(*s);
        }
    }
    let r_small = w.spheres[1].radius / 10.0;
    let mut spheres: Vec<Sphere> = w
        .spheres
        .iter()
        .enumerate()
        .filter(|(i, _)| !big.contains(i))
        .map(|(_, s)| Sphere::new(s.pos, s.vel, r_small))
        .collect();
    // Big ones: radius 100 x small, placed on free sites far apart.
    for (k, s) in kept.iter().enumerate() {
        let _ = s;
        let c = DVec3::new(0.2 + 0.3 * k as f64, 0.5, 0.5 + 0.1 * k as f64);
        spheres.retain(|t| t.pos.distance(c) > 100.0 * r_small + r_small + 1e-9);
        spheres.push(Sphere::new(c, DVec3::new(0.1, -0.2, 0.05), 100.0 * r_small));
    }
    w = World::new(1.0, spheres);
    assert_eq!(w.max_overlap_rel(), 0.0);
    let e0 = w.kinetic_energy();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 60, &Serial);
    assert!(w.counters.sphere_collisions > 100, "{:?}", w.counters);
    check_invariants(&w, e0, 1e-12, 1e-10);
}

#[test]
fn changes_from_outside_rebuild_the_schedule() {
    let mut w = lattice_world(343, 0.2, 1.0, 11).unwrap();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 10, &Serial);
    // Halve the count and grow the radius without a touch: the count
    // alone tells the model.
    w.spheres.truncate(150);
    for s in &mut w.spheres {
        *s = Sphere::new(s.pos, s.vel, s.radius * 1.05);
    }
    if w.max_overlap_rel() > 0.0 {
        // Growth may touch; the model must still never deepen an overlap.
    }
    let ov0 = w.max_overlap_rel();
    let e0 = w.kinetic_energy();
    m.advance(&mut w, 1.0 / 60.0, 10, &Serial);
    assert!(w.counters.sphere_collisions > 0);
    check_invariants(&w, e0, 1e-12, ov0.max(1e-10));
    // And a touch (an edit from outside) reloads.
    w.touch();
    m.advance(&mut w, 1.0 / 60.0, 5, &Serial);
    check_invariants(&w, e0, 1e-12, ov0.max(1e-10));
}

/// The edit signal is the world's generation: an edit at the same count
/// and time, announced by `touch`, is run as a fresh model would run the
/// edited world, bit for bit.
#[test]
fn a_touched_edit_is_run_as_a_fresh_model_runs_it() {
    let mut w = lattice_world(343, 0.2, 1.0, 11).unwrap();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 10, &Serial);
    for s in w.spheres.iter_mut().step_by(3) {
        s.vel = -s.vel;
    }
    w.touch();
    let mut fresh = w.clone();
    m.advance(&mut w, 1.0 / 60.0, 10, &Serial);
    Exact::default().advance(&mut fresh, 1.0 / 60.0, 10, &Serial);
    assert_eq!(w.spheres, fresh.spheres);
    assert!(w.counters.sphere_collisions > 0);
}

#[test]
fn a_run_is_reproducible() {
    let run = || {
        let mut w = lattice_world(400, 0.3, 1.0, 5).unwrap();
        let mut m = Exact::default();
        m.advance(&mut w, 1.0 / 30.0, 15, &Serial);
        w
    };
    assert_eq!(run(), run());
}

#[test]
fn event_cap_reports_instead_of_hanging() {
    let mut w = lattice_world(1000, 0.45, 1.0, 2).unwrap();
    let e0 = w.kinetic_energy();
    let mut m = Exact::default().with_event_cap(1000);
    m.advance(&mut w, 0.1, 3, &Serial);
    assert_eq!(w.counters.capped_steps, 3);
    assert!((w.time - 0.3).abs() < 1e-15);
    // Capped steps finish by free flight: energy kept, nobody leaves the box.
    assert!(!w.has_non_finite());
    assert_eq!(w.escaped(), 0);
    assert!((w.kinetic_energy() - e0).abs() <= 1e-12 * e0);
}

#[test]
fn dense_scene_with_a_large_sphere_uses_lists_with_a_second_level() {
    let w0 = lattice_world(1000, 0.35, 1.0, 13).unwrap();
    let r = w0.spheres[0].radius;
    let centre = DVec3::splat(0.55);
    let big = 3.4 * r;
    let mut spheres: Vec<Sphere> = w0
        .spheres
        .iter()
        .filter(|s| s.pos.distance(centre) > big + r + 1e-9)
        .copied()
        .collect();
    spheres.push(Sphere::new(centre, DVec3::new(0.3, 0.1, -0.2), big));
    let mut w = World::new(1.0, spheres);
    let filled: f64 = w
        .spheres
        .iter()
        .map(|s| ballpit::physics::sphere::volume(s.radius))
        .sum();
    assert!(filled > ballpit::physics::exact::LISTS_ABOVE_PACKING);
    let e0 = w.kinetic_energy();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 30, &Serial);
    assert!(
        m.stats.relists > 0 && m.stats.crossings == 0,
        "{:?}",
        m.stats
    );
    let last = w.spheres.len() - 1;
    assert!(
        w.spheres[last].vel != DVec3::new(0.3, 0.1, -0.2),
        "the big one was hit"
    );
    check_invariants(&w, e0, 1e-12, 1e-10);
}

#[test]
fn dilute_scene_uses_cell_crossings() {
    let mut w = lattice_world(1000, 0.05, 1.0, 14).unwrap();
    let e0 = w.kinetic_energy();
    let mut m = Exact::default();
    m.advance(&mut w, 1.0 / 60.0, 60, &Serial);
    assert!(
        m.stats.crossings > 0 && m.stats.relists == 0,
        "{:?}",
        m.stats
    );
    assert!(w.counters.sphere_collisions > 1000);
    check_invariants(&w, e0, 1e-12, 1e-10);
}

#[test]
fn observer_and_results_use_world_indices() {
    // Listed against the model's spatial order: world index 0 is the high one.
    use std::sync::{Arc, Mutex};
    let mut w = World::new(
        1.0,
        vec![
            sphere([0.5, 0.5, 0.8], [0.0, 0.0, -1.0], 0.1),
            sphere([0.5, 0.5, 0.2], [0.0, 0.0, 1.0], 0.1),
            sphere([0.1, 0.1, 0.1], [0.0; 3], 0.05),
        ],
    );
    let seen = Arc::new(Mutex::new(Vec::new()));
    let s2 = seen.clone();
    let mut m = Exact::default();
    m.set_observer(Some(Box::new(move |c| {
        s2.lock()
            .unwrap()
            .push((c.i.min(c.j), c.i.max(c.j), c.pos_i.z.max(c.pos_j.z)));
    })));
    m.advance(&mut w, 0.25, 1, &Serial);
    let seen = seen.lock().unwrap();
    assert_eq!(seen.len(), 1);
    assert_eq!((seen[0].0, seen[0].1), (0, 1));
    assert!((seen[0].2 - 0.6).abs() < 1e-15);
    // After the bounce at t = 0.2 each has gone back 0.05.
    assert!((w.spheres[0].pos.z - 0.65).abs() < 1e-15);
    assert!((w.spheres[1].pos.z - 0.35).abs() < 1e-15);
    assert_eq!(w.spheres[2].pos, DVec3::splat(0.1));
}

/// Every contact of a run (world ids, time and impulse bits) and the final
/// state, with `m`.
fn record(mut w: World, m: Exact, dt: f64, steps: u64) -> (Vec<[u64; 4]>, World) {
    use std::sync::{Arc, Mutex};
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&seen);
    let mut m = m;
    m.set_observer(Some(Box::new(move |c| {
        let word = [
            c.i as u64,
            c.j as u64,
            c.time.to_bits(),
            c.impulse.to_bits(),
        ];
        sink.lock().expect("observer lock").push(word);
    })));
    let e0 = w.kinetic_energy();
    m.advance(&mut w, dt, steps, &Serial);
    check_invariants(&w, e0, 1e-10, 1e-9);
    let contacts = seen.lock().expect("observer lock").clone();
    (contacts, w)
}

/// Two scenes of 3000 spheres, with their step and steps: a dense one (on
/// neighbour lists) and a dilute one (on cells) with three large spheres
/// among them, 3.5 to 4.3 times the rest (on the second level, clear of
/// the lattice neighbours).
fn lists_and_cells_scenes() -> [(World, f64, u64); 2] {
    let mut dilute = lattice_world(3000, 0.02, 1.0, 9).expect("lattice");
    for (k, s) in dilute.spheres.iter_mut().step_by(1000).enumerate() {
        s.radius *= 3.5 + 0.4 * k as f64;
        s.mass = s.radius.powi(3);
    }
    let dense = lattice_world(3000, 0.4, 1.0, 7).expect("lattice");
    [(dense, 0.005, 60), (dilute, 0.01, 100)]
}

/// Prefetching only loads lines early: with it at every count and with it
/// off, the same contacts in the same order and the same final state, bit
/// for bit, with neighbour lists (dense) and with cells (dilute, a few large
/// spheres among them, which take the large spheres' paths).
#[test]
fn prefetching_changes_nothing() {
    for (w, dt, steps) in lists_and_cells_scenes() {
        let (off, w_off) = record(
            w.clone(),
            Exact::default().with_prefetching(false),
            dt,
            steps,
        );
        let (on, w_on) = record(w, Exact::default().with_prefetching(true), dt, steps);
        assert!(off.len() > 10_000, "only {} contacts", off.len());
        // Reported lower world id first, whichever sphere predicted it.
        assert!(off.iter().all(|c| c[0] < c[1]));
        assert!(off == on, "the contacts differ");
        for (a, b) in w_off.spheres.iter().zip(&w_on.spheres) {
            assert_eq!((a.pos, a.vel), (b.pos, b.vel));
        }
    }
}

/// The model's whole heap at 100k spheres (issue 20): a body of one line
/// holding its count and species (no arrays of counts or masses), the slot,
/// the tournament, the cells, the labels. 137 bytes a sphere when this was
/// written (at a million, where the tree wastes less, 131); a new 4-byte
/// array per sphere would pass 140.
#[test]
fn the_model_holds_under_140_bytes_a_sphere_at_100k() {
    use ballpit::scene::{SceneSpec, build_world};
    for radius in [0.002_285_39, 0.006_19] {
        let mut w = build_world(&SceneSpec {
            count: Some(100_000),
            radius: Some(radius),
            seed: Some(5),
            ..Default::default()
        })
        .unwrap();
        let mut model = Exact::default();
        model.advance(&mut w, 1e-9, 1, &Serial);
        let per = model.heap_bytes() as f64 / w.spheres.len() as f64;
        assert!(per > 100.0 && per < 140.0, "{per} bytes a sphere");
    }
}
