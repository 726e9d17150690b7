//! The exact model against hard-sphere theory, in the bulk of the box (at
//! least three diameters from every wall, where the wall's layering has died
//! out):
//! - collision rate per sphere against Enskog, `Z = 4 n σ² sqrt(π kT/m) g(σ)`,
//!   with the Carnahan–Starling contact value `g(σ) = (1-φ/2)/(1-φ)^3`;
//! - pressure from the collision virial, `P = n kT + Σ σ |Δp| / (3 V t)`,
//!   against the Carnahan–Starling equation of state
//!   `P = n kT (1+φ+φ²-φ³)/(1-φ)^3`;
//! - the wall pressure readout (momentum to the walls per time and area the
//!   centres can reach) against the same bulk pressure (a dilute gas; in a
//!   dense one the edges of a small box lift it, and the test bounds by how much).
//!
//! Densities are measured in the same bulk region, so the adsorption at the
//! walls does not bias them. Tolerances (3 %, 5 % for the walls) sit well
//! above the statistical and finite-size errors here (under 1 %) and well
//! below what missing 5 % of the collisions does to both figures.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::exact::{Contact, Exact};
use ballpit::physics::{Counters, Model, Serial};
use ballpit::scene::lattice::lattice_world;
use glam::DVec3;
use std::sync::{Arc, Mutex};

#[derive(Default)]
struct Tally {
    collisions: u64,
    virial: f64,
}

/// `wall` bounds the relative excess of the face-averaged wall pressure over
/// the bulk pressure.
fn check(packing: f64, seed: u64, wall: (f64, f64)) {
    let n = 4000;
    let mut w = lattice_world(n, packing, 1.0, seed).unwrap();
    let r = w.spheres[0].radius;
    let sigma = 2.0 * r;
    let m = w.spheres[0].mass;
    let lo = 3.0 * sigma;
    let hi = 1.0 - lo;
    let inside = move |p: DVec3| p.cmpge(DVec3::splat(lo)).all() && p.cmple(DVec3::splat(hi)).all();
    let region = (hi - lo).powi(3);

    let mut model = Exact::default();
    // Melt the lattice: about 30 collisions per sphere.
    let dt = 0.01;
    while w.counters.sphere_collisions < 30 * n as u64 / 2 {
        model.advance(&mut w, dt, 1, &Serial);
    }
    let tally = Arc::new(Mutex::new(Tally::default()));
    let t2 = tally.clone();
    model.set_observer(Some(Box::new(move |c: &Contact| {
        let mid = 0.5 * (c.pos_i + c.pos_j);
        if inside(mid) {
            let mut t = t2.lock().unwrap();
            t.collisions += 1;
            t.virial += c.pos_i.distance(c.pos_j) * c.impulse;
        }
    })));
    w.counters = Counters::default();
    let t0 = w.time;
    let e0 = w.kinetic_energy();
    let mut count_sum = 0.0;
    let mut samples = 0.0;
    while w.counters.sphere_collisions < 1_500_000 {
        model.advance(&mut w, dt, 1, &Serial);
        count_sum += w.spheres.iter().filter(|s| inside(s.pos)).count() as f64;
        samples += 1.0;
    }
    let time = w.time - t0;
    assert_eq!(w.counters.capped_steps, 0);
    assert!((w.kinetic_energy() - e0).abs() <= 1e-12 * e0);
    assert!(w.max_overlap_rel() <= 1e-10);
    assert_eq!(w.escaped(), 0);

    let kt = w.temperature();
    let n_bulk = count_sum / samples / region;
    let phi = n_bulk * std::f64::consts::PI / 6.0 * sigma.powi(3);
    let g = (1.0 - phi / 2.0) / (1.0 - phi).powi(3);
    let t = tally.lock().unwrap();

    let rate = 2.0 * t.collisions as f64 / (n_bulk * region * time);
    let enskog = 4.0 * n_bulk * sigma * sigma * (std::f64::consts::PI * kt / m).sqrt() * g;
    let p_virial = n_bulk * kt + t.virial / (3.0 * region * time);
    let p_cs = n_bulk * kt * (1.0 + phi + phi * phi - phi.powi(3)) / (1.0 - phi).powi(3);
    let area = 6.0 * (1.0 - 2.0 * r).powi(2);
    let p_wall = w.counters.wall_momentum / (time * area);
    eprintln!(
        "packing {packing}: bulk φ {phi:.4}; rate {rate:.3} vs Enskog {enskog:.3} ({:+.2} %); \
         P virial {p_virial:.3} vs CS {p_cs:.3} ({:+.2} %); wall {p_wall:.3} ({:+.2} %)",
        100.0 * (rate / enskog - 1.0),
        100.0 * (p_virial / p_cs - 1.0),
        100.0 * (p_wall / p_cs - 1.0),
    );
    assert!(
        (rate / enskog - 1.0).abs() < 0.03,
        "rate {rate} vs Enskog {enskog}"
    );
    assert!(
        (p_virial / p_cs - 1.0).abs() < 0.03,
        "P {p_virial} vs CS {p_cs}"
    );
    let excess = p_wall / p_cs - 1.0;
    assert!(
        excess > wall.0 && excess < wall.1,
        "wall P {p_wall} vs CS {p_cs}"
    );
}

#[test]
fn dilute_gas_matches_enskog_and_carnahan_starling() {
    check(0.1, 1, (-0.05, 0.05));
}

#[test]
fn dense_liquid_matches_enskog_and_carnahan_starling() {
    // In a dense liquid the box's edges and corners (two or three walls at
    // once) hold more spheres at contact than a flat wall; with faces only 18
    // diameters wide they lift the face average by several per cent.
    check(0.35, 2, (0.0, 0.12));
}
