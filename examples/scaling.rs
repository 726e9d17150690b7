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
//! `cargo run --release --example scaling -- table [rounds] [max N] [model ...]`:
//! each model (default all three) at 10k, 100k and 1M spheres (up to
//! `max N`), packing 0.005 and 0.1, and 0.4 for `exact` (the radius set by
//! N, the box 1, seed 5, as `ballpit bench --count N --radius R --seed 5`).
//! Per size: the time to load the spheres (the first advance, a step of
//! 1e-9 s), `exact`'s heap bytes per sphere, the peak resident bytes per
//! sphere of a process that builds the scene and runs two steps (a child
//! process per size, less what it held before the scene), then blocks of steps (`exact`: 2 ms, 100
//! at 10k, 10 at 100k, 1 at 1M; the others: 1/60 s, 20, 2 and 1) timed in
//! alternation between the sizes: ns per sphere-step, events per second
//! (`exact`: collisions, crossings, walls, relists, stale; the others:
//! sphere and wall contacts) and sphere collisions per CPU second (issue
//! 31's table), each against 10k's.
//! `exact [rounds] [max N]` is the table of `exact` alone.
//! `exact-one N packing steps [dt]` runs one size only (for callgrind).
//! (`exact-renumber` and `exact-queues`, which compared `exact` with its
//! spheres relabelled as they drift and over other event queues, went with
//! those experiments: docs/perf-log.md, 2026-12-07.)
//!
//! With `sorted`, both worlds are sorted in space (by cell of the 10k
//! scene's grid, z then y then x) before every block, outside the timing:
//! how much a world kept in spatial order for free would buy. The model
//! itself never reorders the world (the screen, the CSV and the model
//! comparisons read spheres by index).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::cpu::{current_tid, thread_cpu_seconds_of};
use ballpit::physics::exact::{EventStats, Exact};
use ballpit::physics::sphere::volume;
use ballpit::physics::{Model, ModelKind, Serial, World};
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

/// The exact benchmark's scene: `n` spheres filling `packing` of the unit box.
fn exact_scene(n: usize, packing: f64) -> World {
    let radius = (packing / (n as f64 * volume(1.0))).cbrt();
    build_world(&SceneSpec {
        count: Some(n),
        radius: Some(radius),
        seed: Some(5),
        ..Default::default()
    })
    .expect("scene")
}

/// The exact runs' step: about 400 events at 10k spheres, packing 0.005.
const DT_EXACT: f64 = 2e-3;

fn events(s: &EventStats) -> u64 {
    s.pairs + s.stale + s.walls + s.relists + s.crossings
}

fn exact_one(args: &[String]) {
    let num = |k: usize| args.get(k).and_then(|a| a.parse::<f64>().ok());
    let (n, packing, steps) = (
        num(0).expect("N") as usize,
        num(1).expect("packing"),
        num(2).expect("steps") as u64,
    );
    let empty = status_kib("VmRSS");
    let mut world = exact_scene(n, packing);
    let (scene_peak, scene_rss) = (status_kib("VmHWM"), status_kib("VmRSS"));
    let mut model = Exact::default();
    let start = Instant::now();
    model.advance(&mut world, 1e-9, 1, &Serial);
    let load = start.elapsed();
    let e0 = events(&model.stats);
    let start = Instant::now();
    // By default a step holds about 400 events whatever N (packing 0.005).
    let dt = num(3).unwrap_or(1e-3 * 10_000.0 / n as f64);
    model.advance(&mut world, dt, steps, &Serial);
    let secs = start.elapsed().as_secs_f64();
    let ev = events(&model.stats) - e0;
    let per = |kib: u64| (kib.saturating_sub(empty) * 1024) as f64 / n.max(1) as f64;
    println!(
        "{n} spheres, packing {packing}: load {:.3} s, model heap {} bytes a sphere; \
         RSS a sphere: {:.0} after the scene (peak {:.0}), {:.0} after the steps (peak {:.0}); \
         {ev} events, {:.3} M/s ({:?})",
        load.as_secs_f64(),
        model.heap_bytes() / n.max(1),
        per(scene_rss),
        per(scene_peak),
        per(status_kib("VmRSS")),
        per(status_kib("VmHWM")),
        ev as f64 / secs / 1e6,
        model.stats
    );
}

