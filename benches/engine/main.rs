//! Engine benchmarks: `pool` against `off` on a big `swept` scene (with the
//! share of a step that can run in parallel at all), `split` against
//! `pool`, and the frames per second pipelining buys `worker` when drawing
//! costs about as much as the physics.
//!
//! `cargo bench --bench engine` (criterion; a phase breakdown is printed
//! first).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::cpu::CpuReport;
use ballpit::engine::{Engine, Settings, Snapshot, Threading};
use ballpit::physics::{Exec, ModelKind, Sphere, World};
use ballpit::tui::backend::{Counting, Lean};
use ballpit::tui::canvas::Raster;
use ballpit::tui::layout::{self, View};
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use criterion::{Criterion, SamplingMode};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use ratatui::layout::Rect;
use ratatui::{Terminal, TerminalOptions, Viewport};
use std::hint::black_box;
use std::time::{Duration, Instant};

mod phases;

use phases::phases;

const DT: f64 = 1.0 / 60.0;

/// `n` spheres of radius `r` on a jittered lattice, random velocities.
fn scene(n: usize, r: f64, speed: f64, seed: u64) -> World {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let m = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / m as f64;
    assert!(r < 0.5 * cell);
    let room = 0.5 * cell - r;
    let mut u = |a: f64| rng.random_range(-a..=a);
    let spheres = (0..n)
        .map(|i| {
            let c = DVec3::new((i % m) as f64, ((i / m) % m) as f64, (i / (m * m)) as f64);
            let p = (c + 0.5) * cell + DVec3::new(u(room), u(room), u(room));
            let v = DVec3::new(u(1.0), u(1.0), u(1.0)) * speed;
            Sphere::new(p, v, r)
        })
        .collect();
    World::new(1.0, spheres)
}

fn settings(threading: Threading, threads: usize, tick: u32) -> Settings {
    Settings {
        model: ModelKind::Swept,
        dt: DT,
        tick,
        threading,
        threads,
    }
}

/// CPU seconds the calling thread has run (its CPU clock, exact to the
/// nanosecond): unlike wall time, not inflated when other processes take
/// the core.
fn cpu_now() -> f64 {
    cpu_time::ThreadTime::now().as_duration().as_secs_f64()
}

/// The calling thread's CPU seconds per call of `f`, over `calls` calls.
fn cpu_per_call(calls: usize, mut f: impl FnMut()) -> f64 {
    let t0 = cpu_now();
    for _ in 0..calls {
        f();
    }
    (cpu_now() - t0) / calls as f64
}

/// Stand-in for the TUI's drawing: rotate, project and plot every sphere
/// into a character canvas, `passes` times.
struct Render {
    canvas: Vec<u8>,
    passes: usize,
}

impl Render {
    const W: usize = 160;
    const H: usize = 96;

    fn draw(&mut self, snap: &Snapshot) -> u64 {
        let (s, c) = (0.6f64.sin(), 0.6f64.cos());
        let mut lit = 0u64;
        for pass in 0..self.passes {
            self.canvas.fill(b' ');
            let tilt = pass as f64 * 1e-3;
            for v in &snap.spheres {
                let [x, y, z] = v.pos.map(|q| f64::from(q) - 0.5 * snap.size);
                let (x, z) = (c * x + s * z, -s * x + c * z);
                let (y, z) = (y * (1.0 - tilt) + z * tilt, z);
                let k = 1.5 / (2.5 + z);
                let px = ((x * k + 0.5) * Self::W as f64) as isize;
                let py = ((y * k + 0.5) * Self::H as f64) as isize;
                if (0..Self::W as isize).contains(&px) && (0..Self::H as isize).contains(&py) {
                    let shade = (f64::from(v.speed) * 8.0).min(7.0) as u8;
                    self.canvas[py as usize * Self::W + px as usize] = b'0' + shade;
                }
            }
            lit += self.canvas.iter().filter(|&&b| b != b' ').count() as u64;
        }
        lit
    }
}

