//! Every notice the app can produce is shown whole inside the readouts
//! panel at 80x24 and 120x40 (issue 28): wrapped between words, no word cut
//! at the border, nothing lost. The notices come from the code itself: each
//! key of the key table pressed in many states, the engine's edits and
//! resets, the memory check's screen form, the pause and the event cap.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::names::thread_names;
use crate::common::screen;
use ballpit::cpu::{CpuReport, ThreadLoad, ThreadRole};
use ballpit::engine::{Command, Engine, MAX_THREADS, Settings, Snapshot, Threading};
use ballpit::physics::{ModelKind, Sphere, World, edit};
use ballpit::tui::canvas::Raster;
use ballpit::tui::keys::TABLE;
use ballpit::tui::layout::{self, View};
use ballpit::tui::look::DrawStyle;
use ballpit::tui::readouts::{NOTICE_ROWS, Readouts, Stats};
use ballpit::tui::state::{AppState, FPS_STEPS, MAX_KEY_COUNT, MAX_TICK, MIN_RADIUS};
use ballpit::tui::theme::Palette;
use ballpit::tui::threads;
use glam::DVec3;
use rand::SeedableRng;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::layout::Rect;
use ratatui::style::Modifier;
use std::collections::BTreeMap;

fn settings(model: ModelKind, threading: Threading) -> Settings {
    Settings {
        model,
        threading,
        ..screen::settings(2)
    }
}

fn world() -> World {
    let spheres = (0..300)
        .map(|i| {
            let f = f64::from(i);
            let pos = DVec3::new(0.05 + (f * 0.37) % 0.9, 0.05 + (f * 0.53) % 0.9, 0.5);
            Sphere::new(pos, DVec3::new(0.1, 0.0, 0.0), 0.004)
        })
        .collect();
    World::new(1.0, spheres)
}

fn snapshot() -> Snapshot {
    let e = Engine::new(world(), settings(ModelKind::Swept, Threading::Off)).unwrap();
    e.snapshot().clone()
}

/// Every state a key's notice depends on: each mode and model, paused or
/// not, flat out or not, the chart or the canvas, and the settings at their
/// low limits, high limits and one step below the high ones.
fn states() -> Vec<AppState> {
    let mut out = Vec::new();
    for threading in Threading::ALL {
        for model in ModelKind::ALL {
            for flags in 0..8u8 {
                for limit in 0..3 {
                    let mut st = AppState::new(&settings(model, threading), 300, 0.004, 30.0);
                    (st.paused, st.flat_out, st.chart) =
                        (flags & 1 != 0, flags & 2 != 0, flags & 4 != 0);
                    let (points, shaded) = (DrawStyle::PointsSpeed, DrawStyle::Shaded);
                    (st.threads, st.tick, st.count, st.radius, st.fps, st.style) = match limit {
                        0 => (1, 0, 1, MIN_RADIUS * 1.1, FPS_STEPS[0], points),
                        1 => (
                            MAX_THREADS,
                            MAX_TICK,
                            MAX_KEY_COUNT,
                            1.0,
                            FPS_STEPS[6],
                            points,
                        ),
                        _ => (
                            MAX_THREADS - 1,
                            MAX_TICK - 1,
                            MAX_KEY_COUNT / 2,
                            0.5,
                            60.0,
                            shaded,
                        ),
                    };
                    out.push(st);
                }
            }
        }
    }
    out
}

/// The notices the keys give, each with a state that shows it.
fn key_notices(into: &mut BTreeMap<String, (AppState, Snapshot)>) {
    // What ran before the key: the state's own mode and model, so the
    // notices that read the snapshot (`exact` on one lane) come up too.
    let mut ran = std::collections::HashMap::new();
    let actions: Vec<_> = TABLE
        .iter()
        .flat_map(|b| b.presses.iter().map(|(_, a)| *a))
        .collect();
    for st in states() {
        let snap: &Snapshot = ran.entry((st.threading, st.model)).or_insert_with(|| {
            let e = Engine::new(world(), settings(st.model, st.threading)).unwrap();
            e.snapshot().clone()
        });
        // The pause's own line, when no key has spoken.
        if let Some(n) = readouts(&st, snap).notice() {
            into.entry(n).or_insert_with(|| (st.clone(), snap.clone()));
        }
        for a in &actions {
            let mut after = st.clone();
            after.apply(*a, snap);
            if let Some(n) = after.notice.clone() {
                into.entry(n).or_insert_with(|| (after, snap.clone()));
            }
        }
    }
}

