//! Property tests: random scenes run with `exact`, random scene files read
//! and run. The scenes lean on the rounding cases: radii and speeds over
//! many orders of magnitude, spheres placed exactly touching each other and
//! the walls, equal velocities, zero velocities. More cases:
//! `PROPTEST_CASES=20000 cargo test --release --test physics fuzz_exact::`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
#![allow(clippy::format_push_string)] // fuzz inputs read best as format strings
use crate::common::cli::scratch;
use ballpit::physics::exact::Exact;
use ballpit::physics::{Model, ModelKind, Serial, Sphere, World};
use ballpit::scene::{SceneSpec, build_world, csv_io};
use glam::DVec3;
use proptest::prelude::*;

#[derive(Clone, Debug)]
struct Seed {
    pos: [f64; 3],
    dir: [f64; 3],
    speed_exp: f64,
    radius_exp: f64,
    mass_exp: f64,
    /// 0: free; 1: touch the previous sphere along x; 2: touch the low wall
    /// on x; 3: copy the previous velocity.
    how: u8,
}

fn seed() -> impl Strategy<Value = Seed> {
    (
        prop::array::uniform3(0.0..1.0f64),
        prop::array::uniform3(-1.0..1.0f64),
        -4.0..2.0f64,
        -4.0..-1.0f64,
        -3.0..3.0f64,
        0u8..4,
    )
        .prop_map(|(pos, dir, speed_exp, radius_exp, mass_exp, how)| Seed {
            pos,
            dir,
            speed_exp,
            radius_exp,
            mass_exp,
            how,
        })
}

/// Turn seeds into a valid world: spheres that would overlap are dropped.
fn scene(seeds: &[Seed]) -> World {
    let mut spheres: Vec<Sphere> = Vec::new();
    for s in seeds {
        let r = 10f64.powf(s.radius_exp);
        let mut pos = DVec3::from(s.pos) * (1.0 - 2.0 * r) + r;
        let mut vel = DVec3::from(s.dir) * 10f64.powf(s.speed_exp);
        if vel.length() == 0.0 || s.dir[0] == 0.0 {
            vel = DVec3::ZERO;
        }
        if let Some(prev) = spheres.last() {
            match s.how {
                1 => pos = prev.pos + DVec3::X * (prev.radius + r),
                3 => vel = prev.vel,
                _ => {}
            }
        }
        if s.how == 2 {
            pos.x = r;
        }
        let inside = (0..3).all(|k| pos[k] >= r && pos[k] <= 1.0 - r);
        let clear = spheres.iter().all(|o| o.pos.distance(pos) >= o.radius + r);
        if inside && clear {
            let mut sp = Sphere::new(pos, vel, r);
            sp.mass = 10f64.powf(s.mass_exp);
            spheres.push(sp);
        }
    }
    World::new(1.0, spheres)
}

