//! `swept`'s work budget per step: a step whose contacts would take minutes
//! (paths across much of the box, or a fast close-packed lattice) ends in
//! bounded time, finished in free flight and reported; a capped step is the
//! same bits on any lanes; a step under its budget is untouched by it.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::bits;
use crate::common::json;
use ballpit::engine::{PoolExec, SplitExec};
use ballpit::physics::swept::Swept;
use ballpit::physics::{Exec, Model, Serial, Sphere, World};
use ballpit::scene::{SceneSpec, build_world};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::fmt::Write as _;
use std::time::Duration;

/// Today's code took minutes for each of these steps; the budget ends them
/// in a second or two. A run past this is killed and fails.
const DEADLINE: Duration = Duration::from_mins(1);

/// One step, finished coarsely by the budget and said so; energy kept,
/// nobody out of the box.
fn assert_budget_step(v: &serde_json::Value) {
    assert_eq!(v["capped_steps"], 1, "{v}");
    assert_eq!(v["budget_steps"], 1, "{v}");
    assert_eq!(v["escaped"], 0, "{v}");
    assert!(v["energy_drift_rel"].as_f64().unwrap() < 1e-12, "{v}");
    let w = v["warnings"].as_array().unwrap();
    assert!(
        w.iter().any(|w| {
            let w = w.as_str().unwrap();
            w.contains("work budget") && w.contains("--dt or --speed")
        }),
        "{w:?}"
    );
}

#[test]
fn a_step_across_the_box_ends_within_its_budget() {
    // 10^4 box lengths a second: every path crosses the box 170 times.
    assert_budget_step(&json::bench_within(
        &["--steps", "1", "--speed", "1e4"],
        DEADLINE,
    ));
}

/// 864 spheres on a face-centred cubic lattice filling the box (packing
/// 0.667, neighbours 1e-4 apart), Gaussian velocities of `sigma` a
/// component, as a CSV scene.
fn lattice_csv(sigma: f64) -> String {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let r: f64 = 0.0569;
    let (edge, step) = (1.001 * r, (1.0 - 2.002 * r) / 11.0);
    let mut csv = String::from("x,y,z,vx,vy,vz,radius,mass\n");
    let mut gauss = || {
        // Box–Muller.
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos() * sigma
    };
    for (i, j, k) in
        (0..12).flat_map(|i| (0..12).flat_map(move |j| (0..12).map(move |k| (i, j, k))))
    {
        if (i + j + k) % 2 == 1 {
            continue;
        }
        let p = [i, j, k].map(|c| edge + f64::from(c) * step);
        let v = [gauss(), gauss(), gauss()];
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{r},1",
            p[0], p[1], p[2], v[0], v[1], v[2]
        );
    }
    csv
}

#[test]
fn a_fast_close_packed_lattice_ends_within_its_budget() {
    let path = std::env::temp_dir().join(format!("ballpit-budget-{}.csv", std::process::id()));
    std::fs::write(&path, lattice_csv(100.0)).unwrap();
    let v = json::bench_within(
        &["--steps", "1", "--scene", path.to_str().unwrap()],
        DEADLINE,
    );
    std::fs::remove_file(&path).unwrap();
    assert_eq!(v["n"], 864);
    assert_budget_step(&v);
}

fn gas(count: usize, speed: f64) -> World {
    build_world(&SceneSpec {
        scene: Some("gas".into()),
        count: Some(count),
        speed: Some(speed),
        seed: Some(3),
        ..Default::default()
    })
    .unwrap()
}

fn inside(w: &World) -> bool {
    let fits = |s: &Sphere| {
        let (lo, hi) = (DVec3::splat(s.radius), DVec3::splat(w.size - s.radius));
        s.pos.cmpge(lo - 1e-12).all() && s.pos.cmple(hi + 1e-12).all()
    };
    w.spheres.iter().all(fits)
}

#[test]
fn a_capped_step_is_the_same_bits_on_any_lanes() {
    let start = gas(2000, 40.0);
    let e0 = start.kinetic_energy();
    let pools = [PoolExec::new(2).unwrap(), PoolExec::new(3).unwrap()];
    let split = SplitExec::new().unwrap();
    let execs: [&dyn Exec; 4] = [&Serial, &pools[0], &pools[1], &split];
    // Budgets that stop the runs' events, and one so small that the
    // detection of the first part overruns it.
    for (base, steps) in [(3_000_000, 3), (400_000, 3), (100, 2)] {
        let mut reference: Option<Vec<u64>> = None;
        for exec in execs {
            let mut world = start.clone();
            let mut model = Swept::default().with_work_budget(base, 0);
            // Ask for the overlap between steps as the engine does: the
            // detection made ahead must reach the same decision.
            for _ in 0..steps {
                let _ = model.max_overlap_rel(&world, 1.0 / 60.0, exec);
                model.advance(&mut world, 1.0 / 60.0, 1, exec);
            }
            let w = world;
            let c = w.counters;
            assert_eq!(c.budget_steps, steps, "{base}: {c:?}");
            assert!(inside(&w), "{base}");
            let e = w.kinetic_energy();
            assert!((e - e0).abs() <= 1e-12 * e0, "{base}: {e} vs {e0}");
            match &reference {
                None => reference = Some(bits(&w)),
                Some(r) => assert!(*r == bits(&w), "budget {base}: lanes differ"),
            }
        }
    }
}

#[test]
fn a_step_under_its_budget_is_untouched_by_it() {
    for (scene, count, speed, steps) in [
        ("gas", 1000, None, 30),
        ("dense", 1500, None, 6),
        ("projectiles", 400, None, 10),
    ] {
        let start = build_world(&SceneSpec {
            scene: Some(scene.into()),
            count: Some(count),
            speed,
            seed: Some(5),
            ..Default::default()
        })
        .unwrap();
        let run = |m: Swept| {
            let mut w = start.clone();
            let mut m = m;
            m.advance(&mut w, 1.0 / 60.0, steps, &PoolExec::new(2).unwrap());
            w
        };
        let budgeted = run(Swept::default());
        let unlimited = run(Swept::default().with_work_budget(u64::MAX, 0));
        assert_eq!(budgeted.counters.capped_steps, 0, "{scene}");
        assert!(budgeted.counters.sphere_collisions > 0, "{scene}");
        assert!(
            bits(&budgeted) == bits(&unlimited),
            "{scene}: the budget changed an uncapped run"
        );
    }
}
