//! The screen parts at a fixed state, drawn on ratatui's `TestBackend`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::names::thread_names;
use crate::common::screen::{rows, settings, text};
use ballpit::cpu::{CpuReport, ThreadLoad, ThreadRole};
use ballpit::engine::{Engine, Settings, Snapshot, Threading};
use ballpit::physics::{Sphere, World};
use ballpit::tui::canvas::{Raster, Scene};
use ballpit::tui::help::{HelpBar, HelpOverlay};
use ballpit::tui::layout::{self, View};
use ballpit::tui::look::Camera;
use ballpit::tui::look::DrawStyle;
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use ballpit::tui::threads::Threads;
use glam::DVec3;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;

pub(crate) fn snapshot() -> Snapshot {
    snapshot_at(settings(2))
}

/// The snapshot of a frame that ran with the settings `st` asked for: the
/// screen in steady state, once the engine has applied the keys.
pub(crate) fn ran(st: &AppState) -> Snapshot {
    snapshot_at(Settings {
        model: st.model,
        tick: st.engine_tick(),
        threading: st.threading,
        threads: st.threads,
        ..settings(2)
    })
}

pub(crate) fn snapshot_at(s: Settings) -> Snapshot {
    let spheres = vec![
        Sphere::new(DVec3::new(0.5, 0.5, 0.5), DVec3::new(0.1, 0.0, 0.0), 0.12),
        Sphere::new(DVec3::new(0.2, 0.3, 0.7), DVec3::new(0.0, 0.9, 0.0), 0.08),
        Sphere::new(DVec3::new(0.8, 0.2, 0.2), DVec3::new(0.0, 0.0, 0.4), 0.1),
        Sphere::new(DVec3::new(0.75, 0.8, 0.8), DVec3::new(0.3, 0.3, 0.0), 0.15),
    ];
    let engine = Engine::new(World::new(1.0, spheres), s).unwrap();
    let mut snap = engine.snapshot().clone();
    snap.physics_seconds = 0.00123;
    snap.energy = snap.energy_reset * (1.0 + 2.5e-13);
    snap
}

pub(crate) fn stats() -> Stats {
    Stats {
        fps: 29.9,
        physics_seconds: 0.00123,
        render_seconds: 0.00087,
        frame_bytes: 4321,
        steps_per_second: 30.0,
        collisions_per_second: 12.0,
        detected: Some(Palette::True),
        link: None,
        link_slow: false,
        ..Stats::default()
    }
}

pub(crate) fn report() -> CpuReport {
    let load = |tid, name: &str, percent, history: Vec<f64>| ThreadLoad {
        tid,
        role: ThreadRole::of(name),
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
        others_percent: Some(42.0),
    }
}

/// The threads the app has in `mode` with `pool` pool threads, loaded
/// unevenly, with a minute of history each.
pub(crate) fn report_for(mode: Threading, pool: usize) -> CpuReport {
    let names = thread_names(&["main", "physics", "signals", "input"], mode, pool);
    // Loads a two-core machine could give: the more threads, the less each.
    let scale = (8.0 / names.len() as f64).min(1.0);
    let threads: Vec<ThreadLoad> = names
        .into_iter()
        .enumerate()
        .map(|(i, name)| {
            let base = ((i * 37) % 101) as f64;
            let history: Vec<f64> = (0..60)
                .map(|s| ((base + (s * (i + 3)) as f64 % 40.0) * scale).min(100.0))
                .collect();
            ThreadLoad {
                tid: 100 + i as i32,
                role: ThreadRole::of(&name),
                name,
                percent: *history.last().unwrap(),
                cpu_seconds: 1.0,
                history,
            }
        })
        .collect();
    CpuReport::new(threads, 2, Some(37.5))
}

pub(crate) fn state() -> AppState {
    AppState::new(&settings(2), 4, 0.15, 30.0)
}

pub(crate) fn render(w: u16, h: u16, f: impl FnOnce(&mut ratatui::Frame)) -> Terminal<TestBackend> {
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(f).unwrap();
    t
}