fn check_run(world: &World, dt: f64, steps: u64) -> Result<World, TestCaseError> {
    let mut w = world.clone();
    let mut m = Exact::default().with_event_cap(200_000);
    let e0 = w.kinetic_energy();
    for _ in 0..steps {
        let capped = w.counters.capped_steps;
        m.advance(&mut w, dt, 1, &Serial);
        prop_assert!(!w.has_non_finite());
        prop_assert_eq!(w.escaped(), 0);
        let de = (w.kinetic_energy() - e0).abs();
        prop_assert!(
            de <= 1e-10 * e0.max(f64::MIN_POSITIVE),
            "energy {de:e} of {e0:e}"
        );
        if w.counters.capped_steps == capped {
            let ov = w.max_overlap_rel();
            prop_assert!(ov <= 1e-9, "overlap {ov:e}");
        } else {
            break;
        }
    }
    Ok(w)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(192),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_scenes_keep_every_invariant(
        seeds in prop::collection::vec(seed(), 0..40),
        dt_exp in -6.0..-0.5f64,
        steps in 1u64..12,
    ) {
        let w = scene(&seeds);
        check_run(&w, 10f64.powf(dt_exp), steps)?;
    }

    #[test]
    fn dense_mixed_scenes_keep_every_invariant(
        k in 2usize..8,
        packing in 0.4..0.52f64,
        seed in 0u64..1000,
        shrink in prop::collection::vec(0.85..1.0f64, 343),
        dt_exp in -4.0..-1.0f64,
    ) {
        // Lattice starts (the neighbour-list broad phase above packing 0.3),
        // radii shrunk at random so sizes differ.
        let mut w = ballpit::scene::lattice::lattice_world(k * k * k, packing, 1.0, seed).unwrap();
        for (s, f) in w.spheres.iter_mut().zip(&shrink) {
            *s = Sphere::new(s.pos, s.vel, s.radius * f);
        }
        check_run(&w, 10f64.powf(dt_exp), 6)?;
    }

    #[test]
    fn a_rebuilt_schedule_continues_the_same_physics(
        seeds in prop::collection::vec(seed(), 2..30),
        dt_exp in -3.0..-1.0f64,
    ) {
        // Splitting a run into advance calls (each re-checks the world) and
        // forcing a rebuild in the middle must keep every invariant.
        let w = scene(&seeds);
        let dt = 10f64.powf(dt_exp);
        let mut a = w.clone();
        let mut m = Exact::default();
        m.advance(&mut a, dt, 3, &Serial);
        a.touch();
        m.advance(&mut a, dt, 3, &Serial);
        prop_assert!(!a.has_non_finite());
        prop_assert_eq!(a.escaped(), 0);
        prop_assert!(a.max_overlap_rel() <= 1e-9);
        let e0 = w.kinetic_energy();
        prop_assert!((a.kinetic_energy() - e0).abs() <= 1e-10 * e0.max(f64::MIN_POSITIVE));
    }

    #[test]
    fn csv_scenes_either_load_and_run_or_say_why(
        rows in prop::collection::vec(
            (prop::array::uniform3(-0.2..1.2f64), prop::array::uniform3(-5.0..5.0f64),
             -0.1..0.3f64, -1.0..5.0f64, 0u8..8),
            0..12),
    ) {
        let mut text = String::from("x,y,z,vx,vy,vz,radius,mass\n");
        for (p, v, r, m, junk) in &rows {
            match junk {
                0 => text.push_str("1,2,three,4,5,6,7,8\n"),
                1 => text.push_str("0.5,0.5\n"),
                2 => text.push_str(&format!("{},{},{},NaN,0,0,{},{}\n", p[0], p[1], p[2], r, m)),
                _ => text.push_str(&format!(
                    "{},{},{},{},{},{},{},{}\n", p[0], p[1], p[2], v[0], v[1], v[2], r, m)),
            }
        }
        match csv_io::parse(&text, 1.0, "fuzz.csv") {
            Ok(w) => { check_run(&w, 1.0 / 60.0, 5)?; }
            Err(e) => prop_assert!(e.0.starts_with("fuzz.csv"), "{}", e.0),
        }
    }

    #[test]
    fn toml_scenes_either_load_and_run_or_say_why(
        preset in prop::sample::select(vec!["gas", "billiards", "dense", "cradle", "mixed", "projectiles", "nope"]),
        count in prop::option::of(0usize..300),
        radius in prop::option::of(-0.01..0.3f64),
        speed in prop::option::of(-1.0..50.0f64),
        size in prop::option::of(0.5..3.0f64),
        extra in 0u8..3,
    ) {
        let mut text = format!("preset = \"{preset}\"\n");
        if let Some(c) = count { text += &format!("count = {c}\n"); }
        if let Some(r) = radius { text += &format!("radius = {r}\n"); }
        if let Some(v) = speed { text += &format!("speed = {v}\n"); }
        if let Some(l) = size { text += &format!("box = {l}\n"); }
        match extra {
            1 => text += "colour = \"red\"\n",
            2 => text += "[[sphere]]\npos = [0.5, 0.5, 0.5]\nvel = [1.0, 0.0, 0.0]\nradius = 0.1\n",
            _ => {}
        }
        let dir = scratch("fuzz");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("s{}.toml", text.len() % 7));
        std::fs::write(&path, &text).unwrap();
        let spec = SceneSpec { scene: Some(path.display().to_string()), ..SceneSpec::default() };
        match build_world(&spec) {
            Ok(w) => {
                // Presets place touching spheres: rounding-level overlap only.
                prop_assert!(w.max_overlap_rel() <= 1e-12);
                let mut m = ModelKind::Exact.build();
                let mut x = w.clone();
                m.advance(&mut x, 1.0 / 60.0, 3, &Serial);
                prop_assert!(!x.has_non_finite());
                prop_assert_eq!(x.escaped(), 0);
                // A preset packed into a row touching both walls jams: the
                // cap reports it and the capped step's flight may overlap.
                if x.counters.capped_steps == 0 {
                    prop_assert!(x.max_overlap_rel() <= 1e-9);
                }
            }
            Err(e) => {
                // One line, naming what is wrong, checked in the order the
                // loader meets it: the file's fields, the preset, the
                // values, then whether the spheres fit.
                let msg = &e.0;
                prop_assert_eq!(msg.lines().count(), 1, "{}", msg);
                let want: &[&str] = if extra == 1 {
                    &["colour"]
                } else if extra == 2 {
                    // Explicit spheres replace the preset's: the sphere or
                    // the box it does not fit.
                    &["sphere 1", "box"]
                } else if preset == "nope" {
                    &["'nope'"]
                } else if radius.is_some_and(|r| r <= 0.0) {
                    &["radius"]
                } else if speed.is_some_and(|v| v < 0.0) {
                    &["speed"]
                } else {
                    &["cannot fit", "too big", "needs", "outside the cube"]
                };
                prop_assert!(want.iter().any(|w| msg.contains(w)), "{:?} not in: {}", want, msg);
            }
        }
    }
}
