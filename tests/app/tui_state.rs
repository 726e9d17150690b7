//! Every key's effect on the app state, without a terminal.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::screen::settings;
use ballpit::engine::{Command, Settings, Snapshot, Threading};
use ballpit::physics::ModelKind;
use ballpit::tui::keys::{Action, Press, lookup};
use ballpit::tui::look::{DrawStyle, LIGHT_STEPS};
use ballpit::tui::state::{AppState, CAMERA_STEP, MAX_PITCH, MAX_TICK, MIN_RADIUS, RADIUS_STEP};
use std::sync::LazyLock;

fn app() -> AppState {
    AppState::new(&settings(4), 1000, 0.02, 30.0)
}

/// What ran before the keys: the engine's first snapshot of a small scene
/// at `settings(4)`.
fn ran() -> &'static Snapshot {
    static RAN: LazyLock<Snapshot> = LazyLock::new(|| ran_with(settings(4)));
    &RAN
}

fn ran_with(s: Settings) -> Snapshot {
    use ballpit::physics::{Sphere, World};
    use glam::DVec3;
    let spheres = vec![Sphere::new(DVec3::splat(0.5), DVec3::X, 0.05)];
    ballpit::engine::Engine::new(World::new(1.0, spheres), s)
        .unwrap()
        .snapshot()
        .clone()
}

fn key(app: &mut AppState, press: Press) -> Vec<Command> {
    key_after(app, press, ran())
}

/// A key pressed with `ran` the latest snapshot.
fn key_after(app: &mut AppState, press: Press, ran: &Snapshot) -> Vec<Command> {
    let a = lookup(press).expect("a mapped key");
    app.apply(a, ran)
}

#[test]
fn q_esc_and_ctrl_c_quit() {
    for code in [Press::Char('q'), Press::Esc] {
        let mut a = app();
        assert!(key(&mut a, code).is_empty());
        assert!(a.quit, "{code:?}");
    }
    let mut a = app();
    let ctrl_c = lookup(Press::Ctrl('c')).unwrap();
    a.apply(ctrl_c, ran());
    assert!(a.quit);
}

#[test]
fn esc_closes_the_help_before_it_quits() {
    let mut a = app();
    key(&mut a, Press::Char('?'));
    assert!(a.help);
    key(&mut a, Press::Esc);
    assert!(!a.help && !a.quit);
    key(&mut a, Press::Char('?'));
    key(&mut a, Press::Char('?'));
    assert!(!a.help);
}

#[test]
fn t_goes_off_to_the_last_threaded_mode_and_back() {
    let mut a = app();
    assert_eq!(
        key(&mut a, Press::Char('t')),
        [Command::SetThreading(Threading::Worker)]
    );
    assert_eq!(a.threading, Threading::Worker);
    key(&mut a, Press::Char('d'));
    assert_eq!(a.threading, Threading::Pool);
    assert_eq!(
        key(&mut a, Press::Char('t')),
        [Command::SetThreading(Threading::Off)]
    );
    assert_eq!(a.threading, Threading::Off);
    assert_eq!(
        key(&mut a, Press::Char('t')),
        [Command::SetThreading(Threading::Pool)]
    );
}

#[test]
fn d_cycles_worker_pool_split_and_only_picks_while_off() {
    let mut a = app();
    key(&mut a, Press::Char('t'));
    let mut seen = vec![];
    for _ in 0..3 {
        let cmds = key(&mut a, Press::Char('d'));
        assert_eq!(cmds, [Command::SetThreading(a.threading)]);
        seen.push(a.threading);
    }
    assert_eq!(seen, [Threading::Pool, Threading::Split, Threading::Worker]);
    // While off, `d` chooses what `t` will switch to, and sends nothing.
    let mut a = app();
    assert!(key(&mut a, Press::Char('d')).is_empty());
    assert_eq!(
        (a.threading, a.last_threaded),
        (Threading::Off, Threading::Pool)
    );
    assert!(a.notice.as_deref().unwrap().contains("pool"));
    key(&mut a, Press::Char('t'));
    assert_eq!(a.threading, Threading::Pool);
}

#[test]
fn p_and_shift_p_change_the_pool_within_limits() {
    let mut a = app();
    assert_eq!(key(&mut a, Press::Char('P')), [Command::SetThreads(5)]);
    assert_eq!(key(&mut a, Press::Char('p')), [Command::SetThreads(4)]);
    for _ in 0..3 {
        key(&mut a, Press::Char('p'));
    }
    assert_eq!(a.threads, 1);
    assert!(key(&mut a, Press::Char('p')).is_empty());
    assert_eq!(a.threads, 1);
    assert!(a.notice.as_deref().unwrap().contains("limit"));
}

