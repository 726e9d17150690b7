//! `auto` running: the promise kept on random scenes, the same bits in
//! every threading mode, live edits and their switch notices, a broken
//! promise, its threads, the CLI flag and model row, choosing again on
//! drift. Its choice as a pure function is `auto_choice.rs`, which shares
//! the fixtures here (`DTS`, `preset`, `tol`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::json;
use crate::common::random_scene::random_scene;
use ballpit::engine::{Command, Engine, Settings, Threading};
use ballpit::physics::auto::Tolerance;
use ballpit::physics::{ModelKind, Serial, World};
use ballpit::scene::presets::PRESETS;
use ballpit::scene::{SceneSpec, build_world};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The three steps the tests choose at: coarse, the screen's, fine.
pub(crate) const DTS: [f64; 3] = [1.0 / 15.0, 1.0 / 60.0, 1.0 / 1920.0];

/// A preset's world at seed 1.
pub(crate) fn preset(name: &str) -> World {
    build_world(&SceneSpec {
        scene: Some(name.into()),
        seed: Some(1),
        ..Default::default()
    })
    .unwrap()
}

pub(crate) fn tol(t: f64) -> Tolerance {
    Tolerance::new(t).unwrap()
}

/// 60 scenes over count, packing, speed, radius spread, `dt` and the
/// tolerance: whatever `auto` runs keeps the tolerance (deepest overlap
/// within `T` of the smaller radius), keeps energy and loses no sphere.
/// Few steps each, so the test stays cheap; larger counts go slower.
#[test]
fn random_scenes_keep_the_tolerance() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(29);
    let mut seen = std::collections::BTreeMap::new();
    for case in 0..60 {
        let n = if case % 12 == 11 {
            rng.random_range(5_000..=20_000)
        } else {
            (100.0 * 30f64.powf(rng.random_range(0.0..1.0))) as usize
        };
        let packing = 0.001 * 450f64.powf(rng.random_range(0.0..1.0));
        let mut speed = 0.01 * 2000f64.powf(rng.random_range(0.0..1.0));
        if n > 3_000 {
            speed = speed.min(1.0);
        }
        let spread = 100f64.powf(rng.random_range(0.0..1.0));
        let dt = DTS[rng.random_range(0..DTS.len())];
        let t = [0.0, 0.01, 0.1, 0.5][rng.random_range(0..4)];
        let world = random_scene(&mut rng, n, packing, spread, speed);
        let what = format!(
            "case {case}: n {n}, packing {packing:.3}, speed {speed:.2}, spread {spread:.1}, dt {dt:.2e}, tol {t}"
        );
        assert_eq!(world.max_overlap_rel(), 0.0, "{what}: the start overlaps");
        let mut model = ModelKind::Auto(tol(t)).build();
        let mut w = world.clone();
        let e0 = w.kinetic_energy();
        let mut worst: f64 = 0.0;
        for _ in 0..3 {
            model.advance(&mut w, dt, 1, &Serial);
            worst = worst.max(w.max_overlap_rel());
            // As the engine: the model's readout, else the caller's.
            let read = model.max_overlap_rel(&w, dt, &Serial);
            model.overlap_read(read.unwrap_or_else(|| w.max_overlap_rel()));
        }
        let c = model.choice().unwrap().clone();
        *seen.entry(c.model.name()).or_insert(0) += 1;
        let de = (w.kinetic_energy() - e0).abs() / e0;
        assert!(de < 1e-9, "{what}: energy {de:e}");
        assert_eq!(w.escaped(), 0, "{what}");
        if !c.unmet {
            assert_eq!(w.counters.capped_steps, 0, "{what}: {}", c.reason);
            assert!(
                worst <= t + 1e-9,
                "{what}: {} sank {worst:e} r ({})",
                c.model,
                c.reason
            );
        }
    }
    eprintln!("choices: {seen:?}");
}

fn settings(model: ModelKind, threading: Threading, dt: f64) -> Settings {
    Settings {
        model,
        dt,
        tick: 3,
        threading,
        threads: 2,
    }
}

