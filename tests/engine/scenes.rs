//! Presets, placement, CSV round trip, TOML files.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::scratch;
use ballpit::physics::sphere::volume;
use ballpit::scene::csv_io;
use ballpit::scene::presets::PRESETS;
use ballpit::scene::{SceneSpec, build_world};

fn spec(scene: &str) -> SceneSpec {
    SceneSpec {
        scene: Some(scene.into()),
        ..Default::default()
    }
}

fn packing(w: &ballpit::physics::World) -> f64 {
    w.spheres.iter().map(|s| volume(s.radius)).sum::<f64>() / w.size.powi(3)
}

#[test]
fn every_preset_is_valid_and_reproducible() {
    for p in PRESETS {
        let a = build_world(&spec(p.name)).unwrap();
        assert_eq!(a.spheres.len(), p.count, "{}", p.name);
        assert_eq!(a.escaped(), 0, "{}", p.name);
        assert!(a.max_overlap_rel() < 1e-9, "{}", p.name);
        assert!(a.kinetic_energy() > 0.0, "{}", p.name);
        assert_eq!(
            a,
            build_world(&spec(p.name)).unwrap(),
            "{} is not reproducible",
            p.name
        );
    }
}

#[test]
fn dense_reaches_its_packing_fraction_and_mixed_spreads_radii() {
    let dense = build_world(&spec("dense")).unwrap();
    assert!((packing(&dense) - 0.4).abs() < 1e-3, "{}", packing(&dense));
    let mixed = build_world(&spec("mixed")).unwrap();
    let (lo, hi) = mixed
        .spheres
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), s| {
            (lo.min(s.radius), hi.max(s.radius))
        });
    assert!(hi / lo > 50.0 && hi / lo <= 100.0, "spread {}", hi / lo);
}

#[test]
fn gas_speed_is_the_rms_speed_with_no_net_momentum() {
    let w = build_world(&SceneSpec {
        speed: Some(0.7),
        ..spec("gas")
    })
    .unwrap();
    let ms = w
        .spheres
        .iter()
        .map(|s| s.vel.length_squared())
        .sum::<f64>()
        / w.spheres.len() as f64;
    assert!((ms.sqrt() - 0.7).abs() < 1e-12);
    assert!(w.momentum().length() < 1e-12 * w.spheres.len() as f64);
}

#[test]
fn impossible_counts_say_they_cannot_fit() {
    let err = build_world(&SceneSpec {
        count: Some(5000),
        radius: Some(0.05),
        ..spec("gas")
    })
    .unwrap_err();
    assert!(err.0.contains("cannot fit 5000 spheres"), "{err}");
}

#[test]
fn csv_round_trip_is_bit_exact() {
    let w = build_world(&spec("mixed")).unwrap();
    let mut text = Vec::new();
    csv_io::write(&w, &mut text).unwrap();
    let back = csv_io::parse(std::str::from_utf8(&text).unwrap(), 1.0, "t.csv").unwrap();
    assert_eq!(back.spheres.len(), w.spheres.len());
    for (a, b) in w.spheres.iter().zip(&back.spheres) {
        assert_eq!(
            a.pos.to_array().map(f64::to_bits),
            b.pos.to_array().map(f64::to_bits)
        );
        assert_eq!(
            a.vel.to_array().map(f64::to_bits),
            b.vel.to_array().map(f64::to_bits)
        );
        assert_eq!(a.radius.to_bits(), b.radius.to_bits());
        assert_eq!(a.mass.to_bits(), b.mass.to_bits());
    }
}

#[test]
fn csv_errors_name_the_line() {
    let head = "x,y,z,vx,vy,vz,radius,mass\n";
    let cases = [
        (
            "0.5,0.5,0.5,0,0,0,0.1,1\n0.5,0.5,abc,0,0,0,0.1,1\n",
            "line 3: z = `abc` is not a number",
        ),
        (
            "0.5,0.5,0.5,0,0,0,-0.1,1\n",
            "line 2: radius must be positive",
        ),
        ("0.5,0.5,0.5,0,0,0,0.1,0\n", "line 2: mass must be positive"),
        (
            "0.5,0.5,0.5,NaN,0,0,0.1,1\n",
            "line 2: a value is not a finite number",
        ),
        ("0.95,0.5,0.5,0,0,0,0.1,1\n", "line 2: sphere at"),
        (
            "0.5,0.5,0.5,0,0,0,0.1,1\n0.6,0.5,0.5,0,0,0,0.1,1\n",
            "t.csv: line 2 and line 3 overlap",
        ),
        ("0.5,0.5,0.5,0,0,0,0.1\n", "line 2"),
    ];
    for (body, want) in cases {
        let err = csv_io::parse(&format!("{head}{body}"), 1.0, "t.csv").unwrap_err();
        assert!(err.0.contains(want), "{body:?}: got `{err}`, want `{want}`");
    }
    let err = csv_io::parse("x,y,z\n1,2,3\n", 1.0, "t.csv").unwrap_err();
    assert!(err.0.contains("line 1: header must be"), "{err}");
    // Touching spheres are allowed.
    let ok = csv_io::parse(
        &format!("{head}0.3,0.5,0.5,0,0,0,0.1,1\n0.5,0.5,0.5,0,0,0,0.1,1\n"),
        1.0,
        "t.csv",
    );
    assert!(ok.is_ok(), "{ok:?}");
}

#[test]
fn toml_scene_files_override_presets_and_list_spheres() {
    let dir = scratch("toml");
    std::fs::create_dir_all(&dir).unwrap();
    let a = dir.join("a.toml");
    std::fs::write(&a, "preset = \"billiards\"\ncount = 3\nspeed = 0.25\n").unwrap();
    let w = build_world(&spec(a.to_str().unwrap())).unwrap();
    assert_eq!(w.spheres.len(), 3);
    assert!(
        w.spheres
            .iter()
            .all(|s| (s.vel.length() - 0.25).abs() < 1e-12)
    );
    let b = dir.join("b.toml");
    std::fs::write(&b, "box = 2.0\n[[sphere]]\npos = [1.0, 1.0, 1.0]\nvel = [0.5, 0, 0]\nradius = 0.2\nmass = 3.0\n").unwrap();
    let w = build_world(&spec(b.to_str().unwrap())).unwrap();
    assert_eq!((w.size, w.spheres.len(), w.spheres[0].mass), (2.0, 1, 3.0));
    let c = dir.join("c.toml");
    std::fs::write(&c, "count = 3\ncolour = \"red\"\n").unwrap();
    let err = build_world(&spec(c.to_str().unwrap())).unwrap_err();
    assert!(
        err.0.contains("line 2") && err.0.contains("colour"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