#[test]
fn brackets_change_the_tick_and_zero_freezes() {
    let mut a = app();
    // The tick goes to the engine like any setting, so the snapshot that
    // answers it says the tick that ran.
    assert_eq!(key(&mut a, Press::Char(']')), [Command::SetTick(2)]);
    assert_eq!(a.tick, 2);
    key(&mut a, Press::Char('['));
    assert_eq!(key(&mut a, Press::Char('[')), [Command::SetTick(0)]);
    assert_eq!(a.tick, 0);
    assert!(!a.running());
    assert!(key(&mut a, Press::Char('[')).is_empty());
    assert_eq!(a.tick, 0);
    assert!(a.notice.as_deref().unwrap().contains("frozen"));
    a.tick = MAX_TICK;
    key(&mut a, Press::Char(']'));
    assert_eq!(a.tick, MAX_TICK);
}

#[test]
fn space_pauses_and_resumes() {
    let mut a = app();
    assert!(a.running());
    key(&mut a, Press::Char(' '));
    assert!(a.paused && !a.running());
    key(&mut a, Press::Char(' '));
    assert!(a.running());
}

#[test]
fn n_halves_and_shift_n_doubles_the_count() {
    let mut a = app();
    assert_eq!(key(&mut a, Press::Char('N')), [Command::SetCount(2000)]);
    assert_eq!(key(&mut a, Press::Char('n')), [Command::SetCount(1000)]);
    a.count = 1;
    assert!(key(&mut a, Press::Char('n')).is_empty());
    assert_eq!(a.count, 1);
}

#[test]
fn r_and_shift_r_scale_the_radius() {
    let mut a = app();
    let cmds = key(&mut a, Press::Char('R'));
    assert_eq!(cmds, [Command::SetRadius(0.02 * RADIUS_STEP)]);
    let cmds = key(&mut a, Press::Char('r'));
    assert_eq!(cmds, [Command::SetRadius(0.02 * RADIUS_STEP / RADIUS_STEP)]);
    a.radius = MIN_RADIUS;
    assert!(key(&mut a, Press::Char('r')).is_empty());
    assert_eq!(a.radius, MIN_RADIUS);
}

#[test]
fn m_cycles_the_model() {
    let mut a = app();
    let first = a.model;
    let cmds = key(&mut a, Press::Char('m'));
    assert_eq!(cmds, [Command::SetModel(first.next())]);
    assert_ne!(a.model, first);
    for _ in 1..ModelKind::ALL.len() {
        key(&mut a, Press::Char('m'));
    }
    assert_eq!(a.model, first);
}

#[test]
fn arrows_rotate_the_camera_and_pitch_stops_short_of_the_pole() {
    let mut a = app();
    let c0 = a.camera;
    key(&mut a, Press::Left);
    assert!((a.camera.yaw - (c0.yaw - CAMERA_STEP)).abs() < 1e-12);
    key(&mut a, Press::Right);
    key(&mut a, Press::Right);
    assert!((a.camera.yaw - (c0.yaw + CAMERA_STEP)).abs() < 1e-12);
    key(&mut a, Press::Up);
    assert!((a.camera.pitch - (c0.pitch + CAMERA_STEP)).abs() < 1e-12);
    key(&mut a, Press::Down);
    key(&mut a, Press::Down);
    assert!((a.camera.pitch - (c0.pitch - CAMERA_STEP)).abs() < 1e-12);
    for _ in 0..40 {
        key(&mut a, Press::Up);
    }
    assert_eq!(a.camera.pitch, MAX_PITCH);
}

#[test]
fn v_cycles_the_styles_and_l_moves_the_light_round() {
    let mut a = app();
    assert_eq!(a.style, DrawStyle::PointsSpeed);
    key(&mut a, Press::Char('v'));
    assert_eq!(a.style, DrawStyle::PointsDepth);
    key(&mut a, Press::Char('v'));
    assert_eq!(a.style, DrawStyle::Shaded);
    key(&mut a, Press::Char('v'));
    assert_eq!(a.style, DrawStyle::PointsSpeed);
    key(&mut a, Press::Char('l'));
    assert!(a.notice.as_deref().unwrap().contains("shaded"));
    a.style = DrawStyle::Shaded;
    for i in 2..=LIGHT_STEPS + 1 {
        key(&mut a, Press::Char('l'));
        assert_eq!(a.light, i % LIGHT_STEPS);
        assert!(a.notice.is_none());
    }
}

