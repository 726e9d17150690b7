//! `ballpit tradeoff` end to end on a small scene.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::{ballpit, scratch};
use ballpit::physics::ModelKind;
use ballpit::scene::{SceneSpec, build_world};
use ballpit::tradeoff::{LADDER, REFERENCE_NOTE, RUN_SECONDS, measure};

#[test]
fn table_ranks_the_models_as_their_contracts_say() {
    let world = build_world(&SceneSpec {
        count: Some(150),
        radius: Some(0.04),
        ..SceneSpec::default()
    })
    .unwrap();
    let rows = measure(&world);
    assert_eq!(rows.len(), ModelKind::ALL.len() * LADDER.len());
    let n = world.spheres.len() as f64;
    for r in &rows {
        assert_eq!(r.steps, (RUN_SECONDS / r.dt).round() as u64, "{r:?}");
        // Both costs come from the same wall time: cost = n / (dt * rate).
        let implied = n / (r.dt * r.sphere_steps_per_second);
        assert!((r.cost / implied - 1.0).abs() < 1e-9, "{r:?}");
        assert!(r.energy_err.is_finite() && r.pos_err.is_finite());
        assert!(r.horizon >= r.dt);
    }
    let get = |m: ModelKind, dt: f64| rows.iter().find(|r| r.model == m && r.dt == dt).unwrap();
    let mut reference_collisions = None;
    for dt in LADDER {
        let e = get(ModelKind::Exact, dt);
        // Exact against the independent brute-force reference: the same
        // contacts, the same positions up to rounding, at every sampling.
        assert!(e.pos_err < 1e-12, "{e:?}");
        assert!(e.max_overlap_rel <= 1e-10 && e.escaped == 0 && e.energy_err < 1e-12);
        assert_eq!(e.missed, 0.0, "{e:?}");
        assert!(e.collisions > 100, "{e:?}");
        let want = *reference_collisions.get_or_insert(e.collisions);
        assert_eq!(e.collisions, want, "{e:?}");
        let s = get(ModelKind::Swept, dt);
        assert!(s.escaped == 0 && s.energy_err < 1e-12);
        assert!(s.max_overlap_rel < 1e-9, "{s:?}");
        assert_eq!(s.collisions, want, "{s:?}");
        assert!(s.pos_err < 1e-12, "{s:?}");
    }
    // Discrete at the coarsest step overlaps deeply and misses or repeats
    // contacts; refining dt shrinks both its overlap and position error.
    let coarse = get(ModelKind::Discrete, LADDER[0]);
    let fine = get(ModelKind::Discrete, LADDER[LADDER.len() - 1]);
    assert!(coarse.max_overlap_rel > 0.1, "{coarse:?}");
    assert!(coarse.missed.abs() > 0.05, "{coarse:?}");
    assert!(fine.max_overlap_rel < coarse.max_overlap_rel / 8.0);
    assert!(fine.pos_err < coarse.pos_err / 8.0);
    assert!(coarse.pos_err > 1e-6);
}

/// The reference itself, on cases with a known answer, and its invariants.
#[test]
fn the_reference_takes_known_contacts_and_keeps_the_invariants() {
    use ballpit::physics::{Sphere, World, reference};
    use glam::DVec3;
    // Head-on, equal masses: the gap of 0.3 closes at 2 per second, so
    // they meet at t = 0.15 at x = 0.4 and 0.6 and swap velocities.
    let mut w = World::new(
        1.0,
        vec![
            Sphere::new(DVec3::new(0.25, 0.5, 0.5), DVec3::new(1.0, 0.0, 0.0), 0.1),
            Sphere::new(DVec3::new(0.75, 0.5, 0.5), DVec3::new(-1.0, 0.0, 0.0), 0.1),
        ],
    );
    // A coordinate of a position or velocity is `want`, to `tol`.
    let at = |got: f64, want: f64, tol: f64, w: &World| {
        assert!((got - want).abs() < tol, "{got} != {want}: {:?}", w.spheres);
    };
    reference::run(&mut w, 0.2);
    assert_eq!(w.counters.sphere_collisions, 1);
    assert_eq!(w.counters.wall_collisions, 0);
    at(w.spheres[0].vel.x, -1.0, 1e-15, &w);
    at(w.spheres[0].pos.x, 0.35, 1e-14, &w);
    // Sphere 0 reaches x = 0.1 at t = 0.45 and is back at 0.15 at t = 0.5;
    // sphere 1 mirrors it.
    reference::run(&mut w, 0.3);
    assert_eq!(w.counters.wall_collisions, 2);
    at(w.spheres[0].pos.x, 0.15, 1e-14, &w);
    at(w.spheres[1].pos.x, 0.85, 1e-14, &w);
    assert!((w.time - 0.5).abs() < 1e-15);
    // Momentum to the walls: 2 m |v| per hit.
    let m = w.spheres[0].mass;
    assert!((w.counters.wall_momentum - 4.0 * m).abs() < 1e-15);

    // A crowded random scene: energy to rounding, nobody out, no overlap,
    // and exact's contacts over a short run.
    let start = build_world(&SceneSpec {
        scene: Some("dense".into()),
        count: Some(300),
        seed: Some(4),
        ..SceneSpec::default()
    })
    .unwrap();
    let mut w = start.clone();
    let events = reference::run(&mut w, 0.05);
    assert!(events > 200, "{events} events");
    let e0 = start.kinetic_energy();
    assert!((w.kinetic_energy() - e0).abs() <= 1e-12 * e0);
    assert_eq!(w.escaped(), 0);
    assert!(w.max_overlap_rel() < 1e-9);
    let mut exact = start.clone();
    ModelKind::Exact
        .build()
        .advance(&mut exact, 0.05, 1, &ballpit::physics::Serial);
    assert_eq!(
        w.counters.sphere_collisions,
        exact.counters.sphere_collisions
    );
    assert_eq!(w.counters.wall_collisions, exact.counters.wall_collisions);
    let apart = w
        .spheres
        .iter()
        .zip(&exact.spheres)
        .map(|(a, b)| a.pos.distance(b.pos))
        .fold(0.0, f64::max);
    assert!(apart < 1e-10, "{apart:e}");
}

#[test]
fn cli_writes_the_table_the_csv_and_the_plot() {
    let dir = scratch("tradeoff");
    let out = ballpit()
        .args(["tradeoff", "--count", "60", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The progress bar is for terminals only: nothing on a piped stderr.
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
    let table = String::from_utf8(out.stdout).unwrap();
    // The note naming the reference, a blank line, the header, the rows.
    assert_eq!(table.lines().next(), Some(REFERENCE_NOTE));
    let models = ModelKind::ALL.len();
    assert_eq!(table.lines().count(), 4 + models * LADDER.len());
    assert!(table.contains("| exact | 1/1920 |"));
    // `auto` says what it ran on each row.
    assert!(table.contains("| auto → "), "{table}");
    let csv = std::fs::read_to_string(dir.join("tradeoff.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + models * LADDER.len());
    let svg = std::fs::read_to_string(dir.join("tradeoff.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("discrete") && svg.contains("exact"));
    let _ = std::fs::remove_dir_all(&dir);
    // Bad scene flags: exit code 2 and one message.
    let bad = ballpit()
        .args(["tradeoff", "--count", "10", "--radius", "0.6"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
