//! Threads the system will not create (`ulimit -v`): at start-up one
//! message naming what failed and exit 2; while running, the app keeps the
//! threads it has and says so.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::pty;

use portable_pty::CommandBuilder;

/// Enough address space for the app, not for 256 more thread stacks.
const LIMIT: &str = "ulimit -v 400000";

#[test]
fn at_start_up_a_refused_pool_is_one_message_and_exit_2() {
    let bin = env!("CARGO_BIN_EXE_ballpit");
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!(
            "{LIMIT}; exec {bin} bench --threading pool --threads 256 --steps 10 --count 100"
        ))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cannot start 256 pool threads"), "{err}");
    assert_eq!(err.matches("os error").count(), 1, "the cause once: {err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn while_running_a_refused_pool_is_a_notice_and_the_app_goes_on() {
    let bin = env!("CARGO_BIN_EXE_ballpit");
    let mut cmd = CommandBuilder::new("bash");
    cmd.arg("-c");
    cmd.arg(format!(
        "{LIMIT}; exec {bin} --threading worker --threads 256"
    ));
    let mut app = pty::start_command(cmd, None, (40, 120), "xterm-256color");
    app.wait_for("the first frame", 20.0, |s| s.contains("threading"));
    app.send("d");
    let shown = app.wait_for("the notice", 20.0, |s| s.contains("refused 256 pool"));
    assert!(shown.contains("running on worker"), "{shown}");
    // Back on worker, and the app still answers keys.
    app.wait_for("worker", 10.0, |s| s.contains("threading  worker"));
    assert!(app.alive(), "the app ended:\n{shown}");
    app.send("t");
    app.wait_for("threading off", 10.0, |s| s.contains("threading  off"));
    app.quit();
}
