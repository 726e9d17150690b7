//! `auto`'s cost on random scenes: for each scene, every model and `auto`
//! run the same simulated time on one thread with the overlap read every
//! step (as the engine reads it); the cheapest model that keeps the
//! tolerance is the base, and `auto`'s CPU seconds over it is the ratio.
//! Prints a line a scene and the worst and median ratio.
//!
//! `cargo run --release --example auto_sweep -- [scenes] [sim_seconds] [seed]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
#[path = "../tests/common/random_scene.rs"]
mod random_scene;

use ballpit::physics::auto::Tolerance;
use ballpit::physics::{ModelKind, Serial, World};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// CPU seconds, deepest overlap (of the smaller radius), sphere collisions
/// and capped steps of `kind` on `world` for `steps` steps of `dt`.
fn run(world: &World, kind: ModelKind, dt: f64, steps: u64) -> (f64, f64, u64, u64, String) {
    let mut model = kind.build();
    let mut w = world.clone();
    let mut deepest: f64 = 0.0;
    let cpu = cpu_time::ThreadTime::now();
    for _ in 0..steps {
        model.advance(&mut w, dt, 1, &Serial);
        let read = model.max_overlap_rel(&w, dt, &Serial);
        let d = read.unwrap_or_else(|| w.max_overlap_rel());
        model.overlap_read(d);
        deepest = deepest.max(d);
    }
    let secs = cpu.elapsed().as_secs_f64();
    let ran = model
        .choice()
        .map_or_else(|| kind.name().to_string(), |c| c.model.name().to_string());
    let c = w.counters;
    (secs, deepest, c.sphere_collisions, c.capped_steps, ran)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let scenes: usize = arg(0, "50").parse().expect("scenes");
    let sim: f64 = arg(1, "0.1").parse().expect("sim seconds");
    let seed: u64 = arg(2, "26").parse().expect("seed");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let dts = [1.0 / 15.0, 1.0 / 60.0, 1.0 / 1920.0];
    let mut ratios = Vec::new();
    for case in 0..scenes {
        let n = (100.0 * 1000f64.powf(rng.random_range(0.0..1.0))) as usize;
        let packing = 0.001 * 450f64.powf(rng.random_range(0.0..1.0));
        let speed = 0.01 * 2000f64.powf(rng.random_range(0.0..1.0));
        let spread = 100f64.powf(rng.random_range(0.0..1.0));
        let dt = dts[rng.random_range(0..dts.len())];
        let t = [0.0, 0.01, 0.1][rng.random_range(0..3)];
        let world = random_scene::random_scene(&mut rng, n, packing, spread, speed);
        let steps = ((sim / dt).round() as u64).max(1);
        let tol = Tolerance::new(t).expect("tolerance");
        let exact = run(&world, ModelKind::Exact, dt, steps);
        let mut kept = Vec::new();
        for kind in [ModelKind::Discrete, ModelKind::Swept, ModelKind::Exact] {
            let r = if kind == ModelKind::Exact {
                exact.clone()
            } else {
                run(&world, kind, dt, steps)
            };
            // Only `discrete` misses contacts; the others' counts part from
            // exact's by chaos, not by misses.
            let missed = if kind == ModelKind::Discrete && exact.2 > 0 {
                1.0 - r.2 as f64 / exact.2 as f64
            } else {
                0.0
            };
            if r.1 <= t + 1e-12 && r.3 == 0 && missed.abs() <= t.max(1e-12) {
                kept.push((r.0, kind));
            }
        }
        let auto = run(&world, ModelKind::Auto(tol), dt, steps);
        let best = kept
            .iter()
            .copied()
            .fold(None, |b: Option<(f64, ModelKind)>, k| match b {
                Some(b) if b.0 <= k.0 => Some(b),
                _ => Some(k),
            });
        let kept_t = auto.1 <= t + 1e-12;
        match best {
            Some((cpu, kind)) => {
                let ratio = auto.0 / cpu;
                ratios.push(ratio);
                println!(
                    "{case:2} n {n:6} packing {packing:.3} speed {speed:6.2} spread {spread:5.1} dt 1/{:.0} T {t}: auto ran {} {:.3}s, cheapest keeping T {} {:.3}s, ratio {ratio:.2}, auto kept T {kept_t}",
                    1.0 / dt,
                    auto.4,
                    auto.0,
                    kind.name(),
                    cpu
                );
            }
            None => println!(
                "{case:2} n {n:6} packing {packing:.3} speed {speed:6.2} dt 1/{:.0} T {t}: no model kept T; auto ran {}, kept T {kept_t}",
                1.0 / dt,
                auto.4
            ),
        }
    }
    ratios.sort_by(f64::total_cmp);
    if let (Some(worst), Some(mid)) = (ratios.last(), ratios.get(ratios.len() / 2)) {
        let over = ratios.iter().filter(|&&r| r > 1.25).count();
        println!(
            "{} scenes compared: median ratio {mid:.2}, worst {worst:.2}, {over} above 1.25",
            ratios.len()
        );
    }
}
