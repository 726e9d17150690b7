//! Frame cost and wire cost of the screen.
//!
//! - `frame/10k_spheres_200x60_*`: projection, raster, ratatui diff and the
//!   terminal bytes for one frame of 10 000 moving spheres at 200×60
//!   (target < 4 ms); `frame_cpu/...` prints the same on-CPU time alone,
//!   from the thread's schedstat, for shared machines.
//! - then prints bytes per second at 120×40 for the default scene at 30 fps,
//!   in 16 colours (target < 150 KB/s) and in truecolor.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::cpu::CpuReport;
use ballpit::engine::{Engine, Settings, Snapshot, Threading};
use ballpit::physics::{ModelKind, Sphere, World};
use ballpit::tui::backend::{Counting, Lean};
use ballpit::tui::canvas::Raster;
use ballpit::tui::layout::{self, View};
use ballpit::tui::look::DrawStyle;
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use criterion::{Criterion, criterion_group};
use crossterm::queue;
use crossterm::terminal::{BeginSynchronizedUpdate, EndSynchronizedUpdate};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use ratatui::layout::Rect;
use ratatui::{Terminal, TerminalOptions, Viewport};
use std::sync::atomic::Ordering;

fn lattice_world(n: usize, radius: f64, speed: f64, seed: u64) -> World {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let side = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / side as f64;
    let slack = (cell / 2.0 - radius).max(0.0);
    let mut spheres = Vec::with_capacity(n);
    for i in 0..side.pow(3) {
        if spheres.len() == n {
            break;
        }
        let idx = DVec3::new(
            (i / side / side) as f64,
            (i / side % side) as f64,
            (i % side) as f64,
        );
        let mut c = idx * cell + DVec3::splat(cell / 2.0);
        for a in 0..3 {
            c[a] += rng.random_range(-slack..=slack);
        }
        let dir = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize_or(DVec3::X);
        spheres.push(Sphere::new(c, dir * speed, radius));
    }
    World::new(1.0, spheres)
}

fn settings() -> Settings {
    Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick: 1,
        threading: Threading::Off,
        threads: 1,
    }
}

type Term = Terminal<Lean<Counting<std::io::Sink>>>;

fn terminal(w: u16, h: u16) -> (Term, std::sync::Arc<std::sync::atomic::AtomicU64>) {
    let (writer, bytes) = Counting::new(std::io::sink());
    let t = Terminal::with_options(
        Lean::new(writer),
        TerminalOptions {
            viewport: Viewport::Fixed(Rect::new(0, 0, w, h)),
        },
    )
    .unwrap();
    (t, bytes)
}

fn frame(t: &mut Term, raster: &mut Raster, view: &View) {
    queue!(t.backend_mut(), BeginSynchronizedUpdate).unwrap();
    t.draw(|f| layout::draw(f, raster, view)).unwrap();
    queue!(t.backend_mut(), EndSynchronizedUpdate).unwrap();
}

/// [`frame`] of `snap` in state `st`, with empty statistics and CPU report.
fn frame_of(t: &mut Term, raster: &mut Raster, st: &AppState, snap: &Snapshot) {
    let (stats, report) = (Stats::default(), CpuReport::default());
    let view = View {
        state: st,
        snap,
        stats: &stats,
        report: &report,
        palette: Palette::C16,
        aspect: 2.0,
    };
    frame(t, raster, &view);
}

/// Snapshots of `frames` consecutive frames.
fn frames(world: World, frames: usize) -> Vec<Snapshot> {
    let mut e = Engine::new(world, settings()).unwrap();
    (0..frames)
        .map(|_| {
            e.start_frame().unwrap();
            e.finish_frame().unwrap().clone()
        })
        .collect()
}

/// Time building whole frames at 200×60, alternating two snapshots so every
/// frame has changes to send.
fn bench_view(c: &mut Criterion, id: &str, st: &AppState, snaps: &[Snapshot]) {
    let (mut t, _) = terminal(200, 60);
    let mut raster = Raster::new();
    let mut k = 0;
    c.bench_function(id, |b| {
        b.iter(|| {
            k += 1;
            frame_of(&mut t, &mut raster, st, &snaps[k % 2]);
        });
    });
}

