//! Issue 27, item 7: the memory estimate counts the process's fixed cost
//! once, so a tiny run under a tight address-space limit is not refused
//! ("0 spheres would need about 64 MiB ... of the 58 MiB available"), and a
//! large one still is, with the figure.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test

fn bench_under_60_mb(args: &str) -> (Option<i32>, String) {
    let line = format!(
        "ulimit -v 60000; exec {} bench --steps 10 {args}",
        env!("CARGO_BIN_EXE_ballpit")
    );
    let out = std::process::Command::new("sh")
        .args(["-c", &line])
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn tiny_runs_fit_under_ulimit_v_60000_and_large_ones_are_refused() {
    for count in ["0", "1", "1000"] {
        let (code, err) = bench_under_60_mb(&format!("--count {count}"));
        assert_eq!(code, Some(0), "--count {count}: {err}");
    }
    let (code, err) = bench_under_60_mb("--count 200000 --radius 0.002");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.starts_with("ballpit: 200000 spheres would need about ")
            && err.contains("16 MiB for the process"),
        "{err}"
    );
}
