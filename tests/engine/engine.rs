//! The engine: every threading mode gives the same bits, mode switches lose
//! nothing, the idle physics thread sleeps, panics come back as errors, and
//! count and radius edits keep spheres apart and inside.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::bits;
use ballpit::engine::{Command, Engine, Settings, Threading};
use ballpit::physics::{Exec, Model, ModelKind, Sphere, World};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::time::{Duration, Instant};

/// `n` spheres on a jittered lattice (so none overlap), radii in
/// `[r·(1-spread), r·(1+spread)]`, every `big`-th one as large as its lattice
/// cell allows, random velocities of rms `speed`.
fn scene(n: usize, r: f64, spread: f64, big: usize, speed: f64, seed: u64) -> World {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let m = (n as f64).cbrt().ceil() as usize;
    let cell = 1.0 / m as f64;
    let mut spheres = Vec::with_capacity(n);
    for i in 0..n {
        let c = DVec3::new((i % m) as f64, ((i / m) % m) as f64, (i / (m * m)) as f64);
        let centre = (c + 0.5) * cell;
        let radius = if big > 0 && i % big == big - 1 {
            0.49 * cell
        } else {
            r * (1.0 + spread * rng.random_range(-1.0..=1.0))
        };
        assert!(radius < 0.5 * cell, "scene too dense for its lattice");
        let room = 0.5 * cell - radius;
        let jitter = DVec3::new(
            rng.random_range(-room..=room),
            rng.random_range(-room..=room),
            rng.random_range(-room..=room),
        );
        let vel = DVec3::new(
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
        ) * speed;
        spheres.push(Sphere::new(centre + jitter, vel, radius));
    }
    World::new(1.0, spheres)
}

fn settings(model: ModelKind, threading: Threading, threads: usize, tick: u32) -> Settings {
    Settings {
        model,
        dt: 1.0 / 60.0,
        tick,
        threading,
        threads,
    }
}

fn run(world: &World, s: Settings, frames: usize) -> World {
    let mut e = Engine::new(world.clone(), s).unwrap();
    for _ in 0..frames {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    }
    e.world().clone()
}

fn modes() -> Vec<(Threading, usize)> {
    vec![
        (Threading::Worker, 1),
        (Threading::Pool, 1),
        (Threading::Pool, 2),
        (Threading::Pool, 3),
        (Threading::Split, 2),
    ]
}

/// Deepest overlap a model may leave: `discrete` moves spheres into each
/// other by up to the relative displacement of a step; `swept` resolves
/// every contact it foresaw, and these scenes are sparse enough that no
/// unforeseen chain leaves more than rounding.
fn allowed_overlap(model: ModelKind, w: &World, dt: f64) -> f64 {
    let vmax = w.spheres.iter().map(|s| s.vel.length()).fold(0.0, f64::max);
    let rmin = w
        .spheres
        .iter()
        .map(|s| s.radius)
        .fold(f64::INFINITY, f64::min);
    match model {
        ModelKind::Discrete => 2.0 * vmax * dt / rmin,
        _ => 1e-9,
    }
}

fn check_invariants(start: &World, end: &World, max_overlap: f64) {
    eprintln!(
        "overlap seen {} allowed {max_overlap}",
        end.max_overlap_rel()
    );
    let (e0, e1) = (start.kinetic_energy(), end.kinetic_energy());
    assert!((e1 - e0).abs() / e0 < 1e-9, "energy {e0} -> {e1}");
    assert_eq!(end.spheres.len(), start.spheres.len());
    assert_eq!(end.escaped(), 0);
    let overlap = end.max_overlap_rel();
    assert!(overlap <= max_overlap, "overlap {overlap} > {max_overlap}");
}