#[test]
fn threads_panel() {
    let r = report();
    let t = render(44, 9, |f| {
        f.render_widget(
            Threads {
                report: &r,
                palette: Palette::C16,
                by_cpu: false,
                pool: None,
            },
            f.area(),
        );
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
        );
    });
    insta::assert_snapshot!("help_bar", t.backend());
    let t = render(70, 20, |f| {
        f.render_widget(
            HelpOverlay {
                palette: Palette::C16,
            },
            f.area(),
        );
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
        raster.draw(&snap.spheres, &scene, f.area(), f.buffer_mut());
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
    let text = text(&t);
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
    let t = render(120, 30, |f| layout::draw(f, &mut raster, &view));
    insta::assert_snapshot!("whole_screen", t.backend());
    let t = render(60, 12, |f| layout::draw(f, &mut raster, &view));
    insta::assert_snapshot!("too_small", t.backend());
}

const CELLS: &str = "·▁▂▃▄▅▆▇█";

/// Every thread of `r` is on screen: its name on a row of its own, or, for
/// the numbered group in the compact view, a cell each (or a cell per
/// `k` threads when the summary says `k/cell`); and the total and others.
fn assert_every_thread_visible(text: &[String], r: &CpuReport, what: &str) {
    let all = text.join("\n");
    assert!(all.contains("process"), "{what}: no process total\n{all}");
    assert!(all.contains("other procs"), "{what}: no other procs\n{all}");
    let (singles, group) = ballpit::tui::threads::split_group(r);
    let summary = group.as_ref().and_then(|(prefix, members)| {
        let head = format!("{prefix} x{}:", members.len());
        text.iter().position(|l| l.contains(&head))
    });
    match (group, summary) {
        (Some((_, members)), Some(at)) => {
            for t in &singles {
                let name: String = t.name.chars().take(11).collect();
                assert!(all.contains(&name), "{what}: {name} missing\n{all}");
            }
            // "each cell: the busiest of K threads" when cells are shared.
            let per_cell: usize = text[at + 1]
                .split("busiest of ")
                .nth(1)
                .map_or(1, |k| k.split(' ').next().unwrap().parse().unwrap());
            let cells: usize = text[at + 1..]
                .iter()
                .take_while(|l| !l.contains("total") && !l.contains("idle"))
                .map(|l| l.chars().filter(|c| CELLS.contains(*c)).count())
                .sum();
            assert_eq!(
                cells,
                members.len().div_ceil(per_cell),
                "{what}: cells for {} threads at {per_cell}/cell\n{all}",
                members.len()
            );
        }
        _ => {
            for t in &r.threads {
                let name: String = t.name.chars().take(11).collect();
                assert!(
                    text.iter().any(|l| l.contains(&name)),
                    "{what}: {name} missing\n{all}"
                );
            }
        }
    }
}

pub(crate) fn screen(w: u16, h: u16, st: &AppState, r: &CpuReport) -> Terminal<TestBackend> {
    screen_with(w, h, st, r, &stats())
}

pub(crate) fn screen_with(
    w: u16,
    h: u16,
    st: &AppState,
    r: &CpuReport,
    stats: &Stats,
) -> Terminal<TestBackend> {
    let snap = ran(st);
    let view = View {
        state: st,
        snap: &snap,
        stats,
        report: r,
        palette: Palette::C16,
        aspect: 2.0,
    };
    let mut raster = Raster::new();
    render(w, h, |f| layout::draw(f, &mut raster, &view))
}

pub(crate) fn mode_state(mode: Threading, pool: usize) -> AppState {
    let mut st = state();
    st.threading = mode;
    st.threads = pool;
    st
}

#[test]
fn every_thread_and_the_total_at_80x24_and_120x40() {
    let cases = [
        ("pool_2", Threading::Pool, 2),
        ("split", Threading::Split, 2),
        ("pool_64", Threading::Pool, 64),
    ];
    for (name, mode, pool) in cases {
        let r = report_for(mode, pool);
        let st = mode_state(mode, pool);
        for (w, h) in [(80, 24), (120, 40)] {
            let t = screen(w, h, &st, &r);
            let what = format!("{name}_{w}x{h}");
            assert_every_thread_visible(&rows(&t), &r, &what);
            insta::assert_snapshot!(what, t.backend());
        }
    }
}

#[test]
fn sixty_four_pool_threads_at_80x24_are_a_grid_with_min_mean_max() {
    let r = report_for(Threading::Pool, 64);
    let t = screen(80, 24, &mode_state(Threading::Pool, 64), &r);
    let text = rows(&t).join("\n");
    let loads: Vec<f64> = r
        .threads
        .iter()
        .filter(|t| t.name.starts_with("pool-"))
        .map(|t| t.percent)
        .collect();
    let min = loads.iter().copied().fold(f64::INFINITY, f64::min);
    let max = loads.iter().copied().fold(0.0, f64::max);
    let mean = loads.iter().sum::<f64>() / 64.0;
    let want = format!("pool x64: min {min:.0} mean {mean:.0} max {max:.0} %");
    assert!(text.contains(&want), "{want}\n{text}");
    // A cell a thread: no "/cell" in the summary.
    assert!(!text.contains("/cell"), "{text}");
}

#[test]
fn any_size_from_the_minimum_and_any_thread_count_shows_every_thread() {
    use ballpit::tui::layout::{MIN_HEIGHT, MIN_WIDTH};
    for pool in [1, 3, 9, 33, 100, 256] {
        let r = report_for(Threading::Pool, pool);
        let mut st = mode_state(Threading::Pool, pool);
        for w in (MIN_WIDTH..=250).step_by(29).chain([80, 250]) {
            for h in (MIN_HEIGHT..=80).step_by(9).chain([24, 80]) {
                st.chart = (w + h) % 2 == 0;
                let t = screen(w, h, &st, &r);
                assert_every_thread_visible(&rows(&t), &r, &format!("{pool} at {w}x{h}"));
            }
        }
    }
}

#[test]
fn below_the_minimum_a_message_and_no_panic_at_0x0_or_1x1() {
    use ballpit::tui::layout::{MIN_HEIGHT, MIN_WIDTH};
    let r = report_for(Threading::Pool, 2);
    let st = state();
    for (w, h) in [
        (0, 0),
        (1, 1),
        (0, 5),
        (5, 0),
        (MIN_WIDTH - 1, 40),
        (100, MIN_HEIGHT - 1),
    ] {
        let t = screen(w, h, &st, &r);
        if w >= 30 {
            let text = rows(&t).join("\n");
            assert!(
                text.contains(&format!("needs at least {MIN_WIDTH}x{MIN_HEIGHT}")),
                "{text}"
            );
            assert!(text.contains(&format!("is {w}x{h}")), "{text}");
        }
    }
}

#[test]
fn help_overlay_fits_at_80x24() {
    let mut st = state();
    st.help = true;
    let r = report_for(Threading::Pool, 2);
    let t = screen(80, 24, &st, &r);
    insta::assert_snapshot!("help_overlay_80x24", t.backend());
    let text = rows(&t).join("\n");
    for b in ballpit::tui::keys::TABLE {
        assert!(text.contains(b.help), "{} missing\n{text}", b.help);
    }
    assert!(text.contains("? or Esc closes this help"), "{text}");
}

#[test]
fn a_slow_link_is_shown_at_80x24_in_place_of_the_render_time() {
    let (st, r) = (state(), report_for(Threading::Off, 0));
    let slow = Stats {
        link: Some("109ms 16KB/s 5fps mono".into()),
        link_slow: true,
        ..stats()
    };
    let text = rows(&screen_with(80, 24, &st, &r, &slow)).join("\n");
    assert!(
        text.contains("link    109ms 16KB/s 5fps mono 4321 B/fr"),
        "{text}"
    );
    assert!(!text.contains("render"), "{text}");
    // A fast link keeps the render time.
    let fast = Stats {
        link_slow: false,
        ..slow
    };
    let text = rows(&screen_with(80, 24, &st, &r, &fast)).join("\n");
    assert!(
        text.contains("render") && !text.contains("16KB/s"),
        "{text}"
    );
}

#[test]
fn the_key_bar_at_80_columns_keeps_the_keys_that_matter_most() {
    let t = screen(80, 24, &state(), &report_for(Threading::Off, 0));
    let bar = rows(&t).pop().unwrap();
    for k in [
        "? help", "q quit", "t thread", "d mode", "c chart", "p/P pool",
    ] {
        assert!(bar.contains(k), "{k} missing: {bar}");
    }
}

#[test]
fn chart_view_has_a_line_per_thread_and_groups_many() {
    let mut st = mode_state(Threading::Pool, 2);
    st.chart = true;
    let r = report_for(Threading::Pool, 2);
    let t = screen(120, 40, &st, &r);
    insta::assert_snapshot!("chart_120x40_pool_2", t.backend());
    let text = rows(&t).join("\n");
    assert!(text.contains("CPU per thread, last 60 s"), "{text}");
    for name in ["main", "physics", "pool-0", "pool-1"] {
        assert!(text.contains(name), "{name}\n{text}");
    }
    // Lines are drawn in braille, in one colour per thread.
    let buf = t.backend().buffer();
    let braille_colours: std::collections::BTreeSet<String> = buf
        .content()
        .iter()
        .filter(|c| {
            c.symbol()
                .chars()
                .any(|ch| ('\u{2801}'..='\u{28ff}').contains(&ch))
        })
        .map(|c| format!("{:?}", c.fg))
        .collect();
    assert!(braille_colours.len() >= 4, "{braille_colours:?}");
    assert!(text.contains("100 %") && text.contains("-59 s"), "{text}");

    let mut st = mode_state(Threading::Pool, 64);
    st.chart = true;
    let r = report_for(Threading::Pool, 64);
    let t = screen(80, 24, &st, &r);
    insta::assert_snapshot!("chart_80x24_pool_64", t.backend());
    let text = rows(&t).join("\n");
    assert!(text.contains("pool-* mean of 64"), "{text}");
    assert!(text.contains("pool-* max of 64"), "{text}");
}

#[test]
fn others_line_shows_what_other_processes_take() {
    let r = report_for(Threading::Pool, 2);
    let t = screen(120, 40, &mode_state(Threading::Pool, 2), &r);
    let text = rows(&t).join("\n");
    assert!(text.contains("other procs   37.5 % of 200 %"), "{text}");
    let mut r = r;
    r.others_percent = None;
    let text = rows(&screen(80, 24, &mode_state(Threading::Pool, 2), &r)).join("\n");
    // Not known yet: a dash, not a made-up zero.
    assert!(
        text.lines()
            .any(|l| l.contains("other procs") && l.contains(" - % of 200 %")),
        "{text}"
    );
}

#[test]
fn two_hundred_fifty_six_pool_threads_at_80x24_share_cells_and_say_so() {
    let r = report_for(Threading::Pool, 256);
    let t = screen(80, 24, &mode_state(Threading::Pool, 256), &r);
    let text = rows(&t);
    let summary = text
        .iter()
        .find(|l| l.contains("pool x256:"))
        .expect("the pool summary");
    assert!(
        text.iter()
            .any(|l| l.contains("each cell: the busiest of 4 threads")),
        "{}",
        text.join("\n")
    );
    assert!(summary.contains("min 0 mean"), "{summary}");
    assert_every_thread_visible(&text, &r, "256 at 80x24");
}

#[test]
fn a_wide_terminal_shows_more_seconds_of_sparkline_and_the_thread_ids() {
    let r = report_for(Threading::Pool, 2);
    let text = rows(&screen(250, 60, &mode_state(Threading::Pool, 2), &r)).join("\n");
    // The widest panel (84 columns) less name, id and figure: 52 s.
    assert!(text.contains("last 52 s"), "{text}");
    assert!(text.contains("TID"), "{text}");
    // The 52 newest one-second samples of `physics` (never idle), all drawn.
    let row = text.lines().rfind(|l| l.contains("│physics ")).unwrap();
    let bars = row.chars().filter(|c| "▁▂▃▄▅▆▇█".contains(*c)).count();
    assert_eq!(bars, 52, "{row}");
    let text = rows(&screen(80, 24, &mode_state(Threading::Pool, 2), &r)).join("\n");
    assert!(text.contains("last 20 s"), "{text}");
}

#[test]
fn no_per_thread_figures_yet_still_draws_chart_and_panel() {
    let r = CpuReport::default();
    let mut st = state();
    for chart in [false, true] {
        st.chart = chart;
        let text = rows(&screen(80, 24, &st, &r)).join("\n");
        assert!(text.contains("no per-thread figures yet"), "{text}");
        assert!(text.contains("other procs"), "{text}");
    }
}
