//! The thread panel alone, in the place the layout gives it at 80x24,
//! 120x40 and 200x60, with 1, 2, 64 and 256 pool threads: a stable order,
//! every figure with its `%` and base, the pool's own total, and the grid
//! only where the rows run out.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::screen::{rows, settings};
use ballpit::cpu::{CpuReport, ThreadLoad, ThreadRole};
use ballpit::tui::layout;
use ballpit::tui::theme::Palette;
use ballpit::tui::threads::{self, Layout, Threads};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::layout::Rect;

/// The app's threads with `pool` pool threads, given in thread-id order as
/// procfs lists them: the pool's ids are lower than `main`'s, so an order
/// by id would put `pool-0` first.
fn report(pool: usize) -> CpuReport {
    let mut threads: Vec<ThreadLoad> = Vec::new();
    let mut add = |tid: i32, name: String, percent: f64| {
        let history = (0..60)
            .map(|s| percent * f64::from(s % 5 + 1) / 5.0)
            .collect();
        threads.push(ThreadLoad {
            tid,
            role: ThreadRole::of(&name),
            name,
            percent,
            cpu_seconds: 1.0,
            history,
        });
    };
    for i in 0..pool {
        // 256 threads on two cores: most idle, a few busy.
        let load = if i % 16 == 0 {
            40.0
        } else {
            (i % 7) as f64 * 0.3
        };
        add(100 + i as i32, format!("pool-{i}"), load);
    }
    add(5000, "main".into(), 3.1);
    add(5001, "physics".into(), 1.2);
    add(5002, "signals".into(), 0.0);
    add(5003, "output".into(), 0.4);
    add(5004, "input".into(), 0.1);
    threads.sort_by_key(|t| t.tid);
    CpuReport::new(threads, 2, Some(37.5))
}

#[test]
fn order_percent_base_and_pool_total_at_three_sizes_and_four_pools() {
    for (w, h) in [(80u16, 24u16), (120, 40), (200, 60)] {
        for pool in [1usize, 2, 64, 256] {
            let r = report(pool);
            let area = layout::areas(Rect::new(0, 0, w, h), &r).unwrap().threads;
            let mut t = Terminal::new(TestBackend::new(area.width, area.height)).unwrap();
            let panel = Threads {
                report: &r,
                palette: Palette::Mono,
                by_cpu: false,
                pool: None,
            };
            let (iw, ih) = (usize::from(area.width) - 2, usize::from(area.height) - 2);
            let layout = panel.layout(iw, ih);
            t.draw(|f| {
                f.render_widget(
                    Threads {
                        report: &r,
                        palette: Palette::Mono,
                        by_cpu: false,
                        pool: None,
                    },
                    f.area(),
                );
            })
            .unwrap();
            let text = rows(&t);
            let all = text.join("\n");
            let what = format!("{pool} pool threads at {w}x{h} ({layout:?})");
            // Every figure with its % and the same base.
            let line = |key: &str| text.iter().find(|l| l.contains(key)).cloned();
            let process = line("process").unwrap_or_else(|| panic!("{what}\n{all}"));
            assert!(process.contains(" % of 200 %"), "{what}\n{all}");
            let others = line("other procs").unwrap_or_else(|| panic!("{what}\n{all}"));
            assert!(others.contains("37.5 % of 200 %"), "{what}\n{all}");
            let sum: f64 = r
                .threads
                .iter()
                .filter(|t| t.name.starts_with("pool-"))
                .map(|t| t.percent)
                .sum();
            let want = format!("{sum:.1} % of {pool} thread");
            let total = line("pool total").unwrap_or_else(|| panic!("{what}\n{all}"));
            assert!(total.contains(&want), "{what}: {want}\n{all}");
            // main, physics, the pool, then the rest, whatever the ids.
            let at = |name: &str| {
                let pat = format!("{name} ");
                text.iter().position(|l| l.contains(&pat))
            };
            let main = at("main").unwrap();
            assert!(main <= at("physics").unwrap(), "{what}\n{all}");
            if layout == Layout::Rows {
                assert!(
                    at("physics").unwrap() < at("pool-0").unwrap(),
                    "{what}\n{all}"
                );
                assert!(
                    at("pool-0").unwrap() < at("input").unwrap(),
                    "{what}\n{all}"
                );
                assert!(text[1].contains("CPU %"), "{what}\n{all}");
                // The id, as `top -H` shows it, on wide panels.
                assert_eq!(
                    all.contains("5000"),
                    iw >= threads::TID_WIDTH,
                    "{what}\n{all}"
                );
            }
            // The grid only when a line per thread's figure does not fit.
            let grid = all.contains(&format!("pool x{pool}:"));
            assert_eq!(grid, layout == Layout::Grid, "{what}\n{all}");
            assert_eq!(
                grid,
                panel.column_lines(iw).len() > ih,
                "{what}: grid drawn with rows to spare\n{all}"
            );
            if grid {
                assert!(all.contains(threads::LEGEND), "{what}\n{all}");
            } else {
                for t in &r.threads {
                    let name: String = t.name.chars().take(11).collect();
                    assert!(all.contains(&name), "{what}: {name} missing\n{all}");
                }
            }
            insta::assert_snapshot!(format!("threads_{w}x{h}_pool_{pool}"), t.backend());
        }
    }
}