/// A `kB` field of /proc/self/status (0 where there is none).
fn status_kib(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|t| {
            let line = t.lines().find(|l| l.starts_with(field))?.to_owned();
            line.split_whitespace().nth(1)?.parse().ok()
        })
        .unwrap_or(0)
}

/// The model a size runs: `exact` concretely, for its event counts and heap.
enum Held {
    Exact(Box<Exact>),
    Other(Box<dyn Model>),
}

impl Held {
    fn new(kind: ModelKind) -> Held {
        match kind {
            ModelKind::Exact => Held::Exact(Box::default()),
            other => Held::Other(other.build()),
        }
    }

    fn model(&mut self) -> &mut dyn Model {
        match self {
            Held::Exact(m) => &mut **m,
            Held::Other(m) => &mut **m,
        }
    }

    /// Events so far: `exact`'s every kind (contacts, crossings, walls,
    /// relists, stale), the others' contacts (sphere and wall).
    fn events(&self, world: &World) -> u64 {
        match self {
            Held::Exact(m) => events(&m.stats),
            Held::Other(_) => world.counters.sphere_collisions + world.counters.wall_collisions,
        }
    }
}

/// One size of a model's runs and what its timed blocks add up to.
struct Run {
    n: usize,
    world: World,
    model: Held,
    /// Steps a timed block.
    block: u64,
    load: f64,
    /// `exact`'s own heap a sphere (`None` for the others).
    heap: Option<f64>,
    /// Peak resident memory a sphere of a process that builds the scene
    /// and runs two steps, less the process before it built anything.
    peak: f64,
    spent: Duration,
    events: u64,
    steps: u64,
    /// CPU seconds of the timed blocks (this thread's), and the sphere
    /// collisions in them: the issue-31 table's rate.
    cpu: f64,
    collisions: u64,
}

/// `table [rounds] [max N] [model ...]` (and `exact ...`, the
/// same for `exact` alone): per model and packing, the sizes 10k, 100k
/// and 1M timed in alternation.
fn table(args: &[String], default_models: &[ModelKind]) {
    let rounds: usize = args.first().map_or(5, |r| r.parse().expect("rounds"));
    let max: usize = args.get(1).map_or(1_000_000, |m| m.parse().expect("max N"));
    let mut models: Vec<ModelKind> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if models.is_empty() {
        models = default_models.to_vec();
    }
    let sizes: Vec<usize> = [10_000, 100_000, 1_000_000]
        .into_iter()
        .filter(|&n| n <= max)
        .collect();
    for kind in models {
        // `exact` takes 2 ms steps (thousands of events each at 10k); the
        // per-step models the screen's 1/60 s.
        let (dt, work, packings): (f64, u64, &[f64]) = match kind {
            ModelKind::Exact => (DT_EXACT, 1_000_000, &[0.005, 0.1, 0.4]),
            _ => (DT, 200_000, &[0.005, 0.1]),
        };
        for &packing in packings {
            let runs = build_runs(kind, &sizes, packing, work);
            time_runs(runs, rounds, dt, kind, packing);
        }
    }
}

fn build_runs(kind: ModelKind, sizes: &[usize], packing: f64, work: u64) -> Vec<Run> {
    let mut runs = Vec::new();
    for &n in sizes {
        let peak = peak_bytes(kind, n, packing);
        let mut world = exact_scene(n, packing);
        let mut model = Held::new(kind);
        let start = Instant::now();
        model.model().advance(&mut world, 1e-9, 1, &Serial);
        let load = start.elapsed().as_secs_f64();
        let heap = match &model {
            Held::Exact(m) => Some(m.heap_bytes() as f64 / n as f64),
            Held::Other(_) => None,
        };
        runs.push(Run {
            n,
            world,
            model,
            // The same dt at every size, so the per-step work outside
            // the event loop (checking and writing back the world,
            // linear in N) stays a small share; fewer steps as N grows.
            block: (work / n as u64).max(1),
            load,
            heap,
            peak,
            spent: Duration::ZERO,
            events: 0,
            steps: 0,
            cpu: 0.0,
            collisions: 0,
        });
    }
    runs
}

