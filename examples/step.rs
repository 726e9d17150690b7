//! Runs one model serially on a gas at a given size and packing and prints
//! sphere-steps per second: a small target for profilers (callgrind counts
//! the instructions of a step as the difference of two step counts).
//!
//! `cargo run --release --example step -- swept 10000 0.005 200`
use ballpit::physics::sphere::volume;
use ballpit::physics::{ModelKind, Serial};
use ballpit::scene::{SceneSpec, build_world};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let model: ModelKind = arg(0, "swept").parse().expect("model");
    let n: usize = arg(1, "10000").parse().expect("count");
    let phi: f64 = arg(2, "0.005").parse().expect("packing");
    let steps: u64 = arg(3, "200").parse().expect("steps");
    let speed: f64 = arg(4, "0.5").parse().expect("speed");
    let radius = (phi / (n as f64 * volume(1.0))).cbrt();
    let mut world = build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        speed: Some(speed),
        seed: Some(7),
        ..Default::default()
    })
    .expect("scene");
    let threads: usize = arg(5, "1").parse().expect("threads");
    let pool = (threads > 1).then(|| ballpit::engine::PoolExec::new(threads).expect("pool"));
    let exec: &dyn ballpit::physics::Exec = match &pool {
        Some(p) => p,
        None => &Serial,
    };
    let mut m = model.build();
    let start = Instant::now();
    m.advance(&mut world, 1.0 / 60.0, steps, exec);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{model} n={n} packing={phi} steps={steps} threads={threads}: {:.2} M sphere-steps/s, {} contacts, {} wall hits",
        (n as u64 * steps) as f64 / secs / 1e6,
        world.counters.sphere_collisions,
        world.counters.wall_collisions
    );
}
