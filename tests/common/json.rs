//! `ballpit bench`'s one line of JSON, for the test files that read its
//! fields: the built binary run with `bench` and the arguments, its exit
//! checked (stderr in the message), its stdout parsed.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use std::io::Read;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn command(args: &[&str]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.arg("bench").args(args);
    cmd
}

/// The stdout of a run that exited 0.
fn stdout(args: &[&str], out: Output, took: &str) -> String {
    assert!(
        out.status.success(),
        "bench {args:?}: {}{took} {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The line `ballpit bench args` prints, as written (its keys in their
/// printed order).
pub fn bench_line(args: &[&str]) -> String {
    stdout(args, command(args).output().unwrap(), "")
}

/// The JSON of `ballpit bench args`.
pub fn bench(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&bench_line(args)).unwrap()
}

/// The JSON of `ballpit bench args`; a run still going at `deadline` is
/// killed and fails.
pub fn bench_within(args: &[&str], deadline: Duration) -> serde_json::Value {
    let mut child = command(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > deadline {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("bench {args:?} still running after {deadline:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let took = start.elapsed();
    // One line of JSON and a few of warnings: read once the run is over.
    let (mut out, mut err) = (Vec::new(), Vec::new());
    child.stdout.take().unwrap().read_to_end(&mut out).unwrap();
    child.stderr.take().unwrap().read_to_end(&mut err).unwrap();
    let out = Output {
        status,
        stdout: out,
        stderr: err,
    };
    let line = stdout(args, out, &format!(" after {took:.1?}"));
    eprintln!("bench {args:?}: {took:.1?}");
    serde_json::from_str(&line).unwrap()
}