#[test]
fn every_mode_gives_the_same_bits() {
    let scenes = [
        ("few, all pairs", scene(20, 0.08, 0.0, 0, 0.6, 1)),
        ("uniform", scene(400, 0.03, 0.0, 0, 0.8, 2)),
        ("mixed radii, big ones", scene(5000, 0.012, 0.5, 97, 1.0, 3)),
    ];
    for model in [ModelKind::Discrete, ModelKind::Swept] {
        for (name, world) in &scenes {
            let reference = run(world, settings(model, Threading::Off, 1, 5), 8);
            assert!(reference.time > 0.6, "{name}: the world moved");
            assert!(
                reference.counters.sphere_collisions > 0,
                "{model} {name}: collisions happen"
            );
            check_invariants(world, &reference, allowed_overlap(model, world, 1.0 / 60.0));
            for (threading, k) in modes() {
                let got = run(world, settings(model, threading, k, 5), 8);
                assert!(
                    bits(&got) == bits(&reference),
                    "{model} {name}: {threading} K={k} differs from off"
                );
            }
        }
    }
}

#[test]
fn every_mode_gives_the_same_bits_on_the_presets() {
    use ballpit::scene::{SceneSpec, build_world, presets::PRESETS};
    for preset in PRESETS {
        // Enough gas spheres that three pool lanes all get blocks.
        let count = (preset.name == "gas").then_some(6000);
        let spec = SceneSpec {
            scene: Some(preset.name.into()),
            count,
            ..SceneSpec::default()
        };
        let world = build_world(&spec).unwrap();
        for model in [ModelKind::Discrete, ModelKind::Swept] {
            let name = preset.name;
            let reference = run(&world, settings(model, Threading::Off, 1, 4), 5);
            check_invariants(
                &world,
                &reference,
                allowed_overlap(model, &world, 1.0 / 60.0),
            );
            for (threading, k) in modes() {
                let got = run(&world, settings(model, threading, k, 4), 5);
                assert!(
                    bits(&got) == bits(&reference),
                    "{model} {name}: {threading} K={k} differs from off"
                );
            }
        }
    }
}

#[test]
fn a_thousand_mode_switches_change_nothing() {
    let world = scene(2500, 0.015, 0.3, 0, 0.8, 4);
    for model in [ModelKind::Discrete, ModelKind::Swept] {
        let reference = run(&world, settings(model, Threading::Off, 1, 1), 1000);
        let mut e = Engine::new(world.clone(), settings(model, Threading::Off, 1, 1)).unwrap();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut seen = std::collections::HashSet::new();
        for frame in 0..1000 {
            let t = Threading::ALL[rng.random_range(0..4)];
            e.command(Command::SetThreading(t));
            e.command(Command::SetThreads(rng.random_range(1..=3)));
            e.start_frame().unwrap();
            // Sometimes read the snapshot while the frame runs, as the TUI does.
            if frame % 3 == 0 {
                assert_eq!(e.snapshot().spheres.len(), 2500);
            }
            let snap = e.finish_frame().unwrap();
            assert_eq!(snap.frame, frame + 1);
            assert_eq!(snap.settings.threading, t);
            seen.insert(t);
        }
        assert_eq!(seen.len(), 4);
        assert!(
            bits(e.world()) == bits(&reference),
            "{model}: switched run differs"
        );
        check_invariants(
            &world,
            e.world(),
            allowed_overlap(model, &world, 1.0 / 60.0),
        );
    }
}

#[test]
fn worker_pipelines_snapshots() {
    let world = scene(300, 0.02, 0.0, 0, 0.5, 6);
    let mut e = Engine::new(world, settings(ModelKind::Swept, Threading::Worker, 2, 3)).unwrap();
    e.start_frame().unwrap();
    // While frame 1 computes, the screen still has frame 0.
    assert_eq!(e.snapshot().frame, 0);
    assert!(e.in_flight());
    assert!(e.try_world().is_none());
    let snap = e.finish_frame().unwrap();
    assert_eq!((snap.frame, snap.steps), (1, 3));
    assert!((snap.time - 3.0 / 60.0).abs() < 1e-15);
    // A second start without finish finishes the first one itself.
    e.start_frame().unwrap();
    e.start_frame().unwrap();
    assert_eq!(e.finish_frame().unwrap().frame, 3);
    assert_eq!(e.physics_threads(), ["physics"]);
    e.command(Command::SetThreading(Threading::Pool));
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    // The pool runs the frame; `physics` waits for it.
    assert_eq!(e.physics_threads(), ["pool-0", "pool-1"]);
    assert!((e.world().time - 12.0 / 60.0).abs() < 1e-12);
}