/// The app state of the 10k lattice in each drawing style, by name.
fn styles_at_10k() -> [(&'static str, AppState); 2] {
    [
        ("braille", DrawStyle::PointsSpeed),
        ("shaded", DrawStyle::Shaded),
    ]
    .map(|(name, style)| {
        let mut st = AppState::new(&settings(), 10_000, 0.01, 30.0);
        st.style = style;
        (name, st)
    })
}

fn bench_frame(c: &mut Criterion) {
    let snaps = frames(lattice_world(10_000, 0.01, 0.5, 7), 2);
    for (name, st) in styles_at_10k() {
        bench_view(c, &format!("frame/10k_spheres_200x60_{name}"), &st, &snaps);
    }
    // 100 000 spheres still draw (as points).
    let snaps = frames(lattice_world(100_000, 0.002, 0.5, 7), 2);
    let st = AppState::new(&settings(), 100_000, 0.002, 30.0);
    bench_view(c, "frame/100k_spheres_200x60_braille", &st, &snaps);
}

/// Bytes written per second at 120×40, default scene, 30 fps, 3 seconds.
fn wire_bytes() {
    let default_scene = ballpit::scene::build_world(&ballpit::scene::SceneSpec::default()).unwrap();
    let snaps = frames(default_scene, 90);
    for (palette, style) in [
        (Palette::C16, DrawStyle::PointsSpeed),
        (Palette::True, DrawStyle::PointsSpeed),
        (Palette::C16, DrawStyle::Shaded),
        (Palette::True, DrawStyle::Shaded),
    ] {
        let mut st = AppState::new(&settings(), 1000, 0.02, 30.0);
        st.style = style;
        let report = CpuReport::default();
        let (mut t, bytes) = terminal(120, 40);
        let mut raster = Raster::new();
        let mut stats = Stats::default();
        // The first frame paints everything; what matters is the steady state.
        let mut first = 0;
        for (i, snap) in snaps.iter().enumerate() {
            if i % 30 == 0 {
                stats.fps = 30.0 - (i / 30) as f64 * 0.1;
            }
            let view = View {
                state: &st,
                snap,
                stats: &stats,
                report: &report,
                palette,
                aspect: 2.0,
            };
            frame(&mut t, &mut raster, &view);
            if i == 0 {
                first = bytes.load(Ordering::Relaxed);
            }
        }
        let steady = bytes.load(Ordering::Relaxed) - first;
        let per_frame = steady as f64 / (snaps.len() - 1) as f64;
        println!(
            "wire/120x40_default_scene_{}_{}: {:.0} B/frame, {:.1} KB/s at 30 fps (first frame {} B)",
            palette.name(),
            if style == DrawStyle::Shaded {
                "shaded"
            } else {
                "braille"
            },
            per_frame,
            per_frame * 30.0 / 1000.0,
            first
        );
    }
}

/// On-CPU and run-queue nanoseconds of this thread so far (Linux
/// schedstat): on a shared machine the wall-clock figures above include
/// time spent waiting for a core; this says what a frame itself costs.
fn schedstat() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let mut it = s.split_whitespace().map(|v| v.parse::<u64>().ok());
    Some((it.next()??, it.next()??))
}

fn frame_cpu() {
    let snaps = frames(lattice_world(10_000, 0.01, 0.5, 7), 2);
    for (name, st) in styles_at_10k() {
        let (mut t, _) = terminal(200, 60);
        let mut raster = Raster::new();
        let n = 400;
        let mut run = |k: usize| frame_of(&mut t, &mut raster, &st, &snaps[k % 2]);
        for k in 0..20 {
            run(k);
        }
        let wall = std::time::Instant::now();
        let Some((cpu0, wait0)) = schedstat() else {
            return;
        };
        for k in 0..n {
            run(k);
        }
        let (cpu1, wait1) = schedstat().unwrap();
        println!(
            "frame_cpu/10k_spheres_200x60_{name}: {:.2} ms on CPU per frame ({:.2} ms wall, {:.2} ms waiting for a core)",
            (cpu1 - cpu0) as f64 / n as f64 / 1e6,
            wall.elapsed().as_secs_f64() / n as f64 * 1e3,
            (wait1 - wait0) as f64 / n as f64 / 1e6,
        );
    }
}

criterion_group!(benches, bench_frame);

fn main() {
    wire_bytes();
    frame_cpu();
    benches();
    Criterion::default().configure_from_args().final_summary();
}
