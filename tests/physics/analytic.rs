//! Hand-computed cases for the contact maths and both step models.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::contact::{pair_toi, resolve_pair};
use ballpit::physics::{ModelKind, Serial, Sphere, World};
use glam::DVec3;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn ball(p: DVec3, vel: DVec3, r: f64, m: f64) -> Sphere {
    Sphere {
        pos: p,
        vel,
        radius: r,
        mass: m,
    }
}

fn run(model: ModelKind, spheres: Vec<Sphere>, dt: f64, steps: u64) -> World {
    let mut w = World::new(1.0, spheres);
    model.build().advance(&mut w, dt, steps, &Serial);
    w
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn toi_is_exact_off_head_on() {
    // Offset b = 0.1 along y, sigma = 0.2: contact when the x gap is
    // sqrt(0.2^2 - 0.1^2); distance/speed would say 0.8 - 0.2 = 0.6.
    let t = pair_toi(v(-0.8, -0.1, 0.0), v(1.0, 0.0, 0.0), 0.2).unwrap();
    assert!(close(t, 0.8 - (0.04f64 - 0.01).sqrt(), 1e-15), "t = {t}");
    // Receding pairs never collide, overlapping approaching ones collide now.
    assert_eq!(pair_toi(v(-0.8, 0.0, 0.0), v(-1.0, 0.0, 0.0), 0.2), None);
    assert_eq!(
        pair_toi(v(-0.1, 0.0, 0.0), v(1.0, 0.0, 0.0), 0.2),
        Some(0.0)
    );
    assert_eq!(pair_toi(v(-0.1, 0.0, 0.0), v(-1.0, 0.0, 0.0), 0.2), None);
    // A miss: offset larger than sigma.
    assert_eq!(pair_toi(v(-0.8, -0.3, 0.0), v(1.0, 0.0, 0.0), 0.2), None);
}

#[test]
fn equal_masses_head_on_swap_velocities() {
    for model in ModelKind::ALL {
        let w = run(
            model,
            vec![
                ball(v(0.3, 0.5, 0.5), v(0.6, 0.0, 0.0), 0.05, 1.0),
                ball(v(0.7, 0.5, 0.5), v(-0.2, 0.0, 0.0), 0.05, 1.0),
            ],
            1.0 / 60.0,
            24,
        );
        assert_eq!(w.counters.sphere_collisions, 1, "{model}");
        assert!(
            close(w.spheres[0].vel.x, -0.2, 1e-14),
            "{model}: {:?}",
            w.spheres[0].vel
        );
        assert!(
            close(w.spheres[1].vel.x, 0.6, 1e-14),
            "{model}: {:?}",
            w.spheres[1].vel
        );
    }
}

#[test]
fn unequal_masses_follow_the_1d_formulas() {
    let (m1, m2, u1, u2) = (3.0, 1.0, 0.5, -0.25);
    let v1 = ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2);
    let v2 = ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2);
    let mut a = ball(v(0.4, 0.5, 0.5), v(u1, 0.0, 0.0), 0.1, m1);
    let mut b = ball(v(0.6, 0.5, 0.5), v(u2, 0.0, 0.0), 0.1, m2);
    assert!(resolve_pair(&mut a, &mut b));
    assert!(
        close(a.vel.x, v1, 1e-15) && close(b.vel.x, v2, 1e-15),
        "{a:?} {b:?}"
    );
    // Momentum and energy are conserved.
    assert!(close(m1 * a.vel.x + m2 * b.vel.x, m1 * u1 + m2 * u2, 1e-15));
    let e0 = 0.5 * (m1 * u1 * u1 + m2 * u2 * u2);
    assert!(close(a.kinetic_energy() + b.kinetic_energy(), e0, 1e-15));
}