/// `auto` gives the same bits and the same choice in every threading mode
/// on every preset.
#[test]
fn auto_is_bit_identical_across_threading_modes_on_every_preset() {
    for name in PRESETS.map(|p| p.name) {
        let start = preset(name);
        let mut first: Option<(World, ModelKind)> = None;
        for mode in Threading::ALL {
            let mut e = Engine::new(
                start.clone(),
                settings(ModelKind::Auto(tol(0.0)), mode, 1.0 / 60.0),
            )
            .unwrap();
            for _ in 0..4 {
                e.start_frame().unwrap();
                e.finish_frame().unwrap();
            }
            let chosen = e.snapshot().choice.as_ref().unwrap().model;
            let w = e.world().clone();
            assert_eq!(w.escaped(), 0, "{name} {mode}");
            match &first {
                None => first = Some((w, chosen)),
                Some((w0, c0)) => {
                    assert_eq!(&w, w0, "{name}: {mode} differs");
                    assert_eq!(chosen, *c0, "{name}: {mode} chose otherwise");
                }
            }
        }
    }
}

/// A live edit that crosses a boundary changes the choice at the next
/// frame: slowing the projectiles' cousins by growing them into a crowd.
#[test]
fn a_live_edit_across_a_boundary_changes_the_choice_at_the_next_frame() {
    let start = preset("projectiles");
    let mut e = Engine::headless(
        start,
        settings(ModelKind::Auto(tol(0.0)), Threading::Off, 1.0 / 60.0),
    )
    .unwrap();
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    assert_eq!(
        e.snapshot().choice.as_ref().unwrap().model,
        ModelKind::Swept
    );
    e.command(Command::SetRadius(0.05));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    let c = snap.choice.as_ref().unwrap();
    assert_eq!(c.model, ModelKind::Exact, "{}", c.reason);
    assert!(snap.max_overlap_rel <= 1e-9);
    let said = format!("auto: swept → exact ({})", c.reason);
    assert_eq!(snap.switch_notice.as_deref(), Some(said.as_str()));
    // The notice is the switch's frame only, and an edit that does not
    // cross (larger still: denser, still exact) gives none.
    e.command(Command::SetRadius(0.06));
    assert_eq!(frame(&mut e), (ModelKind::Exact, None));
    assert_eq!(frame(&mut e), (ModelKind::Exact, None));
}

/// One frame: what `auto` ran and the switch notice.
fn frame(e: &mut Engine) -> (ModelKind, Option<String>) {
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    (
        snap.choice.as_ref().unwrap().model,
        snap.switch_notice.clone(),
    )
}

/// The tick and the tolerance are part of the choice: a change across a
/// boundary switches at the next frame with the notice, one that does not
/// cross gives none, and a model other than `auto` none either.
#[test]
fn a_tick_or_tolerance_across_a_boundary_is_a_switch_with_its_notice() {
    use ModelKind::{Discrete as D, Exact as E, Swept as S};
    let s = Settings {
        tick: 1,
        ..settings(ModelKind::Auto(tol(0.0)), Threading::Off, 1.0 / 60.0)
    };
    // The cradle: exact's sync each frame outweighs its events at 1 step.
    let mut e = Engine::headless(preset("cradle"), s).unwrap();
    assert_eq!(frame(&mut e), (S, None));
    e.command(Command::SetTick(4));
    let (m, said) = frame(&mut e);
    assert_eq!(m, E);
    assert!(said.unwrap().starts_with("auto: swept → exact ("));
    e.command(Command::SetTick(16));
    assert_eq!(frame(&mut e), (E, None));

    let s = Settings {
        dt: 1.0 / 1920.0,
        ..s
    };
    let mut e = Engine::headless(preset("dense"), s).unwrap();
    assert_eq!(frame(&mut e), (S, None));
    e.command(Command::SetModel(ModelKind::Auto(tol(0.1))));
    let (m, said) = frame(&mut e);
    assert_eq!(m, D);
    assert!(said.unwrap().starts_with("auto: swept → discrete (sinks"));
    e.command(Command::SetModel(ModelKind::Auto(tol(0.3))));
    assert_eq!(frame(&mut e), (D, None));
    e.command(Command::SetModel(ModelKind::Exact));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    assert!(snap.choice.is_none() && snap.switch_notice.is_none());
    // Back to `auto` from another model: a choice, not a switch.
    e.command(Command::SetModel(ModelKind::Auto(tol(0.1))));
    assert_eq!(frame(&mut e), (D, None));
}

