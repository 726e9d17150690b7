//! The screen parts at a fixed state, drawn on ratatui's TestBackend.
use ballpit::cpu::{CpuReport, ThreadLoad};
use ballpit::engine::{Engine, Settings, Snapshot, Threading};
use ballpit::physics::{ModelKind, Sphere, World};
use ballpit::tui::app::{self, View};
use ballpit::tui::canvas::{DrawStyle, Raster, Scene};
use ballpit::tui::help::{HelpBar, HelpOverlay};
use ballpit::tui::projection::Camera;
use ballpit::tui::readouts::{Readouts, Stats};
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use ballpit::tui::threads::Threads;
use glam::DVec3;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;

fn settings() -> Settings {
    Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick: 1,
        threading: Threading::Off,
        threads: 2,
    }
}

fn snapshot() -> Snapshot {
    let spheres = vec![
        Sphere::new(DVec3::new(0.5, 0.5, 0.5), DVec3::new(0.1, 0.0, 0.0), 0.12),
        Sphere::new(DVec3::new(0.2, 0.3, 0.7), DVec3::new(0.0, 0.9, 0.0), 0.08),
        Sphere::new(DVec3::new(0.8, 0.2, 0.2), DVec3::new(0.0, 0.0, 0.4), 0.1),
        Sphere::new(DVec3::new(0.75, 0.8, 0.8), DVec3::new(0.3, 0.3, 0.0), 0.15),
    ];
    let engine = Engine::new(World::new(1.0, spheres), settings()).unwrap();
    let mut snap = engine.snapshot().clone();
    snap.physics_seconds = 0.00123;
    snap.energy = snap.energy_reset * (1.0 + 2.5e-13);
    snap
}

fn stats() -> Stats {
    Stats {
        fps: 29.9,
        physics_seconds: 0.00123,
        render_seconds: 0.00087,
        frame_bytes: 4321,
        steps_per_second: 30.0,
        collisions_per_second: 12.0,
        detected: Some(Palette::True),
        link: None,
    }
}

fn report() -> CpuReport {
    let load = |tid, name: &str, percent, history: Vec<f64>| ThreadLoad {
        tid,
        name: name.into(),
        percent,
        cpu_seconds: 1.0,
        history,
    };
    CpuReport {
        threads: vec![
            load(1, "main", 12.5, vec![90.0, 80.0, 40.0, 12.5]),
            load(2, "physics", 87.0, vec![0.0, 10.0, 60.0, 87.0]),
            load(3, "input", 0.0, vec![0.0; 70]),
        ],
        total_percent: 99.5,
        cores: 2,
    }
}

fn state() -> AppState {
    AppState::new(&settings(), 4, 0.15, 30.0)
}

fn render(w: u16, h: u16, f: impl FnOnce(&mut ratatui::Frame)) -> Terminal<TestBackend> {
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(f).unwrap();
    t
}

fn readouts(st: &AppState, snap: &Snapshot, palette: Palette) -> Terminal<TestBackend> {
    let stats = stats();
    render(44, 18, |f| {
        f.render_widget(
            Readouts {
                state: st,
                snap,
                stats: &stats,
                palette,
            },
            f.area(),
        )
    })
}

#[test]
fn readouts_panel() {
    let t = readouts(&state(), &snapshot(), Palette::C16);
    insta::assert_snapshot!(t.backend());
}

#[test]
fn readouts_panel_says_when_steps_are_cut_into_parts() {
    let mut snap = snapshot();
    let whole = format!(
        "{:?}",
        readouts(&state(), &snap, Palette::C16).backend().buffer()
    );
    assert!(!whole.contains("steps cut"), "{whole}");
    snap.parts = 4;
    let t = readouts(&state(), &snap, Palette::C16);
    let text = format!("{:?}", t.backend().buffer());
    assert!(text.contains("swept    steps cut in 4"), "{text}");
}

#[test]
fn readouts_panel_says_when_the_event_cap_was_hit() {
    let mut snap = snapshot();
    snap.counters.capped_steps = 3;
    let t = readouts(&state(), &snap, Palette::C16);
    let text = format!("{:?}", t.backend().buffer());
    assert!(text.contains("event cap hit in 3 steps"), "{text}");
}

