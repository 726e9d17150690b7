//! The span executor (`SpanExec`) runs `P` lanes one after another on one
//! thread: the physics must end in the bits a serial run ends in, for every
//! model and every `P`, and the work and span it measures must be ordered
//! as they must (span∞ ≤ span ≤ work, speed-up ≤ P and ≤ parallelism).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::bits::bits;
use ballpit::engine::SpanExec;
use ballpit::physics::{ModelKind, Serial, World};
use ballpit::scene::{SceneSpec, build_world};

fn gas(count: usize) -> World {
    build_world(&SceneSpec {
        scene: Some("gas".into()),
        count: Some(count),
        radius: Some(0.006),
        seed: Some(5),
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn span_runs_end_in_the_serial_bits_and_order_work_and_span() {
    let start = gas(12_000);
    let (e0, size) = (start.kinetic_energy(), start.size);
    for model in [ModelKind::Swept, ModelKind::Discrete] {
        let mut reference = start.clone();
        model
            .build()
            .advance(&mut reference, 1.0 / 60.0, 6, &Serial);
        for lanes in [2, 16, 64] {
            let exec = SpanExec::new(lanes);
            let mut w = start.clone();
            let mut m = model.build();
            let ws = exec.measure(&mut || m.advance(&mut w, 1.0 / 60.0, 6, &exec));
            assert_eq!(bits(&w), bits(&reference), "{model} on {lanes} lanes");
            assert!(ws.work > 0.0, "{ws:?}");
            assert!(
                ws.span_inf <= ws.span && ws.span <= ws.work,
                "{model} {lanes}: {ws:?}"
            );
            assert!(
                ws.speedup() <= lanes as f64 + 1e-9,
                "{model} {lanes}: {ws:?}"
            );
            assert!(ws.speedup() <= ws.parallelism() + 1e-9, "{ws:?}");
            assert!(ws.parallelism() >= 1.0, "{ws:?}");
            // 12 000 spheres on 16 lanes and more: the sections spread.
            if lanes >= 16 {
                assert!(ws.speedup() > 1.2, "{model} {lanes}: {ws:?}");
            }
            // The invariants of the run itself: no escape, energy kept
            // (swept's elastic contacts; discrete's within its promise).
            let r = |s: &ballpit::physics::Sphere| s.radius;
            for s in &w.spheres {
                for x in s.pos.to_array() {
                    assert!(
                        x >= r(s) - 1e-9 && x <= size - r(s) + 1e-9,
                        "{model}: escaped"
                    );
                }
            }
            let drift = (w.kinetic_energy() - e0).abs() / e0;
            assert!(drift < 1e-6, "{model}: energy drift {drift}");
        }
    }
}

/// `exact` runs its events one after another on one thread: its work and
/// span say so (a model built to be serial has no parallelism to find).
#[test]
fn the_exact_models_events_are_one_chain() {
    let start = gas(12_000);
    let e0 = start.kinetic_energy();
    let mut reference = start.clone();
    ModelKind::Exact
        .build()
        .advance(&mut reference, 1.0 / 60.0, 6, &Serial);
    let exec = SpanExec::new(64);
    let mut w = start.clone();
    let mut m = ModelKind::Exact.build();
    let ws = exec.measure(&mut || m.advance(&mut w, 1.0 / 60.0, 6, &exec));
    assert_eq!(bits(&w), bits(&reference));
    assert!(ws.parallelism() <= 1.5, "{ws:?}");
    assert!(
        ws.speedup() >= 1.0 && ws.speedup() <= ws.parallelism() + 1e-9,
        "{ws:?}"
    );
    let drift = (w.kinetic_energy() - e0).abs() / e0;
    assert!(drift < 1e-9, "energy drift {drift}");
    assert!(
        w.max_overlap_rel() < 1e-6,
        "overlap {}",
        w.max_overlap_rel()
    );
}

/// `bench --threading pool`: the same steps replayed on the pool's lanes
/// give `work_seconds ≥ span_seconds > 0` and a parallelism at least their
/// ratio (the replay ending in the timed run's bits, or the run fails); the
/// other modes leave the three null (docs/design.md, bench JSON).
#[test]
fn bench_gives_work_and_span_for_pool_runs_and_null_for_the_others() {
    use crate::common::json;
    let run = |threading: &str, threads: &str| {
        json::bench(&[
            "--threading",
            threading,
            "--threads",
            threads,
            "--steps",
            "12",
            "--count",
            "12000",
            "--radius",
            "0.006",
        ])
    };
    for threads in ["2", "64"] {
        let v = run("pool", threads);
        let f = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k}: {v}"));
        let (work, span, par) = (f("work_seconds"), f("span_seconds"), f("parallelism"));
        assert!(span > 0.0 && work >= span, "{threads}: {v}");
        assert!(par >= work / span - 1e-9, "{threads}: {v}");
        // 12 000 spheres: some sections spread over the lanes.
        assert!(par > 1.2, "{threads}: {v}");
        assert_eq!(v["escaped"], 0, "{v}");
        assert!(f("energy_drift_rel") < 1e-6, "{v}");
    }
    for threading in ["off", "worker", "split"] {
        let v = run(threading, "2");
        for k in ["work_seconds", "span_seconds", "parallelism"] {
            assert!(v[k].is_null(), "{threading} {k}: {v}");
        }
    }
}