/// The peak resident bytes a sphere of `n` spheres under `kind`, in a
/// child process (`peak MODEL N PACKING`) so that no other size's memory
/// counts: its peak less what it held before building the scene.
fn peak_bytes(kind: ModelKind, n: usize, packing: f64) -> f64 {
    let out = std::process::Command::new(std::env::current_exe().expect("this example"))
        .args(["peak", kind.name(), &n.to_string(), &packing.to_string()])
        .output()
        .expect("the peak run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .trim()
        .parse()
        .expect("bytes")
}

/// The child of [`peak_bytes`]: the scene, the model's load and two steps.
fn peak(args: &[String]) {
    let kind: ModelKind = args[0].parse().expect("model");
    let n: usize = args[1].parse().expect("N");
    let packing: f64 = args[2].parse().expect("packing");
    let before = status_kib("VmHWM:");
    let mut world = exact_scene(n, packing);
    let mut model = Held::new(kind);
    let dt = if kind == ModelKind::Exact {
        DT_EXACT
    } else {
        DT
    };
    model.model().advance(&mut world, 1e-9, 1, &Serial);
    model.model().advance(&mut world, dt, 2, &Serial);
    let grown = status_kib("VmHWM:").saturating_sub(before);
    println!("{}", grown as f64 * 1024.0 / n as f64);
}

/// CPU seconds this thread has run (exact: from the scheduler's count).
fn cpu_now() -> f64 {
    current_tid()
        .and_then(thread_cpu_seconds_of)
        .expect("this thread's CPU time")
}

fn time_runs(mut runs: Vec<Run>, rounds: usize, dt: f64, kind: ModelKind, packing: f64) {
    for _ in 0..rounds {
        for r in &mut runs {
            // Untimed: the caches after the other sizes.
            r.model.model().advance(&mut r.world, dt, 1, &Serial);
            let (e0, c0) = (r.model.events(&r.world), r.world.counters.sphere_collisions);
            let (start, cpu) = (Instant::now(), cpu_now());
            r.model.model().advance(&mut r.world, dt, r.block, &Serial);
            r.cpu += cpu_now() - cpu;
            r.spent += start.elapsed();
            r.events += r.model.events(&r.world) - e0;
            r.collisions += r.world.counters.sphere_collisions - c0;
            r.steps += r.block;
        }
    }
    let per_cpu = |r: &Run| r.collisions as f64 / r.cpu;
    let rate = |r: &Run| r.events as f64 / r.spent.as_secs_f64();
    let ns = |r: &Run| r.spent.as_secs_f64() / (r.steps as f64 * r.n as f64) * 1e9;
    let (base_rate, base_ns) = (rate(&runs[0]), ns(&runs[0]));
    for r in &runs {
        let heap = r.heap.map_or(String::new(), |h| {
            format!("{h:.0} model heap bytes a sphere, ")
        });
        println!(
            "{kind} packing {packing} N {}: load {:.3} s, {heap}{:.0} peak bytes a sphere, \
             {:.0} ns a sphere-step (this / 10k: {:.2}), {:.3} M events/s (10k rate / this: {:.2}), \
             {:.4} M sphere collisions per CPU second (10k / this: {:.2}), {} events, escaped {}",
            r.n,
            r.load,
            r.peak,
            ns(r),
            ns(r) / base_ns,
            rate(r) / 1e6,
            base_rate / rate(r),
            per_cpu(r) / 1e6,
            per_cpu(&runs[0]) / per_cpu(r),
            r.events,
            r.world.escaped()
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("exact") => return table(&args[1..], &[ModelKind::Exact]),
        Some("table") => return table(&args[1..], &ModelKind::ALL),
        Some("peak") => return peak(&args[1..]),
        Some("exact-one") => return exact_one(&args[1..]),
        _ => {}
    }
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
                world.touch();
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
