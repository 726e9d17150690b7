//! A preset scene run by `swept` with its steps whole, cut into the parts
//! the scene calls for, or into K parts: sphere-steps per second, the
//! contacts taken (the same in every case, up to rounding's drift over
//! many steps), and the parts of the last step. Peak memory is the
//! process's: run it under `/usr/bin/time -v`.
//!
//! `cargo run --release --example parts -- projectiles 3000 5 [whole|auto|K] [radius]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::physics::swept::Swept;
use ballpit::physics::{Model, Serial};
use ballpit::scene::{SceneSpec, build_world};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let scene = arg(0, "projectiles");
    let count: usize = arg(1, "3000").parse().expect("count");
    let steps: u64 = arg(2, "5").parse().expect("steps");
    let parts = match arg(3, "auto").as_str() {
        "auto" => None,
        "whole" => Some(1),
        k => Some(k.parse().expect("parts: whole, auto or a number")),
    };
    let radius = args.get(4).map(|r| r.parse().expect("radius"));
    let mut world = build_world(&SceneSpec {
        scene: Some(scene.clone()),
        count: Some(count),
        radius,
        seed: Some(7),
        ..Default::default()
    })
    .expect("scene");
    let mut model = Swept::default().fixed_parts(parts);
    let start = Instant::now();
    model.advance(&mut world, 1.0 / 60.0, steps, &Serial);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{scene} n={count} steps={steps} parts={}: {:.3} M sphere-steps/s, {:.4} ms a step, {} contacts, {} wall hits",
        model.last_parts(),
        (count as u64 * steps) as f64 / secs / 1e6,
        secs / steps as f64 * 1e3,
        world.counters.sphere_collisions,
        world.counters.wall_collisions
    );
}