#[test]
fn zero_resets_the_scene() {
    let mut a = app();
    assert_eq!(key(&mut a, Press::Char('0')), [Command::Reset]);
}

#[test]
fn f_and_shift_f_step_the_frame_rate() {
    let mut a = app();
    key(&mut a, Press::Char('F'));
    assert_eq!(a.fps, 60.0);
    key(&mut a, Press::Char('f'));
    key(&mut a, Press::Char('f'));
    assert_eq!(a.fps, 20.0);
    let mut b = AppState::new(&settings(4), 10, 0.1, 24.0);
    b.apply(Action::FasterFps, ran());
    assert_eq!(b.fps, 30.0);
    for _ in 0..10 {
        b.apply(Action::SlowerFps, ran());
    }
    assert_eq!(b.fps, 5.0);
}

#[test]
fn threading_given_on_the_command_line_is_what_t_returns_to() {
    let mut s = settings(4);
    s.threading = Threading::Split;
    let mut a = AppState::new(&s, 10, 0.1, 30.0);
    key(&mut a, Press::Char('t'));
    assert_eq!(a.threading, Threading::Off);
    key(&mut a, Press::Char('t'));
    assert_eq!(a.threading, Threading::Split);
}

#[test]
fn sync_takes_the_real_count_radius_and_the_engine_notice() {
    use ballpit::engine::Engine;
    use ballpit::physics::{Sphere, World};
    use glam::DVec3;
    let spheres = vec![
        Sphere::new(DVec3::splat(0.3), DVec3::X, 0.05),
        Sphere::new(DVec3::splat(0.7), DVec3::Y, 0.1),
    ];
    let engine = Engine::new(World::new(1.0, spheres), settings(4)).unwrap();
    let mut snap = engine.snapshot().clone();
    let mut a = app();
    key(&mut a, Press::Char('N'));
    snap.notice = Some("count limit: no free space".into());
    a.sync(&snap, true, false);
    assert_eq!((a.count, a.radius), (2, 0.1));
    assert_eq!(a.notice.as_deref(), Some("count limit: no free space"));
    // A frame that applied nothing of ours leaves the notice alone.
    snap.notice = None;
    a.sync(&snap, false, false);
    assert!(a.notice.is_some());
    // The next key's frame, with no limit hit, leaves no notice.
    key(&mut a, Press::Char('n'));
    a.sync(&snap, true, false);
    assert!(a.notice.is_none());
}

/// A frame that lands after more keys were pressed answers the keys before
/// them: its threading must not undo the later ones (`t` then `d` quickly
/// cycled from the mode `t` had left), but with no key since, what really
/// ran (threads the system refused fall back) is taken.
#[test]
fn sync_keeps_the_threading_of_keys_pressed_since_the_frame_started() {
    let mut a = app();
    let before = a.threading;
    key(&mut a, Press::Char('t'));
    assert_ne!(a.threading, before, "t switched the mode");
    let asked = a.threading;
    // The landing frame ran the settings from before `t`.
    let snap = ran().clone();
    assert_eq!(snap.settings.threading, before);
    a.sync(&snap, true, true);
    assert_eq!(a.threading, asked, "a key since the frame started stands");
    a.sync(&snap, true, false);
    assert_eq!(a.threading, before, "what ran, once no key is unanswered");
}

#[test]
fn c_swaps_the_canvas_for_the_chart_and_back() {
    let mut a = app();
    assert!(!a.chart);
    assert!(key(&mut a, Press::Char('c')).is_empty());
    assert!(a.chart);
    // Keys for the hidden canvas still act, and say why nothing shows.
    let yaw = a.camera.yaw;
    key(&mut a, Press::Left);
    assert!(a.camera.yaw < yaw);
    assert!(a.notice.as_deref().unwrap().contains("chart"));
    key(&mut a, Press::Char('c'));
    assert!(!a.chart);
    key(&mut a, Press::Left);
    assert!(a.notice.is_none());
}

