//! What drawing the screen costs the frame loop, by size, thread count and
//! view: the default scene's snapshot and a made-up CPU report with a
//! minute of history per thread, drawn into ratatui's `TestBackend` (the
//! widgets and the buffer diff; no terminal writes). CPU time is the
//! thread's own on-CPU time (Linux schedstat), so waiting for a core on a
//! shared machine does not count.
//!
//!     cargo run --release --example screen_cost [FRAMES [WxH POOL canvas|chart]]
//!
//! With a size, pool and view it draws only that one (for callgrind: the
//! difference between two frame counts is the cost of the frames).
use ballpit::cpu::{CpuReport, ThreadLoad, ThreadRole};
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::ModelKind;
use ballpit::tui::canvas::Raster;
use ballpit::tui::layout::{self, View};
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

fn report(pool: usize) -> CpuReport {
    let mut names: Vec<String> = ["main", "physics", "signals", "input"]
        .map(String::from)
        .to_vec();
    names.extend((0..pool).map(|i| format!("pool-{i}")));
    let threads: Vec<ThreadLoad> = names
        .into_iter()
        .enumerate()
        .map(|(i, name)| {
            let history: Vec<f64> = (0..60).map(|s| ((i * 37 + s * 7) % 101) as f64).collect();
            ThreadLoad {
                tid: i as i32 + 1,
                role: ThreadRole::of(&name),
                name,
                percent: history[59],
                cpu_seconds: 1.0,
                history,
            }
        })
        .collect();
    CpuReport::new(threads, 2, Some(50.0))
}

/// On-CPU nanoseconds of this thread so far.
fn on_cpu() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn main() -> anyhow::Result<()> {
    let world = ballpit::scene::build_world(&ballpit::scene::SceneSpec::default())?;
    let settings = Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick: 1,
        threading: Threading::Pool,
        threads: 2,
    };
    let engine = Engine::new(world, settings)?;
    let snap = engine.snapshot().clone();
    let stats = Stats::default();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: u32 = args.first().map_or(Ok(400), |a| a.parse())?;
    let only = args.get(1..4).map(|a| a.join(" "));
    println!("size    pool  view    us on CPU per frame");
    for (w, h) in [(80u16, 24u16), (120, 40)] {
        for pool in [2, 64, 256] {
            let r = report(pool);
            for chart in [false, true] {
                let name = format!("{w}x{h} {pool} {}", if chart { "chart" } else { "canvas" });
                if only.as_ref().is_some_and(|o| *o != name) {
                    continue;
                }
                let mut st = AppState::new(&settings, snap.spheres.len(), 0.02, 30.0);
                st.threading = Threading::Pool;
                st.threads = pool;
                st.chart = chart;
                let view = View {
                    state: &st,
                    snap: &snap,
                    stats: &stats,
                    report: &r,
                    palette: Palette::C16,
                    aspect: 2.0,
                };
                let mut raster = Raster::new();
                let mut t = Terminal::new(TestBackend::new(w, h))?;
                for _ in 0..20 {
                    t.draw(|f| layout::draw(f, &mut raster, &view))?;
                }
                let Some(c0) = on_cpu() else {
                    println!("no /proc/thread-self/schedstat here");
                    return Ok(());
                };
                for _ in 0..frames {
                    t.draw(|f| layout::draw(f, &mut raster, &view))?;
                }
                let c1 = on_cpu().unwrap_or(c0);
                println!(
                    "{w}x{h:<4} {pool:>4}  {:<7} {:>8.1}",
                    if chart { "chart" } else { "canvas" },
                    (c1 - c0) as f64 / f64::from(frames) / 1e3
                );
            }
        }
    }
    Ok(())
}