#[test]
fn idle_physics_threads_use_no_cpu() {
    let world = scene(3000, 0.01, 0.0, 0, 0.5, 7);
    let mut e = Engine::new(world, settings(ModelKind::Swept, Threading::Worker, 2, 4)).unwrap();
    // Run every threaded mode, so every engine thread exists and has worked.
    for t in [Threading::Worker, Threading::Pool, Threading::Split] {
        e.command(Command::SetThreading(t));
        for _ in 0..10 {
            e.start_frame().unwrap();
            e.finish_frame().unwrap();
        }
    }
    let threads = e.thread_ids();
    let names: Vec<&str> = threads.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["physics", "pool-0", "pool-1", "split-pair", "split-wall"]
    );
    let cpu = || -> Vec<f64> {
        threads
            .iter()
            .map(|&(_, tid)| ballpit::cpu::thread_cpu_seconds_of(tid).unwrap())
            .collect()
    };
    let worked = cpu();
    assert!(
        worked.iter().all(|&c| c > 0.0),
        "every thread ran: {worked:?}"
    );
    e.command(Command::SetThreading(Threading::Off));
    e.start_frame().unwrap();
    let t0 = Instant::now();
    let before = cpu();
    let mut frames = 0;
    while t0.elapsed() < Duration::from_secs(1) {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
        frames += 1;
    }
    let wall = t0.elapsed().as_secs_f64();
    assert!(frames > 10, "the main thread ran frames meanwhile");
    for (((name, _), b), a) in threads.iter().zip(before).zip(cpu()) {
        let per_second = (a - b) / wall;
        assert!(per_second < 1e-3, "{name} used {per_second} s/s while off");
    }
}

/// Panics on the frame it is told to, on the lane it is told to.
struct Faulty {
    frames: u32,
    panic_at: u32,
    lane: Option<usize>,
}

impl Model for Faulty {
    fn kind(&self) -> ModelKind {
        ModelKind::Swept
    }
    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec) {
        self.frames += 1;
        if self.frames == self.panic_at {
            match self.lane {
                None => panic!("injected fault"),
                Some(l) => exec.for_each_lane(&|lane| {
                    assert!(lane != l, "injected fault on lane {lane}");
                }),
            }
        }
        world.time += dt * steps as f64;
    }
}

#[test]
fn a_panic_in_physics_is_an_error() {
    let cases = [
        (Threading::Off, None, "injected fault"),
        (Threading::Worker, None, "injected fault"),
        (Threading::Split, None, "injected fault"),
        (Threading::Pool, Some(1), "injected fault on lane 1"),
    ];
    for (threading, lane, msg) in cases {
        let world = scene(30, 0.02, 0.0, 0, 0.5, 8);
        let model = Box::new(Faulty {
            frames: 0,
            panic_at: 3,
            lane,
        });
        let mut e =
            Engine::with_model(world, settings(ModelKind::Swept, threading, 2, 1), model).unwrap();
        let mut outcome = Ok(());
        for _ in 0..5 {
            outcome = e.start_frame().and_then(|()| e.finish_frame().map(|_| ()));
            if outcome.is_err() {
                break;
            }
        }
        let err = outcome.expect_err("the panic must surface").to_string();
        assert!(err.contains(msg), "{threading}: got '{err}'");
        assert_eq!(
            e.snapshot().frame,
            2,
            "{threading}: last good frame stays on screen"
        );
        // The engine stays failed and says so; it does not hang.
        assert!(e.start_frame().unwrap_err().to_string().contains(msg));
    }
}

