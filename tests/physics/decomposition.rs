//! Any way of cutting the work gives the same bits: lanes run in any order,
//! functional (split) or data (pool) decomposition.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::{Exec, ModelKind, Serial, World};
use ballpit::scene::{SceneSpec, build_world};

/// Runs lanes one after another, last first, to shake out any dependence on
/// lane count or order without threads.
struct Shuffled {
    lanes: usize,
    functional: bool,
}

impl Exec for Shuffled {
    fn lanes(&self) -> usize {
        self.lanes
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        (0..self.lanes).rev().for_each(f);
    }
    fn lane_cost(&self) -> usize {
        1
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        b();
        a();
    }
    fn functional(&self) -> bool {
        self.functional
    }
}

fn run(world: &World, model: ModelKind, exec: &dyn Exec) -> World {
    let mut w = world.clone();
    model.build().advance(&mut w, 1.0 / 60.0, 25, exec);
    w
}

#[test]
fn every_decomposition_gives_identical_bits() {
    for (scene, count) in [
        ("gas", 3000),
        ("dense", 2000),
        ("mixed", 300),
        ("projectiles", 200),
    ] {
        let world = build_world(&SceneSpec {
            scene: Some(scene.into()),
            count: Some(count),
            ..Default::default()
        })
        .unwrap();
        for model in ModelKind::ALL {
            let reference = run(&world, model, &Serial);
            assert!(reference.counters.sphere_collisions > 0, "{scene} {model}");
            for lanes in [1, 2, 3, 7] {
                for functional in [false, true] {
                    let got = run(&world, model, &Shuffled { lanes, functional });
                    assert_eq!(
                        got, reference,
                        "{scene} {model} lanes={lanes} functional={functional}"
                    );
                }
            }
        }
    }
}

/// Past 32 768 spheres a lane sorts its spheres into cells by placing
/// indices and copying the records after; with more lanes each has fewer
/// and places the records directly. Both must give the same grid, so the
/// same bits.
#[test]
fn a_large_grid_sorts_the_same_either_way() {
    let world = build_world(&SceneSpec {
        count: Some(40_000),
        radius: Some(0.003),
        seed: Some(11),
        ..Default::default()
    })
    .unwrap();
    let reference = run_steps(&world, ModelKind::Swept, &Serial, 4);
    assert!(reference.counters.sphere_collisions > 100);
    assert!(reference.counters.wall_collisions > 100);
    for lanes in [2, 3] {
        let got = run_steps(
            &world,
            ModelKind::Swept,
            &Shuffled {
                lanes,
                functional: false,
            },
            4,
        );
        assert_eq!(got, reference, "lanes={lanes}");
    }
}

fn run_steps(world: &World, model: ModelKind, exec: &dyn Exec, steps: u64) -> World {
    let mut w = world.clone();
    model.build().advance(&mut w, 1.0 / 60.0, steps, exec);
    w
}