/// `discrete` under `auto` is checked against the engine's own overlap
/// readout: a scene that starts with a pair sunk half a radius breaks the
/// tolerance in the first frame, and the next one runs a stricter model
/// and says why.
#[test]
fn a_broken_promise_moves_auto_to_a_stricter_model_and_says_so() {
    for mode in [Threading::Off, Threading::Pool] {
        let mut w = preset("dense");
        let (a, b) = (w.spheres[0], &mut w.spheres[1]);
        b.pos = a.pos + DVec3::new(1.5 * a.radius.min(b.radius), 0.0, 0.0);
        let s = Settings {
            tick: 1,
            ..settings(ModelKind::Auto(tol(0.1)), mode, 1.0 / 1920.0)
        };
        let mut e = Engine::headless(w, s).unwrap();
        e.start_frame().unwrap();
        let snap = e.finish_frame().unwrap();
        assert_eq!(snap.choice.as_ref().unwrap().model, ModelKind::Discrete);
        assert!(
            snap.max_overlap_rel > 0.1,
            "{mode}: {}",
            snap.max_overlap_rel
        );
        let (m, said) = frame(&mut e);
        assert_ne!(m, ModelKind::Discrete, "{mode}");
        let said = said.unwrap();
        assert!(
            said.starts_with("auto: discrete → ") && said.contains("discrete broke tol (overlap)"),
            "{mode}: {said}"
        );
    }
}

/// The threads named for `auto` are those of the model it runs: `exact`
/// on `physics` alone in split mode, `swept` on the split lanes too.
#[test]
fn auto_names_the_threads_of_the_model_it_runs() {
    let split = |name: &str| {
        let s = settings(ModelKind::Auto(tol(0.0)), Threading::Split, 1.0 / 60.0);
        let mut e = Engine::headless(preset(name), s).unwrap();
        let (m, _) = frame(&mut e);
        let fixed = Engine::headless(preset(name), Settings { model: m, ..s }).unwrap();
        assert_eq!(e.physics_threads(), fixed.physics_threads(), "{name}");
        (m, e.physics_threads().len())
    };
    assert_eq!(split("dense"), (ModelKind::Exact, 1));
    let (m, lanes) = split("projectiles");
    assert_eq!(m, ModelKind::Swept);
    assert!(lanes > 1, "{lanes}");
}

fn ballpit(args: &[&str]) -> std::process::Output {
    crate::common::cli::ballpit().args(args).output().unwrap()
}

