//! `auto`'s choice as a pure function: `choose` on the presets (two
//! tables), on a scene it cannot keep, and its cost model on hand-made
//! `Summary`s (exact's event cap, exact out of cache).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use super::auto::{DTS, preset, tol};
use ballpit::physics::auto::{Ask, Summary, Tolerance, choose};
use ballpit::physics::swept::parts;
use ballpit::physics::{ModelKind, World};

fn ask(w: &World, dt: f64, tol: Tolerance, frame: u64) -> Ask {
    Ask {
        dt,
        frame,
        tol,
        parts: parts(&w.spheres, w.size, dt),
        floor: 0,
        readouts: true,
    }
}

fn chosen(w: &World, dt: f64, t: Tolerance, frame: u64) -> ModelKind {
    let c = choose(&Summary::of(w), ask(w, dt, t, frame));
    eprintln!("{dt:.2e} {t}: {} ({})", c.model, c.reason);
    c.model
}

/// The calibration's verdict on the presets at one step a frame (the
/// screen's default tick; docs/models.md, "auto"): `swept` where exact's
/// per-frame sync and readout cost more, `exact` where events are few a
/// step; `discrete` never keeps 0.1 of a radius on a preset at these steps
/// but at the finest.
#[test]
fn the_presets_choose_as_the_table_says() {
    use ModelKind::{Exact as E, Swept as S};
    let table: [(&str, [ModelKind; 3]); 6] = [
        ("gas", [E, S, S]),
        ("billiards", [E, S, S]),
        ("dense", [E, E, S]),
        ("projectiles", [S, S, S]),
        ("cradle", [S, S, S]),
        ("mixed", [S, S, S]),
    ];
    for t in [0.0, 0.01, 0.1] {
        let got: Vec<_> = table
            .iter()
            .map(|(name, _)| (*name, DTS.map(|dt| chosen(&preset(name), dt, tol(t), 1))))
            .collect();
        let mut want = table.to_vec();
        if t >= 0.1 {
            // At the fine step the slow presets sink at most a few
            // hundredths of a radius: `discrete` keeps 0.1 (dense measured
            // 0.017 over 2 s, docs/models.md).
            for row in [1, 2, 4] {
                want[row].1[2] = ModelKind::Discrete;
            }
        }
        assert_eq!(got, want, "tolerance {t}");
    }
}

/// At the bench's tick (a hundredth of a simulated second's steps: 1, 1
/// and 19), the choices docs/models.md measured against the three models:
/// each the cheapest that keeps the tolerance, but `billiards` at 1/15
/// (`exact`, 1.1× dearer than `swept`: predicted within the margin) and at
/// 1/60 for 0.1 (`swept`; `discrete` is let in only within half of 0.1).
#[test]
fn at_the_bench_s_tick_the_presets_choose_as_measured() {
    use ModelKind::{Exact as E, Swept as S};
    let table: [(&str, [ModelKind; 3]); 6] = [
        ("gas", [E, S, E]),
        ("billiards", [E, S, E]),
        ("dense", [E, E, E]),
        ("projectiles", [S, S, E]),
        ("cradle", [S, S, E]),
        ("mixed", [S, S, E]),
    ];
    for t in [0.0, 0.01, 0.1] {
        let got: Vec<_> = table
            .iter()
            .map(|(name, _)| {
                let w = preset(name);
                (
                    *name,
                    [(DTS[0], 1), (DTS[1], 1), (DTS[2], 19)]
                        .map(|(dt, f)| chosen(&w, dt, tol(t), f)),
                )
            })
            .collect();
        assert_eq!(got, table.to_vec(), "tolerance {t}");
    }
}

/// A scene the choice cannot keep within exact's event cap: the strictest
/// model, and the reason says why.
#[test]
fn an_impossible_scene_takes_exact_and_says_so() {
    let mut w = preset("gas");
    for s in &mut w.spheres {
        s.vel *= 2e4;
    }
    let c = choose(&Summary::of(&w), ask(&w, 1.0 / 15.0, tol(0.0), 1));
    assert_eq!(c.model, ModelKind::Exact);
    assert!(c.unmet);
    assert!(c.reason.contains("cannot be met"), "{}", c.reason);
}

/// A uniform scene of `n` spheres of radius `r` at rms speed `v` in a unit box.
fn uniform(n: usize, r: f64, v: f64) -> Summary {
    Summary {
        count: n,
        size: 1.0,
        r_min: r,
        r_max: r,
        r_mean: r,
        r2_mean: r * r,
        packing: n as f64 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3),
        v_rms: v,
        v_max: 3.0 * v,
    }
}

fn ask_swept_one_part(dt: f64) -> Ask {
    Ask {
        dt,
        frame: 1,
        tol: tol(0.1),
        parts: 1,
        floor: 0,
        readouts: true,
    }
}