fn frame(e: &mut Engine, render: &mut Render) {
    e.start_frame().unwrap();
    black_box(render.draw(e.snapshot()));
    e.finish_frame().unwrap();
}

fn bench_pool(c: &mut Criterion, label: &str, world: &World) {
    let mut g = c.benchmark_group(format!("swept_100k_{label}_5_steps"));
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for (name, threading, k) in [
        ("off", Threading::Off, 1),
        ("pool1", Threading::Pool, 1),
        ("pool2", Threading::Pool, 2),
        ("split", Threading::Split, 2),
    ] {
        let mut e = Engine::new(world.clone(), settings(threading, k, 5)).unwrap();
        g.bench_function(name, |b| {
            b.iter(|| {
                e.start_frame().unwrap();
                black_box(e.finish_frame().unwrap().energy);
            });
        });
    }
    g.finish();
}

/// Wall and per-thread CPU time of `frames` frames of physics plus drawing.
fn pipeline_check(world: &World, threading: Threading, passes: usize, frames: usize) {
    let mut e = Engine::new(world.clone(), settings(threading, 1, 1)).unwrap();
    let mut render = Render {
        canvas: vec![b' '; Render::W * Render::H],
        passes,
    };
    frame(&mut e, &mut render);
    let tid = e.physics_tid().unwrap();
    let phys = || ballpit::cpu::thread_cpu_seconds_of(tid).unwrap();
    let (m0, p0, t0) = (cpu_now(), phys(), Instant::now());
    let mut physics_wall = 0.0;
    for _ in 0..frames {
        frame(&mut e, &mut render);
        physics_wall += e.snapshot().physics_seconds;
    }
    let wall = t0.elapsed().as_secs_f64();
    let f = frames as f64;
    eprintln!(
        "pipelining {threading}: {:.2} ms/frame wall; CPU per frame: main {:.2} ms, \
         physics thread {:.2} ms; physics step wall {:.2} ms/frame",
        wall / f * 1e3,
        (cpu_now() - m0) / f * 1e3,
        (phys() - p0) / f * 1e3,
        physics_wall / f * 1e3,
    );
}

/// Drawing passes that cost about what a frame's physics costs.
fn calibrate(world: &World) -> usize {
    let mut e = Engine::new(world.clone(), settings(Threading::Off, 1, 1)).unwrap();
    // CPU time, not wall: other processes on the machine must not skew it.
    let physics = cpu_per_call(20, || {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    });
    let mut one = Render {
        canvas: vec![b' '; Render::W * Render::H],
        passes: 200,
    };
    // One call of 200 passes.
    let pass = cpu_per_call(1, || {
        black_box(one.draw(e.snapshot()));
    }) / 200.0;
    let passes = (physics / pass).round().max(1.0) as usize;
    eprintln!(
        "pipelining: physics {:.2} ms/frame, drawing {passes} passes x {:.3} ms",
        physics * 1e3,
        pass * 1e3
    );
    passes
}

fn bench_pipelining(c: &mut Criterion, world: &World, passes: usize) {
    for threading in [Threading::Off, Threading::Worker] {
        pipeline_check(world, threading, passes, 100);
    }
    let mut g = c.benchmark_group("frame_physics_plus_draw_20k");
    g.sample_size(30).measurement_time(Duration::from_secs(8));
    for (name, threading) in [("off", Threading::Off), ("worker", Threading::Worker)] {
        let mut e = Engine::new(world.clone(), settings(threading, 1, 1)).unwrap();
        let mut render = Render {
            canvas: vec![b' '; Render::W * Render::H],
            passes,
        };
        g.bench_function(name, |b| b.iter(|| frame(&mut e, &mut render)));
    }
    g.finish();
}