/// `--tolerance` out of [0, 1] is refused with one line and exit 2; with
/// a model other than `auto` it warns; the JSON says what `auto` chose.
#[test]
fn the_tolerance_flag_is_checked_and_reported() {
    for bad in ["-0.5", "NaN", "1.5"] {
        let out = ballpit(&[
            "bench",
            "--model",
            "auto",
            "--tolerance",
            bad,
            "--steps",
            "2",
        ]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("--tolerance must be"), "{err}");
    }
    let out = ballpit(&[
        "bench",
        "--model",
        "exact",
        "--tolerance",
        "0.1",
        "--steps",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("only steers --model auto")
    );
    let v = json::bench(&["--scene", "dense", "--model", "auto", "--steps", "4"]);
    assert_eq!(v["model"], "auto");
    assert_eq!(v["model_chosen"], "exact");
    assert!(
        v["model_reason"].as_str().unwrap().starts_with("dense"),
        "{v}"
    );
    let v = json::bench(&[
        "--model", "auto", "--speed", "10000", "--dt", "1/15", "--steps", "2",
    ]);
    assert_eq!(v["model_chosen"], "exact");
    let warned = v["warnings"].to_string();
    assert!(warned.contains("could not meet its tolerance"), "{warned}");
    let v = json::bench(&["--model", "swept", "--steps", "2"]);
    assert!(v["model_chosen"].is_null());
}

/// The readouts' model row names what `auto` runs (its reason follows as
/// far as the panel is wide).
#[test]
fn the_model_row_says_what_auto_runs() {
    use ballpit::tui::readouts::{Readouts, Stats};
    use ballpit::tui::state::AppState;
    use ballpit::tui::theme::Palette;
    let s = settings(ModelKind::Auto(tol(0.0)), Threading::Off, 1.0 / 60.0);
    let mut e = Engine::new(preset("dense"), s).unwrap();
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap().clone();
    let st = AppState::new(&s, snap.count, 0.0363, 30.0);
    let stats = Stats {
        fps: 30.0,
        physics_seconds: snap.physics_seconds,
        render_seconds: 0.001,
        frame_bytes: 1000,
        steps_per_second: 30.0,
        collisions_per_second: 1.0,
        detected: Some(Palette::True),
        ..Stats::default()
    };
    let mut t = ratatui::Terminal::new(ratatui::backend::TestBackend::new(
        72,
        ballpit::tui::readouts::HEIGHT,
    ))
    .unwrap();
    t.draw(|f| {
        f.render_widget(
            Readouts {
                state: &st,
                snap: &snap,
                stats: &stats,
                palette: Palette::C16,
            },
            f.area(),
        );
    })
    .unwrap();
    let text = crate::common::screen::rows(&t);
    let row = text.iter().find(|r| r.contains("model")).unwrap();
    assert!(row.contains("auto → exact (dense:"), "{text:#?}");
}

/// Collisions pass the energy of big spheres started at the common speed
/// to the small ones, so the scene `auto` chose for is gone within a few
/// steps: the drift check looks again and chooses for the scene as it is,
/// and says so. Equal spheres keep their rms speed (the energy is kept)
/// and are never chosen for again.
#[test]
fn auto_chooses_again_when_collisions_change_the_speeds() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(22);
    let world = random_scene(&mut rng, 948, 0.043, 50.0, 14.0);
    let dt = 1.0 / 15.0;
    let mut model = ModelKind::Auto(tol(0.01)).build();
    let mut w = world.clone();
    let e0 = w.kinetic_energy();
    let mut reasons = Vec::new();
    for _ in 0..4 {
        model.advance(&mut w, dt, 1, &Serial);
        let read = model.max_overlap_rel(&w, dt, &Serial);
        model.overlap_read(read.unwrap_or_else(|| w.max_overlap_rel()));
        reasons.push(model.choice().unwrap().reason.clone());
    }
    assert!(!reasons[0].contains("drifted"), "{reasons:#?}");
    assert!(
        reasons[1..]
            .iter()
            .any(|r| r.contains("speeds drifted (rms 14")),
        "{reasons:#?}"
    );
    assert!((w.kinetic_energy() - e0).abs() / e0 < 1e-9);
    assert!(w.max_overlap_rel() <= 0.01 + 1e-12);
    assert_eq!(w.escaped(), 0);

    let spec = SceneSpec {
        scene: Some("gas".into()),
        ..SceneSpec::default()
    };
    let mut w = build_world(&spec).unwrap();
    let mut model = ModelKind::Auto(tol(0.0)).build();
    for _ in 0..200 {
        model.advance(&mut w, 1.0 / 60.0, 1, &Serial);
        let read = model.max_overlap_rel(&w, 1.0 / 60.0, &Serial);
        model.overlap_read(read.unwrap_or_else(|| w.max_overlap_rel()));
        let reason = &model.choice().unwrap().reason;
        assert!(!reason.contains("drifted"), "{reason}");
    }
}
