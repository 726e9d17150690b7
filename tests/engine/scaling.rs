//! `ballpit scaling` on a tiny scene: the table with every column and every
//! configuration, the CSV and SVG written, a fitted fraction within [0, 1],
//! the same bits in every mode, a progress bar on a terminal, and bad input.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::{ballpit, scratch};
use crate::common::pty;

use ballpit::engine::Threading;
use ballpit::scaling::{CSV_COLUMNS, configs};
use std::path::PathBuf;
use std::time::Duration;

const TINY: [&str; 8] = [
    "--count",
    "300",
    "--rounds",
    "1",
    "--seconds",
    "0.05",
    "--threads",
    "2",
];

fn scaling(args: &[&str]) -> std::process::Output {
    ballpit()
        .arg("scaling")
        .args(args)
        .timeout(Duration::from_mins(2))
        .output()
        .unwrap()
}

/// The tiny sweep on `count` spheres into a scratch `out`: the scratch
/// directory, `out` and the table printed.
fn tiny_sweep(name: &str, count: &str) -> (PathBuf, PathBuf, String) {
    let dir = scratch(name);
    let out_dir = dir.join("out");
    let mut args = TINY.to_vec();
    args[1] = count;
    args.extend(["--out", out_dir.to_str().unwrap()]);
    let out = scaling(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (dir, out_dir, String::from_utf8(out.stdout).unwrap())
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
}

#[test]
fn a_tiny_sweep_prints_every_column_and_writes_csv_and_svg() {
    let (dir, out_dir, table) = tiny_sweep("scaling", "300");
    for col in [
        "mode",
        "threads",
        "steps/s",
        "speed-up over off",
        "efficiency",
        "physics CPU s",
        "serial fraction, measured",
        "Karp–Flatt",
    ] {
        assert!(table.contains(col), "no column {col}:\n{table}");
    }
    // A row per configuration: off, worker, split, pools of 1, 2 and 4.
    let sweep = configs(2);
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| mode"))
        .collect();
    assert_eq!(rows.len(), sweep.len(), "{table}");
    for (row, c) in rows.iter().zip(&sweep) {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!(cells[1], c.threading.name(), "{row}");
        assert_eq!(cells[2], c.threads.to_string(), "{row}");
        let rate: f64 = cells[4].parse().unwrap();
        assert!(rate > 0.0, "{row}");
    }
    assert!(
        rows[0].contains("1.00×"),
        "off is its own base: {}",
        rows[0]
    );
    assert!(
        table.contains("Every run ended in the same bits as off."),
        "{table}"
    );
    let csv = std::fs::read_to_string(out_dir.join("scaling.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), CSV_COLUMNS.join(","));
    let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(body.iter().all(|r| r.len() == CSV_COLUMNS.len()), "{csv}");
    let measured: Vec<&Vec<&str>> = body.iter().filter(|r| r[0] != "predicted").collect();
    assert_eq!(measured.len(), sweep.len(), "{csv}");
    assert!(measured.iter().all(|r| r[13] == "true"), "same bits: {csv}");
    fractions_within_0_and_1(&measured, &csv);
    let pools = measured
        .iter()
        .filter(|r| r[0] == Threading::Pool.name())
        .count();
    assert_eq!(pools, 3, "{csv}");
    let predicted = body.len() - measured.len();
    assert_eq!(predicted, if cores() >= 2 { 3 } else { 0 }, "{csv}");
    if cores() >= 2 {
        the_fit_lies_among_the_pools_fractions(&table, &body);
    } else {
        assert!(table.contains("no serial fraction to fit"), "{table}");
    }

    let svg = std::fs::read_to_string(out_dir.join("scaling.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("speed-up over off"),
        "{svg:.200}"
    );
    assert!(svg.contains("pool, measured"), "{svg:.200}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The CSV's measured serial fraction and Karp–Flatt cells: empty or in
/// [0, 1], however slow a pool ran.
fn fractions_within_0_and_1(rows: &[&Vec<&str>], csv: &str) {
    for r in rows {
        for cell in [r[11], r[12]] {
            if !cell.is_empty() {
                let f: f64 = cell.parse().unwrap();
                assert!((0.0..=1.0).contains(&f), "{cell} in {csv}");
            }
        }
    }
}

/// The fit is a weighted mean of the fitted pools' Karp–Flatt fractions
/// (clamped to [0, 1]): the printed fraction lies between the least and
/// the greatest of them, and it is the one the CSV's predictions come from.
fn the_fit_lies_among_the_pools_fractions(table: &str, body: &[Vec<&str>]) {
    let f: f64 = table
        .split("serial fraction ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    let num = |c: &str| c.parse::<f64>().unwrap();
    let kf = |s: f64, p: f64| ((1.0 / s - 1.0 / p) / (1.0 - 1.0 / p)).clamp(0.0, 1.0);
    let fitted: Vec<f64> = body
        .iter()
        .filter(|r| r[0] == Threading::Pool.name())
        .filter(|r| num(r[2]) > 1.0 && num(r[1]) <= cores() as f64)
        .map(|r| kf(num(r[7]), num(r[2])))
        .collect();
    assert!(!fitted.is_empty(), "{table}");
    let lo = fitted.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = fitted.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        lo - 5e-4 <= f && f <= hi + 5e-4,
        "fit {f} outside the pools' fractions {fitted:?}:\n{table}"
    );
    let at16 = body.iter().find(|r| r[0] == "predicted" && r[1] == "16");
    let from_prediction = kf(num(at16.unwrap()[7]), 16.0);
    assert!(
        (from_prediction - f).abs() <= 5e-4,
        "the predictions come from {from_prediction}, the table says {f}:\n{table}"
    );
    assert!(
        table.contains("Predicted by that fit, not measured"),
        "{table}"
    );
    for c in ["16 cores", "64 cores", "128 cores"] {
        assert!(table.contains(c), "{table}");
    }
}

#[test]
fn an_empty_scene_is_refused_with_the_range() {
    let out = scaling(&["--count", "0"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--count must be 1 to 10000000"), "{err}");
    assert_eq!(err.lines().count(), 1, "one message: {err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn one_sphere_is_said_to_have_nothing_to_share() {
    let (dir, out_dir, table) = tiny_sweep("scaling-one", "1");
    let says: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("Nothing to share: "))
        .collect();
    assert_eq!(says.len(), 1, "{table}");
    assert!(says[0].contains("on 1 sphere") || cores() < 2, "{table}");
    // Before the table, not after it.
    assert!(table.find("Nothing to share").unwrap() < table.find("| mode").unwrap());
    assert!(!table.contains("packing -"), "{table}");
    let csv = std::fs::read_to_string(out_dir.join("scaling.csv")).unwrap();
    let body: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let measured: Vec<&Vec<&str>> = body.iter().filter(|r| r[0] != "predicted").collect();
    assert_eq!(measured.len(), configs(2).len(), "{csv}");
    fractions_within_0_and_1(&measured, &csv);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_is_one_message_and_exit_2() {
    for (args, says) in [
        (vec!["--rounds", "0"], "--rounds"),
        (vec!["--seconds", "0"], "--seconds"),
        (vec!["--seconds", "nan"], "--seconds"),
        (vec!["--threads", "0"], "--threads"),
        (vec!["--dt", "-1"], "--dt"),
        (vec!["--count", "1000", "--radius", "0.4"], "cannot fit"),
        (
            vec!["--count", "100", "--out", "/dev/null/x"],
            "cannot create directory",
        ),
    ] {
        let out = scaling(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn on_a_terminal_a_progress_bar_counts_the_runs() {
    let args = [
        "scaling",
        "--count",
        "2000",
        "--rounds",
        "3",
        "--seconds",
        "0.3",
        "--threads",
        "2",
    ];
    let mut app = pty::start(&args, None);
    let runs = 1 + 3 * configs(2).len();
    let shown = app.wait_for("the progress bar", 60.0, |s| {
        s.contains(&format!("/{runs} runs"))
    });
    assert!(shown.contains("round"), "{shown}");
    let end = app.wait_exit(120.0).expect("scaling finishes");
    assert!(end.success(), "{end:?}");
    let text = app.wait_for("the table", 10.0, |s| s.contains("same bits as off"));
    assert!(
        !text.contains(" runs, "),
        "the bar is cleared at the end:\n{text}"
    );
}