#[test]
fn count_edits_go_into_free_space() {
    let world = scene(500, 0.02, 0.0, 0, 0.5, 9);
    let rms = ballpit::physics::edit::rms_speed(&world);
    // Tick 0: the frame applies the edit and steps nothing, so what the
    // snapshot shows is what the edit made.
    let mut e = Engine::new(
        world.clone(),
        settings(ModelKind::Swept, Threading::Worker, 2, 0),
    )
    .unwrap();
    e.command(Command::SetCount(1000));
    let snap = e.finish_frame().unwrap().clone();
    assert_eq!(
        snap.spheres.len(),
        500,
        "commands wait for the frame boundary"
    );
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap().clone();
    assert_eq!(snap.spheres.len(), 1000);
    assert_eq!(snap.notice, None);
    let w = e.world();
    assert_eq!((w.max_overlap_rel(), w.escaped()), (0.0, 0));
    for s in &w.spheres[500..] {
        assert_eq!(s.radius, 0.02);
        assert!((s.vel.length() - rms).abs() < 1e-12 * rms);
    }
    // The drift restarts from the new energy.
    assert!((snap.energy_reset - w.kinetic_energy()).abs() < 1e-9 * snap.energy_reset);
    // Halving drops the last ones.
    let kept: Vec<_> = w.spheres[..250].to_vec();
    e.command(Command::SetCount(250));
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    assert_eq!(e.world().spheres, kept);
    // Asking for far more than fits stops at full, says so, overlaps nothing.
    e.command(Command::SetCount(200_000));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap().clone();
    let n = snap.spheres.len();
    assert!(n > 2000 && n < 200_000, "filled up to {n}");
    assert!(
        snap.notice.as_deref().unwrap().starts_with("count limit"),
        "{:?}",
        snap.notice
    );
    assert_eq!((snap.max_overlap_rel, snap.escaped), (0.0, 0));
    // Stepping on from the packed state keeps everyone inside.
    e.command(Command::SetTick(2));
    for _ in 0..3 {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    }
    assert_eq!(e.world().escaped(), 0);
}

#[test]
fn an_emptied_scene_refills_like_the_start() {
    let world = scene(100, 0.03, 0.0, 0, 0.4, 12);
    let rms = ballpit::physics::edit::rms_speed(&world);
    // Tick 0: the frames apply the edits and step nothing.
    let mut e = Engine::new(world, settings(ModelKind::Discrete, Threading::Pool, 2, 0)).unwrap();
    e.command(Command::SetCount(0));
    e.start_frame().unwrap();
    let snap = e.finish_frame().unwrap().clone();
    assert_eq!(
        (snap.spheres.len(), snap.energy, snap.energy_drift()),
        (0, 0.0, 0.0)
    );
    e.command(Command::SetRadius(0.05));
    e.command(Command::SetCount(40));
    e.start_frame().unwrap();
    e.finish_frame().unwrap();
    let w = e.world();
    assert_eq!(w.spheres.len(), 40);
    assert!(w.spheres.iter().all(|s| s.radius == 0.03));
    assert!(
        w.spheres
            .iter()
            .all(|s| (s.vel.length() - rms).abs() < 1e-12)
    );
    assert_eq!((w.escaped(), w.max_overlap_rel()), (0, 0.0));
}