/// Engines run in turn, `batch` frames each, `rounds` times; the time
/// ratios are taken round by round, so a machine whose load drifts (other
/// processes) moves both sides of a ratio alike. Prints the median ratio of
/// each pair `(slow, fast)` as the speed-up of `fast`, with min and max.
fn paired(label: &str, engines: &mut [(&str, Engine)], batch: usize, rounds: usize, passes: usize) {
    let mut render = Render {
        canvas: vec![b' '; Render::W * Render::H],
        passes,
    };
    let mut times = vec![Vec::new(); engines.len()];
    for round in 0..rounds {
        // Rotate who goes first, so no engine always runs after the same one.
        for k in 0..engines.len() {
            let i = (round + k) % engines.len();
            let e = &mut engines[i].1;
            let t0 = Instant::now();
            for _ in 0..batch {
                if passes == 0 {
                    e.start_frame().unwrap();
                    black_box(e.finish_frame().unwrap().energy);
                } else {
                    frame(e, &mut render);
                }
            }
            times[i].push(t0.elapsed().as_secs_f64());
        }
    }
    let names: Vec<&str> = engines.iter().map(|(n, _)| *n).collect();
    if names.contains(&"pool2") {
        capacity(label, rounds);
    }
    for i in 0..names.len() {
        for j in i + 1..names.len() {
            let mut r: Vec<f64> = times[i].iter().zip(&times[j]).map(|(a, b)| a / b).collect();
            r.sort_by(f64::total_cmp);
            let mut ti = times[i].clone();
            ti.sort_by(f64::total_cmp);
            eprintln!(
                "paired {label}: {} over {}: median {:.2}x (min {:.2}, max {:.2}; {rounds} rounds; \
                 {} median {:.1} ms per {batch} frames)",
                names[j],
                names[i],
                r[r.len() / 2],
                r[0],
                r[r.len() - 1],
                names[i],
                ti[ti.len() / 2] * 1e3,
            );
        }
    }
}

/// What two threads buy on this machine right now, with nothing of ours in
/// the way: a loop of arithmetic run twice on one thread against once on
/// each of two pool threads, paired round by round. On a shared host the
/// second core is not always there; pool figures are read against this.
fn capacity(label: &str, rounds: usize) {
    fn spin(seed: u64) -> u64 {
        let mut x = seed;
        for i in 0..4_000_000u64 {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(i);
        }
        x
    }
    let pool = ballpit::engine::PoolExec::new(2).unwrap();
    let mut r: Vec<f64> = (0..rounds)
        .map(|_| {
            let t0 = Instant::now();
            black_box(spin(1));
            black_box(spin(2));
            let one = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            pool.for_each_lane(&|l| {
                black_box(spin(l as u64));
            });
            one / t0.elapsed().as_secs_f64()
        })
        .collect();
    r.sort_by(f64::total_cmp);
    eprintln!(
        "paired {label}: the machine's own two-thread speed-up (arithmetic loop): median {:.2}x \
         (min {:.2}, max {:.2}; {rounds} rounds)",
        r[r.len() / 2],
        r[0],
        r[r.len() - 1]
    );
}

