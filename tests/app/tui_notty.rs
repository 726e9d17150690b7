//! Started without a terminal, the app says so and exits 2.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::ballpit;

#[test]
fn without_a_tty_it_suggests_bench_and_exits_2() {
    let out = ballpit()
        .write_stdin("")
        .timeout(std::time::Duration::from_secs(10))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("terminal") && err.contains("ballpit bench"),
        "{err}"
    );
    // Nothing was drawn: no escape sequences on stdout.
    assert!(
        !out.stdout.contains(&0x1b),
        "{:?}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn a_bad_fps_or_colour_is_bad_input() {
    for (flag, value, says) in [("--fps", "0", "--fps"), ("--color", "99", "--color")] {
        let out = ballpit()
            .args([flag, value])
            .write_stdin("")
            .timeout(std::time::Duration::from_secs(10))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{flag} {value}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{err}");
    }
}