#[test]
fn p_while_not_in_pool_mode_keeps_the_size_and_says_where_it_applies() {
    let mut a = app();
    assert_eq!(a.threading, Threading::Off);
    assert_eq!(key(&mut a, Press::Char('P')), [Command::SetThreads(5)]);
    assert_eq!(a.threads, 5);
    let n = a.notice.clone().unwrap();
    assert!(
        n.contains("pool threads 5") && n.contains("pool mode") && n.contains("off"),
        "{n}"
    );
    // In pool mode the key just acts.
    a.threading = Threading::Pool;
    assert_eq!(key(&mut a, Press::Char('p')), [Command::SetThreads(4)]);
    assert!(a.notice.is_none());
    // In pool mode with exact, the size has no effect either: the engine
    // said exact ran on one lane.
    let exact = ran_with(Settings {
        model: ModelKind::Exact,
        ..settings(4)
    });
    assert!(exact.one_lane);
    a.model = ModelKind::Exact;
    key_after(&mut a, Press::Char('P'), &exact);
    assert!(a.notice.as_deref().unwrap().contains("exact"));
    // Another model asked since: the snapshot cannot say, so no claim.
    a.model = ModelKind::Swept;
    key_after(&mut a, Press::Char('P'), &exact);
    assert!(a.notice.is_none());
}

#[test]
fn tick_keys_while_paused_say_the_tick_runs_on_resume() {
    let mut a = app();
    // The pause is the loop's to hold: the engine keeps its tick.
    assert!(key(&mut a, Press::Char(' ')).is_empty());
    // Paused, the tick is sent all the same: the held frame that answers
    // it runs no step but shows the tick the resume runs.
    assert_eq!(key(&mut a, Press::Char(']')), [Command::SetTick(2)]);
    assert_eq!(a.tick, 2);
    assert!(a.notice.as_deref().unwrap().contains("resumed"));
    assert!(key(&mut a, Press::Char(' ')).is_empty());
}

/// The pause as the loop holds it: a held frame applies the commands and
/// answers them with a fresh snapshot, but runs no step, and its settings
/// keep the tick for the resume (no tick 0 stands in for the pause).
#[test]
fn a_held_frame_answers_commands_without_a_step_and_keeps_the_tick() {
    use ballpit::engine::Engine;
    use ballpit::physics::{Sphere, World};
    use glam::DVec3;
    let spheres = vec![Sphere::new(DVec3::splat(0.5), DVec3::X, 0.05)];
    let mut e = Engine::new(World::new(1.0, spheres), settings(4)).unwrap();
    e.start_frame().unwrap();
    let t = e.finish_frame().unwrap().time;
    e.set_hold(true);
    e.command(Command::SetTick(7));
    e.command(Command::SetThreading(Threading::Worker));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    assert_eq!((snap.frame, snap.steps, snap.time), (2, 0, t));
    assert_eq!(
        (snap.settings.tick, snap.settings.threading),
        (7, Threading::Worker)
    );
    assert_eq!(snap.physics_threads, ["physics"]);
    e.set_hold(false);
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    assert_eq!((snap.steps, snap.settings.tick), (7, 7));
    assert!(snap.time > t);
}

#[test]
fn x_toggles_flat_out_and_goes_back_to_the_tick_before() {
    let mut a = app();
    a.tick = 0;
    assert!(!a.running());
    // Flat out needs a tick above 0 for the engine; the tick is kept.
    assert_eq!(key(&mut a, Press::Char('x')), [Command::SetTick(1)]);
    assert!(a.flat_out && a.running());
    assert_eq!((a.tick, a.engine_tick()), (0, 1));
    assert!(a.notice.as_deref().unwrap().contains("flat out"));
    // The tick keys leave the tick alone while flat out, and say so.
    key(&mut a, Press::Char(']'));
    assert_eq!(a.tick, 0);
    assert!(a.notice.as_deref().unwrap().contains("x goes back"));
    assert_eq!(key(&mut a, Press::Char('x')), [Command::SetTick(0)]);
    assert!(!a.flat_out && !a.running());
}

#[test]
fn esc_closes_the_help_then_the_chart_then_quits() {
    let mut a = app();
    a.help = true;
    a.chart = true;
    key(&mut a, Press::Esc);
    assert!(!a.help && a.chart && !a.quit);
    key(&mut a, Press::Esc);
    assert!(!a.chart && !a.quit);
    key(&mut a, Press::Esc);
    assert!(a.quit);
}

#[test]
fn a_key_that_does_nothing_yet_keeps_its_notice_through_the_frame() {
    let mut a = app();
    let mut snap = ballpit::engine::Engine::new(
        ballpit::scene::build_world(&ballpit::scene::SceneSpec::default()).unwrap(),
        settings(4),
    )
    .unwrap()
    .snapshot()
    .clone();
    snap.notice = None;
    key(&mut a, Press::Char('P'));
    a.sync(&snap, true, false);
    assert!(a.notice.as_deref().unwrap().contains("kept for pool mode"));
    key(&mut a, Press::Char('0'));
    a.sync(&snap, true, false);
    assert!(a.notice.as_deref().unwrap().contains("back to its start"));
    // Changes of scene are counted, so flat out's comparison starts again.
    let before = a.scene;
    key(&mut a, Press::Char('n'));
    assert_eq!(a.scene, before + 1);
}

