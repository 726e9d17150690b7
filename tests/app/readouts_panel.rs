//! The readouts panel at fixed states, drawn on ratatui's `TestBackend`:
//! what ran (not what was asked), the steps cut, the caps and budgets hit,
//! paused and frozen, and notices that wrap.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::screen::{rows, settings};
use crate::tui_snapshots::{
    mode_state, ran, render, report_for, screen, snapshot, snapshot_at, state, stats,
};
use ballpit::engine::{Settings, Snapshot, Threading};
use ballpit::physics::ModelKind;
use ballpit::tui::readouts::Readouts;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

fn readouts(st: &AppState, snap: &Snapshot, palette: Palette) -> Terminal<TestBackend> {
    let stats = stats();
    render(44, ballpit::tui::readouts::HEIGHT, |f| {
        f.render_widget(
            Readouts {
                state: st,
                snap,
                stats: &stats,
                palette,
            },
            f.area(),
        );
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
fn readouts_panel_says_when_the_work_budget_was_hit() {
    let mut snap = snapshot();
    snap.counters.capped_steps = 3;
    snap.counters.budget_steps = 2;
    let t = readouts(&state(), &snap, Palette::C16);
    let text = format!("{:?}", t.backend().buffer());
    assert!(text.contains("work budget hit in 3 steps"), "{text}");
    assert!(!text.contains("event cap"), "{text}");
}

#[test]
fn readouts_panel_marks_an_overlap_readout_cut_at_its_budget_as_a_lower_bound() {
    let mut snap = snapshot();
    snap.max_overlap_rel = 1.5;
    let text = |snap: &ballpit::engine::Snapshot| {
        format!(
            "{:?}",
            readouts(&state(), snap, Palette::C16).backend().buffer()
        )
    };
    let whole = text(&snap);
    assert!(whole.contains("overlap    1.5e0 "), "{whole}");
    assert!(!whole.contains('≥'), "{whole}");
    snap.overlap_partial = true;
    let cut = text(&snap);
    assert!(cut.contains("overlap    ≥1.5e0"), "{cut}");
}

#[test]
fn readouts_panel_says_exact_runs_on_one_thread_in_pool_mode() {
    let mut st = state();
    st.threading = Threading::Pool;
    st.model = ballpit::physics::ModelKind::Exact;
    let t = readouts(&st, &ran(&st), Palette::C16);
    let text = format!("{:?}", t.backend().buffer());
    assert!(text.contains("pool     exact on 1 pool thread"), "{text}");
}

#[test]
fn readouts_panel_paused_in_pool_mode() {
    let mut st = state();
    st.threading = Threading::Pool;
    st.threads = 3;
    st.paused = true;
    let t = readouts(&st, &ran(&st), Palette::Mono);
    insta::assert_snapshot!(t.backend());
    // Without colour, the pause cue is reverse video.
    let buf = t.backend().buffer();
    let y = (0..ballpit::tui::readouts::HEIGHT)
        .find(|&y| buf[(2, y)].symbol() == "P")
        .expect("the PAUSED line");
    assert!(
        buf[(2, y)]
            .modifier
            .contains(ratatui::style::Modifier::REVERSED)
    );
}

/// The rows that say what ran read the snapshot, never the state: a state
/// asking for one thing beside a snapshot that ran another shows the
/// snapshot's (as between a key and the frame that applies it).
#[test]
fn readouts_show_the_mode_threads_model_and_tick_that_ran_not_those_asked() {
    let compact = |st: &AppState, snap: &Snapshot| {
        let stats = stats();
        let t = render(44, ballpit::tui::readouts::COMPACT_HEIGHT, |f| {
            f.render_widget(
                Readouts {
                    state: st,
                    snap,
                    stats: &stats,
                    palette: Palette::C16,
                },
                f.area(),
            );
        });
        rows(&t).join("\n")
    };
    // Asked: pool of 3, exact, tick 5. Ran: worker, swept, tick 2.
    let mut st = mode_state(Threading::Pool, 3);
    st.model = ModelKind::Exact;
    st.tick = 5;
    let worker = snapshot_at(Settings {
        threading: Threading::Worker,
        tick: 2,
        ..settings(2)
    });
    let text = rows(&readouts(&st, &worker, Palette::C16)).join("\n");
    assert!(
        text.contains("threading  worker   1 physics thread "),
        "{text}"
    );
    assert!(text.contains("tick       2 steps/frame"), "{text}");
    assert!(text.contains("model      swept"), "{text}");
    assert!(!text.contains("pool") && !text.contains("exact"), "{text}");
    let small = compact(&st, &worker);
    assert!(small.contains("worker   1 physics thread "), "{small}");
    assert!(small.contains("tick    2 steps"), "{small}");
    assert!(small.contains("model   swept"), "{small}");
    // Asked: off. Ran: a pool of 3, whose threads the engine names.
    let st = state();
    let pool = snapshot_at(Settings {
        threading: Threading::Pool,
        threads: 3,
        ..settings(2)
    });
    assert_eq!(pool.physics_threads, ["pool-0", "pool-1", "pool-2"]);
    let text = rows(&readouts(&st, &pool, Palette::C16)).join("\n");
    assert!(
        text.contains("threading  pool     3 physics threads"),
        "{text}"
    );
    assert!(!text.contains("threading  off"), "{text}");
    // One lane is the engine's word: exact ran in split while swept is
    // asked, and the row says where exact ran.
    let split = snapshot_at(Settings {
        threading: Threading::Split,
        model: ModelKind::Exact,
        ..settings(2)
    });
    assert!(split.one_lane);
    let text = rows(&readouts(&st, &split, Palette::C16)).join("\n");
    assert!(text.contains("split    exact runs on physics"), "{text}");
    assert!(text.contains("model      exact"), "{text}");
    // Frozen is the tick that ran: a snapshot of tick 0 beside a state
    // that asks for 1 (a paused frame keeps the tick, so only tick 0 does).
    let frozen = snapshot_at(Settings {
        tick: 0,
        ..settings(2)
    });
    let text = rows(&readouts(&st, &frozen, Palette::C16)).join("\n");
    assert!(
        text.contains("tick       0        steps/frame  frozen"),
        "{text}"
    );
    // Flat out is the screen's: "max" and the tick x goes back to.
    let mut st = state();
    st.flat_out = true;
    st.tick = 7;
    let text = rows(&readouts(&st, &worker, Palette::C16)).join("\n");
    assert!(text.contains("max      flat out (x: tick 7)"), "{text}");
}

#[test]
fn readouts_show_the_radius_in_force_not_the_one_asked_for() {
    let mut st = state();
    // Asked for 0.5; the snapshot's spheres span 0.08 to 0.15.
    st.radius = 0.5;
    let t = readouts(&st, &ran(&st), Palette::C16);
    let text = rows(&t).join("\n");
    assert!(text.contains("radius     0.08000-0.15000"), "{text}");
    assert!(!text.contains("0.50000"), "{text}");
}

#[test]
fn paused_and_frozen_say_so_instead_of_a_frame_rate() {
    let mut st = state();
    st.paused = true;
    let text = rows(&readouts(&st, &ran(&st), Palette::C16)).join("\n");
    assert!(text.contains("fps        paused"), "{text}");
    assert!(!text.contains("29.9"), "{text}");
    assert!(text.contains("physics    idle"), "{text}");
    let mut st = state();
    st.tick = 0;
    let text = rows(&readouts(&st, &ran(&st), Palette::C16)).join("\n");
    assert!(text.contains("fps        frozen (tick 0)"), "{text}");
    // The compact form too.
    let t = screen(80, 24, &st, &report_for(Threading::Pool, 2));
    let text = rows(&t).join("\n");
    assert!(text.contains("fps     frozen"), "{text}");
}

#[test]
fn a_long_notice_wraps_instead_of_being_cut() {
    let mut st = state();
    let notice = "count limit: no free space for more spheres (1234 of 2000)";
    st.notice = Some(notice.into());
    let r = report_for(Threading::Pool, 2);
    let small = ballpit::tui::layout::areas(ratatui::layout::Rect::new(0, 0, 80, 24), &r).unwrap();
    for (t, x0) in [
        (readouts(&st, &ran(&st), Palette::C16), 0),
        (screen(80, 24, &st, &r), small.readouts.x),
    ] {
        let text: String = rows(&t)
            .iter()
            .map(|l| l.chars().skip(usize::from(x0)).collect::<String>())
            .map(|l| l.replace('│', " "))
            .collect::<Vec<_>>()
            .join(" ");
        let words: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(words.contains(notice), "{words}");
    }
}
