//! `ballpit scaling` on a tiny scene: the table with every column and every
//! configuration, the CSV and SVG written, a fitted fraction within [0, 1],
//! the same bits in every mode, a progress bar on a terminal, and bad input.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::{ballpit, scratch};
use crate::common::pty;

use ballpit::engine::Threading;
use ballpit::scaling::{CSV_COLUMNS, configs};
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

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
}

#[test]
fn a_tiny_sweep_prints_every_column_and_writes_csv_and_svg() {
    let dir = scratch("scaling");
    let out_dir = dir.join("out");
    let mut args = TINY.to_vec();
    args.extend(["--out", out_dir.to_str().unwrap()]);
    let out = scaling(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).unwrap();
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
    if cores() >= 2 {
        let f: f64 = table
            .split("serial fraction ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .unwrap()
            .parse()
            .unwrap();
        assert!((0.0..=1.0).contains(&f), "fitted fraction {f}");
        assert!(
            table.contains("Predicted by that fit, not measured"),
            "{table}"
        );
        for c in ["16 cores", "64 cores", "128 cores"] {
            assert!(table.contains(c), "{table}");
        }
    } else {
        assert!(table.contains("no serial fraction to fit"), "{table}");
    }

    let csv = std::fs::read_to_string(out_dir.join("scaling.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), CSV_COLUMNS.join(","));
    let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(body.iter().all(|r| r.len() == CSV_COLUMNS.len()), "{csv}");
    let measured: Vec<&Vec<&str>> = body.iter().filter(|r| r[0] != "predicted").collect();
    assert_eq!(measured.len(), sweep.len(), "{csv}");
    assert!(measured.iter().all(|r| r[12] == "true"), "same bits: {csv}");
    let pools = measured
        .iter()
        .filter(|r| r[0] == Threading::Pool.name())
        .count();
    assert_eq!(pools, 3, "{csv}");
    let predicted = body.len() - measured.len();
    assert_eq!(predicted, if cores() >= 2 { 3 } else { 0 }, "{csv}");

    let svg = std::fs::read_to_string(out_dir.join("scaling.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("speed-up over off"),
        "{svg:.200}"
    );
    assert!(svg.contains("pool, measured"), "{svg:.200}");
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