#[test]
fn readouts_panel_says_exact_runs_on_one_thread_in_pool_mode() {
    let mut st = state();
    st.threading = Threading::Pool;
    st.model = ballpit::physics::ModelKind::Exact;
    let t = readouts(&st, &snapshot(), Palette::C16);
    let text = format!("{:?}", t.backend().buffer());
    assert!(text.contains("pool     exact runs on physics"), "{text}");
}

#[test]
fn readouts_panel_paused_in_pool_mode() {
    let mut st = state();
    st.threading = Threading::Pool;
    st.threads = 3;
    st.paused = true;
    let t = readouts(&st, &snapshot(), Palette::Mono);
    insta::assert_snapshot!(t.backend());
    // Without colour, the pause cue is reverse video.
    let buf = t.backend().buffer();
    let y = (0..18)
        .find(|&y| buf[(2, y)].symbol() == "P")
        .expect("the PAUSED line");
    assert!(
        buf[(2, y)]
            .modifier
            .contains(ratatui::style::Modifier::REVERSED)
    );
}

#[test]
fn threads_panel() {
    let r = report();
    let t = render(44, 8, |f| {
        f.render_widget(
            Threads {
                report: &r,
                palette: Palette::C16,
            },
            f.area(),
        )
    });
    insta::assert_snapshot!(t.backend());
}

#[test]
fn help_bar_and_overlay() {
    let t = render(140, 1, |f| {
        f.render_widget(
            HelpBar {
                palette: Palette::C16,
            },
            f.area(),
        )
    });
    insta::assert_snapshot!("help_bar", t.backend());
    let t = render(70, 22, |f| {
        f.render_widget(
            HelpOverlay {
                palette: Palette::C16,
            },
            f.area(),
        )
    });
    insta::assert_snapshot!("help_overlay", t.backend());
}

fn canvas(style: DrawStyle, palette: Palette) -> Terminal<TestBackend> {
    let snap = snapshot();
    let scene = Scene {
        box_size: 1.0,
        camera: Camera::default(),
        style,
        light: 0,
        palette,
        aspect: 2.0,
    };
    let mut raster = Raster::new();
    render(40, 16, |f| {
        raster.draw(&snap.spheres, &scene, f.area(), f.buffer_mut())
    })
}

#[test]
fn small_canvas_braille() {
    let t = canvas(DrawStyle::PointsSpeed, Palette::C16);
    insta::assert_snapshot!(t.backend());
    // The fastest sphere is hot, the slowest cold; the edges grey.
    let colours: Vec<Color> = t
        .backend()
        .buffer()
        .content()
        .iter()
        .map(|c| c.fg)
        .collect();
    assert!(colours.contains(&Color::LightRed));
    assert!(colours.contains(&Color::LightBlue));
    assert!(colours.contains(&Color::Gray));
}

#[test]
fn small_canvas_shaded() {
    let t = canvas(DrawStyle::Shaded, Palette::C16);
    insta::assert_snapshot!(t.backend());
}

#[test]
fn small_canvas_shaded_without_colour_uses_a_glyph_ramp() {
    let t = canvas(DrawStyle::Shaded, Palette::Mono);
    insta::assert_snapshot!(t.backend());
    let text: String = t
        .backend()
        .buffer()
        .content()
        .iter()
        .map(|c| c.symbol())
        .collect();
    assert!(text.contains('@') && text.contains('+'), "{text}");
}

#[test]
fn whole_screen_and_the_too_small_message() {
    let (st, snap, stats, r) = (state(), snapshot(), stats(), report());
    let view = View {
        state: &st,
        snap: &snap,
        stats: &stats,
        report: &r,
        palette: Palette::C16,
        aspect: 2.0,
    };
    let mut raster = Raster::new();
    let t = render(120, 30, |f| app::draw(f, &mut raster, &view));
    insta::assert_snapshot!("whole_screen", t.backend());
    let t = render(60, 12, |f| app::draw(f, &mut raster, &view));
    insta::assert_snapshot!("too_small", t.backend());
}
