//! `ballpit bench`'s one line of JSON, for the test files that read its
//! fields: the built binary run with `bench` and the arguments, its exit
//! checked (stderr in the message), its stdout parsed.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use std::time::{Duration, Instant};

/// The stdout of `ballpit bench args` that exited 0; with a `deadline`, a
/// run still going then is killed and fails.
fn run(args: &[&str], deadline: Option<Duration>) -> String {
    let mut cmd = assert_cmd::Command::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.arg("bench").args(args);
    if let Some(d) = deadline {
        cmd.timeout(d);
    }
    let start = Instant::now();
    let out = cmd.output().unwrap();
    let took = start.elapsed();
    let within = deadline.map_or(String::new(), |d| format!(" (deadline {d:?})"));
    assert!(
        out.status.success(),
        "bench {args:?}: {} after {took:.1?}{within} {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    if deadline.is_some() {
        eprintln!("bench {args:?}: {took:.1?}");
    }
    String::from_utf8(out.stdout).unwrap()
}

/// The line `ballpit bench args` prints, as written (its keys in their
/// printed order).
pub fn bench_line(args: &[&str]) -> String {
    run(args, None)
}

/// The JSON of `ballpit bench args`.
pub fn bench(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&run(args, None)).unwrap()
}

/// The JSON of `ballpit bench args`, run killed and failed at `deadline`.
pub fn bench_within(args: &[&str], deadline: Duration) -> serde_json::Value {
    serde_json::from_str(&run(args, Some(deadline))).unwrap()
}
