//! Runs one model serially on a gas at a given size and packing and prints
//! sphere-steps per second: a small target for profilers (callgrind counts
//! the instructions of a step as the difference of two step counts).
//!
//! `cargo run --release --example step -- swept 10000 0.005 200 [speed] [threads|sK] [box] [parts]`
//!
//! `parts` (swept only): cut every step into that many parts instead of
//! the number the scene calls for (0: that number).
//!
//! `sorted` (1: yes): renumber the spheres in space (cell by cell of a grid
//! of about one sphere a cell, untimed) before the run, to measure what a
//! world kept in spatial order would gain. Not the same results.
//!
//! Prints the rate by the clock and the thread's CPU nanoseconds per
//! sphere-step (on a shared host, the CPU time is the steadier one).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::physics::sphere::volume;
use ballpit::physics::swept::Swept;
use ballpit::physics::{Exec, Model, ModelKind, Serial};
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
    // The box (default 1): with the speed in absolute units, a bigger box at
    // the same packing keeps the spheres and their motion as they are.
    let size: f64 = arg(6, "1").parse().expect("box");
    let radius = (phi * size.powi(3) / (n as f64 * volume(1.0))).cbrt();
    let mut world = build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        speed: Some(speed),
        seed: Some(7),
        size: Some(size),
        ..Default::default()
    })
    .expect("scene");
    // `s2`: two lanes taken one after the other on this thread, for
    // counting what a step hands its lanes (`*run_lanes*` in callgrind)
    // against what it runs alone.
    let lanes_arg = arg(5, "1");
    let (threads, sequential) = match lanes_arg.strip_prefix('s') {
        Some(k) => (k.parse().expect("lanes"), true),
        None => (lanes_arg.parse().expect("threads"), false),
    };
    let pool = (threads > 1 && !sequential)
        .then(|| ballpit::engine::PoolExec::new(threads).expect("pool"));
    let one_by_one = SequentialLanes(threads);
    let exec: &dyn Exec = match &pool {
        Some(p) => p,
        None if sequential => &one_by_one,
        None => &Serial,
    };
    let parts: u32 = arg(7, "0").parse().expect("parts");
    if arg(8, "0") == "1" {
        sort_in_space(&mut world.spheres, size);
    }
    let mut m: Box<dyn Model> = match (model, parts) {
        (ModelKind::Swept, k @ 1..) => Box::new(Swept::default().fixed_parts(Some(k))),
        _ => model.build(),
    };
    let start = Instant::now();
    let cpu = cpu_time::ThreadTime::now();
    exec.host(&mut || m.advance(&mut world, 1.0 / 60.0, steps, exec));
    let cpu_ns = cpu.elapsed().as_secs_f64() * 1e9 / (n as u64 * steps).max(1) as f64;
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{model} n={n} packing={phi} steps={steps} threads={threads}: {:.2} M sphere-steps/s, {} contacts, {} wall hits, {} parts (last step), {cpu_ns:.1} CPU ns per sphere-step",
        (n as u64 * steps) as f64 / secs / 1e6,
        world.counters.sphere_collisions,
        world.counters.wall_collisions,
        m.last_parts()
    );
}

/// Spheres in the order of the cells of their centres (z, then y, then x).
fn sort_in_space(spheres: &mut [ballpit::physics::Sphere], size: f64) {
    let side = (spheres.len() as f64).cbrt().ceil().max(1.0);
    let cell = |x: f64| ((x / size * side) as u64).min(side as u64 - 1);
    let key = |s: &ballpit::physics::Sphere| {
        let side = side as u64;
        (cell(s.pos.z) * side + cell(s.pos.y)) * side + cell(s.pos.x)
    };
    spheres.sort_by_cached_key(key);
}

/// Lanes run one after the other on the calling thread. A section the lane
/// rule gives one lane runs as `f(0)`, as the pool runs it; one of more
/// lanes goes through `run_lanes`, so callgrind's
/// `--toggle-collect='*run_lanes*'` counts what a pool would share.
struct SequentialLanes(usize);

impl SequentialLanes {
    #[inline(never)]
    fn run_lanes(lanes: usize, f: &(dyn Fn(usize) + Sync)) {
        (0..lanes).for_each(f);
    }
    /// A section the lane rule keeps on one lane (`*one_lane*` in callgrind).
    #[inline(never)]
    fn one_lane(f: &(dyn Fn(usize) + Sync)) {
        f(0);
    }
}

impl Exec for SequentialLanes {
    fn lanes(&self) -> usize {
        self.0
    }
    fn cores(&self) -> usize {
        self.0
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        self.for_lanes(self.0, f);
    }
    fn for_lanes(&self, lanes: usize, f: &(dyn Fn(usize) + Sync)) {
        if lanes <= 1 {
            Self::one_lane(f);
        } else {
            Self::run_lanes(lanes.min(self.0), f);
        }
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        a();
        b();
    }
}