#[test]
fn sparklines_tell_one_percent_from_fifteen() {
    let mut r = report(0);
    r.threads[0].history = vec![1.0; 10];
    r.threads[1].history = vec![15.0; 10];
    let top = threads::scale_top(&r);
    assert_eq!(top, 20.0);
    let low = threads::sparkline(&r.threads[0].history, 10, top);
    let high = threads::sparkline(&r.threads[1].history, 10, top);
    assert_eq!(low, "▁".repeat(10));
    assert_eq!(high, "▆".repeat(10));
    // At full load the scale is 100 % and idle stays blank.
    r.threads[2].history = vec![95.0];
    assert_eq!(threads::scale_top(&r), 100.0);
    assert_eq!(threads::sparkline(&[0.0], 1, 100.0), " ");
}

#[test]
fn s_sorts_the_rows_by_cpu_and_back() {
    use ballpit::tui::keys::Action;
    use ballpit::tui::state::AppState;
    let r = report(2);
    let draw = |by_cpu| {
        let mut t = Terminal::new(TestBackend::new(70, 16)).unwrap();
        t.draw(|f| {
            f.render_widget(
                Threads {
                    report: &r,
                    palette: Palette::Mono,
                    by_cpu,
                    pool: None,
                },
                f.area(),
            );
        })
        .unwrap();
        rows(&t)
    };
    let at = |text: &[String], name: &str| {
        let pat = format!("│{name} ");
        text.iter().position(|l| l.contains(&pat)).unwrap()
    };
    let fixed = draw(false);
    assert!(at(&fixed, "main") < at(&fixed, "pool-0"), "{fixed:#?}");
    let busy = draw(true);
    // pool-0 at 40 % above main at 3.1 % above physics at 1.2 %.
    assert!(at(&busy, "pool-0") < at(&busy, "main"), "{busy:#?}");
    assert!(at(&busy, "main") < at(&busy, "physics"), "{busy:#?}");
    assert!(busy[0].contains("threads by CPU"), "{busy:#?}");
    // The key toggles the state the panel reads.
    let settings = settings(2);
    let mut st = AppState::new(&settings, 4, 0.1, 30.0);
    let ran = ballpit::engine::Engine::new(ballpit::physics::World::new(1.0, Vec::new()), settings)
        .unwrap()
        .snapshot()
        .clone();
    assert!(!st.threads_by_cpu);
    assert!(st.apply(Action::SortThreads, &ran).is_empty());
    assert!(st.threads_by_cpu);
    st.apply(Action::SortThreads, &ran);
    assert!(!st.threads_by_cpu);
}

