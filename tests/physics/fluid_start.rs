//! Dense scenes start as a fluid at their packing, at any count (issue 31):
//! a cubic lattice over the whole box, `⌈∛N⌉` sites a side, its spare sites
//! spread evenly, where the old start packed the spheres on a lattice of
//! pitch near a diameter (1.0035 at a million spheres), colliding several
//! times faster than the fluid. Checked by the collision rate against
//! Enskog's after a melt of one `σ / v_rms` (the rate comes within 10 % in
//! about half of that at 10k, 100k and 1M; docs/history/2026-12-02-evening.md).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::exact::Exact;
use ballpit::physics::sphere::volume;
use ballpit::physics::{Model, Serial, World};
use ballpit::scene::{SceneSpec, build_world};
use std::collections::HashSet;
use std::f64::consts::PI;

fn scene(name: &str, count: usize, radius: Option<f64>) -> World {
    build_world(&SceneSpec {
        scene: Some(name.into()),
        count: Some(count),
        radius,
        ..SceneSpec::default()
    })
    .unwrap()
}

fn packing(w: &World) -> f64 {
    w.spheres.iter().map(|s| volume(s.radius)).sum::<f64>() / w.size.powi(3)
}

/// Every sphere within its slack of its own site of the `k³` lattice,
/// `k = ⌈∛n⌉`, and each half of the box (along every axis) holding half
/// the spheres to 1 % (a block filling the sites in order misses it by
/// about 10 % at 2000 spheres).
fn assert_whole_box_lattice(w: &World, label: &str) {
    let n = w.spheres.len();
    let k = (1..=n).find(|k| k.pow(3) >= n).unwrap();
    let pitch = w.size / k as f64;
    let mut sites = HashSet::new();
    for s in &w.spheres {
        let slack = 0.5 * pitch - s.radius;
        let idx = (s.pos / pitch).floor().as_uvec3();
        let centre = (idx.as_dvec3() + 0.5) * pitch;
        assert!(
            (s.pos - centre).abs().max_element() <= slack + 1e-12 * w.size,
            "{label}: sphere at {:?} off its site of a {k}³ lattice",
            s.pos
        );
        assert!(
            sites.insert(idx.to_array()),
            "{label}: two spheres on a site"
        );
    }
    for axis in 0..3 {
        let low = w
            .spheres
            .iter()
            .filter(|s| s.pos[axis] < 0.5 * w.size)
            .count();
        let share = low as f64 / n as f64;
        assert!(
            (share - 0.5).abs() < 0.01,
            "{label}: {low} of {n} spheres in the lower half along axis {axis}"
        );
    }
}

#[test]
fn dense_scenes_start_on_the_widest_lattice_over_the_whole_box() {
    for count in [2000, 10_000, 27_000] {
        let w = scene("dense", count, None);
        assert!((packing(&w) - 0.4).abs() < 1e-9, "dense {count}");
        assert_whole_box_lattice(&w, &format!("dense {count}"));
    }
    // A gas too dense for random placement (packing 0.4) falls back to the
    // same lattice.
    let r = (0.4 / (1000.0 * 4.0 / 3.0 * PI)).cbrt();
    let gas = scene("gas", 1000, Some(r));
    assert_whole_box_lattice(&gas, "gas at packing 0.4");
}

/// Enskog's collisions per unit time for `n` equal spheres in the box at
/// the nominal packing: `n/2 · 4 ρ σ² √(π kT/m) g(σ)`, with the
/// Carnahan–Starling contact value `g = (1 − φ/2)/(1 − φ)³`.
fn enskog(w: &World) -> f64 {
    let n = w.spheres.len() as f64;
    let sigma = 2.0 * w.spheres[0].radius;
    let phi = packing(w);
    let g = (1.0 - 0.5 * phi) / (1.0 - phi).powi(3);
    let kt_over_m = w.temperature() / w.spheres[0].mass;
    let rho = n / w.size.powi(3);
    0.5 * n * 4.0 * rho * sigma * sigma * (PI * kt_over_m).sqrt() * g
}

/// 10 000 spheres at packing 0.4: after a melt of one `σ / v_rms` (about
/// 13 collisions a sphere) the rate over the next `σ / v_rms` is Enskog's
/// to 10 % (the walls lift the steady rate about 6 % at this size), with the energy kept,
/// no sphere out and no overlap.
#[test]
fn the_dense_start_melts_to_enskogs_collision_rate() {
    let mut w = scene("dense", 10_000, None);
    let e0 = w.kinetic_energy();
    let v_rms = (2.0 * e0 / (w.spheres.len() as f64 * w.spheres[0].mass)).sqrt();
    let unit = 2.0 * w.spheres[0].radius / v_rms;
    let want = enskog(&w);
    let mut m = Exact::default();
    m.advance(&mut w, unit / 10.0, 10, &Serial);
    let (c0, t0) = (w.counters.sphere_collisions, w.time);
    m.advance(&mut w, unit / 10.0, 10, &Serial);
    let rate = (w.counters.sphere_collisions - c0) as f64 / (w.time - t0);
    assert!(
        (rate / want - 1.0).abs() < 0.10,
        "rate {rate:.4e} against Enskog {want:.4e} ({:+.1} %)",
        100.0 * (rate / want - 1.0)
    );
    assert_eq!(w.counters.capped_steps, 0);
    assert!((w.kinetic_energy() - e0).abs() <= 1e-10 * e0);
    assert_eq!(w.escaped(), 0);
    assert!(w.max_overlap_rel() <= 1e-9);
}