/// The notices the engine leaves in its snapshot, and the memory check's.
fn engine_notices() -> Vec<String> {
    let mut out = Vec::new();
    let s = settings(ModelKind::Swept, Threading::Off);
    let frame = |e: &mut Engine, c: Command| {
        e.command(c);
        e.command(Command::SetTick(0));
        e.start_frame().unwrap();
        e.finish_frame().unwrap().notice.clone()
    };
    // Radius: the box full before the radius asked for.
    let mut e = Engine::new(world(), s).unwrap();
    out.extend(frame(&mut e, Command::SetRadius(0.3)));
    // Count: more than the box holds (a few big spheres), or the machine.
    let big = vec![Sphere::new(DVec3::splat(0.5), DVec3::X, 0.2)];
    let mut e = Engine::new(World::new(1.0, big), s).unwrap();
    out.extend(frame(&mut e, Command::SetCount(1000)));
    // The widest count figures: a million spheres kept, two million asked.
    let many = vec![Sphere::new(DVec3::splat(0.5), DVec3::X, 0.6); MAX_KEY_COUNT / 2 + 1];
    let mut w = World::new(1.0, many);
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    out.extend(edit::set_count(&mut w, MAX_KEY_COUNT, 0.6, 1.0, &mut rng));
    let need = ballpit::memory::need(MAX_KEY_COUNT, None);
    for free in [0, 100 << 20, need - 1] {
        out.extend(ballpit::memory::count_notice(MAX_KEY_COUNT, Some(free)));
    }
    // Threads the system refused while running, and what runs instead.
    let refused = ballpit::engine::Refused {
        what: format!("{MAX_THREADS} pool threads"),
        cause: "Resource temporarily unavailable (os error 11)".into(),
    };
    let kept = [
        ballpit::engine::KEPT_WORKER.to_string(),
        ballpit::engine::kept_pool(MAX_THREADS - 1),
    ];
    out.extend(kept.iter().map(|k| refused.notice(k)));
    // Reset: no start kept, a start that rebuilt differently, one that failed.
    let mut e = Engine::headless(world(), s).unwrap();
    out.extend(frame(&mut e, Command::Reset));
    let mut e = Engine::with_rebuild(world(), s, Box::new(|| Ok(World::new(1.0, vec![])))).unwrap();
    out.extend(frame(&mut e, Command::Reset));
    out
}

/// A reset whose scene file went away: the one notice of unbounded length
/// (it quotes the file's path and the system's error).
fn failed_reset() -> String {
    let s = settings(ModelKind::Swept, Threading::Off);
    let gone = "/home/someone/projects/ballpit-scenes/crowded/mixed-radii.toml";
    let fail = move || {
        Err(anyhow::anyhow!(
            "cannot read {gone}: No such file or directory"
        ))
    };
    let mut e = Engine::with_rebuild(world(), s, Box::new(fail)).unwrap();
    e.command(Command::Reset);
    e.start_frame().unwrap();
    e.finish_frame().unwrap().notice.clone().unwrap()
}

/// Every notice, with a state and snapshot that show it.
fn all_notices() -> BTreeMap<String, (AppState, Snapshot)> {
    let mut all = BTreeMap::new();
    key_notices(&mut all);
    let base = AppState::new(
        &settings(ModelKind::Swept, Threading::Off),
        300,
        0.004,
        30.0,
    );
    for n in engine_notices() {
        let mut st = base.clone();
        st.notice = Some(n.clone());
        all.insert(n, (st, snapshot()));
    }
    // Steps that hit the work budget or the event cap, many of them.
    for budget in [0, 1] {
        let mut snap = snapshot();
        snap.counters.capped_steps = 10u64.pow(12);
        snap.counters.budget_steps = budget;
        let text = readouts(&base, &snap).notice().unwrap();
        all.insert(text, (base.clone(), snap));
    }
    all
}