/// A real pool frame of `exact` (40 000 spheres: enough for the frame's
/// readouts to spread over both lanes): the panel says one thread is busy,
/// and why, not what the readouts kept busy; `swept` on the tour's 8 000
/// spheres has the work for both (the lane rule is by work).
#[test]
fn the_pool_line_says_a_serial_model_keeps_one_thread_busy() {
    use ballpit::engine::{Engine, Settings, Threading};
    use ballpit::physics::ModelKind;
    use ballpit::scene::{SceneSpec, build_world};
    let world = |count, radius| {
        build_world(&SceneSpec {
            count: Some(count),
            radius,
            ..SceneSpec::default()
        })
        .unwrap()
    };
    for (model, world, want) in [
        (
            ModelKind::Exact,
            world(40_000, Some(0.004)),
            "pool: 1 of 2 busy — exact is serial",
        ),
        (ModelKind::Swept, world(8000, None), "pool: 2 of 2 busy"),
    ] {
        let mut e = Engine::new(
            world,
            Settings {
                model,
                threading: Threading::Pool,
                ..settings(2)
            },
        )
        .unwrap();
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
        let line = threads::pool_line_of(e.snapshot());
        assert_eq!(line.as_deref(), Some(want), "{model}");
    }
}

/// The pool line with the parallelism the engine measured: whole where it
/// fits, without ` (work/span)` where not, and the figure on a row of its
/// own when even that is too wide; never past the panel's edge at 80x24.
#[test]
fn the_pool_line_gives_the_parallelism_within_the_panel() {
    use ballpit::physics::ModelKind;
    use ballpit::physics::exec::{Bound, Busy};
    let mut snap =
        ballpit::engine::Engine::new(ballpit::physics::World::new(1.0, Vec::new()), settings(2))
            .unwrap()
            .snapshot()
            .clone();
    let busy = |busy, threads, bound| Busy {
        busy,
        threads,
        bound,
    };
    snap.pool_busy = Some(busy(2, 2, Bound::Threads));
    snap.parallelism = Some(38.4);
    let line = threads::pool_line_of(&snap).unwrap();
    assert_eq!(line, "pool: 2 of 2 busy · parallelism 38 (work/span)");
    snap.parallelism = Some(1.46);
    assert_eq!(
        threads::pool_line_of(&snap).unwrap(),
        "pool: 2 of 2 busy · parallelism 1.5 (work/span)"
    );
    // A model on one lane: the line says so, and gives no figure.
    snap.one_lane = true;
    snap.settings.model = ModelKind::Exact;
    assert_eq!(
        threads::pool_line_of(&snap).unwrap(),
        "pool: 1 of 2 busy — exact is serial"
    );
    snap.one_lane = false;
    snap.settings.model = ModelKind::Swept;
    snap.parallelism = Some(38.4);
    // (At 80x24 a pool of 64 has no spare row for the pool line at all.)
    for (w, h, pool) in [
        (80u16, 24u16, 2usize),
        (120, 40, 2),
        (120, 40, 64),
        (200, 60, 2),
    ] {
        {
            let r = report(pool);
            // Two of two: nothing to explain; two of 64: one a core.
            let bound = if pool == 2 {
                Bound::Threads
            } else {
                Bound::Cores
            };
            snap.pool_busy = Some(busy(2, pool, bound));
            let area = layout::areas(Rect::new(0, 0, w, h), &r).unwrap().threads;
            let mut t = Terminal::new(TestBackend::new(area.width, area.height)).unwrap();
            t.draw(|f| {
                f.render_widget(
                    Threads {
                        report: &r,
                        palette: Palette::Mono,
                        by_cpu: false,
                        pool: threads::pool_line_of(&snap),
                    },
                    f.area(),
                );
            })
            .unwrap();
            let text = rows(&t);
            let all = text.join("\n");
            let inner = usize::from(area.width) - 2;
            let full = threads::pool_line_of(&snap).unwrap();
            let at = text.iter().position(|l| l.contains("pool: 2 of")).unwrap();
            let shown = text[at].trim_matches('│').trim_end();
            if full.chars().count() <= inner {
                assert_eq!(shown, full, "{w}x{h} pool {pool}\n{all}");
            } else {
                // Cut where it must be, and the figure still shown.
                assert!(shown.chars().count() < full.chars().count(), "{all}");
                assert!(all.contains("parallelism 38"), "{w}x{h} pool {pool}\n{all}");
            }
            assert!(
                text.iter()
                    .all(|l| l.chars().count() == usize::from(area.width))
            );
            insta::assert_snapshot!(format!("parallelism_{w}x{h}_pool_{pool}"), t.backend());
        }
    }
}