#[test]
fn radius_grows_by_making_room_until_the_box_is_full() {
    let world = scene(300, 0.02, 0.0, 0, 0.5, 10);
    let mut e = Engine::new(world, settings(ModelKind::Swept, Threading::Off, 1, 0)).unwrap();
    e.command(Command::SetRadius(0.01));
    e.start_frame().unwrap();
    let w = e.world();
    assert!(w.spheres.iter().all(|s| s.radius == 0.01));
    assert_eq!(e.snapshot().notice, None);
    let energy = w.kinetic_energy();
    let masses: Vec<f64> = w.spheres.iter().map(|s| s.mass).collect();
    // 300 spheres of radius 0.3 would fill the box 113 times over.
    e.command(Command::SetRadius(0.3));
    e.start_frame().unwrap();
    let snap = e.snapshot().clone();
    let w = e.world();
    let r = w.spheres[0].radius;
    assert!(r > 0.01 && r < 0.3, "grew to {r}");
    assert!(
        snap.notice.as_deref().unwrap().starts_with("radius limit"),
        "{:?}",
        snap.notice
    );
    assert_eq!((w.max_overlap_rel(), w.escaped()), (0.0, 0));
    // It grew far past the first contact (packing 0.004 at r = 0.01): the
    // spheres made room. One jump this size lands short of what repeated
    // presses reach.
    let filled = ballpit::physics::relax::packing(&w.spheres, w.size);
    assert!(filled > 0.3, "stopped at packing {filled}");
    // Only positions moved: masses, velocities and energy are as they were.
    assert!(w.spheres.iter().zip(&masses).all(|(s, m)| s.mass == *m));
    assert!((w.kinetic_energy() / energy - 1.0).abs() < 1e-12);
    // Mixed radii keep their ratios; the largest becomes the target.
    let world = scene(200, 0.02, 0.5, 0, 0.5, 11);
    let before: Vec<f64> = world.spheres.iter().map(|s| s.radius).collect();
    let largest = before.iter().copied().fold(0.0, f64::max);
    let f = 1.5;
    let mut m = Engine::new(world, settings(ModelKind::Swept, Threading::Off, 1, 0)).unwrap();
    m.command(Command::SetRadius(largest * f));
    m.start_frame().unwrap();
    assert_eq!(m.snapshot().notice, None);
    for (s, r0) in m.world().spheres.iter().zip(&before) {
        assert!((s.radius / r0 - f).abs() < 1e-12);
    }
    assert_eq!(m.world().max_overlap_rel(), 0.0);
    // Off: the physics runs on the caller.
    assert_eq!(
        m.physics_threads(),
        [std::thread::current().name().unwrap()]
    );
}

/// The snapshot tells the screen how many parts `swept` cut its last step
/// into: several for fast spheres in a crowd, on every threading mode.
#[test]
fn snapshots_carry_the_parts_of_the_last_step() {
    // 3 000 spheres of radius 0.005 at 20 box lengths a second: paths long
    // against the gaps.
    let fast = scene(3000, 0.005, 0.0, 0, 20.0, 5);
    for (threading, threads) in [(Threading::Off, 1), (Threading::Pool, 2)] {
        let mut e = Engine::new(
            fast.clone(),
            settings(ModelKind::Swept, threading, threads, 1),
        )
        .unwrap();
        e.start_frame().unwrap();
        let parts = e.finish_frame().unwrap().parts;
        assert!(parts > 4, "{threading:?}: {parts}");
    }
    let mut e = Engine::new(fast, settings(ModelKind::Exact, Threading::Off, 1, 1)).unwrap();
    e.start_frame().unwrap();
    assert_eq!(e.finish_frame().unwrap().parts, 1);
    // A slow gas stays whole.
    let slow = scene(1000, 0.01, 0.0, 0, 0.5, 5);
    let mut e = Engine::new(slow, settings(ModelKind::Swept, Threading::Off, 1, 1)).unwrap();
    e.start_frame().unwrap();
    assert_eq!(e.finish_frame().unwrap().parts, 1);
}

#[test]
fn a_threaded_frame_says_when_it_is_done() {
    let world = scene(500, 0.01, 0.1, 0, 0.3, 4);
    for threading in [Threading::Worker, Threading::Pool, Threading::Split] {
        let mut e =
            Engine::new(world.clone(), settings(ModelKind::Swept, threading, 2, 3)).unwrap();
        let (tx, rx) = crossbeam_channel::unbounded();
        e.set_notify(Box::new(move || {
            let _ = tx.send(());
        }));
        for _ in 0..3 {
            e.start_frame().unwrap();
            // Awaited, not polled: the notice comes once the frame is back.
            rx.recv_timeout(Duration::from_secs(20)).unwrap();
            assert!(e.frame_ready(), "{threading}");
            e.finish_frame().unwrap();
        }
        assert!(rx.try_recv().is_err(), "one notice a frame");
        check_invariants(&world, e.world(), 1e-9);
    }
}