fn readouts<'a>(st: &'a AppState, snap: &'a Snapshot) -> Readouts<'a> {
    static STATS: std::sync::LazyLock<Stats> = std::sync::LazyLock::new(|| Stats {
        fps: 30.0,
        physics_seconds: 0.001,
        render_seconds: 0.001,
        frame_bytes: 4000,
        steps_per_second: 30.0,
        collisions_per_second: 10.0,
        ..Stats::default()
    });
    Readouts {
        state: st,
        snap,
        stats: &STATS,
        palette: Palette::C16,
    }
}

/// The app's threads in `mode`, with `pool` pool threads.
fn report(mode: Threading, pool: usize) -> CpuReport {
    let names = thread_names(
        &["main", "physics", "signals", "input", "output"],
        mode,
        pool,
    );
    let threads: Vec<ThreadLoad> = (0..names.len())
        .zip(names)
        .map(|(i, name)| ThreadLoad {
            tid: 100 + i32::try_from(i).unwrap(),
            role: ThreadRole::of(&name),
            name,
            percent: 1.0 + (i % 7) as f64,
            cpu_seconds: 1.0,
            history: vec![1.0 + (i % 7) as f64; 60],
        })
        .collect();
    CpuReport::new(threads, 2, Some(12.5))
}

/// What the screen shows in the notice's style, row by row, and whether
/// any of it lies outside `inside`.
fn notice_cells(t: &Terminal<TestBackend>, inside: Rect) -> (Vec<String>, bool) {
    let alert = Palette::C16.alert();
    let buf = t.backend().buffer();
    let mut rows = Vec::new();
    let mut outside = false;
    for y in 0..buf.area.height {
        let mut row = String::new();
        for x in 0..buf.area.width {
            let c = &buf[(x, y)];
            if Some(c.fg) == alert.fg && c.modifier.contains(Modifier::BOLD) {
                outside |= !inside.contains((x, y).into());
                row.push_str(c.symbol());
            }
        }
        if !row.is_empty() {
            rows.push(row);
        }
    }
    (rows, outside)
}

fn reports() -> [CpuReport; 5] {
    [
        report(Threading::Off, 0),
        report(Threading::Split, 0),
        report(Threading::Pool, 2),
        report(Threading::Pool, 64),
        report(Threading::Pool, 256),
    ]
}

/// The screen at `w` x `h` showing `st`'s notice: the notice's rows as
/// drawn, the readouts' inner area, and the whole screen's text.
fn shown(
    st: &AppState,
    snap: &Snapshot,
    r: &CpuReport,
    (w, h): (u16, u16),
) -> (Vec<String>, Rect, String) {
    let notice = readouts(st, snap).notice();
    let a = layout::areas_with(Rect::new(0, 0, w, h), r, notice.as_deref()).unwrap();
    let view = View {
        state: st,
        snap,
        stats: readouts(st, snap).stats,
        report: r,
        palette: Palette::C16,
        aspect: 2.0,
    };
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(|f| layout::draw(f, &mut Raster::new(), &view))
        .unwrap();
    let inner = Rect {
        x: a.readouts.x + 1,
        y: a.readouts.y + 1,
        width: a.readouts.width - 2,
        height: a.readouts.height - 2,
    };
    let (rows, outside) = notice_cells(&t, inner);
    assert!(!outside, "{notice:?} at {w}x{h}: drawn outside the panel");
    (rows, inner, screen::text(&t))
}

