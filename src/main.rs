#![forbid(unsafe_code)]
//! Temporary entry point for the TUI branch: a small gas scene on the screen.
//! The CLI on main replaces this; its change here is the `tui::run` call.
use ballpit::engine::{Settings, Threading};
use ballpit::physics::{ModelKind, Sphere, World};
use glam::DVec3;
use rand::{Rng, SeedableRng};

fn lattice_world(n: usize, radius: f64, speed: f64, seed: u64) -> World {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let side = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / side as f64;
    let slack = (cell / 2.0 - radius).max(0.0);
    let mut spheres = Vec::with_capacity(n);
    'fill: for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                if spheres.len() == n {
                    break 'fill;
                }
                let mut c =
                    DVec3::new(i as f64, j as f64, k as f64) * cell + DVec3::splat(cell / 2.0);
                for a in 0..3 {
                    c[a] += rng.random_range(-slack..=slack);
                }
                let dir = loop {
                    let v = DVec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    );
                    let l = v.length();
                    if l > 1e-3 && l <= 1.0 {
                        break v / l;
                    }
                };
                spheres.push(Sphere::new(c, dir * speed, radius));
            }
        }
    }
    World::new(1.0, spheres)
}

fn main() {
    let mut opts = ballpit::tui::Options::default();
    let mut count = 1000;
    let mut tick = 1;
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        match (pair[0].as_str(), pair.get(1)) {
            ("--fps", Some(v)) => opts.fps = v.parse().unwrap_or(f64::NAN),
            ("--count", Some(v)) => count = v.parse().unwrap_or(1000),
            ("--tick", Some(v)) => tick = v.parse().unwrap_or(1),
            ("--color", Some(v)) => opts.color = v.parse().unwrap_or_default(),
            _ => {}
        }
    }
    let world = lattice_world(count, 0.02f64.min(0.4 / (count as f64).cbrt()), 0.5, 1);
    let settings = Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick,
        threading: Threading::Off,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    if let Err(e) = ballpit::tui::run(world, settings, opts) {
        eprintln!("ballpit: {e:#}");
        let bad = e.downcast_ref::<ballpit::error::BadInput>().is_some();
        std::process::exit(if bad { 2 } else { 1 });
    }
}
