//! Command-line messages that must match the data and give advice that
//! works: empty scene files, huge numbers, flags that do nothing, flags in
//! the wrong place, the no-terminal message.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::{ballpit, scratch};
use crate::common::json;

/// Stderr and exit code of `ballpit args`, stdin empty.
fn run(args: &[&str]) -> (String, Option<i32>, Vec<u8>) {
    let out = ballpit().args(args).write_stdin("").output().unwrap();
    (
        String::from_utf8_lossy(&out.stderr).into_owned(),
        out.status.code(),
        out.stdout,
    )
}

fn temp(name: &str, text: &str) -> std::path::PathBuf {
    let dir = scratch("msg");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn empty_scene_files_are_an_error_with_one_message() {
    for (name, text, want) in [
        ("empty.toml", "", "the file is empty"),
        ("comments.toml", "# nothing\n\n", "the file is empty"),
        ("empty.csv", "", "the file is empty"),
        (
            "header.csv",
            "x,y,z,vx,vy,vz,radius,mass\n",
            "a header and no spheres",
        ),
    ] {
        let path = temp(name, text);
        let p = path.to_str().unwrap();
        let (err, code, out) = run(&["bench", "--scene", p, "--steps", "1"]);
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(err.contains(want), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(out.is_empty(), "{name}");
    }
}

#[test]
fn a_huge_count_in_toml_is_printed_at_a_sane_width() {
    let path = temp("big.toml", "count = 1e308\n");
    let (err, code, _) = run(&["bench", "--scene", path.to_str().unwrap(), "--steps", "1"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("`1e308`"), "{err}");
    assert!(err.len() < 200, "{err}");
}

#[test]
fn zero_energy_from_tiny_masses_is_not_called_at_rest() {
    // Moving at 0.1 box/s, but 0.5 m v^2 underflows to 0 in f64.
    let path = temp(
        "tiny.csv",
        "x,y,z,vx,vy,vz,radius,mass\n0.5,0.5,0.5,0.1,0,0,0.1,5e-324\n",
    );
    let v = json::bench(&["--scene", path.to_str().unwrap(), "--steps", "1"]);
    let w = v["warnings"].to_string();
    assert!(!w.contains("every sphere is at rest"), "{w}");
    assert!(w.contains("kinetic energy is 0"), "{w}");
    assert!(w.contains("too small"), "{w}");
}

#[test]
fn threads_without_the_pool_warns_and_runs() {
    let (err, code, out) = run(&["bench", "--threads", "4", "--steps", "1", "--count", "10"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: --threads 4 does nothing with --threading off"),
        "{err}"
    );
    assert!(!out.is_empty());
    let (err, code, _) = run(&[
        "bench",
        "--threading",
        "pool",
        "--threads",
        "2",
        "--steps",
        "1",
        "--count",
        "10",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn advice_for_flags_before_bench_works_when_followed() {
    let (err, code, _) = run(&[
        "--color", "256", "--fps", "60", "--model", "exact", "bench", "--steps", "1",
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--model must come after `bench`"), "{err}");
    assert!(
        err.contains("--fps, --color are the terminal app's and do nothing for `bench`: drop them"),
        "{err}"
    );
    // Doing what it says: --model after bench, --fps and --color dropped.
    let (err, code, _) = run(&["bench", "--model", "exact", "--steps", "1", "--count", "10"]);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn the_no_terminal_message_names_ballpit_once_and_its_advice_runs() {
    let (err, code, _) = run(&["--count", "10"]);
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(
        err.matches("ballpit").count(),
        2,
        "the prefix and the command: {err}"
    );
    assert!(!err.contains("ballpit's"), "{err}");
    let advice = err.split('`').nth(1).expect("a command in backticks");
    let args: Vec<&str> = advice.split_whitespace().skip(1).collect();
    let (err, code, out) = run(&[&args[..], &["--count", "10"]].concat());
    assert_eq!(code, Some(0), "`{advice}`: {err}");
    assert!(!out.is_empty());
}

#[test]
fn the_man_page_has_keys_and_no_pages_it_does_not_ship() {
    let out = ballpit().arg("man").output().unwrap();
    assert!(out.status.success());
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(page.contains(".SH KEYS"), "{page}");
    for b in ballpit::tui::keys::TABLE {
        let help = b.help.replace('-', "\\-");
        assert!(page.contains(&help), "KEYS lacks `{}`", b.help);
    }
    // Only ballpit(1) is generated: no reference to another page.
    assert!(!page.contains("(1)"), "{page}");
    assert!(!page.contains("ballpit\\-bench"), "{page}");
    for sub in ["BALLPIT BENCH", "BALLPIT TRADEOFF", "EXIT STATUS"] {
        assert!(page.contains(sub), "no {sub}");
    }
    assert!(
        page.contains("\\-\\-steps"),
        "bench's options are in the page"
    );
}
