//! `swept` runs a step's contact events in clusters, side by side; the
//! result must be the plain serial event loop's, bit for bit, on every kind
//! of scene, however many lanes run the clusters.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::Lanes;
use ballpit::physics::swept::Swept;
use ballpit::physics::{Model, Serial, World};
use ballpit::scene::{SceneSpec, build_world};

fn world(scene: &str, count: usize, speed: Option<f64>) -> World {
    build_world(&SceneSpec {
        scene: Some(scene.into()),
        count: Some(count),
        // A gas thin enough that the events stay in many small clusters,
        // and crowded enough that some conflict in steps cut into parts.
        radius: (scene == "gas").then_some(0.018),
        speed,
        seed: Some(11),
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn clusters_match_the_serial_event_loop() {
    for (scene, count, speed, steps) in [
        ("gas", 4000, Some(0.8), 20),
        ("dense", 1500, None, 10),
        ("mixed", 400, None, 20),
        ("projectiles", 200, None, 20),
        ("cradle", 5, None, 60),
        ("billiards", 16, None, 60),
    ] {
        let start = world(scene, count, speed);
        let e0 = start.kinetic_energy();
        let mut reference = start.clone();
        let mut serial = Swept::default().serial_events(true);
        serial.advance(&mut reference, 1.0 / 60.0, steps, &Serial);
        for lanes in [1, 2, 3] {
            let mut w = start.clone();
            let mut m = Swept::default();
            let (mut clusters, mut reruns, mut rounds) = (0, 0, 0);
            for _ in 0..steps {
                m.advance(&mut w, 1.0 / 60.0, 1, &Lanes(lanes));
                let s = m.round_stats();
                clusters += s.clusters;
                reruns += s.reruns;
                rounds = rounds.max(s.rounds);
            }
            assert_eq!(w, reference, "{scene}: clusters on {lanes} lanes");
            if scene == "gas" && lanes > 1 {
                assert!(
                    clusters > 10 * steps as usize,
                    "{scene}: {clusters} clusters"
                );
                // Conflicts happen in these scenes: merging and running
                // again is exercised, not only the easy path.
                assert!(reruns > 0 && rounds > 1, "{scene}: no cluster ran twice");
            }
            eprintln!("{scene}: {clusters} clusters, {reruns} reruns, up to {rounds} rounds");
        }
        assert!(reference.counters.sphere_collisions > 0, "{scene}");
        assert_eq!(reference.escaped(), 0, "{scene}");
        let drift = (reference.kinetic_energy() - e0).abs() / e0;
        assert!(drift < 1e-12, "{scene}: energy drift {drift:e}");
    }
}

/// The engine asks `swept` for the overlap of the world a frame ended with;
/// the model answers from the next step's detection and reuses it for that
/// step. The answer is `World::max_overlap_rel`'s, and asking changes
/// nothing in the run.
#[test]
fn overlap_from_the_next_detection_matches_the_world() {
    use ballpit::physics::ModelKind;
    // Discrete steps leave overlaps to measure.
    let mut w = world("dense", 1500, None);
    ModelKind::Discrete
        .build()
        .advance(&mut w, 1.0 / 60.0, 5, &Serial);
    let deepest = w.max_overlap_rel();
    assert!(deepest > 1e-3, "discrete left overlaps: {deepest}");
    let (mut asked, mut plain) = (w.clone(), w.clone());
    let (mut m_asked, mut m_plain) = (Swept::default(), Swept::default());
    for k in 0..12 {
        let got = m_asked
            .max_overlap_rel(&asked, 1.0 / 60.0, &Lanes(2))
            .expect("swept knows");
        assert_eq!(got, asked.max_overlap_rel(), "frame {k}");
        // Asked twice, still right (and the detection kept).
        let again = m_asked.max_overlap_rel(&asked, 1.0 / 60.0, &Serial);
        assert_eq!(again, Some(got));
        m_asked.advance(&mut asked, 1.0 / 60.0, 1, &Lanes(2));
        m_plain.advance(&mut plain, 1.0 / 60.0, 1, &Serial);
        assert_eq!(asked, plain, "frame {k}");
    }
    // A world edited and announced (`World::touch`) is detected afresh.
    let mut moved = asked.clone();
    m_asked.max_overlap_rel(&asked, 1.0 / 60.0, &Serial);
    moved.spheres[0].vel *= -1.0;
    moved.touch();
    let mut reference = moved.clone();
    m_asked.advance(&mut moved, 1.0 / 60.0, 1, &Serial);
    Swept::default().advance(&mut reference, 1.0 / 60.0, 1, &Serial);
    assert_eq!(moved, reference);
}

/// The detection made ahead for the overlap readout is reused only for the
/// world it was made for: an edit of any sphere, announced with
/// `World::touch`, makes the next step detect afresh. Sphere 1 is none of
/// the 64 spheres the old fingerprint sampled (0, 23, 46, ... of 1500), so
/// that key missed this edit and the step ran on a stale detection.
#[test]
fn an_edit_of_any_sphere_drops_the_detection_made_ahead() {
    let dt = 1.0 / 60.0;
    let start = world("dense", 1500, None);
    let edit = |w: &mut World| {
        // Sent through its neighbours at a wall, ten box lengths a second.
        w.spheres[1].vel = glam::DVec3::new(-10.0, 0.0, 0.0);
    };
    let mut fresh = start.clone();
    edit(&mut fresh);
    let mut reference = fresh.clone();
    Swept::default().advance(&mut reference, dt, 1, &Serial);
    assert_eq!(reference.escaped(), 0);
    assert!(reference.max_overlap_rel() < 1e-9);
    let e0 = fresh.kinetic_energy();
    assert!((reference.kinetic_energy() - e0).abs() <= 1e-12 * e0);

    let mut m = Swept::default();
    let mut w = start.clone();
    m.max_overlap_rel(&w, dt, &Serial).expect("swept knows");
    edit(&mut w);
    w.touch();
    m.advance(&mut w, dt, 1, &Serial);
    assert_eq!(w, reference, "a touched world is detected afresh");

    // The check above can fail: the same edit left unannounced (so the
    // stale detection is reused) gives another result.
    let mut m = Swept::default();
    let mut stale = start.clone();
    m.max_overlap_rel(&stale, dt, &Serial).expect("swept knows");
    edit(&mut stale);
    m.advance(&mut stale, dt, 1, &Serial);
    assert_ne!(stale, reference, "the edit changes what a step finds");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 16, ..Default::default() })]

    /// Random crowded, fast, mass-spread scenes: clusters on 2 or 3 lanes
    /// give the serial loop's bits, and the invariants of `swept` hold
    /// (overlap only where a step was capped, as the model promises).
    #[test]
    fn random_scenes_match_the_serial_loop(
        count in 2usize..300,
        radius in 0.005f64..0.05,
        speed in 0.1f64..4.0,
        seed in proptest::prelude::any::<u64>(),
        dt in 1e-3f64..0.02,
        lanes in 2usize..4,
        heavy in 1.0f64..100.0,
    ) {
        let built = build_world(&SceneSpec {
            count: Some(count),
            radius: Some(radius),
            speed: Some(speed),
            seed: Some(seed),
            ..Default::default()
        });
        // A scene that cannot fit is thrown away, and proptest counts it.
        proptest::prop_assume!(built.is_ok(), "the scene does not fit");
        let mut start = built.expect("assumed above");
        for s in start.spheres.iter_mut().step_by(7) {
            s.mass *= heavy;
        }
        let mut reference = start.clone();
        Swept::default()
            .serial_events(true)
            .advance(&mut reference, dt, 8, &Serial);
        let mut w = start.clone();
        Swept::default().advance(&mut w, dt, 8, &Lanes(lanes));
        proptest::prop_assert_eq!(&w, &reference);
        proptest::prop_assert_eq!(w.escaped(), 0);
        // A step that hit the event cap may leave overlaps (it says so).
        if w.counters.capped_steps == 0 {
            proptest::prop_assert!(w.max_overlap_rel() < 1e-9);
        }
        let (e0, e1) = (start.kinetic_energy(), w.kinetic_energy());
        proptest::prop_assert!((e1 - e0).abs() <= 1e-12 * e0);
    }
}