#[test]
fn oblique_hit_changes_only_normal_components() {
    let n = v(1.0, 1.0, 0.0).normalize();
    let mut a = ball(v(0.5, 0.5, 0.5), v(0.3, 0.1, 0.2), 0.1, 2.0);
    let mut b = ball(a.pos + n * 0.2, v(-0.1, 0.0, -0.4), 0.1, 0.5);
    let (a0, b0) = (a, b);
    assert!(resolve_pair(&mut a, &mut b));
    for (before, after) in [(a0, a), (b0, b)] {
        let tangential = |s: &Sphere| s.vel - s.vel.dot(n) * n;
        assert!((tangential(&before) - tangential(&after)).length() < 1e-15);
    }
    let p0 = a0.mass * a0.vel + b0.mass * b0.vel;
    let p1 = a.mass * a.vel + b.mass * b.vel;
    assert!((p0 - p1).length() < 1e-15);
    let e0 = a0.kinetic_energy() + b0.kinetic_energy();
    assert!(close(a.kinetic_energy() + b.kinetic_energy(), e0, 1e-15));
    // Receding pairs are left alone.
    assert!(!resolve_pair(&mut a, &mut b));
}

#[test]
fn wall_hit_reflects_and_corner_hit_flips_three_components() {
    for model in ModelKind::ALL {
        let w = run(
            model,
            vec![ball(v(0.8, 0.5, 0.5), v(1.0, 0.2, 0.0), 0.1, 1.0)],
            0.01,
            20,
        );
        assert!(close(w.spheres[0].vel.x, -1.0, 0.0), "{model}");
        assert!(close(w.spheres[0].vel.y, 0.2, 0.0), "{model}");
        assert_eq!(w.counters.wall_collisions, 1, "{model}");
        // Straight at the corner (0.9, 0.9, 0.9): all three flip together.
        let w = run(
            model,
            vec![ball(v(0.5, 0.5, 0.5), v(1.0, 1.0, 1.0), 0.1, 1.0)],
            0.01,
            50,
        );
        assert_eq!(w.spheres[0].vel, v(-1.0, -1.0, -1.0), "{model}");
        assert_eq!(w.counters.wall_collisions, 3, "{model}");
        assert_eq!(w.escaped(), 0, "{model}");
    }
}

#[test]
fn swept_crosses_several_box_lengths_in_one_step() {
    // Radius 0.1: the centre moves on [0.1, 0.9], a 0.8 segment. Starting at
    // x = 0.5 with vx = 3.7 for one step of 1 s: unfolded distance 0.4 + 3.7
    // = 4.1 = 5 segments + 0.1, so 5 wall hits, odd -> moving down from 0.9:
    // x = 0.9 - 0.1 = 0.8, vx = -3.7.
    let w = run(
        ModelKind::Swept,
        vec![ball(v(0.5, 0.5, 0.5), v(3.7, 0.0, 0.0), 0.1, 1.0)],
        1.0,
        1,
    );
    let s = w.spheres[0];
    assert!(close(s.pos.x, 0.8, 1e-14), "x = {}", s.pos.x);
    assert_eq!(s.vel.x, -3.7);
    assert_eq!(w.counters.wall_collisions, 5);
    assert!(close(w.counters.wall_momentum, 5.0 * 2.0 * 3.7, 1e-15));
    assert_eq!(w.escaped(), 0);
}

#[test]
fn swept_follows_a_chain_inside_one_step() {
    // Newton's cradle hit inside a single long step: the momentum must pass
    // down the touching row, leaving no overlap.
    let r = 0.05;
    let mut spheres = vec![ball(v(0.2, 0.5, 0.5), v(1.0, 0.0, 0.0), r, 1.0)];
    for k in 0..4 {
        spheres.push(ball(
            v(0.4 + 2.0 * r * k as f64, 0.5, 0.5),
            DVec3::ZERO,
            r,
            1.0,
        ));
    }
    let w = run(ModelKind::Swept, spheres, 0.2, 1);
    assert!(w.max_overlap_rel() < 1e-12, "{}", w.max_overlap_rel());
    assert!(w.counters.sphere_collisions >= 4);
    // The far end carries the whole momentum, the rest are (nearly) at rest.
    assert!(
        close(w.spheres[4].vel.x, 1.0, 1e-12),
        "{:?}",
        w.spheres[4].vel
    );
    for s in &w.spheres[..4] {
        assert!(s.vel.length() < 1e-12, "{:?}", s.vel);
    }
}
