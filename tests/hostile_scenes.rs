//! Hostile scene input: every kind gets one clear message naming what the
//! user gave (a flag, a file's key, a file's line), exit code 2, and no
//! panic, allocation blow-up or quadratic placement.
use assert_cmd::Command;
use ballpit::scene::{SceneSpec, build_world, csv_io, toml_file};
use std::time::{Duration, Instant};

fn ballpit() -> Command {
    let mut c = Command::cargo_bin("ballpit").unwrap();
    c.timeout(Duration::from_secs(30));
    c
}

/// Runs `bench` with `args` and returns (exit code, stderr).
fn bench(args: &[&str]) -> (i32, String) {
    let out = ballpit()
        .arg("bench")
        .args(args)
        .args(["--steps", "1"])
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn refused(args: &[&str], want: &str) {
    let (code, err) = bench(args);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert!(err.contains(want), "{args:?}: got `{err}`, want `{want}`");
    assert_eq!(err.trim().lines().count(), 1, "one message: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_tiny_radius_on_a_lattice_neither_aborts_nor_allocates_the_lattice() {
    // The dense preset used to list every site of a (L/2r)^3 lattice:
    // 10^12 slots for r = 1e-4.
    for radius in ["0.0001", "0.0005", "1e-9"] {
        let (code, err) = bench(&["--scene", "dense", "--count", "10", "--radius", radius]);
        assert_eq!(code, 0, "--radius {radius}: {err}");
    }
    let w = build_world(&SceneSpec {
        scene: Some("dense".into()),
        count: Some(1000),
        radius: Some(1e-6),
        ..SceneSpec::default()
    })
    .unwrap();
    assert_eq!(
        (w.spheres.len(), w.escaped(), w.max_overlap_rel()),
        (1000, 0, 0.0)
    );
}

#[test]
fn random_placement_at_tiny_radii_stays_fast() {
    // A cell index that saturated put every sphere in one cell: quadratic.
    let t = Instant::now();
    let w = build_world(&SceneSpec {
        count: Some(200_000),
        radius: Some(1e-11),
        ..SceneSpec::default()
    })
    .unwrap();
    assert_eq!(
        (w.spheres.len(), w.escaped(), w.max_overlap_rel()),
        (200_000, 0, 0.0)
    );
    // Not a speed figure: a quadratic placement takes minutes, this well
    // under a second.
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
}

#[test]
fn lengths_outside_what_f64_holds_are_refused_by_their_flag() {
    refused(&["--box", "1e-80"], "--box 1e-80 is outside");
    refused(&["--box", "1e100"], "--box 1e100 is outside");
    refused(&["--radius", "1e-110"], "--radius 1e-110 is outside");
    refused(
        &["--radius", "1e-13"],
        "--radius 0.0000000000001 is too small",
    );
    refused(&["--speed", "1e-300"], "--speed 1e-300 is too small");
    // Edges that stay valid.
    assert_eq!(bench(&["--box", "1e30"]).0, 0);
    assert_eq!(bench(&["--count", "100", "--radius", "1e-11"]).0, 0);
}

#[test]
fn scene_file_values_are_blamed_on_the_file_not_a_flag() {
    let dir = tempdir();
    let toml = dir.join("big.toml");
    std::fs::write(&toml, "radius = 2\n").unwrap();
    let path = toml.to_str().unwrap();
    refused(&["--scene", path], &format!("{path}: radius 2 is too big"));
    // The same value given as a flag is the flag's.
    refused(
        &["--scene", path, "--radius", "0.7"],
        "--radius 0.7 is too big",
    );
    std::fs::write(&toml, "box = 1e-90\n").unwrap();
    refused(&["--scene", path], &format!("{path}: box 1e-90 is outside"));
}

#[test]
fn toml_vectors_need_exactly_three_numbers() {
    for (pos, found) in [("[0.5, 0.5, 0.5, 0.1]", 4), ("[0.5, 0.5]", 2)] {
        let text = format!("[[sphere]]\npos = {pos}\nradius = 0.1\n");
        let err = toml_file::parse(&text, "s.toml").unwrap_err();
        assert!(
            err.0.contains(&format!(
                "s.toml line 2: expected 3 numbers [x, y, z], found {found}"
            )),
            "{err}"
        );
    }
    let err = toml_file::parse(
        "[[sphere]]\npos = [0.5, 0.5, 0.5]\nvel = [1, 2, 3, 4]\nradius = 0.1\n",
        "s.toml",
    )
    .unwrap_err();
    assert!(err.0.contains("line 3: expected 3 numbers"), "{err}");
}

#[test]
fn csv_messages_count_crlf_lines_name_bad_utf8_and_the_file_once() {
    let head = "x,y,z,vx,vy,vz,radius,mass";
    let lf = format!("{head}\n0.5,0.5,0.5,0,0,0,0.1,1\n0.2,0.2,0.2,0,0,0,-0.1,1\n");
    let crlf = lf.replace('\n', "\r\n");
    for text in [&lf, &crlf] {
        let err = csv_io::parse(text, 1.0, "s.csv").unwrap_err();
        assert!(
            err.0.starts_with("s.csv line 3: radius must be positive"),
            "{err}"
        );
    }
    let overlap = format!("{head}\r\n0.5,0.5,0.5,0,0,0,0.1,1\r\n0.55,0.5,0.5,0,0,0,0.1,1\r\n");
    let err = csv_io::parse(&overlap, 1.0, "s.csv").unwrap_err();
    assert!(
        err.0.starts_with("s.csv: line 2 and line 3 overlap"),
        "{err}"
    );
    assert_eq!(err.0.matches("s.csv").count(), 1, "{err}");
    // A radius of exactly half the box is refused, as `--radius 0.5` is.
    let half = format!("{head}\n0.5,0.5,0.5,0,0,0,0.5,1\n");
    let err = csv_io::parse(&half, 1.0, "s.csv").unwrap_err();
    assert!(err.0.contains("line 2: radius 0.5 does not fit"), "{err}");

    let dir = tempdir();
    let bad = dir.join("bad.csv");
    let mut bytes = format!("{head}\n0.5,0.5,0.5,0,0,0,0.1,1\n0.2,0.2,0.").into_bytes();
    bytes.extend_from_slice(b"\xff,0,0,0,0.1,1\n");
    std::fs::write(&bad, bytes).unwrap();
    let path = bad.to_str().unwrap();
    refused(
        &["--scene", path],
        &format!("{path} line 3: not UTF-8 text"),
    );
}

/// A fresh directory under the target dir (no tempfile crate needed).
fn tempdir() -> std::path::PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let d = std::env::temp_dir().join(format!(
        "ballpit-hostile-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}