/// Enough spheres with events that the clusters really go out to the lanes
/// (small steps stay on one), with conflicts and reruns among them.
#[test]
fn many_events_run_on_the_lanes_and_match() {
    let start = build_world(&SceneSpec {
        scene: Some("gas".into()),
        count: Some(30_000),
        radius: Some(0.005),
        speed: Some(0.8),
        seed: Some(5),
        ..Default::default()
    })
    .unwrap();
    let mut reference = start.clone();
    Swept::default()
        .serial_events(true)
        .advance(&mut reference, 1.0 / 60.0, 3, &Serial);
    for lanes in [2, 3] {
        let mut w = start.clone();
        let mut m = Swept::default();
        let (mut reruns, mut compared, mut apart) = (0, 0, 0);
        for _ in 0..3 {
            m.advance(&mut w, 1.0 / 60.0, 1, &Lanes(lanes));
            let s = m.round_stats();
            assert!(s.involved > 1000, "only {} spheres with events", s.involved);
            assert!(s.clusters > 100, "{} clusters", s.clusters);
            reruns += s.reruns;
            compared += s.compared;
            apart += s.apart;
        }
        assert!(reruns > 0, "no cluster ran twice");
        // Balls of different clusters met, and comparing the paths let
        // some pairs stand without a rerun (and some not).
        assert!(apart > 0 && apart < compared, "{apart} of {compared} apart");
        assert_eq!(w, reference, "{lanes} lanes");
    }
    // And on real threads.
    let pool = ballpit::engine::PoolExec::new(2).unwrap();
    let mut w = start.clone();
    Swept::default().advance(&mut w, 1.0 / 60.0, 3, &pool);
    assert_eq!(w, reference, "pool of 2 threads");
}

