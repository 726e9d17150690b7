//! The threads panel's parallelism (`Snapshot::parallelism`): a pool
//! engine measures it on the running scene, every few seconds one step on
//! the span executor in place of the pool, and that step ends in the bits
//! the pool would have made; the other modes measure nothing.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::bits;
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::{ModelKind, World};
use ballpit::scene::{SceneSpec, build_world};

fn gas() -> World {
    build_world(&SceneSpec {
        scene: Some("gas".into()),
        count: Some(12_000),
        radius: Some(0.006),
        seed: Some(5),
        ..Default::default()
    })
    .unwrap()
}

/// `frames` frames of two steps in `threading`: every parallelism the
/// snapshots carried, and the world at the end.
fn run(world: &World, threading: Threading, threads: usize, frames: usize) -> (Vec<f64>, World) {
    let mut e = Engine::new(
        world.clone(),
        Settings {
            model: ModelKind::Swept,
            dt: 1.0 / 60.0,
            tick: 2,
            threading,
            threads,
        },
    )
    .unwrap();
    let mut seen = Vec::new();
    for _ in 0..frames {
        e.start_frame().unwrap();
        seen.extend(e.finish_frame().unwrap().parallelism);
    }
    (seen, e.into_world().unwrap())
}

#[test]
fn a_pool_engine_measures_the_scenes_parallelism_and_a_worker_engine_none() {
    let start = gas();
    let (e0, size) = (start.kinetic_energy(), start.size);
    let (_, reference) = run(&start, Threading::Off, 1, 6);
    for threads in [2, 64] {
        let (seen, end) = run(&start, Threading::Pool, threads, 6);
        // Measured from the second frame on (the first loads the model).
        assert!(seen.len() >= 4, "pool of {threads}: {seen:?}");
        assert!(seen.iter().all(|&p| p > 1.2), "pool of {threads}: {seen:?}");
        // The measured step is the scene's own: the same bits as `off`.
        assert_eq!(bits(&end), bits(&reference), "pool of {threads}");
    }
    for threading in [Threading::Off, Threading::Worker, Threading::Split] {
        let (seen, end) = run(&start, threading, 2, 6);
        assert!(seen.is_empty(), "{threading}: {seen:?}");
        assert_eq!(bits(&end), bits(&reference), "{threading}");
    }
    // The run itself: energy kept, nobody out of the box, no overlap.
    let drift = (reference.kinetic_energy() - e0).abs() / e0;
    assert!(drift < 1e-6, "energy drift {drift}");
    for s in &reference.spheres {
        for x in s.pos.to_array() {
            assert!(x >= s.radius - 1e-9 && x <= size - s.radius + 1e-9);
        }
    }
    assert!(reference.max_overlap_rel() < 1e-6);
}

/// `exact` keeps to one lane: nothing to measure, the pool line says it
/// is serial instead.
#[test]
fn a_pool_engine_running_a_serial_model_measures_nothing() {
    let start = build_world(&SceneSpec {
        count: Some(500),
        ..SceneSpec::default()
    })
    .unwrap();
    let mut e = Engine::new(
        start,
        Settings {
            model: ModelKind::Exact,
            dt: 1.0 / 60.0,
            tick: 1,
            threading: Threading::Pool,
            threads: 2,
        },
    )
    .unwrap();
    for _ in 0..4 {
        e.start_frame().unwrap();
        let s = e.finish_frame().unwrap();
        assert_eq!(s.parallelism, None);
        assert_eq!(s.escaped, 0);
        assert!(s.max_overlap_rel < 1e-6, "{}", s.max_overlap_rel);
    }
}