/// `rows` hold `text` whole: nothing lost, in order, and every word that
/// fits a row whole in one (only a word wider than the panel is cut).
fn assert_whole(rows: &[String], text: &str, width: u16, what: &str) {
    assert_eq!(squeeze(&rows.concat()), squeeze(text), "{what}: {rows:#?}");
    for word in text.split_whitespace() {
        let fits = word.chars().count() + 2 <= usize::from(width);
        let whole = rows.iter().any(|r| r.split(' ').any(|w| w == word));
        assert!(!fits || whole, "{what}: {word:?} cut in {rows:#?}");
    }
}

fn squeeze(s: &str) -> String {
    s.split_whitespace().collect()
}

#[test]
fn every_notice_is_shown_whole_inside_the_readouts_panel() {
    let all = all_notices();
    // The list is the code's: a key table without notices, or an engine
    // that stopped giving them, would leave it short.
    assert!(all.len() >= 25, "{:#?}", all.keys().collect::<Vec<_>>());
    for (text, (st, snap)) in &all {
        assert_eq!(readouts(st, snap).notice().as_deref(), Some(text.as_str()));
        for size in [(80u16, 24u16), (120, 40)] {
            for r in &reports() {
                let what = format!("{text:?} at {size:?} with {} threads", r.threads.len());
                let (rows, inner, screen) = shown(st, snap, r, size);
                assert_whole(&rows, text, inner.width, &what);
                // The kept rows were enough: the figures and every thread
                // stay as they were without the notice.
                assert!(rows.len() <= usize::from(NOTICE_ROWS), "{what}: {rows:#?}");
                assert!(screen.contains("other procs"), "{what}");
            }
        }
    }
}

#[test]
fn a_notice_longer_than_the_kept_rows_takes_the_threads_spare_rows() {
    let text = failed_reset();
    assert!(text.starts_with("reset: cannot read /home/"), "{text}");
    let mut st = AppState::new(
        &settings(ModelKind::Swept, Threading::Off),
        300,
        0.004,
        30.0,
    );
    st.notice = Some(text.clone());
    let snap = snapshot();
    for size in [(80u16, 24u16), (120, 40)] {
        for r in &reports() {
            let what = format!("{text:?} at {size:?} with {} threads", r.threads.len());
            let (rows, inner, screen) = shown(&st, &snap, r, size);
            // Every thread still shown: the rows come from blank ones, or
            // from a layout of the threads that still shows them all.
            assert!(screen.contains("other procs"), "{what}");
            let threads = layout::areas_with(Rect::new(0, 0, size.0, size.1), r, Some(&text))
                .unwrap()
                .threads;
            // The least rows that show every thread (a cell each, or the
            // rows they had anyway when cells must be shared).
            let before = layout::areas(Rect::new(0, 0, size.0, size.1), r)
                .unwrap()
                .threads;
            let least = threads::full_height(r)
                .min(threads::compact_height(r, usize::from(threads.width - 2)))
                .min(before.height);
            assert!(threads.height >= least, "{what}: a thread hidden");
            assert!(screen.contains("threading"), "{what}: the figures lost");
            if squeeze(&rows.concat()) == squeeze(&text) {
                assert_whole(&rows, &text, inner.width, &what);
            } else {
                // Cut only when the threads had no row to spare, and it
                // says so; what shows is the start.
                assert_eq!(threads.height, least, "{what}: cut with rows to spare");
                let last = rows.last().unwrap();
                assert!(last.trim_end().ends_with('…'), "{what}: {rows:#?}");
                let seen = squeeze(&rows.concat());
                assert!(
                    squeeze(&text).starts_with(seen.trim_end_matches('…')),
                    "{what}: {rows:#?}"
                );
            }
        }
    }
    // Where the threads have blank rows, it is whole: at 120x40 always, and
    // at 80x24 with threading off.
    let (rows, inner, _) = shown(&st, &snap, &reports()[0], (80, 24));
    assert_whole(&rows, &text, inner.width, "off at 80x24");
    for r in &reports() {
        let (rows, inner, _) = shown(&st, &snap, r, (120, 40));
        assert_whole(&rows, &text, inner.width, "120x40");
    }
}