/// The serial loop above shares the clusters' search for partners, so it
/// cannot catch a contact that search misses. The `exact` model finds its
/// partners another way (cells and crossings, no step), so over a step or
/// two it must take the same contacts and end where `swept` ends, up to
/// rounding: on crowded, fast and sparse scenes, where chains of contacts
/// within a step and paths that leave their balls are common; with steps
/// whole and cut into parts.
#[test]
fn swept_takes_the_contacts_the_exact_model_takes() {
    use ballpit::physics::ModelKind;
    for (scene, count, radius, speed) in [
        ("dense", 3000, None, None),
        ("gas", 3000, Some(0.01), Some(3.0)),
        ("projectiles", 200, None, None),
        ("mixed", 300, None, Some(2.0)),
    ] {
        for seed in 0..3 {
            let start = build_world(&SceneSpec {
                scene: Some(scene.into()),
                count: Some(count),
                radius,
                speed,
                seed: Some(seed),
                ..Default::default()
            })
            .unwrap();
            // The parts the scene calls for, whole steps, and three parts.
            for (steps, parts) in [(1u64, None), (2, None), (2, Some(1)), (2, Some(3))] {
                let dt = 1.0 / 60.0;
                let mut swept = start.clone();
                let mut model = Swept::default().fixed_parts(parts);
                model.advance(&mut swept, dt, steps, &Serial);
                if parts.is_none() && scene != "mixed" {
                    // Crowded or fast: these steps are cut.
                    assert!(model.last_parts() > 1, "{scene}: {}", model.last_parts());
                }
                let mut exact = start.clone();
                ModelKind::Exact
                    .build()
                    .advance(&mut exact, dt * steps as f64, 1, &Serial);
                let what = format!("{scene} seed {seed}, {steps} steps in {parts:?} parts");
                let (a, b) = (swept.counters, exact.counters);
                assert!(a.sphere_collisions > 0, "{what}: no contacts");
                assert_eq!(a.sphere_collisions, b.sphere_collisions, "{what}");
                assert_eq!(a.wall_collisions, b.wall_collisions, "{what}");
                let apart = swept
                    .spheres
                    .iter()
                    .zip(&exact.spheres)
                    .map(|(s, e)| s.pos.distance(e.pos) + s.vel.distance(e.vel))
                    .fold(0.0f64, f64::max);
                assert!(apart < 1e-10, "{what}: {apart:e} apart");
                assert_eq!(swept.escaped(), 0, "{what}");
                assert!(swept.max_overlap_rel() < 1e-9, "{what}");
                let (e0, e1) = (start.kinetic_energy(), swept.kinetic_energy());
                assert!((e1 - e0).abs() <= 1e-12 * e0, "{what}");
            }
        }
    }
}
