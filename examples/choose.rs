//! How long `auto`'s choice takes: one pass over the spheres (`Summary`),
//! `swept`'s parts for the scene, and the choice itself, as `Auto` runs them
//! when the scene or the settings change (never on an unchanged frame).
//!
//! `cargo run --release --example choose -- [count] [packing] [repeats]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::physics::auto::{Ask, Summary, Tolerance, choose};
use ballpit::physics::sphere::volume;
use ballpit::physics::swept;
use ballpit::scene::{SceneSpec, build_world};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let n: usize = arg(0, "1000000").parse().expect("count");
    let phi: f64 = arg(1, "0.05").parse().expect("packing");
    let repeats: usize = arg(2, "21").parse().expect("repeats");
    let radius = (phi / (n as f64 * volume(1.0))).cbrt();
    let world = build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        ..Default::default()
    })
    .expect("scene");
    let dt = 1.0 / 60.0;
    let mut times: Vec<f64> = (0..repeats)
        .map(|_| {
            let t0 = Instant::now();
            let summary = Summary::of(&world);
            let ask = Ask {
                dt,
                frame: 1,
                tol: Tolerance::EXACT,
                parts: swept::parts(&world.spheres, world.size, dt),
                floor: 0,
                readouts: true,
            };
            let c = choose(&summary, ask);
            let secs = t0.elapsed().as_secs_f64();
            std::hint::black_box(c);
            secs
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!(
        "choose at n={n} packing={phi}: median {:.3} ms, min {:.3} ms, max {:.3} ms over {repeats}",
        times[repeats / 2] * 1e3,
        times[0] * 1e3,
        times[repeats - 1] * 1e3
    );
}
