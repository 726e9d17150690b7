//! The physics time a snapshot reports covers every bit of physics work the
//! frame did: in `worker` mode the `physics` thread runs nothing but frames,
//! and one thread's CPU time never exceeds the wall time it spans, so the
//! reported physics seconds must be at least (nearly) the CPU the thread
//! burned over the same frames. Work done outside the timer (such as a
//! detection made for a readout and reused by the next step) breaks that.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::{ModelKind, World};
use ballpit::scene::{SceneSpec, build_world};
use std::time::{Duration, Instant};

/// Physics seconds to collect per model: long against the CPU clock's
/// resolution and a frame's untimed copy of the spheres, short for CI.
const PHYSICS_SECONDS: f64 = 0.6;

/// A scene where the model's step is long against the untimed copy of the
/// spheres for the screen, and where the detection a readout could make
/// outside the step would be a large share of the frame: `swept` and
/// `exact` on a dilute gas (whole steps, few events each), `discrete` on a
/// crowd (many near pairs per sphere).
fn scene(model: ModelKind) -> World {
    let spec = match model {
        ModelKind::Discrete => SceneSpec {
            scene: Some("dense".into()),
            count: Some(8000),
            ..Default::default()
        },
        ModelKind::Swept | ModelKind::Exact | ModelKind::Auto(_) => SceneSpec {
            scene: Some("gas".into()),
            count: Some(10_000),
            radius: Some(0.005),
            ..Default::default()
        },
    };
    build_world(&SceneSpec {
        seed: Some(3),
        ..spec
    })
    .unwrap()
}

#[test]
fn physics_seconds_cover_the_physics_threads_cpu() {
    for model in ModelKind::ALL {
        let world = scene(model);
        let settings = Settings {
            model,
            // Long steps: on an idle host the untimed copy of the spheres
            // for the screen (and the thread's wake-ups) stay a few percent
            // of a frame, while the old untimed readout detection was 12-48 %
            // (physics/CPU 0.52 discrete, 0.77 swept, 0.88 exact, measured
            // by moving it back out of the timer).
            dt: 1.0 / 15.0,
            tick: 1,
            threading: Threading::Worker,
            threads: 1,
        };
        let mut e = Engine::new(world.clone(), settings).unwrap();
        // One frame first, so the thread's start-up is not in the count.
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
        let tid = e.physics_tid().expect("Linux gives the thread id");
        let cpu = || ballpit::cpu::thread_cpu_seconds_of(tid).unwrap();
        let cpu0 = cpu();
        let (mut physics, mut frames) = (0.0, 0);
        let deadline = Instant::now() + Duration::from_secs(20);
        while physics < PHYSICS_SECONDS && Instant::now() < deadline {
            e.start_frame().unwrap();
            physics += e.finish_frame().unwrap().physics_seconds;
            frames += 1;
        }
        let burned = cpu() - cpu0;
        eprintln!("{model}: {frames} frames, physics {physics:.3} s, thread CPU {burned:.3} s");
        assert!(frames >= 5, "{model}: only {frames} frames");
        // The clock read is the working thread's (an idle thread's would
        // not move); how much of a core it got depends on the host's load.
        assert!(
            burned > 0.01,
            "{model}: the physics thread's CPU did not move ({burned} s)"
        );
        assert!(
            physics >= 0.9 * burned,
            "{model}: physics {physics:.3} s < 0.9 x thread CPU {burned:.3} s"
        );
        // Invariants of the run the times came from.
        let w = e.world();
        assert_eq!(w.escaped(), 0, "{model}");
        let drift = (w.kinetic_energy() - world.kinetic_energy()).abs() / world.kinetic_energy();
        assert!(drift < 1e-9, "{model}: energy drift {drift:e}");
    }
}
