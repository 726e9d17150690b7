//! Any way of cutting the work gives the same bits: lanes run in any order,
//! functional (split) or data (pool) decomposition.
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
        (0..self.lanes).rev().for_each(f)
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
