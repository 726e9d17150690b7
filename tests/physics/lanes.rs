//! The pool's lane choice never shows in the answer: every preset gives the
//! same bits on 1, 2, 3, 8, 64 and 256 lanes (all of them used, lanes run
//! last first) and on real pools of those sizes, as on one thread.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::{Lanes, bits};
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::{ModelKind, Serial, World};
use ballpit::scene::{SceneSpec, build_world, presets::PRESETS};

const COUNTS: [usize; 6] = [1, 2, 3, 8, 64, 256];
const DT: f64 = 1.0 / 60.0;

fn pool(world: &World, model: ModelKind, threads: usize) -> (World, Option<usize>) {
    let s = Settings {
        model,
        dt: DT,
        tick: 3,
        threading: Threading::Pool,
        threads,
    };
    let mut e = Engine::new(world.clone(), s).unwrap();
    let mut busy = None;
    for _ in 0..3 {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
        busy = e.snapshot().pool_busy.map(|b| b.busy).max(busy);
    }
    (e.world().clone(), busy)
}

#[test]
fn every_lane_count_and_pool_size_gives_the_same_bits_on_every_preset() {
    for preset in PRESETS {
        let spec = SceneSpec {
            scene: Some(preset.name.into()),
            ..SceneSpec::default()
        };
        let world = build_world(&spec).unwrap();
        for model in [ModelKind::Discrete, ModelKind::Swept] {
            let name = preset.name;
            let mut reference = world.clone();
            model.build().advance(&mut reference, DT, 9, &Serial);
            let (e0, e1) = (world.kinetic_energy(), reference.kinetic_energy());
            assert!(
                (e1 - e0).abs() <= 1e-9 * e0,
                "{model} {name}: energy {e0} -> {e1}"
            );
            assert_eq!(reference.escaped(), 0, "{model} {name}: escaped");
            assert!(reference.time > world.time, "{model} {name}: time moved");
            for k in COUNTS {
                let mut got = world.clone();
                model.build().advance(&mut got, DT, 9, &Lanes(k));
                assert!(
                    bits(&got) == bits(&reference),
                    "{model} {name}: {k} lanes differ from one thread"
                );
                let (got, busy) = pool(&world, model, k);
                assert!(
                    bits(&got) == bits(&reference),
                    "{model} {name}: a pool of {k} differs from one thread"
                );
                let busy = busy.expect("a pool says how many lanes it kept busy");
                assert!(
                    (1..=k).contains(&busy),
                    "{model} {name}: {busy} of {k} busy"
                );
            }
        }
    }
}

/// The default scene is too small to share: a pool of 64 keeps one lane
/// busy and says the work is what held it.
#[test]
fn a_small_scene_keeps_one_lane_of_a_large_pool_busy() {
    let world = build_world(&SceneSpec::default()).unwrap();
    let s = Settings {
        model: ModelKind::Swept,
        dt: DT,
        tick: 2,
        threading: Threading::Pool,
        threads: 64,
    };
    let mut e = Engine::new(world, s).unwrap();
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    let b = e.snapshot().pool_busy.unwrap();
    assert_eq!((b.busy, b.threads), (1, 64));
    assert_eq!(b.bound, ballpit::physics::exec::Bound::Work);
}

/// Many lanes on as many cores, at the real lane rule, run one after
/// another: the step takes its parallel forms (`physics::wide`).
struct Wide;

impl ballpit::physics::Exec for Wide {
    fn lanes(&self) -> usize {
        64
    }
    fn cores(&self) -> usize {
        64
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        (0..64).rev().for_each(f);
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        b();
        a();
    }
}

/// At 100 000 spheres every parallel form of the step runs at its real
/// size, and gives the serial forms' bits.
#[test]
fn the_parallel_forms_give_the_serial_bits_at_100k() {
    let n = 100_000;
    let radius = (0.05 / (n as f64 * 4.0 / 3.0 * std::f64::consts::PI)).cbrt();
    let world = build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        speed: Some(0.5),
        seed: Some(7),
        ..SceneSpec::default()
    })
    .unwrap();
    let mut reference = world.clone();
    ModelKind::Swept
        .build()
        .advance(&mut reference, DT, 2, &Serial);
    let (e0, e1) = (world.kinetic_energy(), reference.kinetic_energy());
    assert!((e1 - e0).abs() <= 1e-9 * e0, "energy {e0} -> {e1}");
    assert_eq!(reference.escaped(), 0);
    assert!(reference.counters.sphere_collisions > 1000);
    for lanes in [&Wide as &dyn ballpit::physics::Exec, &Lanes(3)] {
        let mut got = world.clone();
        ModelKind::Swept.build().advance(&mut got, DT, 2, lanes);
        assert!(
            bits(&got) == bits(&reference),
            "{} lanes differ",
            lanes.lanes()
        );
    }
}