fn auto(t: f64) -> ModelKind {
    ModelKind::Auto(ballpit::physics::auto::Tolerance::new(t).unwrap())
}

#[test]
fn angle_brackets_step_auto_s_tolerance_over_the_ladder() {
    let mut a = AppState::new(
        &Settings {
            model: auto(0.0),
            ..settings(4)
        },
        1000,
        0.02,
        30.0,
    );
    let ladder = [0.001, 0.01, 0.03, 0.1, 0.3, 1.0];
    for t in ladder {
        let scene = a.scene;
        assert_eq!(key(&mut a, Press::Char('>')), [Command::SetModel(auto(t))]);
        assert_eq!(a.model, auto(t));
        assert_eq!(a.scene, scene + 1, "another model runs: another scene");
        let n = a.notice.clone().unwrap();
        assert!(n.starts_with(&format!("tolerance {t} ")), "{n}");
    }
    assert!(key(&mut a, Press::Char('>')).is_empty());
    assert!(a.notice.as_deref().unwrap().contains("limit 1"));
    for t in ladder.iter().rev().skip(1).chain(&[0.0]) {
        assert_eq!(key(&mut a, Press::Char('<')), [Command::SetModel(auto(*t))]);
    }
    assert!(key(&mut a, Press::Char('<')).is_empty());
    assert!(a.notice.as_deref().unwrap().contains("limit 0"));
    assert_eq!(a.model, auto(0.0));
}

#[test]
fn the_tolerance_keys_with_another_model_say_it_only_steers_auto_and_m_brings_it() {
    let mut a = app();
    assert_eq!(a.model, ModelKind::Swept);
    assert!(key(&mut a, Press::Char('>')).is_empty());
    assert!(key(&mut a, Press::Char('>')).is_empty());
    let n = a.notice.clone().unwrap();
    assert!(n.contains("0.01") && n.contains("only steers auto"), "{n}");
    assert_eq!(a.model, ModelKind::Swept);
    key(&mut a, Press::Char('m'));
    assert_eq!(
        key(&mut a, Press::Char('m')),
        [Command::SetModel(auto(0.01))]
    );
}

#[test]
fn sync_shows_auto_s_switch_after_the_key_s_answer_and_takes_what_it_runs() {
    use ballpit::engine::Engine;
    use ballpit::physics::auto::Choice;
    use ballpit::physics::{Sphere, World};
    use glam::DVec3;
    let spheres = vec![Sphere::new(DVec3::splat(0.3), DVec3::X, 0.05)];
    let s = Settings {
        model: auto(0.0),
        threading: Threading::Pool,
        ..settings(4)
    };
    let engine = Engine::new(World::new(1.0, spheres), s).unwrap();
    let mut snap = engine.snapshot().clone();
    let mut a = AppState::new(&s, 1, 0.05, 30.0);
    snap.choice = Some(Choice {
        model: ModelKind::Exact,
        reason: "dense".into(),
        unmet: false,
    });
    snap.switch_notice = Some("auto: swept → exact (dense)".into());
    // No key of ours: the switch alone.
    a.sync(&snap, false, false);
    assert_eq!(a.notice.as_deref(), Some("auto: swept → exact (dense)"));
    // `exact` ran, on one lane as the engine says, so the pool size does
    // nothing to it: the key says so.
    snap.one_lane = true;
    assert_eq!(snap.model_ran(), ModelKind::Exact);
    key_after(&mut a, Press::Char('P'), &snap);
    assert!(
        a.notice
            .as_deref()
            .unwrap()
            .contains("exact runs on one thread")
    );
    // A key's answer first, then the switch it caused.
    key(&mut a, Press::Char('>'));
    a.sync(&snap, true, false);
    let n = a.notice.clone().unwrap();
    assert!(
        n.starts_with("tolerance 0.001") && n.ends_with("; auto: swept → exact (dense)"),
        "{n}"
    );
    // The frame after: no switch, the notice stays until the next key.
    snap.switch_notice = None;
    a.sync(&snap, false, false);
    assert_eq!(a.notice.as_deref(), Some(n.as_str()));
    // Another model asked: auto's choice no longer speaks for it.
    key(&mut a, Press::Char('m'));
    key_after(&mut a, Press::Char('P'), &snap);
    assert!(!a.notice.as_deref().unwrap_or("").contains("one thread"));
}