fn engines(
    world: &World,
    modes: &[(&'static str, Threading, usize)],
    tick: u32,
) -> Vec<(&'static str, Engine)> {
    modes
        .iter()
        .map(|&(name, t, k)| {
            (
                name,
                Engine::new(world.clone(), settings(t, k, tick)).unwrap(),
            )
        })
        .collect()
}

/// The TUI's own drawing of a frame (projection, raster, ratatui diff,
/// terminal bytes into a sink) at 200x60, as `benches/frame.rs` does it.
struct TuiDraw {
    term: Terminal<Lean<Counting<std::io::Sink>>>,
    raster: Raster,
    state: AppState,
}

impl TuiDraw {
    fn new(world: &World) -> TuiDraw {
        let (writer, _) = Counting::new(std::io::sink());
        let term = Terminal::with_options(
            Lean::new(writer),
            TerminalOptions {
                viewport: Viewport::Fixed(Rect::new(0, 0, 200, 60)),
            },
        )
        .unwrap();
        let r = world.spheres[0].radius;
        let state = AppState::new(
            &settings(Threading::Off, 1, 1),
            world.spheres.len(),
            r,
            30.0,
        );
        TuiDraw {
            term,
            raster: Raster::new(),
            state,
        }
    }

    fn draw(&mut self, snap: &Snapshot) {
        let (stats, report) = (Stats::default(), CpuReport::default());
        let view = View {
            state: &self.state,
            snap,
            stats: &stats,
            report: &report,
            palette: Palette::C16,
            aspect: 2.0,
        };
        let raster = &mut self.raster;
        self.term.draw(|f| layout::draw(f, raster, &view)).unwrap();
    }
}

/// `off` against `worker` with the TUI's drawing, the physics tick chosen so
/// a frame's physics costs about what its drawing costs.
fn tui_pipelining(c: &mut Criterion) {
    let world = scene(10_000, 0.006, 0.5, 3);
    let mut draw = TuiDraw::new(&world);
    let mut e = Engine::new(world.clone(), settings(Threading::Off, 1, 1)).unwrap();
    let step = cpu_per_call(20, || {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    });
    let drawing = cpu_per_call(20, || draw.draw(e.snapshot()));
    let tick = (drawing / step).round().max(1.0) as u32;
    eprintln!(
        "tui pipelining: drawing {:.2} ms/frame, physics {:.2} ms per frame of 1 step: tick {tick}",
        drawing * 1e3,
        step * 1e3
    );
    let mut engines = engines(
        &world,
        &[("off", Threading::Off, 1), ("worker", Threading::Worker, 1)],
        tick,
    );
    let mut times = [Vec::new(), Vec::new()];
    for round in 0..15 {
        for k in 0..2 {
            let i = (round + k) % 2;
            let t0 = Instant::now();
            for _ in 0..10 {
                let e = &mut engines[i].1;
                e.start_frame().unwrap();
                draw.draw(e.snapshot());
                e.finish_frame().unwrap();
            }
            times[i].push(t0.elapsed().as_secs_f64());
        }
    }
    let mut r: Vec<f64> = times[0].iter().zip(&times[1]).map(|(a, b)| a / b).collect();
    r.sort_by(f64::total_cmp);
    eprintln!(
        "paired TUI drawing + swept N=10000 tick {tick}: worker over off: median {:.2}x \
         (min {:.2}, max {:.2}; 15 rounds of 10 frames)",
        r[7], r[0], r[14]
    );
    let mut g = c.benchmark_group("tui_frame_10k");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    for (name, e) in &mut engines {
        g.bench_function(*name, |b| {
            b.iter(|| {
                e.start_frame().unwrap();
                draw.draw(e.snapshot());
                e.finish_frame().unwrap();
            });
        });
    }
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let fast = scene(100_000, 0.004, 0.5, 1);
    let slow = scene(100_000, 0.004, 0.1, 1);
    phases("N=100000 r=0.004 v=0.5", &fast);
    phases("N=100000 r=0.004 v=0.1", &slow);
    phases("N=100000 r=0.002 v=0.1", &scene(100_000, 0.002, 0.1, 1));
    let modes = [
        ("off", Threading::Off, 1),
        ("pool2", Threading::Pool, 2),
        ("split", Threading::Split, 2),
    ];
    for (label, world) in [
        ("swept N=100000 v=0.1, 5 steps/frame", &slow),
        ("swept N=100000 v=0.5, 5 steps/frame", &fast),
    ] {
        paired(label, &mut engines(world, &modes, 5), 2, 25, 0);
    }
    let small = scene(20_000, 0.006, 0.5, 2);
    let passes = calibrate(&small);
    let modes = [("off", Threading::Off, 1), ("worker", Threading::Worker, 1)];
    paired(
        "physics + drawing, swept N=20000",
        &mut engines(&small, &modes, 1),
        10,
        15,
        passes,
    );
    bench_pool(&mut c, "v0.5", &fast);
    bench_pool(&mut c, "v0.1", &slow);
    tui_pipelining(&mut c);
    bench_pipelining(&mut c, &small, passes);
    c.final_summary();
}
