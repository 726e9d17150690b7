//! `ballpit tradeoff` end to end on a small scene.
use assert_cmd::Command;
use ballpit::physics::ModelKind;
use ballpit::scene::{SceneSpec, build_world};
use ballpit::tradeoff::{LADDER, measure};

#[test]
fn table_ranks_the_models_as_their_contracts_say() {
    let world = build_world(&SceneSpec {
        count: Some(150),
        radius: Some(0.04),
        ..SceneSpec::default()
    })
    .unwrap();
    let rows = measure(&world);
    assert_eq!(rows.len(), ModelKind::ALL.len() * LADDER.len());
    for r in &rows {
        assert!(r.cost > 0.0 && r.sphere_steps_per_second > 0.0);
        assert!(r.energy_err.is_finite() && r.pos_err.is_finite());
        assert!(r.horizon >= r.dt);
    }
    let get = |m: ModelKind, dt: f64| rows.iter().find(|r| r.model == m && r.dt == dt).unwrap();
    for dt in LADDER {
        let e = get(ModelKind::Exact, dt);
        // Exact against itself: rounding only, never an overlap or an escape.
        assert!(e.pos_err < 1e-12, "{e:?}");
        assert!(e.max_overlap_rel <= 1e-10 && e.escaped == 0 && e.energy_err < 1e-12);
        assert!(e.missed.abs() < 0.1, "{e:?}");
        let s = get(ModelKind::Swept, dt);
        assert!(s.escaped == 0 && s.energy_err < 1e-12);
    }
    // Discrete at the coarsest step overlaps deeply and misses or repeats
    // contacts; refining dt shrinks both its overlap and position error.
    let coarse = get(ModelKind::Discrete, LADDER[0]);
    let fine = get(ModelKind::Discrete, LADDER[LADDER.len() - 1]);
    assert!(coarse.max_overlap_rel > 0.1, "{coarse:?}");
    assert!(fine.max_overlap_rel < coarse.max_overlap_rel / 8.0);
    assert!(fine.pos_err < coarse.pos_err / 8.0);
    assert!(coarse.pos_err > 1e-6);
}

#[test]
fn cli_writes_the_table_the_csv_and_the_plot() {
    let dir = std::env::temp_dir().join(format!("ballpit-tradeoff-{}", std::process::id()));
    let out = Command::cargo_bin("ballpit")
        .unwrap()
        .args(["tradeoff", "--count", "60", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).unwrap();
    assert_eq!(table.lines().count(), 2 + 3 * LADDER.len());
    assert!(table.contains("| exact | 1/1920 |"));
    let csv = std::fs::read_to_string(dir.join("tradeoff.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * LADDER.len());
    let svg = std::fs::read_to_string(dir.join("tradeoff.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("discrete") && svg.contains("exact"));
    let _ = std::fs::remove_dir_all(&dir);
    // Bad scene flags: exit code 2 and one message.
    let bad = Command::cargo_bin("ballpit")
        .unwrap()
        .args(["tradeoff", "--count", "10", "--radius", "0.6"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
