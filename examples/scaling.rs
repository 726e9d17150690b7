//! The ratio of the step times at 100 000 and 10 000 spheres, with the same
//! spheres (the `same_spheres` group of `cargo bench --bench physics`: the
//! 10k scene's radius and speed, the box grown to keep packing 0.005), one
//! thread, `swept`. On a shared host the memory-bound 100k step varies by
//! ±10 % from minute to minute, so the two sizes are timed in turns, in the
//! same minutes: blocks of steps alternate, and each block's first step
//! (caches cold after the other scene) is not timed.
//!
//! `cargo run --release --example scaling -- [rounds] [sorted]`
//!
//! With `sorted`, both worlds are sorted in space (by cell of the 10k
//! scene's grid, z then y then x) before every block, outside the timing:
//! how much a world kept in spatial order for free would buy. The model
//! itself never reorders the world (the screen, the CSV and the model
//! comparisons read spheres by index).
use ballpit::physics::sphere::volume;
use ballpit::physics::{ModelKind, Serial, World};
use ballpit::scene::{SceneSpec, build_world};
use std::time::{Duration, Instant};

const SMALL: usize = 10_000;
const PACKING: f64 = 0.005;
const DT: f64 = 1.0 / 60.0;

fn scene(n: usize) -> World {
    let radius = (PACKING / (SMALL as f64 * volume(1.0))).cbrt();
    build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        speed: Some(0.5),
        size: Some((n as f64 / SMALL as f64).cbrt()),
        seed: Some(7),
        ..Default::default()
    })
    .expect("scene")
}

/// Sorts the spheres by the raster index of their cell of side `cell`.
fn sort_in_space(world: &mut World, cell: f64) {
    let side = (world.size / cell).ceil() as u64;
    let c = |x: f64| ((x / cell) as u64).min(side - 1);
    world
        .spheres
        .sort_by_key(|s| (c(s.pos.z) * side + c(s.pos.y)) * side + c(s.pos.x));
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sorted = args.iter().any(|a| a == "sorted");
    let rounds: usize = args
        .iter()
        .find(|a| *a != "sorted")
        .map_or(20, |r| r.parse().expect("rounds"));
    // The first level's cell at 10k (4 cells a sphere, 35 a side), the
    // same at 100k: about the same cell in both worlds.
    let cell = 1.0 / 35.0;
    // (spheres, timed steps per block): about the same time per block.
    let sizes = [(SMALL, 20u64), (10 * SMALL, 2)];
    let mut runs: Vec<_> = sizes
        .iter()
        .map(|&(n, steps)| (scene(n), ModelKind::Swept.build(), steps, Duration::ZERO))
        .collect();
    for _ in 0..rounds {
        for (world, model, steps, spent) in &mut runs {
            if sorted {
                sort_in_space(world, cell);
                model.invalidate();
            }
            model.advance(world, DT, 1, &Serial);
            let start = Instant::now();
            model.advance(world, DT, *steps, &Serial);
            *spent += start.elapsed();
        }
    }
    let per_step: Vec<f64> = runs
        .iter()
        .map(|(_, _, steps, spent)| spent.as_secs_f64() / (*steps * rounds as u64) as f64)
        .collect();
    for (&(n, _), t) in sizes.iter().zip(&per_step) {
        println!(
            "{n} spheres: {:.1} us a step, {:.2} M sphere-steps/s",
            t * 1e6,
            n as f64 / t / 1e6
        );
    }
    println!("100k step / 10k step: {:.2}x", per_step[1] / per_step[0]);
}