/// The random scene that broke its tolerance (94 265 spheres at speed 16.6,
/// dt 1/15): `exact` was predicted under its event cap, ran into it, and
/// finished the step in free flight. A scene predicted within
/// `EXACT_CAP_MARGIN` of the cap, where the costs alone say `exact`, now
/// runs `swept` when `swept` fits its own cap; without the margin this
/// fails. Counts where `exact`'s state stays in cache (at 94 265 its
/// events are priced dearer, and the costs alone say `swept`), at speeds
/// that bring a range of radii near the cap.
#[test]
fn a_scene_near_exacts_event_cap_runs_swept() {
    use ballpit::physics::auto::{EXACT_CAP_MARGIN, costs, rates};
    use ballpit::physics::exact::{EVENT_CAP_BASE, EVENT_CAP_PER_SPHERE};
    let dt = 1.0 / 15.0;
    let mut near_cap = 0;
    for n in [10_000_usize, 20_000, 30_000] {
        let cap = (EVENT_CAP_BASE + EVENT_CAP_PER_SPHERE * n as u64) as f64;
        for v in [6.0, 12.0, 24.0, 48.0] {
            for i in 0..1000 {
                let r = 0.0005 + 0.00002 * f64::from(i);
                let s = uniform(n, r, v);
                // Parts of a path about a radius, as `swept` would cut.
                let parts = (v * dt / r).ceil().clamp(1.0, 256.0) as u32;
                let rt = rates(&s);
                let per_step = (rt.contacts + rt.walls + rt.crossings) * dt;
                let c = costs(&s, dt, parts, 1, true);
                // Near the cap, and where the costs alone would say exact.
                if per_step * EXACT_CAP_MARGIN > cap && per_step <= cap && c.exact < c.swept {
                    near_cap += 1;
                    let got = choose(
                        &s,
                        Ask {
                            parts,
                            ..ask_swept_one_part(dt)
                        },
                    );
                    assert_eq!(got.model, ModelKind::Swept, "n {n} v {v}: {}", got.reason);
                    assert!(got.reason.contains("event cap"), "{}", got.reason);
                    assert!(!got.unmet);
                }
            }
        }
    }
    assert!(near_cap > 0, "no scene put exact near its cap");
}

/// Above `exact`'s event cap `exact` would end its steps in free flight;
/// where `swept` fits its own cap and budget it takes every contact, so
/// it runs (the sweep's 94 265 spheres at speed 16.6, dt 1/15, broke T on
/// `exact` and kept it on `swept`). Where `swept` does not fit either (the
/// impossible scene above), `exact` and "cannot be met".
#[test]
fn a_scene_past_exacts_event_cap_runs_swept_where_swept_fits() {
    use ballpit::physics::auto::rates;
    use ballpit::physics::exact::{EVENT_CAP_BASE, EVENT_CAP_PER_SPHERE};
    let (n, dt) = (94_265_usize, 1.0 / 15.0);
    let cap = (EVENT_CAP_BASE + EVENT_CAP_PER_SPHERE * n as u64) as f64;
    let s = uniform(n, 0.0056, 16.6);
    let rt = rates(&s);
    assert!((rt.contacts + rt.walls + rt.crossings) * dt > cap);
    let got = choose(
        &s,
        Ask {
            parts: 256,
            ..ask_swept_one_part(dt)
        },
    );
    assert_eq!(got.model, ModelKind::Swept, "{}", got.reason);
    assert!(got.reason.contains("event cap"), "{}", got.reason);
    assert!(!got.unmet);
    // Once `swept` broke the tolerance, only `exact` is left.
    let got = choose(
        &s,
        Ask {
            parts: 256,
            floor: 2,
            ..ask_swept_one_part(dt)
        },
    );
    assert_eq!(got.model, ModelKind::Exact);
    assert!(got.unmet, "{}", got.reason);
}

/// Past about 30 000 spheres `exact`'s state leaves this host's cache and
/// an event costs it more (`choose.rs`, `EXACT_CACHED`): the sweep's
/// 49 807 spheres at speed 5.9, packing 0.11, `dt` 1/1920, where `auto`
/// ran `exact` at 1.4× `swept`'s cost, now run `swept`; the same scene
/// with a tenth of the spheres (its state in cache) still runs `exact`.
#[test]
fn exact_out_of_cache_is_priced_dearer() {
    let dt = 1.0 / 1920.0;
    let pick = |n: usize| {
        let r = (0.112 / (n as f64 * 4.0 / 3.0 * std::f64::consts::PI)).cbrt();
        let parts = (5.92 * dt / r).ceil().clamp(1.0, 256.0) as u32;
        let ask = Ask {
            dt,
            frame: 1,
            tol: tol(0.0),
            parts,
            floor: 0,
            readouts: true,
        };
        choose(&uniform(n, r, 5.92), ask)
    };
    let big = pick(49_807);
    assert_eq!(big.model, ModelKind::Swept, "{}", big.reason);
    let small = pick(4_981);
    assert_eq!(small.model, ModelKind::Exact, "{}", small.reason);
}
