//! What the main thread spends drawing one frame of a large scene: the
//! whole screen into ratatui's `TestBackend` (projection, depth test,
//! discs, widgets, buffer diff; no terminal writes). On-CPU time of this
//! thread (Linux schedstat), so waiting for a core does not count; for
//! instruction counts run it under callgrind with
//! `--toggle-collect='*Raster*draw*'`.
//!
//!     cargo run --release --example canvas_cost -- [COUNT [RADIUS [FRAMES [COLSxROWS]]]]
use ballpit::cpu::CpuReport;
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::ModelKind;
use ballpit::scene::SceneSpec;
use ballpit::tui::canvas::Raster;
use ballpit::tui::layout::{self, View};
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

/// On-CPU nanoseconds of this thread so far.
fn on_cpu() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let count: usize = args.first().map_or(Ok(100_000), |a| a.parse())?;
    let radius: f64 = args.get(1).map_or(Ok(0.002_285), |a| a.parse())?;
    let frames: u32 = args.get(2).map_or(Ok(30), |a| a.parse())?;
    let (w, h) = args
        .get(3)
        .and_then(|s| s.split_once('x'))
        .map_or(Ok((120u16, 40u16)), |(c, r)| {
            anyhow::Ok((c.parse()?, r.parse()?))
        })?;
    let spec = SceneSpec {
        count: Some(count),
        radius: Some(radius),
        ..Default::default()
    };
    let world = ballpit::scene::build_world(&spec)?;
    let settings = Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick: 1,
        threading: Threading::Off,
        threads: 1,
    };
    let mut engine = Engine::new(world, settings)?;
    engine.start_frame()?;
    let snap = engine.finish_frame()?.clone();
    let st = AppState::new(&settings, snap.count, radius, 30.0);
    let stats = Stats::default();
    let report = CpuReport::default();
    let view = View {
        state: &st,
        snap: &snap,
        stats: &stats,
        report: &report,
        palette: Palette::C16,
        aspect: 2.0,
    };
    let mut raster = Raster::new();
    let mut t = Terminal::new(TestBackend::new(w, h))?;
    t.draw(|f| layout::draw(f, &mut raster, &view))?;
    let c0 = on_cpu().ok_or_else(|| anyhow::anyhow!("no /proc/thread-self/schedstat"))?;
    for _ in 0..frames {
        t.draw(|f| layout::draw(f, &mut raster, &view))?;
    }
    let c1 = on_cpu().unwrap_or(c0);
    println!(
        "{count} spheres, r {radius}, {w}x{h}: {:.2} ms on CPU per drawn frame",
        (c1 - c0) as f64 / f64::from(frames) / 1e6
    );
    Ok(())
}
