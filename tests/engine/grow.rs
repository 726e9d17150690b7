//! The `R` key: spheres grow by the step, pushed apart where they would
//! touch, until the box is truly full; energy, containment and the no-overlap
//! promise hold at every press.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::engine::{Command, Engine, Settings, Threading};
use ballpit::physics::relax::{MAX_PACKING, packing};
use ballpit::physics::{ModelKind, World};
use ballpit::scene::{SceneSpec, build_world};
use ballpit::tui::state::{RADIUS_STEP, representative_radius};

fn settings(model: ModelKind, tick: u32) -> Settings {
    Settings {
        model,
        dt: 1.0 / 60.0,
        tick,
        threading: Threading::Off,
        threads: 1,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Spheres closer than the sum of their radii, or any at all outside.
fn assert_clean(w: &World, when: &str) {
    assert_eq!(w.max_overlap_rel(), 0.0, "overlap {when}");
    assert_eq!(w.escaped(), 0, "escape {when}");
}

/// Press `R` (as the key does: the largest radius in force times the step)
/// and return the radius in force and the notice after the frame.
fn press_bigger(e: &mut Engine) -> (f64, Option<String>) {
    let r = representative_radius(e.snapshot()).unwrap();
    e.command(Command::SetRadius(r * RADIUS_STEP));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap();
    (representative_radius(snap).unwrap(), snap.notice.clone())
}

#[test]
fn bigger_five_times_from_the_default_scene_grows_until_the_box_is_full() {
    let world = build_world(&SceneSpec::default()).unwrap();
    let energy = world.kinetic_energy();
    let momentum = world.momentum();
    // Tick 0: the frames apply the edits and step nothing, so any change of
    // energy would be the edit's.
    let mut e = Engine::new(world, settings(ModelKind::Swept, 0)).unwrap();
    let mut radius = representative_radius(e.snapshot()).unwrap();
    let mut full = false;
    for press in 1..=5 {
        let (now, notice) = press_bigger(&mut e);
        let w = e.world();
        assert_clean(w, &format!("after press {press}"));
        assert!(rel(w.kinetic_energy(), energy) < 1e-12, "press {press}");
        assert!((w.momentum() - momentum).length() < 1e-12 * momentum.length().max(1.0));
        // The readout's radius is the one in force: every sphere has it.
        assert!(w.spheres.iter().all(|s| s.radius == now));
        if full {
            // A full box may settle a little further, never back.
            assert!(now >= radius, "press {press} shrank: {now}");
            assert!(notice.is_some_and(|n| n.starts_with("radius limit")));
            radius = now;
            continue;
        }
        match notice {
            None => assert!(
                rel(now, radius * RADIUS_STEP) < 1e-12,
                "press {press}: {now}"
            ),
            Some(n) => {
                assert!(n.starts_with("radius limit: no room"), "{n}");
                // Full means truly crowded, not a stray near-contact.
                let p = packing(&w.spheres, w.size);
                assert!(p > 0.8 * MAX_PACKING, "called full at packing {p}");
                assert!(now > radius, "press {press} did not grow: {now}");
                full = true;
            }
        }
        radius = now;
    }
    // The default scene (packing 0.034) fills the box within five steps of 1.25.
    assert!(full, "never reached the limit; radius {radius}");
}

#[test]
fn grown_spheres_keep_running_cleanly_in_every_model() {
    for model in [ModelKind::Exact, ModelKind::Swept] {
        let world = build_world(&SceneSpec {
            count: Some(300),
            ..SceneSpec::default()
        })
        .unwrap();
        let mut e = Engine::new(world, settings(model, 1)).unwrap();
        for _ in 0..3 {
            press_bigger(&mut e);
        }
        let start = e.world().kinetic_energy();
        for _ in 0..60 {
            e.start_frame().unwrap();
            e.finish_frame().unwrap();
        }
        let w = e.world();
        assert!(rel(w.kinetic_energy(), start) < 1e-9, "{model:?}");
        assert!(w.max_overlap_rel() < 1e-9, "{model:?}");
        assert_eq!(w.escaped(), 0, "{model:?}");
    }
}

#[test]
fn smaller_then_bigger_returns_to_the_same_radius() {
    let world = build_world(&SceneSpec::default()).unwrap();
    let mut e = Engine::new(world, settings(ModelKind::Exact, 0)).unwrap();
    let r0 = representative_radius(e.snapshot()).unwrap();
    e.command(Command::SetRadius(r0 / RADIUS_STEP));
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    let (r, notice) = press_bigger(&mut e);
    assert_eq!(notice, None);
    assert!(rel(r, r0) < 1e-12);
    assert_clean(e.world(), "after r then R");
}
