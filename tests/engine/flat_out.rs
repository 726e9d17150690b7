//! Flat out in the engine: frames of as many steps as a time budget allows
//! give, for the steps they ran, the same bits as frames of a fixed tick,
//! in every mode; and every step is inside the physics timer.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::bits;
use ballpit::engine::{Engine, Settings, Threading};
use ballpit::physics::{ModelKind, World};
use ballpit::scene::{SceneSpec, build_world};
use std::time::Duration;

fn settings(model: ModelKind, threading: Threading, tick: u32) -> Settings {
    Settings {
        model,
        dt: 1.0 / 60.0,
        tick,
        threading,
        threads: 2,
    }
}

fn world() -> World {
    build_world(&SceneSpec {
        count: Some(300),
        ..SceneSpec::default()
    })
    .unwrap()
}

/// Flat-out frames of `budget` in `threading`: the end state, the steps
/// run, and the physics seconds the snapshots report.
fn flat_out(model: ModelKind, threading: Threading, frames: usize) -> (World, u64, f64) {
    let mut e = Engine::new(world(), settings(model, threading, 1)).unwrap();
    e.set_budget(Some(Duration::from_millis(3)));
    let (mut steps, mut secs) = (0, 0.0);
    for _ in 0..frames {
        e.start_frame().unwrap();
        let s = e.finish_frame().unwrap();
        steps += s.steps;
        secs += s.physics_seconds;
    }
    (e.into_world().unwrap(), steps, secs)
}

/// The same steps at a fixed tick: one frame of them, except for `exact`
/// and `auto`, whose state depends on how their steps are cut, and which
/// flat out steps one at a time: frames of one step.
fn ticked(model: ModelKind, steps: u64) -> World {
    let mut e = Engine::new(world(), settings(model, Threading::Off, 1)).unwrap();
    let frames = if model.cuts_freely() {
        e.command(ballpit::engine::Command::SetTick(
            u32::try_from(steps).unwrap(),
        ));
        1
    } else {
        steps
    };
    for _ in 0..frames {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    }
    e.into_world().unwrap()
}

#[test]
fn flat_out_steps_give_the_bits_of_the_same_steps_in_one_frame() {
    // Not `auto`: it chooses again when the steps per frame change, so a
    // flat-out run and a ticked one may run different models (its bits
    // across threading modes at one tick are held by tests/physics/auto.rs).
    for model in ModelKind::FIXED {
        for threading in Threading::ALL {
            let (got, steps, secs) = flat_out(model, threading, 6);
            // At least one step a frame, and the steps were timed.
            assert!(steps >= 6, "{model} {threading}: {steps} steps");
            assert!(secs > 0.0, "{model} {threading}");
            let want = ticked(model, steps);
            assert!(
                bits(&got) == bits(&want),
                "{model} {threading}: {steps} flat-out steps differ from one frame of them"
            );
            let e0 = world().kinetic_energy();
            let rel = (got.kinetic_energy() - e0).abs() / e0;
            assert!(rel < 1e-9, "{model} {threading}: energy drift {rel}");
            let n = got.spheres.len();
            assert_eq!(n, 300);
            assert!(got.spheres.iter().all(|s| {
                let p = s.pos.to_array();
                p.iter()
                    .all(|&x| x >= s.radius - 1e-9 && x <= got.size - s.radius + 1e-9)
            }));
        }
    }
}

#[test]
fn a_budget_of_none_goes_back_to_the_tick() {
    let mut e = Engine::new(world(), settings(ModelKind::Swept, Threading::Worker, 3)).unwrap();
    e.set_budget(Some(Duration::from_millis(2)));
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    e.set_budget(None);
    e.start_frame().unwrap();
    assert_eq!(e.finish_frame().unwrap().steps, 3);
}
